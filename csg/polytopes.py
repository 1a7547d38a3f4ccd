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
csg.protocol.NotAPolytope: a Sphere is curved: its hull or Minkowski sum is no polytope (facet it first, as OpenSCAD does: read_openscad(..., facets='openscad'))
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .clipper2d import CLIPPER_SCALE, region_paths
from .clipper2d import minkowski as clipper_minkowski
from .planar import Polygon
from .primitives import ConvexPolyhedron, Polyhedron
from .protocol import NotAMesh, NotAPolytope, NotFlat, fold
from .solid import Solid, Union
from .tree_mesh import tree_mesh
from implicitvox.triangles.closed import is_convex_mesh

__all__ = ["hull", "minkowski", "vertices", "convex_pieces", "convex_solid", "NotAPolytope",
           "MAX_PLANES", "MAX_PIECES", "MAX_SUMS"]

#: convex polytopes with more faces become polyhedra (exact test, grid-indexed) instead of
#: a max over planes, whose cost grows with the number of planes
MAX_PLANES = 64
#: the convex pieces a Minkowski sum may make (each pair of operand pieces is one)
MAX_PIECES = 10_000
#: the vertex sums (over all pieces) a Minkowski sum may compute
MAX_SUMS = 10_000_000

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


class MeshPiece(NamedTuple):
    """A piece of a Minkowski operand that is not convex: its closed mesh."""
    vertices: np.ndarray
    faces: np.ndarray


def _pieces(solid: Solid, matrix: np.ndarray, convex: bool, meshes: bool = False) -> list:
    """The tree walked (:func:`csg.protocol.fold`) through its unions and transforms:
    each leaf's :meth:`~csg.solid.Solid.polytope_vertices`, a difference's or
    intersection's result (:func:`_boolean_vertices`), moved. With ``meshes`` (and
    ``convex``), a 3D piece that is not convex is its closed mesh (a
    :class:`MeshPiece`: a difference's or intersection's by Manifold, a
    polyhedron's own) instead of an error."""
    def leaf(node: Solid, moved: np.ndarray) -> list:
        if node.operation in ("difference", "intersection"):
            if convex and not (meshes and node.dim == 3):
                name = type(node).__name__.lower()
                raise NotAPolytope(f"a {name} in a Minkowski sum (its result is not convex "
                                   "in general, and its convex decomposition is not built: "
                                   "split it into convex parts)")
            if convex:
                v, f = _boolean_mesh(node)
                return [_moved_piece(v, f, moved)]
            points = _boolean_vertices(node)
        else:
            try:
                points = node.polytope_vertices(convex, convex_pieces)
            except NotAPolytope as err:
                if not (convex and meshes and node.dim == 3) or err.curved or err.empty:
                    raise
                try:
                    v, f = node.closed_mesh()
                except NotAMesh:
                    raise err from None
                return [_moved_piece(np.asarray(v, float), np.asarray(f, np.int64), moved)]
        if node.dim == 2:
            return [points[:, :2] @ moved[:2, :2].T + moved[:2, 3]]
        return [points @ moved[:3, :3].T + moved[:3, 3]]

    return fold(solid, leaf, lambda operation, parts: [p for part in parts for p in part],
                matrix, booleans=("union",))


def _moved_piece(v: np.ndarray, f: np.ndarray, moved: np.ndarray):
    """A 3D mesh, moved: its vertices if it is convex (a convex piece), else a
    :class:`MeshPiece`."""
    v = v @ moved[:3, :3].T + moved[:3, 3]
    if np.linalg.det(moved[:3, :3]) < 0:
        f = f[:, ::-1]                       # mirrored: keep the faces outward
    return v[np.unique(f.ravel())] if is_convex_mesh(v, f) else MeshPiece(v, f)


