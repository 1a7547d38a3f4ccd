"""The mesh leaf's memory of the octants (implicitvox.triangles.mesh_classifier) changes no state.

Boxes whose parents the leaf remembered are tested against the parents'
triangles, or, below a box met by one triangle of a closed mesh, by that
triangle's plane and the winding numbers of its two sides. Each run here
voxelizes once with the octants given to the exact test and once without
(the same test behind a plain function), and compares the voxels and the
interior octant for octant.
"""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

import implicitvox as ivx
from csg import Box, Polyhedron, Sphere
from implicitvox.triangles.mesh_classifier import (OFF, BoxMemory, MeshClassifier, edges_balanced,
                                                   edges_shared, forget_decided)
from implicitvox.expr.shape import Octants, takes_octants
from implicitvox.octree.grid import grid_of
from implicitvox.octree.subdivide import subdivide
from implicitvox.triangles.inputs import as_triangles


def _mesh(poly: pv.PolyData) -> tuple[np.ndarray, np.ndarray]:
    return as_triangles(poly.triangulate())


def _cube(center=(0.0, 0.0, 0.0), size=1.0):
    return _mesh(pv.Cube(center=center, x_length=size, y_length=size, z_length=size))


def _two_shells():
    """Two overlapping closed cubes as one mesh: winding number 2 where they overlap."""
    (v1, f1), (v2, f2) = _cube((0, 0, 0), 1.0), _cube((0.37, 0.21, 0.13), 1.0)
    return np.concatenate([v1, v2]), np.concatenate([f1, f2 + len(v1)])


def _turned(faces: np.ndarray, k: int = 3) -> np.ndarray:
    faces = faces.copy()
    faces[k] = faces[k, ::-1]
    return faces


def _plain(test):
    return lambda lo, hi: test(lo, hi)


def _runs(solid, resolution: int, bounds):
    """Codes and interior of the subdivision with the octants passed, and without."""
    grid = grid_of(solid.bounds, bounds, resolution, None)
    func = ivx.compile(solid.expr)
    boxes, voxels = solid.classify_boxes, solid.classify_voxels
    assert takes_octants(boxes) and takes_octants(voxels)
    out = []
    for exact, exact_voxels in ((boxes, voxels), (_plain(boxes), _plain(voxels))):
        run = subdivide(func, grid, exact=exact, exact_voxels=exact_voxels, interior=True)
        out.append((np.sort(run.codes), run.interior))
    return out


SOLIDS = {
    "sphere mesh": (lambda: Polyhedron(_mesh(pv.Sphere(radius=1.0, theta_resolution=18,
                                                       phi_resolution=14))), None),
    "turned cube": (lambda: Polyhedron(_cube()).rotate((1, 2, 3), 21.0), None),
    "two shells": (lambda: Polyhedron(_two_shells()), None),
    "mesh minus sphere": (lambda: Polyhedron(_cube(size=1.6)) - Sphere(0.7, center=(0.4, 0, 0)),
                          None),
    "mesh in a union": (lambda: Polyhedron(_cube()) | Box((0.4, 0.4, 1.6), center=True), None),
    # an open mesh (the two shells, the first without its +x face, whose sides' planes go
    # on past the hole inside the mesh's box): no plane rule, only the parents' triangles;
    # its states are the cold test's, whatever they mean
    "open shells": (lambda: Polyhedron(_two_shells()[0], np.delete(_two_shells()[1], [2, 3], 0)),
                    None),
    # closed but not oriented (one triangle turned over): its ray counts are no winding
    # number, so both sides of a one-triangle box are asked, not one and the other by +-1
    "turned triangle": (lambda: Polyhedron(_cube()[0], _turned(_cube()[1])), None),
    # a lattice the cube's faces lie on: boxes touch faces, edges and corners exactly
    "cube on the lattice": (lambda: Polyhedron(_cube(size=1.0)), ((-1, -1, -1), (1, 1, 1))),
}


