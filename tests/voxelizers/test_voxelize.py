"""voxelize: refine, interior, normals, progress, memory limits and bad input."""
from __future__ import annotations

import math

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox import sqrt, x, y, z
from implicitvox.expr.examples import gear, sinsin

BALL = sqrt(x * x + y * y + z * z) - 0.7
CUBE = ((-1.0,) * 3, (1.0,) * 3)


@pytest.mark.parametrize("shape, res, options", [
    (sinsin(3, 4), 16, {}), (gear(), 24, {}), (BALL, (10, 7, 12), {}),
    (sinsin(3, 4), 16, {"subvoxel": 1}), (gear(), 16, {"mean_value": True}),
    (sinsin(9, 18), 16, {"recheck": 0.2}), (gear(), 16, {"recheck": 0.0}),
])
def test_refine_equals_direct_voxelization(shape, res, options):
    """On the grid ``refine`` documents: the same bounds, a quarter of the voxel
    size; the gear's short axis does not divide evenly (its grid reaches past
    the bounds), and the ball's voxels are not cubes."""
    bounds = CUBE if shape is BALL else None
    coarse = ivx.voxelize(shape, res, bounds=bounds, interior=True, **options)
    refined = coarse.refine(2)
    assert refined.grid == coarse.grid.finer(2)
    direct = ivx.voxelize(shape, bounds=coarse.bounds,
                          voxel_size=tuple(h / 4 for h in coarse.voxel_size),
                          interior=True, **options)
    assert refined.grid == direct.grid
    np.testing.assert_array_equal(refined.coords(), direct.coords())
    np.testing.assert_array_equal(refined.to_dense(), direct.to_dense())


@pytest.mark.parametrize("subvoxel", [1, 2])
def test_subvoxel_refinement_is_a_subset_and_keeps_the_interior(subvoxel):
    base = ivx.voxelize(sinsin(3, 4), resolution=32, interior=True)
    tight = ivx.voxelize(sinsin(3, 4), resolution=32, interior=True, subvoxel=subvoxel)
    assert tight.count < base.count and base.contains(tight.coords()).all()
    # dropped surface voxels are outside or wholly inside: solid = surface + interior grows
    # only by voxels that were surface before
    assert np.all(tight.to_dense() <= base.to_dense())
    ball = ivx.voxelize(BALL, 32, bounds=CUBE, interior=True, subvoxel=subvoxel)
    true = 4 / 3 * math.pi * 0.7 ** 3
    v = np.prod(ball.voxel_size)
    assert ball.interior_count * v <= true <= (ball.interior_count + ball.count) * v


#: affine, with the dependency the natural extension overestimates (3x - 2x: width 5h, not h)
AFFINE = 3 * x - 2 * x + 0.7 * y - 0.45 * y + 0.2 * z - 0.3137


@pytest.mark.parametrize("res", [32, 64, (24, 20, 28)])
def test_recheck_prediction_is_exact_for_affine_functions(res):
    """For affine ``f`` the siblings' spread is the true range and the
    sub-voxel enclosures are what :func:`suspect_voxels` predicts, so
    ``recheck=0.25`` rechecks exactly the voxels that sub-voxels settle: the
    result of ``subvoxel=1``, at a fraction of its work; 0.2 misses some."""
    exact = ivx.voxelize(AFFINE, res, bounds=CUBE, interior=True, recheck=0.25)
    sub = ivx.voxelize(AFFINE, res, bounds=CUBE, interior=True, subvoxel=1, recheck=0.0)
    base = ivx.voxelize(AFFINE, res, bounds=CUBE, interior=True, recheck=0.0)
    assert sub.count < 0.7 * base.count
    np.testing.assert_array_equal(exact.coords(), sub.coords())
    np.testing.assert_array_equal(exact.to_dense(), sub.to_dense())
    assert ivx.voxelize(AFFINE, res, bounds=CUBE, recheck=0.2).count > exact.count


@pytest.mark.parametrize("shape", [sinsin(3, 4), gear()], ids=["sinsin34", "gear"])
def test_recheck_lies_between_subvoxel_refinement_and_none(shape):
    """A stronger recheck drops a superset of voxels, and never one that
    ``subvoxel=1`` keeps; at 4 nearly every voxel is rechecked."""
    counts = []
    sub = ivx.voxelize(shape, resolution=32, subvoxel=1, recheck=0.0)
    previous = ivx.voxelize(shape, resolution=32, recheck=0.0)
    for strength in (0.1, 0.25, 1.0, 4.0):
        vox = ivx.voxelize(shape, resolution=32, recheck=strength)
        assert previous.contains(vox.coords()).all()
        assert vox.contains(sub.coords()).all()
        counts.append(vox.count)
        previous = vox
    assert counts[0] > counts[-1] and counts[-1] <= 1.01 * sub.count


