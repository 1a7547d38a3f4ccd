"""Bézier patches: every voxel a patch meets is output, and not many more (Stolte §4.2)."""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox.octree import morton
from implicitvox.triangles.patches import bezier_triangles
from tests.support.mesh_helpers import misses


def _sampled_voxels(vox, patches, n, rng):
    pts = np.concatenate([p.sample(n, rng) for p in patches])
    return pts, np.unique(morton.encode(vox.grid.voxels_holding(pts)[0]))


@pytest.mark.parametrize("resolution", [64, 128])
def test_teapot_covered_and_tight(resolution):
    patches = ivx.utah_teapot()
    vox = ivx.voxelize_bezier(patches, resolution)
    rng = np.random.default_rng(resolution)
    pts, truth = _sampled_voxels(vox, patches, 10**5, rng)
    assert misses(vox, pts) == 0
    # dense sampling finds (nearly) all voxels the patches meet: a lower bound of the truth
    assert vox.count <= 1.5 * len(truth)


def test_general_degree_patches():
    rng = np.random.default_rng(3)
    patches = [ivx.BezierPatch(rng.normal(size=(m + 1, n + 1, 3)))
               for m, n in [(1, 1), (2, 5), (5, 2), (7, 3)]]
    vox = ivx.voxelize_bezier(patches, 96)
    pts, truth = _sampled_voxels(vox, patches, 10**5, rng)
    assert misses(vox, pts) == 0
    assert vox.count <= 1.5 * len(truth)


def test_far_from_the_origin():
    """Large coordinates, small patch: the rounding bound of the subdivision matters."""
    u, v = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4), indexing="ij")
    net = np.stack([u, v, np.sin(3 * u) * np.cos(2 * v) * 0.3], -1) * 1e-3 + 1e6
    patch = ivx.BezierPatch(net)
    vox = ivx.voxelize_bezier(patch, 64)
    assert misses(vox, patch.sample(10**5, np.random.default_rng(0))) == 0


def test_covering_triangles_hold_the_patch():
    """Every sampled patch point lies within the dilation of some covering triangle:
    the box of half-widths ``dilation`` around the point meets the triangle."""
    from implicitvox.triangles.tribox import Triangles
    rng = np.random.default_rng(4)
    patch = ivx.BezierPatch(rng.normal(size=(4, 4, 3)))
    tri, dil = bezier_triangles([patch], np.full(3, 0.05))
    assert np.all(dil <= 0.05) and len(tri) > 2
    pts = patch.sample(2000, rng)
    t = Triangles(tri)
    pi, ti = np.meshgrid(np.arange(len(pts)), np.arange(len(tri)), indexing="ij")
    pi, ti = pi.ravel(), ti.ravel()
    met = t.meet_boxes(ti, pts[pi] - dil[ti], pts[pi] + dil[ti]).reshape(len(pts), len(tri))
    assert met.any(axis=1).all()
    # and the test can fail: without the dilation most points are off the flat triangles
    flat = t.meet_boxes(ti, pts[pi], pts[pi]).reshape(len(pts), len(tri))
    assert not flat.any(axis=1).all()


def test_flatness_trades_tightness():
    patches = ivx.utah_teapot()[:4]
    loose = ivx.voxelize_bezier(patches, 64, flatness=2.0)
    tight = ivx.voxelize_bezier(patches, 64, flatness=0.05)
    assert tight.count < loose.count
    assert np.all(loose.contains(tight.coords()))


def test_refine_equals_direct():
    patches = ivx.utah_teapot()
    bounds = ((-4, -4, -1), (4, 4, 7))
    coarse = ivx.voxelize_bezier(patches, 32, bounds=bounds)
    fine = coarse.refine(1)
    direct = ivx.voxelize_bezier(patches, 64, bounds=bounds)
    assert fine.grid == direct.grid and np.array_equal(fine.coords(), direct.coords())


@pytest.mark.parametrize("net, match", [
    (np.zeros((1, 4, 3)), r"m, n >= 1"),
    (np.zeros((4, 4, 2)), r"shape"),
    (np.full((4, 4, 3), np.nan), r"control_points\[0, 0\]"),
    ("abc", "numbers"),
])
def test_bad_patches(net, match):
    with pytest.raises(ValueError, match=match):
        ivx.BezierPatch(net)


def test_bad_arguments():
    p = ivx.utah_teapot()[0]
    with pytest.raises(ValueError, match="flatness"):
        ivx.voxelize_bezier(p, 16, flatness=0)
    with pytest.raises(TypeError, match=r"patches\[1\]"):
        ivx.voxelize_bezier([p, "x"], 16)
    with pytest.raises(ValueError, match="no patches"):
        ivx.voxelize_bezier([], 16)
    assert ivx.voxelize_bezier([], 8, bounds=((0, 0, 0), (1, 1, 1))).count == 0