def _boolean_mesh(solid: Solid) -> tuple[np.ndarray, np.ndarray]:
    """The closed mesh of a 3D difference's or intersection's result (Manifold)."""
    try:
        v, f = tree_mesh(solid, np.eye(4))
    except NotAMesh as err:
        raise NotAPolytope(str(err), curved=err.curved) from None
    if not len(f):
        raise NotAPolytope(f"the {type(solid).__name__.lower()} is empty: no vertices",
                           empty=True)
    return v, f


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
            raise NotAPolytope(f"the {type(solid).__name__.lower()} is empty: no vertices",
                               empty=True)
        flat = np.concatenate([np.asarray(q, dtype=np.float64) for q in paths]) / CLIPPER_SCALE
        return np.column_stack([flat, np.zeros(len(flat))])
    v, f = _boolean_mesh(solid)
    return v[np.unique(f.ravel())]


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
    """The Minkowski sum of ``solids`` (polytope trees, all 2D or all 3D), exact: per
    combination of convex pieces, the hull of the pairwise sums of their vertices;
    the union of those (OpenSCAD's ``minkowski()``).

    A 3D piece that is not convex (a difference, a non-convex polyhedron) needs no
    convex decomposition: for a closed mesh ``M`` and a convex ``C`` holding a
    point ``c``, ``M ⊕ C = (M + c) ∪ ⋃ (T ⊕ C)`` over ``M``'s triangles ``T``
    (a point ``m + c'`` of the sum off ``M + c`` is reached from ``m + c`` by
    moving along ``c' - c``, which leaves ``M`` through a triangle while the rest
    of the move stays in ``C``), each ``T ⊕ C`` the hull of ``3 |C|`` sums; for two
    meshes, ``M ⊕ N = ⋃ (N + t) ∪ ⋃ (M + s) ∪ ⋃ (T ⊕ S)`` over their triangles
    ``T ∋ t`` and ``S ∋ s``. The same point set as OpenSCAD's union over the convex
    parts of its decomposition (CGAL's ``convex_decomposition_3``), whatever those
    parts are. Where a 2D piece is not convex (a concave polygon, a difference), the
    sum is OpenSCAD's own (:func:`csg.clipper2d.minkowski`: edge sums and moved
    operands, united by Clipper on OpenSCAD's integer grid).

    Raises
    ------
    NotAPolytope
        An operand has a curved piece.
    ValueError
        The sum would have more than :data:`MAX_PIECES` pieces or
        :data:`MAX_SUMS` vertex sums.
    """
    if _same_dim(solids, "minkowski") == 2:
        errors = []
        for solid in solids:
            try:
                _pieces(solid, np.eye(4), True)
            except NotAPolytope as err:
                errors.append(err)
        for err in errors:
            if err.curved or err.empty:
                raise err
        if errors:
            # a piece that is not convex: OpenSCAD's own 2D sum, on its integers
            try:
                region = clipper_minkowski(solids)
            except NotFlat as err:            # a curved leaf beside the concave piece
                raise NotAPolytope(str(err), curved=True) from None
            if region is None:
                raise ValueError("minkowski: the sum spans no area")
            return region
    sums = _pieces(solids[0], np.eye(4), True, meshes=True)
    for solid in solids[1:]:
        pieces = _pieces(solid, np.eye(4), True, meshes=True)
        sums = _sum_pairs(sums, pieces)
    parts = [Polyhedron(p.vertices, p.faces) if isinstance(p, MeshPiece) else _hull_or_none(p)
             for p in sums]
    parts = [p for p in parts if p is not None]
    if not parts:
        raise ValueError("minkowski: the sum spans no volume")
    if len(parts) == 1:
        return parts[0]
    if not any(isinstance(p, MeshPiece) for p in sums):
        return Union(*parts)
    # a sum through a mesh is many overlapping pieces (one per triangle): their union's
    # boundary, computed once by Manifold as OpenSCAD computes it by CGAL, is one closed
    # mesh, far cheaper to classify than the pieces' overlaps
    try:
        v, f = tree_mesh(Union(*parts), np.eye(4))
    except NotAMesh:          # a mesh Manifold refuses (not manifold): the pieces' union
        return Union(*parts)
    if not len(f):
        raise ValueError("minkowski: the sum spans no volume")
    return Polyhedron(v, f)


