"""csg.prism: the exact box test of straight prisms agrees with the exact mesh test."""
from __future__ import annotations

import numpy as np
import pytest

import csg
from csg.tree_classifier import MeshClassifier
from csg.clipper2d import region_pieces
from csg.prism import Prism
from implicitvox.triangles.prism_classifier import axis_permutation


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


def test_a_ring_touching_itself_gets_the_exact_tests_sign(monkeypatch):
    """A hole of GEB's shadow as Clipper once gave it: one ring touching itself at three
    vertices. Its triangulated function was inside where the crossing number is
    outside, over half its box, so the intervals dropped 416 surface voxels of GEB.
    Clipper now splits such rings (StrictlySimple, in the region's outlines and in a
    Prism's own parts): the prism's function and its exact test agree at every point
    off the surface."""
    import implicitvox as iv
    from pathlib import Path
    from implicitvox.expr.shape import EMPTY, FULL
    ring = np.loadtxt(Path(__file__).parents[1] / "openscad" / "geb_shadow_ring.txt")
    assert len(np.unique(ring, axis=0)) < len(ring)                  # it touches itself
    outer = np.array([[-20.0, -19], [19, -19], [19, 20], [-20, 20]])
    from csg import prism as prism_module
    monkeypatch.setattr(prism_module, "FUNCTION_VERTICES", 10 ** 6)   # its own function
    prism = Prism([(outer, [ring])], 1.0)
    f = iv.compile(prism.expr)
    rng = np.random.default_rng(4)
    lo, hi = ring.min(axis=0), ring.max(axis=0)
    p = np.column_stack([rng.uniform(lo, hi, (6000, 2)), rng.uniform(0.1, 0.9, 6000)])
    _, test = prism.exact_leaf(np.eye(4))
    state = test.classify(p, p)
    off = (state == FULL) | (state == EMPTY)
    assert off.mean() > 0.99 and 0.2 < (state[off] == FULL).mean() < 0.8
    assert np.array_equal(f(p[off, 0], p[off, 1], p[off, 2]) < 0, state[off] == FULL)


def test_the_function_keeps_clippers_nesting_where_rings_touch():
    """An island touching its hole at three vertices (as Clipper's outlines may): found
    again by containment of vertices, the hole would lie in the island and be solid. The
    prism's function takes Clipper's nesting, so its sign is the exact test's."""
    import implicitvox as iv
    from implicitvox.expr.shape import EMPTY, FULL
    outer = np.array([[0.0, 0], [4, 0], [4, 4], [0, 4]])
    hole = np.array([[1.0, 1], [1, 3], [3, 3], [3, 1]])                  # clockwise
    island = np.array([[1.0, 1], [3, 1], [3, 3]])                        # in the hole
    prism = Prism([(outer, [hole]), (island, [])], 1.0)
    f = iv.compile(prism.expr)
    rng = np.random.default_rng(4)
    p = np.column_stack([rng.uniform(-0.5, 4.5, (4000, 2)), rng.uniform(0.1, 0.9, 4000)])
    _, test = prism.exact_leaf(np.eye(4))
    state = test.classify(p, p)
    off = (state == FULL) | (state == EMPTY)
    assert off.mean() > 0.99
    assert np.array_equal(f(p[off, 0], p[off, 1], p[off, 2]) < 0, state[off] == FULL)
    in_hole = (p[off, 0] > 1.1) & (p[off, 0] < 2.9) & (p[off, 1] > 1.1) & (p[off, 1] < 2.9)
    above = p[off, 1] > p[off, 0] + 0.05                   # the hole's half the island leaves
    assert in_hole[above].any() and not (state[off] == FULL)[in_hole & above].any()


def test_a_long_outline_has_a_bound_for_its_function_and_the_same_voxels(monkeypatch):
    """Past FUNCTION_VERTICES outline vertices the prism's function is only a bound (its
    box): the exact test decides every box, giving the voxels of the full function."""
    from csg import prism as prism_module
    from tests.golden.digests import voxel_digests
    angle = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    radius = 1 + 0.3 * np.sin(7 * angle)
    gear = np.column_stack([np.cos(angle), np.sin(angle)]) * radius[:, None]
    hole = 0.3 * np.column_stack([np.cos(angle), -np.sin(angle)])[::8]
    body = Prism([(gear, [hole])], 0.5)
    assert body.needs_exact_test and not body.expression_is_exact
    bounded = body.rotate("x", 90).voxelize(48, interior=True)
    with monkeypatch.context() as m:
        m.setattr(prism_module, "FUNCTION_VERTICES", 10 ** 6)
        full = Prism([(gear, [hole])], 0.5)
        assert not full.needs_exact_test
        exact = full.rotate("x", 90).voxelize(48, interior=True)
    assert bounded.count > 0 and voxel_digests(bounded) == voxel_digests(exact)


def test_many_small_prisms_of_a_model_keep_only_their_bounds_and_the_same_voxels():
    """A model of many short-outlined prisms (OpenSCAD's example023: 51 of 20 vertices)
    pays for every prism's function on every box; past TREE_FUNCTION_VERTICES in all
    they keep only their bounds, and the exact tests give the same voxels."""
    from csg.prism import TREE_FUNCTION_VERTICES, bound_functions
    from tests.golden.digests import voxel_digests
    def letter(i: int) -> str:        # a 5-vertex outline, moved along x
        return (f"multmatrix([[1, 0, 0, {3 * i}], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) "
                "{ linear_extrude(height = 2) { polygon(points = [[0, 0], [2, 0], [2, 2], "
                "[1, 1], [0, 2]], paths = [[0, 1, 2, 3, 4]]); } }")
    letters = " ".join(letter(i) for i in range(TREE_FUNCTION_VERTICES // 5 + 1))
    bounded = csg.read_openscad(f"union() {{ {letters} }}")
    kept = csg.read_openscad(f"union() {{ {letters} }}")
    prisms = [leaf for leaf in bounded.children if isinstance(leaf.children[0], Prism)]
    assert prisms and all(p.children[0].needs_exact_test for p in prisms)
    for leaf in kept.children:
        leaf.children[0].needs_exact_test = False         # their functions, as before
    assert voxel_digests(bounded.voxelize(64, interior=True)) == \
        voxel_digests(kept.voxelize(64, interior=True))
    few = csg.read_openscad(letter(0))                      # one prism: its function
    assert not few.children[0].needs_exact_test and bound_functions(few) == 0
