"""Hulls, Minkowski sums and resize (csg.polytopes, OpenSCAD's hull/minkowski/resize):
exact on polytopes, checked against independent constructions."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial import Delaunay

import csg
import implicitvox as iv
from csg import (Box, Circle, Cylinder, NotAPolytope, Polygon, Polyhedron, Rectangle, Sphere,
                 hull, linear_extrude, minkowski, read_openscad)
from csg.clipper2d import region_paths, to_polygon
from csg.facets import extrusion_mesh_outlines
from csg.polytopes import MAX_PIECES, convex_pieces, vertices


def _voxels(solid, bounds, res=40):
    return solid.voxelize(bounds=bounds, resolution=res, interior=True)


def _in_interior(vox, idx):
    """Whether each voxel index lies in one of the voxelization's interior octants."""
    out = np.zeros(len(idx), dtype=bool)
    depth = vox.grid.depth
    for level, octants in vox.interior.items():
        keys = {tuple(o) for o in np.asarray(octants)}
        out |= np.array([tuple(i >> (depth - level)) in keys for i in idx])
    return out


def _tetra(rng):
    v = rng.uniform(-2, 2, (4, 3))
    if np.linalg.det(v[1:] - v[0]) < 0:
        v[[1, 2]] = v[[2, 1]]
    return v, np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_hull_is_the_hull_of_the_vertices():
    """Points inside the hull of the operands' vertices (scipy's Delaunay, an
    independent oracle) lie in the hull's voxels or interior octants; points
    outside it by more than a voxel's diagonal do not."""
    rng = np.random.default_rng(1)
    parts = [Box(rng.uniform(0.5, 2, 3)).translate(rng.uniform(-3, 3, 3)) for _ in range(4)]
    parts.append(Polyhedron(*_tetra(rng)))
    oracle = Delaunay(np.concatenate([vertices(p) for p in parts]))
    vox = _voxels(hull(*parts), ((-5, -5, -5), (6, 6, 6)))
    g = rng.uniform(-5, 6, (4000, 3))
    idx = vox.grid.voxels_holding(g)[0]
    held = vox.contains(idx) | _in_interior(vox, idx)
    assert held[oracle.find_simplex(g) >= 0].all()
    diagonal = float(np.linalg.norm(vox.voxel_size))
    assert not held[_far_out(oracle, g, diagonal)].any()


def _far_out(oracle, points, distance):
    """Points farther than ``distance`` outside the hull (its facet planes)."""
    from scipy.spatial import ConvexHull
    h = ConvexHull(oracle.points)
    return (points @ h.equations[:, :3].T + h.equations[:, 3]).max(axis=1) > distance


def test_minkowski_of_boxes_is_a_box():
    a = Box((2, 1, 3)).translate((1, 2, 3))
    b = Box((1, 4, 1), center=True)
    s = minkowski(a, b)
    assert np.allclose(np.array(s.bounds), [(0.5, 0, 2.5), (3.5, 5, 6.5)])
    box = Box((3, 5, 4)).translate((0.5, 0, 2.5))
    bounds = ((0, -1, 2), (4, 6, 7))
    assert np.array_equal(_voxels(s, bounds).coords(), _voxels(box, bounds).coords())


def test_minkowski_distributes_over_unions():
    """An L of two boxes plus a box: the union of the two sums, each a box."""
    ell = Box((6, 2, 2)) | Box((2, 6, 2)).translate((0, 4, 0))
    assert len(convex_pieces(ell)) == 2
    s = minkowski(ell, Box((1, 1, 1), center=True))
    expected = Box((7, 3, 3)).translate((-0.5, -0.5, -0.5)) | \
        Box((3, 7, 3)).translate((-0.5, 3.5, -0.5))
    bounds = ((-1, -1, -1), (7, 11, 3))
    assert np.array_equal(_voxels(s, bounds).coords(), _voxels(expected, bounds).coords())


def test_2d_hull_and_sum():
    h = hull(Rectangle((1, 1)), Rectangle((1, 1)).translate((3, 2, 0)))
    assert h.dim == 2 and isinstance(h, Polygon) and len(h.points) == 6
    m = minkowski(Rectangle((2, 2)), Rectangle((1, 1), center=True))
    assert np.allclose(np.array(m.bounds)[:, :2], [(-0.5, -0.5), (2.5, 2.5)])
    prism = linear_extrude(m, 1)
    assert prism.bounds[1][2] == 1


def _area(polygon: Polygon) -> float:
    def ring(k):
        x, y = polygon.points[polygon.paths[k]].T
        return abs(float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))) / 2
    return sum(ring(outer) - sum(ring(h) for h in holes) for outer, holes in polygon.pieces)


