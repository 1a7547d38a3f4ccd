"""OpenSCAD's projection (csg.projection): sections and shadows checked against
independent oracles; the fixture projections.scad compares with OpenSCAD's STL."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import csg
import implicitvox as iv
from csg import Box, ConvexPolyhedron, Sphere
from csg.projection import NotAMesh, projection, section_outlines


def _inside(region, points):
    f = iv.Function(region.expr)
    return f(points[:, 0], points[:, 1], np.zeros(len(points))) < 0


def test_section_of_a_polytope_is_its_plane_cut():
    rng = np.random.default_rng(2)
    points = rng.normal(size=(40, 3))
    solid = ConvexPolyhedron(points=points)
    section = projection(solid.rotate((1, 2, 3), 40), cut=True)
    q = rng.uniform(-2.5, 2.5, (5000, 2))
    moved = solid.rotate((1, 2, 3), 40)
    oracle = iv.Function(moved.expr)(q[:, 0], q[:, 1], np.zeros(len(q)))
    clear = np.abs(oracle) > 1e-3                      # off the outline (Clipper's 2^-16 grid)
    assert np.array_equal(_inside(section, q)[clear], (oracle < 0)[clear])


def test_section_through_booleans_and_a_face_on_the_plane():
    ring = projection(Box((4, 4, 2), center=True) - Box((2, 2, 4), center=True), cut=True)
    assert sorted(len(p) for p in ring.paths) == [4, 4]
    lying = projection(Box((3, 2, 1)), cut=True)        # resting on z = 0: its footprint
    assert np.allclose(np.array(lying.bounds)[:, :2], [(0, 0), (3, 2)])
    assert projection(Box((3, 2, 1)).translate((0, 0, -1)), cut=True) is None
    v = np.array([[0, 0, -1], [1, 0, -1], [0, 1, -1], [0, 0, 1], [1, 0, 1], [0, 1, 1.0]])
    f = np.array([[0, 2, 1], [3, 4, 5], [0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4],
                  [2, 0, 3], [2, 3, 5]])
    (loop,) = section_outlines(v, f)          # a prism over a triangle, cut half way up
    assert {(0.0, 0.0), (0.0, 1.0), (1.0, 0.0)} <= set(map(tuple, loop.tolist()))
    area = 0.5 * abs(np.sum(loop[:, 0] * np.roll(loop[:, 1], -1) - np.roll(loop[:, 0], -1) * loop[:, 1]))
    assert area == pytest.approx(0.5)         # the diagonals' crossings lie on its sides


def test_shadow_is_the_union_of_the_projected_triangles():
    box = Box((3, 1, 2), center=True).rotate((1, 1, 0), 50)
    shadow = projection(box)
    corners = np.array([[i, j, k] for i in (-1.5, 1.5) for j in (-.5, .5) for k in (-1, 1.)])
    moved = corners @ box.matrix[:3, :3].T
    hull = ConvexHull(moved[:, :2])                     # the oracle: the hull of the corners
    q = np.random.default_rng(4).uniform(-2.5, 2.5, (5000, 2))
    signed = (q @ hull.equations[:, :2].T + hull.equations[:, 2]).max(axis=1)
    clear = np.abs(signed) > 1e-3                       # off the outline (Clipper's 2^-16 grid)
    assert np.array_equal(_inside(shadow, q)[clear], (signed < 0)[clear])
    two = projection(Box((1, 1, 1)) | Box((1, 1, 1)).translate((3, 0, 0)))
    assert len(two.paths) == 2


def test_shadow_of_a_boolean_is_that_of_its_result():
    # a hole through the whole block shows; one stopping short (or hidden) does not
    through = projection(Box((2, 2, 2), center=True) - Box((1, 1, 4), center=True))
    blind = projection(Box((2, 2, 2), center=True) - Box((1, 1, 1), center=True))
    crossed = projection(Box((2, 2, 2), center=True)
                         - Box((1, 1, 4), center=True).rotate("x", 90))
    for region, area in ((through, 3.0), (blind, 4.0), (crossed, 4.0)):
        q = np.random.default_rng(0).uniform(-1.2, 1.2, (4000, 2))
        hole = (np.abs(q) < 0.5).all(axis=1)
        square = (np.abs(q) < 1).all(axis=1)
        expected = square & ~hole if area == 3.0 else square
        clear = (np.abs(np.abs(q) - 0.5).min(axis=1) > 1e-3) & \
            (np.abs(np.abs(q) - 1).min(axis=1) > 1e-3)
        assert np.array_equal(_inside(region, q)[clear], expected[clear])
    # an intersection: the lens of two offset boxes turned about z
    lens = projection(Box((2, 2, 1), center=True) & Box((2, 2, 1), center=True).rotate("z", 45))
    q = np.random.default_rng(1).uniform(-1.5, 1.5, (4000, 2))
    turned = q @ np.array([[np.cos(np.pi / 4), -np.sin(np.pi / 4)],
                           [np.sin(np.pi / 4), np.cos(np.pi / 4)]])
    d = np.minimum(1 - np.abs(q).max(axis=1), 1 - np.abs(turned).max(axis=1))
    clear = np.abs(d) > 1e-3
    assert np.array_equal(_inside(lens, q)[clear], (d > 0)[clear])


def test_what_has_no_mesh_is_refused_saying_why():
    with pytest.raises(NotAMesh, match="Sphere is curved") as err:
        projection(Sphere(1), cut=True)
    assert err.value.curved
    open_mesh = csg.Polyhedron(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]),
                               np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2]]))
    with pytest.raises(NotAMesh, match="not a closed manifold mesh"):
        projection(Box((2, 2, 2)) - open_mesh)
    text = "linear_extrude(height = 1) projection(cut = true) " \
           "{ sphere($fn = 8, $fa = 12, $fs = 2, r = 1); }"
    with pytest.warns(csg.OpenSCADWarning, match="projection: its curved children"):
        true = csg.read_openscad(text, facets="true")
    assert np.allclose(true.children[0].points,
                       csg.read_openscad(text, facets="openscad").children[0].points)
    with pytest.warns(csg.OpenSCADWarning, match="nothing meets z = 0"):
        csg.read_openscad("linear_extrude(1) projection(cut = true) "
                          "{ multmatrix([[1,0,0,0],[0,1,0,0],[0,0,1,5],[0,0,0,1]]) cube(1); }"
                          "cube(size = 1);", facets="true")
