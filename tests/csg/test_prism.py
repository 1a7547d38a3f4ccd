"""csg.prism: the exact box test of straight prisms agrees with the exact mesh test."""
from __future__ import annotations

import numpy as np
import pytest

import csg
from csg.classify import MeshClassifier
from csg.clipper2d import region_pieces
from csg.prism import Prism, axis_permutation


def _star(rng, n, r0, r1, centre):
    angle = np.sort(rng.uniform(0, 2 * np.pi, n))
    radius = rng.uniform(r0, r1, n)
    return np.column_stack([np.cos(angle), np.sin(angle)]) * radius[:, None] + centre


PLACEMENTS = {
    "identity": np.eye(4),
    "standing": np.array([[1, 0, 0, 2], [0, 0, -1, 0.5], [0, 1, 0, -1], [0, 0, 0, 1.0]]),
    "mirrored, scaled": np.array([[0, 0, 2, 0], [-1, 0, 0, 0.25], [0, 0.5, 0, 0], [0, 0, 0, 1.0]]),
    "turned": csg.Box((1, 1, 1)).rotate("z", 30).matrix,
}


@pytest.mark.parametrize("placement", PLACEMENTS)
def test_prism_box_test_is_the_mesh_test(placement):
    rng = np.random.default_rng(3)
    matrix = PLACEMENTS[placement]
    # a concave star with a star-shaped hole and an island, snapped to a 1/8 grid so that
    # edges and vertices lie on the box lattice (ties everywhere)
    outer = np.round(_star(rng, 14, 0.6, 1.6, (0, 0)) * 8) / 8
    hole = np.round(_star(rng, 9, 0.2, 0.5, (0.1, 0))[::-1] * 8) / 8
    island = np.array([[0.0, 0.0], [0.125, 0.0], [0.125, 0.125], [0.0, 0.125]])
    region = csg.Polygon(np.concatenate([outer, hole, island]),
                         [list(range(14)), list(range(14, 23)), list(range(23, 27))])
    prism = Prism(region_pieces(region), 1.25, center=True)
    kind, test = prism.exact_leaf(matrix)
    assert kind == ("mesh" if axis_permutation(matrix[:3, :3]) is None else "prism")
    v, f = prism.mesh(matrix)
    oracle = MeshClassifier(v, f, np.linalg.det(matrix[:3, :3]) < 0)
    lo = np.round(rng.uniform(-2.5, 2.5, (20000, 3)) * 16) / 16
    hi = lo + rng.choice([1 / 16, 1 / 8, 1 / 2, 2], (20000, 1))
    got, want = test.classify(lo, hi), oracle.classify(lo, hi)
    assert np.array_equal(got, want)
    assert len(np.unique(want)) == 3                     # every answer well represented


def test_openscad_extrusions_are_prisms_and_exact():
    text = ("linear_extrude(height = 2, center = true) difference() { square(size = [4, 4]); "
            "polygon(points = [[1, 1], [3, 1], [2, 3]]); }")
    solid = csg.read_openscad(text)
    assert isinstance(solid, Prism)
    vox = solid.voxelize(32)
    mesh = csg.Polyhedron(*solid.mesh()).voxelize(bounds=vox.bounds, voxel_size=vox.voxel_size)
    assert vox.count == mesh.count and np.all(vox.contains(mesh.coords()))