def test_2d_sums_with_pieces_that_are_not_convex():
    """OpenSCAD's own 2D sum (Clipper's edge sums and moved operands); the fixture
    tests/openscad/minkowski2d.scad holds it to OpenSCAD's STL voxel for voxel."""
    ell = Rectangle((2, 2)) - Rectangle((1, 1))          # an L: a difference
    m = minkowski(ell, Rectangle((1, 1)))
    assert isinstance(m, Polygon)
    assert np.allclose(np.array(m.bounds)[:, :2], [(0, 0), (3, 3)])
    assert _area(m) == 8.0                               # 3 x 3 less the corner square
    # a dart is the union of three triangles: its sum, the union of theirs (each by
    # the convex path: the hull of the pairwise sums)
    corners = [[0, 0], [4, 0], [4, 4], [2, 1], [0, 4]]
    dart = Polygon(corners)
    tilted = Polygon([[0, 0], [1, 0.25], [0.5, 1]])
    m = minkowski(dart, tilted)
    pieces = [minkowski(Polygon([corners[i] for i in t]), tilted)
              for t in ((0, 1, 3), (1, 2, 3), (0, 3, 4))]
    union = to_polygon(region_paths(csg.Union(*pieces)))
    assert np.allclose(m.bounds, union.bounds)
    assert _area(m) == pytest.approx(_area(union), rel=1e-9) and _area(m) > _area(dart) + 4
    three = minkowski(ell, Rectangle((1, 1)), Rectangle((1, 1)))
    assert np.allclose(np.array(three.bounds)[:, :2], [(0, 0), (4, 4)]) and _area(three) == 15


def test_what_is_no_polytope_is_refused_saying_why():
    with pytest.raises(NotAPolytope, match="Sphere is curved") as err:
        hull(Sphere(1), Box((1, 1, 1)))
    assert err.value.curved
    with pytest.raises(NotAPolytope, match="Cylinder is curved"):
        minkowski(Box((1, 1, 1)), Cylinder(h=1, r=1))
    with pytest.raises(NotAPolytope, match="Circle is curved"):
        minkowski(Rectangle((2, 2)) - Rectangle((1, 1)), Circle(1))
    with pytest.raises(NotAPolytope, match="Circle is curved"):
        hull(Circle(1))
    with pytest.raises(ValueError, match="2D and 3D"):
        hull(Box((1, 1, 1)), Rectangle((1, 1)))
    with pytest.raises(ValueError, match="span no volume"):
        hull(Polyhedron(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]), np.array([[0, 1, 2]])))


def test_minkowski_pieces_are_bounded():
    many = csg.Union(*[Box((1, 1, 1)).translate((2 * i, 0, 0)) for i in range(101)])
    with pytest.raises(ValueError, match="MAX_PIECES"):
        minkowski(many, many)
    assert 101 * 101 > MAX_PIECES


BOUNDS = ((-0.513, -0.513, -0.513), (3.487, 3.487, 3.487))     # no face on a voxel face


def _same_voxels(a, b):
    va, vb = (iv.voxelize(x, 40, bounds=BOUNDS, workers=1) for x in (a, b))
    assert va.count > 0 and np.array_equal(va.coords(), vb.coords())


def test_a_sum_with_pieces_that_are_not_convex_is_exact():
    """``M ⊕ C = (M + c) ∪ ⋃ (T ⊕ C)``: a cube less a corner (a difference), an L-shaped
    prism (a non-convex polyhedron) and two such together, summed, voxelize as the
    sums of their convex parts (unions of boxes), which the sum distributes over."""
    notched = Box((2, 2, 2)) - Box((1, 1, 1))
    parts = [Box((1, 2, 2)).translate((1, 0, 0)), Box((1, 1, 2)).translate((0, 1, 0)),
             Box((1, 1, 1)).translate((0, 0, 1))]
    unit = Box((1, 1, 1), center=True)
    _same_voxels(minkowski(notched, unit), minkowski(csg.Union(*parts), unit))
    ell = Polygon([[0, 0], [3, 0], [3, 1], [1, 1], [1, 3], [0, 3]])
    v, f = extrusion_mesh_outlines([(ell.points, [])], 1.0, 0.0, np.ones(2), 1, 0.0)
    poly = Polyhedron(v, f)
    ell_boxes = csg.Union(Box((3, 1, 1)), Box((1, 3, 1)))
    small = Box((0.5, 0.25, 0.5), center=True)
    _same_voxels(minkowski(poly, small), minkowski(ell_boxes, small))
    _same_voxels(minkowski(small, poly), minkowski(ell_boxes, small))
    # two meshes: M ⊕ N = ⋃ (N + t) ∪ ⋃ (M + s) ∪ ⋃ (T ⊕ S)
    tiny = Polyhedron(0.2 * np.asarray(v), f)
    tiny_boxes = csg.Union(Box((0.6, 0.2, 0.2)), Box((0.2, 0.6, 0.2)))
    _same_voxels(minkowski(poly, tiny), minkowski(ell_boxes, tiny_boxes))
    assert hull(poly, Box((1, 1, 1))).bounds[1][0] == pytest.approx(3.0)


