"""Convex hulls and Minkowski sums of polytopes, exact from their vertices.

The convex hull of solids whose boundaries are flat (boxes, polyhedra,
polygons, OpenSCAD's faceted spheres and cylinders, straight extrusions of
polygons, moved and united) is the hull of their vertices, a convex polytope;
the Minkowski sum of two convex polytopes is the hull of the pairwise sums of
their vertices, and the sum distributes over unions,
``(A ∪ B) ⊕ C = (A ⊕ C) ∪ (B ⊕ C)``, so a sum of unions of convex pieces is a
union of convex polytopes. Both are exact (up to the rounding of the sums)
and are what OpenSCAD's ``hull`` and ``minkowski`` compute on its facets.

The hull of a difference or intersection is that of the boolean's result, computed
first as OpenSCAD computes it: in 2D by Clipper, in 3D by Manifold
(:mod:`csg.tree_mesh`). What has no vertex set raises :class:`NotAPolytope` saying
why: a curved solid (a true sphere or cylinder: the hull of spheres is not a
polytope), or a non-convex piece of a Minkowski sum (a difference among them).

Examples
--------
>>> from csg import Box, Sphere
>>> capsule_box = hull(Box((1, 1, 1)), Box((1, 1, 1)).translate((3, 0, 0)))
>>> capsule_box.bounds
((0.0, 0.0, 0.0), (4.0, 1.0, 1.0))
>>> rounded = minkowski(Box((2, 2, 2), center=True), Box((1, 1, 1), center=True))
>>> rounded.bounds
((-1.5, -1.5, -1.5), (1.5, 1.5, 1.5))
>>> hull(Sphere(1), Box((1, 1, 1)))
Traceback (most recent call last):
...
csg.polytopes.NotAPolytope: a Sphere is curved: its hull or Minkowski sum is no polytope (facet it first, as OpenSCAD does: read_openscad(..., facets='openscad'))
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .clipper2d import CLIPPER_SCALE, NotFlat, region_paths
from .planar import Circle, LinearExtrude, Polygon, Rectangle
from .primitives import Box, ConvexPolyhedron, Cylinder, Ellipsoid, Polyhedron, Sphere, Torus
from .solid import Solid, Transformed, Union
from .tree_mesh import NotAMesh, mesh_volume, tree_mesh

__all__ = ["hull", "minkowski", "vertices", "convex_pieces", "convex_solid", "NotAPolytope",
           "MAX_PLANES", "MAX_PIECES", "MAX_SUMS"]

#: convex polytopes with more faces become polyhedra (exact test, grid-indexed) instead of
#: a max over planes, whose cost grows with the number of planes
MAX_PLANES = 64
#: the convex pieces a Minkowski sum may make (each pair of operand pieces is one)
MAX_PIECES = 10_000
#: the vertex sums (over all pieces) a Minkowski sum may compute
MAX_SUMS = 10_000_000

_CURVED = (Sphere, Cylinder, Torus, Ellipsoid, Circle)


class NotAPolytope(ValueError):
    """A solid with no vertex set: curved, or (for a Minkowski sum) a non-convex
    piece."""

    def __init__(self, message: str, curved: bool = False):
        super().__init__(message)
        #: the reason is a curved surface (facetting the solid would make it a polytope)
        self.curved = curved


def vertices(solid: Solid) -> np.ndarray:
    """The vertices of a polytope tree: (n, 3), or (n, 2) for a 2D shape; their
    convex hull is the solid's.

    Raises
    ------
    NotAPolytope
        A curved leaf, a twisted extrusion, an empty boolean.
    """
    return np.concatenate(convex_pieces(solid, convex=False))


def convex_pieces(solid: Solid, convex: bool = True) -> list[np.ndarray]:
    """The vertex sets of the convex pieces whose union is ``solid`` (a union's
    children, each a convex leaf); with ``convex=False`` any leaf passes (its
    vertices only bound it), as for a hull.

    Raises
    ------
    NotAPolytope
        As :func:`vertices`; with ``convex``, also a leaf that is not convex.
    """
    return _pieces(solid, np.eye(4), convex)


def _pieces(solid: Solid, matrix: np.ndarray, convex: bool) -> list[np.ndarray]:
    dim = solid.dim
    if isinstance(solid, Transformed):
        return _pieces(solid.children[0], matrix @ solid.matrix, convex)
    if isinstance(solid, Union):
        return [p for child in solid.children for p in _pieces(child, matrix, convex)]
    points = _leaf_vertices(solid, convex)
    if dim == 2:
        return [points[:, :2] @ matrix[:2, :2].T + matrix[:2, 3]]
    return [points @ matrix[:3, :3].T + matrix[:3, 3]]


def _leaf_vertices(solid: Solid, convex: bool) -> np.ndarray:
    name = type(solid).__name__
    if isinstance(solid, _CURVED):
        raise NotAPolytope(f"a {name} is curved: its hull or Minkowski sum is no polytope "
                           "(facet it first, as OpenSCAD does: read_openscad(..., "
                           "facets='openscad'))", curved=True)
    if isinstance(solid, Box):
        lo = -solid.size / 2 if solid.centered else np.zeros(3)
        corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
        return lo + corners * solid.size
    if isinstance(solid, ConvexPolyhedron):
        if solid.points is None:
            raise NotAPolytope("a ConvexPolyhedron given by planes has no vertex list "
                               "(give points=)")
        return solid.points
    if isinstance(solid, Polyhedron):
        used = np.unique(solid.faces.ravel())
        v = solid.vertices[used]
        if convex and not _is_convex(solid.vertices, solid.faces):
            raise NotAPolytope("a non-convex Polyhedron in a Minkowski sum (its convex "
                               "decomposition is not built: split it into convex parts)")
        return v
    if isinstance(solid, Rectangle):
        lo = -solid.size / 2 if solid.centered else np.zeros(2)
        hi = lo + solid.size
        return np.array([[lo[0], lo[1], 0], [hi[0], lo[1], 0], [hi[0], hi[1], 0],
                         [lo[0], hi[1], 0]], dtype=np.float64)
    if isinstance(solid, Polygon):
        if convex and (len(solid.pieces) != 1 or solid.pieces[0][1] or
                       not _is_convex_polygon(solid.points[solid.paths[solid.pieces[0][0]]])):
            raise NotAPolytope("a non-convex polygon in a Minkowski sum (its convex "
                               "decomposition is not built: split it into convex parts)")
        used = sorted({i for k, _ in solid.pieces for i in solid.paths[k]})
        p = solid.points[used]
        return np.column_stack([p, np.zeros(len(p))])
    if isinstance(solid, LinearExtrude):
        if solid.twist != 0:
            raise NotAPolytope("a twisted linear_extrude is curved: its hull is no polytope "
                               "(facet it first: read_openscad(..., facets='openscad'))",
                               curved=True)
        if convex:
            base = convex_pieces(solid.children[0], convex=True)
            if len(base) != 1:
                raise NotAPolytope("an extrusion of several pieces in a Minkowski sum "
                                   "(split it into one extrusion per convex piece)")
        flat = vertices(solid.children[0])
        z0 = -solid.height / 2 if solid.centered else 0.0
        bottom = np.column_stack([flat, np.full(len(flat), z0)])
        top = np.column_stack([flat * solid.scale_top, np.full(len(flat), z0 + solid.height)])
        return np.concatenate([bottom, top])
    if name in ("Difference", "Intersection"):
        if convex:
            raise NotAPolytope(f"a {name.lower()} in a Minkowski sum (its result is not "
                               "convex in general, and its convex decomposition is not "
                               "built: split it into convex parts)")
        return _boolean_vertices(solid)
    raise NotAPolytope(f"a {name} has no vertex set here (hull and minkowski take boxes, "
                       "polyhedra, polygons, straight extrusions, moved and united)")


def _boolean_vertices(solid: Solid) -> np.ndarray:
    """The vertices of a difference's or intersection's result: in 2D the Clipper
    outlines OpenSCAD computes (:func:`csg.clipper2d.region_paths`), in 3D the mesh
    Manifold computes (:func:`csg.tree_mesh.tree_mesh`), as OpenSCAD computes the
    boolean (CGAL) before its hull."""
    if solid.dim == 2:
        try:
            paths = region_paths(solid)
        except NotFlat as err:
            raise NotAPolytope(str(err), curved=True) from None
        if not paths:
            raise NotAPolytope(f"the {type(solid).__name__.lower()} is empty: no vertices")
        flat = np.concatenate([np.asarray(q, dtype=np.float64) for q in paths]) / CLIPPER_SCALE
        return np.column_stack([flat, np.zeros(len(flat))])
    try:
        v, f = tree_mesh(solid, np.eye(4))
    except NotAMesh as err:
        raise NotAPolytope(str(err), curved=err.curved) from None
    if not len(f):
        raise NotAPolytope(f"the {type(solid).__name__.lower()} is empty: no vertices")
    return v[np.unique(f.ravel())]


def _is_convex_polygon(poly: np.ndarray) -> bool:
    d = np.roll(poly, -1, axis=0) - poly
    cross = d[:, 0] * np.roll(d, -1, axis=0)[:, 1] - d[:, 1] * np.roll(d, -1, axis=0)[:, 0]
    scale = np.abs(d).max() ** 2
    return bool(np.all(cross >= -1e-12 * scale) or np.all(cross <= 1e-12 * scale))


def _is_convex(v: np.ndarray, f: np.ndarray) -> bool:
    """Whether a closed mesh is convex: its volume equals its hull's."""
    from scipy.spatial import ConvexHull, QhullError
    volume = abs(mesh_volume(v, f))
    try:
        whole = ConvexHull(v[np.unique(f.ravel())]).volume
    except QhullError:
        return False
    return bool(abs(whole - volume) <= 1e-9 * whole)