@pytest.mark.parametrize("name", sorted(SOLIDS))
def test_octant_memory_changes_no_voxel_and_no_interior(name):
    make, bounds = SOLIDS[name]
    (codes, interior), (plain_codes, plain_interior) = _runs(make(), 64, bounds)
    assert len(codes) > 0
    assert np.array_equal(codes, plain_codes)
    assert sorted(interior) == sorted(plain_interior)
    for level in interior:
        assert np.array_equal(interior[level], plain_interior[level])


def test_two_shells_keep_their_overlap_full():
    """Inside both cubes the winding number is 2: FULL, where a side-of-the-plane rule
    that assumed 0 and 1 would call it EMPTY."""
    solid = Polyhedron(_two_shells())
    vox = solid.voxelize(resolution=48, interior=True)
    inside = vox.grid.voxels_holding(np.array([[0.2, 0.1, 0.05]]))[0]
    assert vox.to_dense()[tuple(inside[0])]


def test_edges_shared_tells_closed_from_open_meshes():
    v, f = _cube()
    assert edges_shared(v, f)
    assert not edges_shared(v, f[1:])
    assert edges_shared(*_two_shells())
    # the same closed mesh with every triangle's own vertices (a soup, as an STL stores it)
    assert edges_shared(v[f].reshape(-1, 3), np.arange(3 * len(f)).reshape(-1, 3))


def test_edges_balanced_tells_oriented_meshes():
    v, f = _cube()
    assert edges_balanced(v, f) and edges_balanced(*_two_shells())
    assert not edges_balanced(v, _turned(f))               # closed, not oriented
    assert edges_shared(v, _turned(f))
    assert not MeshClassifier(v, _turned(f)).oriented and MeshClassifier(v, f).oriented


def test_open_mesh_is_never_cut_by_a_plane_alone():
    v, f = _cube()
    leaf = MeshClassifier(v, f[1:])
    assert not leaf.closed


def test_box_memory_gives_each_entry_once():
    memory = BoxMemory()
    codes = np.array([40, 8, 17], dtype=np.uint64)
    memory.put(3, codes, np.array([-1, 5, -1]), np.array([0, 1, 0]), np.array([0, 0, 0]),
               np.array([0, 0, 2]), np.array([7, 9, 4]))
    found, single, above, below, owner, tris = memory.take(
        3, np.array([17, 40, 40, 99], dtype=np.uint64))
    assert found.tolist() == [True, True, True, False]
    assert single.tolist() == [-1, -1, -1, -1]
    pairs = sorted(zip(owner.tolist(), tris.tolist()))
    assert pairs == [(0, 4), (1, 7), (1, 9), (2, 7), (2, 9)]
    assert len(memory) == 1                          # box 8 was never asked for
    again = memory.take(3, np.array([40, 8], dtype=np.uint64))
    assert again[0].tolist() == [False, True] and again[1].tolist() == [-1, 5]
    assert again[2].tolist() == [0, 1]
    assert len(memory) == 0


def test_boxes_the_tree_decided_are_forgotten():
    memory, run = BoxMemory(), {}
    run["mesh"] = memory
    codes = np.array([3, 9, 12], dtype=np.uint64)
    memory.put(2, codes, np.array([OFF, 4, OFF]), np.array([1, 0, 0]), np.zeros(3, int),
               np.zeros(0, int), np.zeros(0, int))
    forget_decided(run, Octants(2, codes, run), np.array([0, 2]))
    assert len(memory) == 1
    found, single, above, *_ = memory.take(2, codes)
    assert found.tolist() == [False, True, False] and single[1] == 4


def test_weld_is_numpys_unique_along_rows():
    from implicitvox.triangles.weld import weld
    rng = np.random.default_rng(3)
    p = rng.integers(-2, 3, (500, 3)).astype(float) * 0.5
    p[5::11, 0] = -0.0                     # equal to 0.0
    rows, inverse = weld(p)
    truth, truth_inverse = np.unique(p, axis=0, return_inverse=True)
    assert np.array_equal(rows, truth) and np.array_equal(inverse, truth_inverse.ravel())
    assert np.array_equal(rows[inverse], p)
