"""2D booleans and offsets as OpenSCAD computes them with Clipper (csg.clipper2d); the
fixture offsets.scad compares with OpenSCAD's own STL."""
from __future__ import annotations

import math

import numpy as np
import pytest

import csg
import implicitvox as iv
from csg import Circle, Polygon, Rectangle
from csg.clipper2d import CLIPPER_SCALE, NotFlat, offset, region_paths, to_polygon


def _inside(region, points):
    f = iv.Function(region.expr)
    return f(points[:, 0], points[:, 1], np.zeros(len(points))) < 0


def test_round_offset_is_at_distance_r_with_openscads_steps():
    square = Rectangle((4, 2), center=True)
    n = 24
    grown = offset(square, 1.5, "round", fragments=n)
    pts = grown.points
    # every point is 1.5 from the rectangle (on a side's parallel or a corner's arc)
    d = np.hypot(np.maximum(np.abs(pts[:, 0]) - 2, 0), np.maximum(np.abs(pts[:, 1]) - 1, 0))
    assert np.allclose(d, 1.5, atol=4 / CLIPPER_SCALE)
    # a quarter turn per corner: n / 4 steps, n / 4 + 1 points
    corner = pts[(pts[:, 0] >= 2 - 1e-4) & (pts[:, 1] >= 1 - 1e-4)]     # the arc's ends too
    assert len(corner) == n // 4 + 1
    assert np.allclose(np.array(grown.bounds), [(-3.5, -2.5, 0), (3.5, 2.5, 0)], atol=1e-4)


def test_sharp_and_chamfered_offsets():
    triangle = Polygon([[0, 0], [4, 0], [0, 3]])
    sharp = offset(triangle, 1.0, "miter")
    assert len(sharp.points) == 3                       # corners stay sharp
    cut = offset(triangle, 1.0, "square")
    assert len(cut.points) == 6                         # each corner cut once
    assert _inside(sharp, np.array([[-0.9, -0.9]]))[0]
    assert not _inside(cut, np.array([[-0.9, -0.9]]))[0]
    assert offset(triangle, -2.0, "miter") is None      # shrunk away


def test_booleans_as_openscad_applies_them():
    square = Rectangle((6, 6))
    hole = Polygon([[2, 2], [4, 2], [4, 4], [2, 4]])
    ring = to_polygon(region_paths(square - hole))
    both = to_polygon(region_paths(square & hole.translate((1, 1, 0))))
    rng = np.random.default_rng(0)
    q = rng.uniform(-1, 7, (4000, 2))
    in_square = np.all((q >= 0) & (q <= 6), axis=1)
    in_hole = np.all((q >= 2) & (q <= 4), axis=1)
    in_moved = np.all((q >= 3) & (q <= 5), axis=1)
    away = lambda lo, hi: np.min(np.abs(np.concatenate([q - lo, q - hi], axis=1)), axis=1) > 1e-3
    keep = away(0, 6) & away(2, 4) & away(3, 5)
    assert np.array_equal(_inside(ring, q)[keep], (in_square & ~in_hole)[keep])
    assert np.array_equal(_inside(both, q)[keep], (in_square & in_moved)[keep])


def test_points_are_truncated_as_openscad_truncates():
    tiny = 1.9 / CLIPPER_SCALE
    paths = region_paths(Polygon([[-tiny, -tiny], [3, 0], [0, 3]]))
    assert min(min(p[0] for p in path) for path in paths) == -1      # toward zero, not -2


def test_true_circles_are_refused_or_faceted_with_a_warning():
    with pytest.raises(NotFlat, match="true circle"):
        offset(Circle(1), 0.5, "round", fragments=12)
    text = "linear_extrude(height = 1) offset(r = 0.5, $fn = 12) " \
           "{ circle($fn = 12, $fa = 12, $fs = 2, r = 1); }"
    faceted = csg.read_openscad(text, facets="openscad")
    with pytest.warns(csg.OpenSCADWarning, match="offset: its circles are taken as OpenSCAD"):
        true = csg.read_openscad(text, facets="true")
    assert np.allclose(true.children[0].points, faceted.children[0].points)
    with pytest.warns(csg.OpenSCADWarning, match="leaves nothing"):
        csg.read_openscad("linear_extrude(1) offset(r = -2, $fn = 8) { square(size = 1); }"
                          "cube(size = 1);", facets="true")
    with pytest.raises(ValueError, match="join must be one of"):
        offset(Rectangle((1, 1)), 1.0, "bevel")
    assert math.isclose(CLIPPER_SCALE, 65536.0)


def test_parts_that_vanish_on_clippers_grid_leave_nothing_not_an_exception():
    """A part smaller than Clipper's 2^-16 truncates to a point: Clipper's own AddPaths
    adds nothing (OpenSCAD goes on with the rest); pyclipper's exception is not let out."""
    from csg.clipper2d import clip, to_clipper
    tiny = to_clipper(np.array([[0, 0], [1e-20, 0], [1e-20, 1e-20]]))
    square = to_clipper(np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]))
    assert clip([tiny], [], "CT_UNION") == []
    assert len(clip([square], [tiny], "CT_DIFFERENCE")) == 1            # nothing is cut
    assert clip([square], [tiny], "CT_INTERSECTION") == []
    solid = csg.read_openscad("linear_extrude(height = 1) square(size = [1e-20, 1]);\n"
                          "cube(size = 1);")
    assert solid.voxelize(8).count > 0