def convex_solid(points: Any) -> Solid:
    """The convex hull of ``points`` as a solid: (n, 3) points give a
    :class:`~csg.primitives.ConvexPolyhedron` (a :class:`~csg.primitives.Polyhedron`
    of its hull's triangles past :data:`MAX_PLANES` faces), (n, 2) points a convex
    :class:`~csg.planar.Polygon`.

    Raises
    ------
    ValueError
        The points span no area (2D) or volume (3D).
    """
    from scipy.spatial import ConvexHull, QhullError
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3) or not np.all(np.isfinite(pts)):
        raise ValueError("points must be an (n, 2) or (n, 3) array of finite numbers")
    what = "area" if pts.shape[1] == 2 else "volume"
    try:
        hull = ConvexHull(pts)
    except QhullError as err:
        raise ValueError(f"the points span no {what} (flat or degenerate): "
                         f"{str(err).splitlines()[0]}") from None
    if pts.shape[1] == 2:
        return Polygon(pts[hull.vertices])           # counter-clockwise in 2D
    if len(np.unique(hull.equations, axis=0)) <= MAX_PLANES:   # a facet's triangles share one
        return ConvexPolyhedron(points=pts)
    faces = hull.simplices.copy()
    # orient every triangle outward: its normal along the hull's facet normal
    v = pts[faces]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    flip = np.einsum("ij,ij->i", n, hull.equations[:, :3]) < 0
    faces[flip] = faces[flip][:, ::-1]
    return Polyhedron(pts, faces)