def test_recheck_drops_voxels_into_the_interior_or_outside():
    """Rechecked voxels only leave the surface: those inside join the interior,
    the others are empty, as ``f`` at their centres says."""
    shape = sinsin(3, 4)
    base = ivx.voxelize(shape, resolution=48, interior=True, recheck=0.0)
    tight = ivx.voxelize(shape, resolution=48, interior=True, recheck=0.5)
    assert tight.count < 0.95 * base.count and base.contains(tight.coords()).all()
    kept = tight.contains(base.coords())
    dropped = base.coords()[~kept]
    solid = tight.to_dense()
    inside = ivx.compile(shape.expr)(*tight.grid.centers(dropped).T) < 0
    assert inside.any() and (~inside).any()
    np.testing.assert_array_equal(solid[dropped[:, 0], dropped[:, 1], dropped[:, 2]], inside)
    np.testing.assert_array_equal(solid & ~base.to_dense(), np.zeros_like(solid))


@pytest.mark.parametrize("recheck", [-0.1, 4.5, True, "0.1", float("nan")])
def test_bad_recheck(recheck):
    with pytest.raises(ValueError, match="recheck"):
        ivx.voxelize(BALL, 8, bounds=CUBE, recheck=recheck)


def test_interior_and_surface_bracket_the_volume():
    vox = ivx.voxelize(BALL, 64, bounds=CUBE, interior=True)
    voxel_volume = np.prod(vox.voxel_size)
    true = 4 / 3 * math.pi * 0.7 ** 3
    assert vox.interior_count * voxel_volume <= true <= (vox.interior_count + vox.count) * voxel_volume
    inner = vox.interior_coords()
    assert len(inner) == vox.interior_count
    assert not vox.contains(inner).any()  # interior and surface are disjoint


def test_normals_are_unit_gradients():
    vox = ivx.voxelize(BALL, 32, bounds=CUBE, normals=True)
    radial = vox.centers() / np.linalg.norm(vox.centers(), axis=1, keepdims=True)
    np.testing.assert_allclose(vox.normals, radial, atol=1e-6)


def test_progress_reports_rising_shares_to_one():
    seen = []
    ivx.voxelize(sinsin(3, 4), resolution=64, progress=seen.append)
    assert seen and seen[-1] == 1.0 and all(b >= a for a, b in zip(seen, seen[1:]))


def test_resolution_sets_near_cubic_voxels_and_exact_bounds():
    vox = ivx.voxelize(BALL, 40, bounds=((-1, -1, -0.5), (1, 1, 0.5)))
    assert vox.resolution == (40, 40, 20)
    assert vox.bounds == ((-1.0, -1.0, -0.5), (1.0, 1.0, 0.5))


def test_undefined_regions_are_empty():
    vox = ivx.voxelize(sqrt(x) - 0.5, 16, bounds=CUBE)  # undefined for x < 0
    assert vox.count > 0 and vox.coords()[:, 0].min() >= 8


@pytest.mark.parametrize("bounds, match", [
    (((0, 0, float("nan")), (1, 1, 1)), "finite"),
    (((0, 0, 0), (1, 0, 1)), "zero or negative extent on axis y"),
    (((0, 0, 0),), "shape"),
    ("abc", "bounds must be"),
])
def test_bad_bounds(bounds, match):
    with pytest.raises(ValueError, match=match):
        ivx.voxelize(BALL, 8, bounds=bounds)


def test_bad_subvoxel():
    with pytest.raises(ValueError, match="subvoxel"):
        ivx.voxelize(BALL, 8, bounds=CUBE, subvoxel=9)


@pytest.mark.parametrize("res, match", [
    (0, "an int from 1 to"), (10**9, "an int from 1 to"), (2.5, "got float 2.5"), (True, "got bool True"),
    ((4, 4), "3 ints"),
])
def test_bad_resolution(res, match):
    with pytest.raises(ValueError, match=match):
        ivx.voxelize(BALL, res, bounds=CUBE)


def test_missing_bounds_and_bad_shape():
    with pytest.raises(ValueError, match="bounds is required"):
        ivx.voxelize(BALL)
    with pytest.raises(TypeError, match="got str"):
        ivx.voxelize("x*x", 8, bounds=CUBE)


def test_memory_budget_refuses_before_starting():
    with pytest.raises(MemoryError, match="over the budget"):
        ivx.voxelize(sinsin(9, 18), resolution=4096, max_memory=100 << 20)
    with pytest.raises(ValueError, match="max_memory"):
        ivx.voxelize(BALL, 8, bounds=CUBE, max_memory=-5)


def test_dense_outputs_check_memory():
    vox = ivx.voxelize(BALL, 32, bounds=CUBE)
    with pytest.raises(MemoryError, match="max_memory"):
        vox.to_dense(max_memory=1000)


def test_refine_of_loaded_voxels_needs_the_shape(tmp_path):
    vox = ivx.voxelize(BALL, 8, bounds=CUBE)
    back = ivx.load(vox.save(str(tmp_path / "b.npz")))
    with pytest.raises(ValueError, match="needs the shape"):
        back.refine()
