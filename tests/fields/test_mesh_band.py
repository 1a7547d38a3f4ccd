"""The band's bricks and a mesh's distance band by scattered triangles, against oracles."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv
from scipy import ndimage

from implicitvox.fields.bricks import BRICK, band_bricks, band_steps, masked_coords
from implicitvox.fields.mesh_band import mesh_band
from implicitvox.linf import TriangleMesh
from implicitvox.octree import morton
from implicitvox.triangles.inputs import as_triangles
from implicitvox.voxelizers.mesh import voxelize_mesh


@pytest.mark.parametrize("band", [1, 3, 9])
def test_band_bricks_are_the_dilation_of_the_surface_voxels(band):
    rng = np.random.default_rng(band)
    shape = (37, 29, 41)
    surface = np.unique(rng.integers(0, shape, (60, 3)), axis=0)
    dense = np.zeros(shape, dtype=bool)
    dense[tuple(surface.T)] = True
    truth = ndimage.binary_dilation(dense, np.ones((2 * band + 1,) * 3, dtype=bool))
    keys, active = band_bricks(surface[rng.permutation(len(surface))], band, shape)
    got = masked_coords(keys, active)
    assert len(got) == truth.sum()
    assert truth[tuple(got.T)].all()
    assert np.array_equal(keys, np.unique(morton.encode(np.argwhere(truth) // BRICK)))
    # the steps: scipy's chessboard transform of the voxels off the surface, capped
    keys, steps = band_steps(surface, band, shape)
    chess = np.minimum(ndimage.distance_transform_cdt(~dense, metric="chessboard"), band + 1)
    coords = masked_coords(keys, np.ones(steps.shape, dtype=bool))
    inside = np.all(coords < shape, axis=1)
    assert np.array_equal(steps.reshape(-1)[inside], chess[tuple(coords[inside].T)])
    assert np.all(steps.reshape(-1)[~inside] == band + 1)


def _mesh_and_band(band):
    sphere = pv.Sphere(radius=1.0, theta_resolution=14, phi_resolution=11)
    sphere.points = sphere.points * np.array([1.0, 0.7, 0.45]) @ np.array(
        [[0.8, 0.6, 0.0], [-0.6, 0.8, 0.0], [0.0, 0.0, 1.0]])
    v, f = as_triangles(sphere)
    mesh = TriangleMesh(v, f)
    vox = voxelize_mesh((v, f), (52, 60, 25), bounds=((-1.3, -1.2, -0.8), (1.3, 1.2, 0.825)))
    assert len(set(vox.grid.voxel_size)) == 3                # not cubes
    keys, active = band_bricks(vox.coords(), band, vox.grid.shape)
    return mesh, vox.grid, keys, active, vox.coords()


def test_the_scattered_band_is_the_walk_bit_for_bit_on_any_number_of_threads():
    mesh, grid, keys, active, _ = _mesh_and_band(3)
    h = np.asarray(grid.voxel_size)
    w = h / h.max()
    points = grid.centers(masked_coords(keys, active))
    walk = np.abs(mesh.distance(points, np.broadcast_to(w, points.shape)))
    one = mesh_band(mesh, grid, keys, active, 3, "linf", w, workers=1)
    assert np.array_equal(one, walk)
    assert np.array_equal(mesh_band(mesh, grid, keys, active, 3, "linf", w, workers=2), one)
    assert one.max() <= 3.5 * h.max()
    walk = np.abs(mesh.euclidean_distance(points))
    one = mesh_band(mesh, grid, keys, active, 3, "euclidean", workers=1)
    assert np.array_equal(one, walk)
    assert np.array_equal(mesh_band(mesh, grid, keys, active, 3, "euclidean", workers=2), one)


def test_the_surface_voxels_bounds_start_the_samples_and_change_no_value():
    mesh, grid, keys, active, surface = _mesh_and_band(3)
    h = np.asarray(grid.voxel_size)
    w = h / h.max()
    same_keys, steps = band_steps(surface, 3, grid.shape)
    assert np.array_equal(same_keys, keys) and np.array_equal(steps <= 3, active)
    for norm in ("linf", "euclidean"):
        plain = mesh_band(mesh, grid, keys, active, 3, norm, w)
        assert np.array_equal(mesh_band(mesh, grid, keys, active, 3, norm, w, steps=steps),
                              plain)
        # bounds that are wrong (too low everywhere): no triangle comes below them, and
        # the walk gives every value
        low = np.zeros_like(steps)
        assert np.array_equal(mesh_band(mesh, grid, keys, active, 3, norm, w, steps=low),
                              plain)


def test_samples_beyond_every_triangles_reach_are_walked():
    mesh, grid, keys, active, _ = _mesh_and_band(1)
    everywhere = np.ones_like(active)          # far more than the band of 1 voxel
    w = np.asarray(grid.voxel_size) / max(grid.voxel_size)
    points = grid.centers(masked_coords(keys, everywhere))
    got = mesh_band(mesh, grid, keys, everywhere, 1, "linf", w)
    assert got.max() > 1.5 * max(grid.voxel_size)
    assert np.array_equal(got, np.abs(mesh.distance(points, np.broadcast_to(w, points.shape))))
    got = mesh_band(mesh, grid, keys, everywhere, 1, "euclidean")
    assert np.array_equal(got, np.abs(mesh.euclidean_distance(points)))


@pytest.mark.parametrize("workers", [1, 2])
def test_a_mesh_fields_progress_is_monotone_and_ends_at_one(workers, monkeypatch):
    import implicitvox as iv
    from implicitvox.fields import mesh_band as module
    monkeypatch.setattr(module, "PIECE_PAIRS", 512)          # several pieces
    seen = []
    sphere = pv.Sphere(radius=1.0, theta_resolution=16, phi_resolution=12)
    field = iv.distance_field(sphere, 40, norm="linf", band=2, workers=workers,
                              progress=seen.append)
    assert field.count
    assert seen == sorted(seen) and seen[-1] == 1.0
    assert len([s for s in seen if 0.2 < s < 1.0]) >= 2        # the scatter's own steps