def _sum_pairs(first: list, second: list) -> list:
    """The pieces of the sum of two operands' pieces (convex vertex sets and
    :class:`MeshPiece` s): see :func:`minkowski`; bounded by :data:`MAX_PIECES` and
    :data:`MAX_SUMS` before anything is summed."""
    def faces(p) -> int:                     # a mesh's triangles; 0 for a convex piece
        return len(p.faces) if isinstance(p, MeshPiece) else 0

    def points(p) -> int:                    # the points it brings to each sum
        return 3 * len(p.faces) if isinstance(p, MeshPiece) else len(p)

    # per pair (see _sum_pair): convex and convex 1 hull; a mesh and a convex piece a
    # hull per triangle and the moved mesh; two meshes a hull per pair of triangles and
    # at most one moved copy of each per triangle of the other
    pieces = sum(max(faces(a), 1) * max(faces(b), 1) + (faces(a) > 0) + (faces(b) > 0) +
                 (faces(a) + faces(b) if faces(a) and faces(b) else 0)
                 for a in first for b in second)
    if pieces > MAX_PIECES:
        raise ValueError(f"minkowski: {pieces:,} pieces, over the limit of {MAX_PIECES:,} "
                         "(csg.polytopes.MAX_PIECES)")
    count = sum(points(a) for a in first) * sum(points(b) for b in second)
    if count > MAX_SUMS:
        raise ValueError(f"minkowski: {count:,} vertex sums, over the limit of "
                         f"{MAX_SUMS:,} (csg.polytopes.MAX_SUMS)")
    out: list = []
    for a in first:
        for b in second:
            out += _sum_pair(a, b)
    return out


def _sum_pair(a, b) -> list:
    """The pieces of ``a ⊕ b`` for two pieces (see :func:`minkowski`)."""
    a_mesh, b_mesh = isinstance(a, MeshPiece), isinstance(b, MeshPiece)
    if not a_mesh and not b_mesh:
        return [(a[:, None, :] + b[None, :, :]).reshape(-1, a.shape[1])]
    if a_mesh and not b_mesh:
        return _mesh_plus_convex(a, b)
    if b_mesh and not a_mesh:
        return _mesh_plus_convex(b, a)
    out = [MeshPiece(b.vertices + t, b.faces) for t in np.unique(a.vertices[a.faces[:, 0]],
                                                                   axis=0)]
    out += [MeshPiece(a.vertices + s, a.faces) for s in np.unique(b.vertices[b.faces[:, 0]],
                                                                   axis=0)]
    ta, tb = a.vertices[a.faces], b.vertices[b.faces]                # (p, 3, 3), (q, 3, 3)
    sums = ta[:, None, :, None, :] + tb[None, :, None, :, :]          # (p, q, 3, 3, 3)
    return out + list(sums.reshape(-1, 9, 3))


def _mesh_plus_convex(mesh: MeshPiece, convex: np.ndarray) -> list:
    """``M ⊕ C = (M + c) ∪ ⋃ (T ⊕ C)`` (see :func:`minkowski`)."""
    triangles = mesh.vertices[mesh.faces]                               # (t, 3, 3)
    sums = (triangles[:, :, None, :] + convex[None, None, :, :]).reshape(len(triangles), -1, 3)
    return [MeshPiece(mesh.vertices + convex[0], mesh.faces)] + list(sums)


def _hull_or_none(points: np.ndarray):
    """:func:`convex_solid` of ``points``, or None where they span no volume (two
    parallel triangles' sums: a flat piece adds nothing to a solid)."""
    try:
        return convex_solid(points)
    except ValueError:
        return None
