"""OpenSCAD's diagonal across a bent quad face (csg.tessellation), against OpenSCAD 2021.01's
own STL of tests/openscad/bent.scad, and both diagonals kept where it is not known."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

import csg
import implicitvox as iv
from csg.tessellation import openscad_vertex_ids, quad_diagonals
from implicitvox.triangles.inputs import as_triangles
from tests.support.mesh_helpers import misses

FIXTURES = Path(__file__).resolve().parents[1] / "openscad"


def _bent_model():
    text = (FIXTURES / "bent.scad").read_text()
    points = np.array(eval(re.search(r"points = (\[.*?\]\]),", text, re.S).group(1)))
    faces = eval(re.search(r"faces = (\[.*?\]\])\)", text, re.S).group(1))
    return points, faces


def _stl_edges(points):
    v, f = as_triangles(str(FIXTURES / "bent.stl"))
    # the STL's corners are the model's, written with 6 digits
    near = np.linalg.norm(v[:, None] - points[None], axis=2)
    assert near.min(axis=1).max() < 1e-3
    index = near.argmin(axis=1)[f]
    return {frozenset((int(t[k]), int(t[(k + 1) % 3]))) for t in index for k in range(3)}


def test_every_diagonal_is_the_one_in_openscads_stl():
    points, faces = _bent_model()
    quads = np.array([q for q in faces if len(q) == 4])
    corners = points[quads]
    bent = np.abs(np.einsum("ij,ij->i", corners[:, 1] - corners[:, 0],
                            np.cross(corners[:, 2] - corners[:, 0],
                                     corners[:, 3] - corners[:, 1]))) > 1e-6
    assert bent.sum() >= 60                      # the fixture is worth its name
    ids = openscad_vertex_ids(points, faces)[quads]
    diagonal = quad_diagonals(corners, ids)
    assert (diagonal >= 0).all()
    # its bow ties are decided by OpenSCAD's vertex numbers: without, they are not known
    assert (quad_diagonals(corners) == -1).sum() >= 5
    assert 5 <= (diagonal == 1).sum() <= len(quads) - 5   # both kinds of cut occur
    edges = _stl_edges(points)
    ends = np.where(diagonal[:, None] == 0, quads[:, [0, 2]], quads[:, [1, 3]])
    others = np.where(diagonal[:, None] == 0, quads[:, [1, 3]], quads[:, [0, 2]])
    for k in np.flatnonzero(bent):
        assert frozenset(ends[k].tolist()) in edges, k
        assert frozenset(others[k].tolist()) not in edges, k


def test_the_bent_polyhedron_voxelizes_as_openscads_stl():
    """Cut along the fan's diagonals instead, thousands of the STL's voxels are missed."""
    solid = csg.read_openscad(FIXTURES / "bent.csg")
    stl = iv.voxelize_mesh(str(FIXTURES / "bent.stl"), 96, workers=1)
    vox = solid.voxelize(bounds=stl.bounds, voxel_size=stl.voxel_size, workers=1)
    assert vox.contains(stl.coords()).all()
    assert vox.count <= 1.002 * stl.count


def test_issue964_is_cut_as_openscads_stl_and_unknown_cuts_keep_both_diagonals():
    # OpenSCAD's test model issue964: face [2, 3, 6, 5] has a tie in libtess2's normal
    # (projected along y, it is a proper quad); face [3, 0, 6, 5] projects along z with two
    # corners on one point; 1-5, 3-6 and 0-4 are cut through a spike at a corner
    points = np.array([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0], [0, -20, 20],
                       [10, -20, 20], [10, -20, 30], [0, -20, 30]], dtype=float)
    faces = [[0, 1, 2, 3], [4, 5, 6, 7], [1, 2, 5, 4], [2, 3, 6, 5], [3, 0, 6, 5],
             [0, 1, 4, 7]]
    ids = openscad_vertex_ids(points, faces)[np.array(faces)]
    # as OpenSCAD 2021.01's STL of issue964 cuts them (the planar ones either way)
    assert quad_diagonals(points[np.array(faces)], ids).tolist() == [0, 1, 0, 1, 0, 0]
    solid = csg.read_openscad(f"polyhedron(points = {points.tolist()}, faces = {faces});")
    assert len(solid.alternative_faces) == 0
    # a face listing a corner twice in a row is that quad, numbered alike
    again = csg.read_openscad(f"polyhedron(points = {points.tolist()}, "
                              f"faces = {faces[:3] + [[2, 3, 3, 6, 5]] + faces[4:]});")
    assert np.array_equal(again.faces, solid.faces)
    # a quad of no normal (its corners on a line) is not known: both cuts count as surface
    line = np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]], dtype=float)
    assert quad_diagonals(line[None]).tolist() == [-1]
    flat = csg.read_openscad(f"polyhedron(points = {points.tolist()}, faces = {faces});",
                             facets="openscad")
    kept = csg.Polyhedron(flat.vertices, flat.faces,
                          alternative_faces=[[2, 3, 6], [2, 6, 5]])
    vox = iv.voxelize(kept, 48, workers=1)
    quad = points[[2, 3, 6, 5]]
    for tri in [(0, 1, 2), (0, 2, 3), (0, 1, 3), (1, 2, 3)]:     # either cut of the quad
        w = np.random.default_rng(sum(tri)).dirichlet(np.ones(3), 300)
        assert misses(vox, w @ quad[list(tri)]) == 0, tri


def test_quads_pinched_in_libtess2s_projection_are_cut_as_openscad_cuts_them():
    """tests/openscad/pinched.scad: 200 quads with two corners (neighbours or opposite) on
    one point of libtess2's projection (neighbours merge, the diagonal runs through the
    corner kept; opposite corners leave no area, and OpenSCAD closes the loop itself) and
    80 generic quads, point numbers shuffled: every diagonal is the one in OpenSCAD's STL."""
    text = (FIXTURES / "pinched.scad").read_text()
    points = np.array(eval(re.search(r"points = (\[.*?\]\]),", text, re.S).group(1)))
    faces = eval(re.search(r"faces = (\[.*?\]\])\)", text, re.S).group(1))
    quads = np.array(faces)
    diagonal = quad_diagonals(points[quads], openscad_vertex_ids(points, faces)[quads])
    assert (diagonal >= 0).all()
    assert 40 <= (diagonal == 1).sum() <= len(quads) - 40
    v, f = as_triangles(str(FIXTURES / "pinched.stl"))
    index = np.linalg.norm(v[:, None] - points[None], axis=2).argmin(axis=1)[f]
    per_face = {}
    for t in index:
        per_face.setdefault(int(np.flatnonzero((quads == t[0]).any(axis=1))[0]), []).append(t)
    for k, quad in enumerate(quads):
        cut = set(per_face[k][0].tolist()) & set(per_face[k][1].tolist())
        assert cut == set(quad[[0, 2]] if diagonal[k] == 0 else quad[[1, 3]]), k