def test_resize_scales_by_the_facets_bounding_box():
    """OpenSCAD's resize of a sphere: the factor comes from its facets' box (a 12-gon
    sphere is narrower than 2r), in both modes; auto axes take the largest factor."""
    text = "resize(newsize = [10, 0, 0], auto = [0, 1, 0]) " \
           "{ sphere($fn = 12, $fa = 12, $fs = 2, r = 2); }"
    facets = read_openscad("sphere($fn = 12, $fa = 12, $fs = 2, r = 2);", facets="openscad")
    lo, hi = np.array(facets.bounds)
    width = hi - lo
    assert width[0] < 4
    lo, hi = np.array(read_openscad(text, facets="openscad").bounds)
    assert np.allclose(hi - lo, [10, width[1] * 10 / width[0], width[2]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")                # no curved hull here: no warning
        lo, hi = np.array(read_openscad(text, facets="true").bounds)
    factor = 10 / width[0]
    assert np.allclose(hi - lo, [4 * factor, 4 * factor, 4])


def test_hull_and_resize_of_a_boolean_take_its_result():
    # the corner cut off a cube leaves a hull without that corner; a hole inside
    # does not change the hull
    cut = hull(Box((2, 2, 2)) - Box((1, 1, 1)).translate((1.5, 1.5, 1.5)))
    q = np.random.default_rng(0).uniform(-0.2, 2.2, (20000, 3))
    inside = iv.Function(cut.expr)(*q.T) < 0
    plane = q.sum(axis=1) - 5.5                   # the hull's cut face: x + y + z = 5.5
    cube = (np.abs(q - 1) < 1).all(axis=1)
    clear = (np.abs(plane) > 1e-6) & (np.abs(np.abs(q - 1) - 1).min(axis=1) > 1e-6)
    assert np.array_equal(inside[clear], (cube & (plane < 0))[clear])
    inner = hull(Box((2, 2, 2)) - Box((1, 1, 1)).translate((0.5, 0.5, 0.5)))
    assert inner.bounds == ((0.0, 0.0, 0.0), (2.0, 2.0, 2.0))
    flat = hull(Rectangle((2, 2)) - Rectangle((1, 1)).translate((1, 1, 0)))
    assert np.allclose(np.array(flat.bounds)[:, :2], [(0, 0), (2, 2)])
    assert not (iv.Function(flat.expr)(1.9, 1.9, 0.0) < 0)   # the corner is cut
    text = "resize(newsize = [6, 6, 6]) { difference() { cube(size = 3); " \
           "multmatrix([[1, 0, 0, 2], [0, 1, 0, 2], [0, 0, 1, 2], [0, 0, 0, 1]]) cube(size = 2); } }"
    lo, hi = np.array(read_openscad(text, facets="openscad").bounds)
    assert np.allclose(lo, 0) and np.allclose(hi, 6)


def test_a_faceted_cone_is_a_convex_polyhedron_of_its_facets_planes():
    """Qhull's triangles of one facet share its plane: OpenSCAD's 30-gon frustum is a
    ConvexPolyhedron of 32 planes (not 116 triangle planes, nor a mesh), and its
    exact test gives the very voxels and interior of the mesh test on its triangles."""
    from scipy.spatial import ConvexHull
    from csg import facets
    from csg.polytopes import convex_solid
    pts = facets.cylinder_points(20.0, 5.0, -25.0, 25.0, 30)
    cone = convex_solid(pts)
    assert isinstance(cone, csg.ConvexPolyhedron) and len(cone.normals) == 32
    h = ConvexHull(pts)
    faces = h.simplices.copy()
    v = pts[faces]
    flip = np.einsum("ij,ij->i", np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]),
                     h.equations[:, :3]) < 0
    faces[flip] = faces[flip][:, ::-1]
    mesh = Polyhedron(pts, faces)
    bounds = ((-21, -21, -26), (21, 21, 26))
    a, b = _voxels(cone, bounds, 48), _voxels(mesh, bounds, 48)
    from tests.golden.digests import voxel_digests
    assert a.count > 0 and voxel_digests(a) == voxel_digests(b)
