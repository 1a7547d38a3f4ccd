"""OpenSCAD's diagonal across a bent quad face (csg.tessellation), against OpenSCAD 2021.01's
own STL of tests/openscad/bent.scad, and both diagonals kept where it is not known."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

import csg
import implicitvox as iv
from csg.tessellation import quad_diagonals
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
    assert bent.sum() >= 20                      # the fixture is worth its name
    diagonal = quad_diagonals(corners)
    assert (diagonal >= 0).all()
    assert 5 <= (diagonal == 1).sum() <= len(quads) - 5   # both kinds of cut occur
    edges = _stl_edges(points)
    ends = np.where(diagonal[:, None] == 0, quads[:, [0, 2]], quads[:, [1, 3]])
    others = np.where(diagonal[:, None] == 0, quads[:, [1, 3]], quads[:, [0, 2]])
    for k in np.flatnonzero(bent):
        assert frozenset(ends[k].tolist()) in edges, k
        assert frozenset(others[k].tolist()) not in edges, k


def test_the_bent_polyhedron_voxelizes_as_openscads_stl():
    """Cut along the fan's diagonals instead, 4,506 of the STL's voxels at 128 were missed."""
    solid = csg.read_openscad(FIXTURES / "bent.csg")
    stl = iv.voxelize_mesh(str(FIXTURES / "bent.stl"), 96, workers=1)
    vox = solid.voxelize(bounds=stl.bounds, voxel_size=stl.voxel_size, workers=1)
    assert vox.contains(stl.coords()).all()
    assert vox.count <= 1.002 * stl.count


def test_a_bow_tie_keeps_both_diagonals_as_surface():
    # a bent quad whose libtess2 projection (along y, off its normal's normal) crosses
    # itself: OpenSCAD's cut is not repeated, and both count as surface
    quad = np.array([[8.7, 2.3, 0.6], [10.8, -0.3, 9.2], [13.2, 3.2, 9.6], [5.1, 6.4, 2.7]])
    assert quad_diagonals(quad[None]).tolist() == [-1]
    normal = np.cross(quad[2] - quad[0], quad[3] - quad[1])
    apex = quad.mean(axis=0) - 0.5 * normal / np.linalg.norm(normal) * 6
    points = np.concatenate([quad, apex[None]])
    faces = [[0, 1, 2, 3], [1, 0, 4], [2, 1, 4], [3, 2, 4], [0, 3, 4]]
    text = f"polyhedron(points = {points.tolist()}, faces = {faces});"
    solid = csg.read_openscad(text)
    assert len(solid.alternative_faces) == 4
    lo, hi = points.min(axis=0) - 1, points.max(axis=0) + 1
    vox = iv.voxelize(solid, 48, bounds=(tuple(lo), tuple(hi)), workers=1)
    for tri in [(0, 1, 2), (0, 2, 3), (0, 1, 3), (1, 2, 3)]:     # either cut of the quad
        w = np.random.default_rng(sum(tri)).dirichlet(np.ones(3), 300)
        assert misses(vox, w @ quad[list(tri)]) == 0, tri
