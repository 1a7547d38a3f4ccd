"""Mesh voxelization: exactly the voxels the triangles meet (Stolte §6, Varadhan §3.3)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
import pyvista as pv

import implicitvox as ivx
from implicitvox.triangles.inputs import as_triangles
from tests.support.mesh_helpers import (BUNNY, misses, neighbours_outside, oracle_meets,
                                sample_surface)

needs_bunny = pytest.mark.skipif(
    not BUNNY.exists(), reason="the Stanford bunny is not redistributed with the repository "
    f"(Stanford's terms); it is read from {BUNNY}")


@pytest.fixture(scope="module")
def bunny():
    return as_triangles(str(BUNNY))


_VOXELS: dict = {}


def bunny_voxels(resolution):
    if resolution not in _VOXELS:
        _VOXELS[resolution] = ivx.voxelize_mesh(str(BUNNY), resolution)
    return _VOXELS[resolution]


@needs_bunny
@pytest.mark.parametrize("resolution", [64, 128, 256, 512])
def test_bunny_never_misses(bunny, resolution):
    v, f = bunny
    vox = bunny_voxels(resolution)
    points = sample_surface(v[f], 10**6, np.random.default_rng(resolution))
    assert misses(vox, points) == 0
    assert vox.resolution[0] == resolution


@needs_bunny
def test_bunny_512_equals_exact_oracle(bunny):
    """Output voxels each meet a triangle; their non-output neighbours meet none."""
    v, f = bunny
    tri = v[f]
    vox = bunny_voxels(512)
    rng = np.random.default_rng(0)
    inside = vox.coords()[rng.choice(vox.count, 400, replace=False)]
    assert oracle_meets(tri, vox.grid, inside).all()
    outside = neighbours_outside(vox, rng, 400)
    assert len(outside) == 400
    assert not oracle_meets(tri, vox.grid, outside).any()


def _all_voxels(shape):
    return np.stack(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij"), -1).reshape(-1, 3)


@pytest.mark.parametrize("name", ["cube-on-grid", "ant", "degenerate"])
def test_small_meshes_equal_the_oracle_everywhere(name):
    """Every voxel of the grid, output or not, agrees with the exact oracle."""
    if name == "cube-on-grid":      # faces exactly on voxel edges: ties on every face
        v, f = as_triangles(pv.Cube(center=(0.5, 0.5, 0.5), x_length=0.5, y_length=0.5,
                                    z_length=0.5))
        bounds, res = ((0, 0, 0), (1, 1, 1)), 8
    elif name == "ant":
        v, f = as_triangles(pv.examples.load_ant())
        bounds, res = None, 12
    else:                           # zero-area triangles: segments and points, on grid edges
        v = np.array([[0.1, 0.2, 0.3], [0.9, 0.8, 0.7], [0.5, 0.5, 0.5], [0.25, 0.25, 0.25]])
        f = np.array([[0, 1, 2], [3, 3, 3], [0, 0, 1], [0, 1, 1]])
        bounds, res = ((0, 0, 0), (1, 1, 1)), 8
    vox = ivx.voxelize_mesh((v, f), res, bounds=bounds)
    every = _all_voxels(vox.resolution)
    assert vox.contains(every).tolist() == oracle_meets(v[f], vox.grid, every).tolist()


def test_pyvista_meshes_never_miss():
    for mesh in (pv.examples.load_airplane(), pv.examples.load_nut(), pv.Sphere()):
        v, f = as_triangles(mesh)
        vox = ivx.voxelize_mesh(mesh, 200)
        assert misses(vox, sample_surface(v[f], 200_000, np.random.default_rng(1))) == 0


def test_duplicate_faces_change_nothing():
    v, f = as_triangles(pv.examples.load_ant())
    a = ivx.voxelize_mesh((v, f), 64)
    b = ivx.voxelize_mesh((v, np.concatenate([f, f[::-1], f[:, [1, 2, 0]]])), 64)
    assert np.array_equal(a.coords(), b.coords())


def test_triangles_outside_the_bounds_are_clipped():
    v, f = as_triangles(pv.Sphere(radius=1.0))
    vox = ivx.voxelize_mesh((v, f), 32, bounds=((0, 0, 0), (2, 2, 2)))
    every = _all_voxels(vox.resolution)
    assert vox.count > 0
    assert vox.contains(every).sum() == vox.count


def test_refine_equals_direct():
    mesh = pv.examples.load_nut()
    mesh = mesh.translate(-np.array(mesh.center)).scale(1.5 / max(mesh.bounds_size))
    bounds = ((-1, -1, -1), (1, 1, 1))
    coarse = ivx.voxelize_mesh(mesh, 32, bounds=bounds)
    fine = coarse.refine(1)
    direct = ivx.voxelize_mesh(mesh, 64, bounds=bounds)
    assert fine.grid == direct.grid          # dyadic voxel sizes: the same edges
    assert fine.count > 4 * coarse.count > 0
    assert np.array_equal(fine.coords(), direct.coords())


def test_solid_brackets_the_volume():
    mesh = pv.Sphere(radius=1.0, theta_resolution=40, phi_resolution=40)
    vox = ivx.voxelize_mesh(mesh, 64, interior=True)
    cell = float(np.prod(vox.voxel_size))
    volume = mesh.volume
    assert vox.interior_count * cell <= volume <= (vox.interior_count + vox.count) * cell
    dense = vox.to_dense()
    assert dense[32, 32, 32] and not dense[0, 0, 0]


def test_solid_of_an_open_mesh_warns():
    """A sphere with a cap cut off: inside and outside are one region of voxels
    (the grid reaches past the hole, so the region joins them through it)."""
    mesh = pv.Sphere(radius=1.0).clip("z", origin=(0, 0, 0.6))
    with pytest.warns(UserWarning, match="not closed"):
        ivx.voxelize_mesh(mesh, 32, bounds=((-1.2,) * 3, (1.2,) * 3), interior=True)


def test_solid_of_two_disjoint_closed_meshes():
    a = pv.Cube(center=(0, 0, 0))
    b = pv.Cube(center=(3, 0, 0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        vox = ivx.voxelize_mesh(a + b, 64, interior=True)
    assert vox.interior_count > 0
    d = vox.to_dense()
    mid = vox.grid.voxels_holding(np.array([[1.5, 0.0, 0.0]]))[0][0]
    assert not d[tuple(mid)]                 # between the cubes: outside


def test_progress_and_memory_budget():
    seen = []
    ivx.voxelize_mesh(pv.Sphere(), 64, progress=seen.append)
    assert seen and seen[-1] == pytest.approx(1.0) and seen == sorted(seen)
    with pytest.raises(MemoryError, match="budget"):
        ivx.voxelize_mesh(pv.Sphere(), 4096, interior=True, max_memory=1 << 20)


@pytest.mark.parametrize("mesh, error, match", [
    ((np.array([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]]), [[0, 1, 2]]), ValueError, "vertex 2"),
    ((np.array([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]]), [[0, 1, 2]]), ValueError, "finite"),
    ((np.eye(3), [[0, 1, 5]]), ValueError, r"faces\[0\] refers to vertex 5"),
    ((np.eye(3), [[0, 1, -1]]), ValueError, "refers to vertex -1"),
    ((np.eye(3), [[0, 1, 2, 0]]), ValueError, r"shape \(f, 3\)"),
    ((np.eye(3), [[0.5, 1, 2]]), ValueError, "integer"),
    ((np.zeros((3, 2)), [[0, 1, 2]]), ValueError, r"vertices must have shape \(n, 3\)"),
    ((np.zeros((0, 3)), np.zeros((0, 3), int)), ValueError, "no triangles"),
    ((np.ones((3, 3)), [[0, 1, 2]]), ValueError, "zero extent"),
    ("missing.stl", FileNotFoundError, "not found"),
    (42, TypeError, "mesh must be"),
])
def test_bad_meshes_are_refused(mesh, error, match):
    with pytest.raises(error, match=match):
        ivx.voxelize_mesh(mesh, 16)


def test_unused_nan_vertex_is_harmless():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [np.nan, 0, 0]])
    assert ivx.voxelize_mesh((v, [[0, 1, 2]]), 8).count > 0


def test_empty_mesh_with_bounds_gives_no_voxels():
    vox = ivx.voxelize_mesh((np.zeros((0, 3)), np.zeros((0, 3), int)), 8,
                            bounds=((0, 0, 0), (1, 1, 1)))
    assert vox.count == 0


@pytest.mark.parametrize("content, suffix, match", [
    (b"", ".stl", "empty"),
    (b"garbage\x00\x01 not a mesh", ".stl", "cannot read"),
    (b"v 1 2\nf 1 2 3\n", ".obj", "cannot read"),
    (b"solid x\n", ".txt", "must be one of"),
])
def test_unreadable_files(tmp_path, content, suffix, match):
    path = tmp_path / f"bad{suffix}"
    path.write_bytes(content)
    with pytest.raises(ValueError, match=match):
        ivx.voxelize_mesh(str(path), 16)


def test_files_round_trip_through_pyvista(tmp_path):
    mesh = pv.examples.load_nut()
    direct = ivx.voxelize_mesh(mesh, 48)
    for suffix in (".stl", ".ply", ".obj", ".vtp"):
        path = tmp_path / f"nut{suffix}"
        mesh.save(str(path))
        vox = ivx.voxelize_mesh(str(path), 48, bounds=direct.bounds)
        assert np.array_equal(vox.coords(), direct.coords()), suffix