def _same_dim(solids: tuple, what: str) -> int:
    if not solids:
        raise ValueError(f"{what} needs at least one solid")
    dims = {s.dim for s in solids}
    if len(dims) != 1:
        raise ValueError(f"{what} of 2D and 3D operands (all must be of one dimension)")
    return dims.pop()


def hull(*solids: Solid) -> Solid:
    """The convex hull of ``solids`` (polytope trees, all 2D or all 3D), exact:
    the hull of their vertices (OpenSCAD's ``hull()``).

    Raises
    ------
    NotAPolytope
        An operand has no vertex set (:func:`vertices`).
    """
    _same_dim(solids, "hull")
    return convex_solid(np.concatenate([vertices(s) for s in solids]))


def minkowski(*solids: Solid) -> Solid:
    """The Minkowski sum of ``solids`` (unions of convex polytopes, all 2D or all
    3D), exact: per combination of convex pieces, the hull of the pairwise sums
    of their vertices; the union of those (OpenSCAD's ``minkowski()``).

    Raises
    ------
    NotAPolytope
        An operand is not a union of convex polytopes (:func:`convex_pieces`).
    ValueError
        The sum would have more than :data:`MAX_PIECES` convex pieces or
        :data:`MAX_SUMS` vertex sums.
    """
    _same_dim(solids, "minkowski")
    sums = convex_pieces(solids[0])
    for solid in solids[1:]:
        pieces = convex_pieces(solid)
        if len(sums) * len(pieces) > MAX_PIECES:
            raise ValueError(f"minkowski: {len(sums) * len(pieces):,} convex pieces, over "
                             f"the limit of {MAX_PIECES:,} (csg.polytopes.MAX_PIECES)")
        count = sum(len(a) for a in sums) * sum(len(b) for b in pieces)
        if count > MAX_SUMS:
            raise ValueError(f"minkowski: {count:,} vertex sums, over the limit of "
                             f"{MAX_SUMS:,} (csg.polytopes.MAX_SUMS)")
        sums = [(a[:, None, :] + b[None, :, :]).reshape(-1, a.shape[1])
                for a in sums for b in pieces]
    parts = [convex_solid(p) for p in sums]
    return parts[0] if len(parts) == 1 else Union(*parts)
