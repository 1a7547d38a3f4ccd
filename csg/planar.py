"""Planar regions and their extrusions.

A 2D shape is a region ``g(x, y) <= 0`` of the plane, held as a solid whose
function ignores ``z`` (``dim = 2``), so 2D booleans and in-plane transforms
are the 3D ones. :func:`linear_extrude` and :func:`rotate_extrude` turn it
into a solid by substitution, which is exact:

* ``linear_extrude(g, h, twist, scale)``: ``0 <= z <= h`` and
  ``g(R(twist * z / h)^-1 (x, y) / s(z)) <= 0``, with ``s`` growing linearly
  from 1 to ``scale`` (OpenSCAD's convention: a positive twist turns
  clockwise going up);
* ``rotate_extrude(g, angle)``: ``g(rho, z) <= 0`` (the region's ``x >= 0``
  half sweeps about the z axis), cut to the wedge ``0 <= theta <= angle``.

Examples
--------
>>> from csg import Circle, Rectangle, linear_extrude, rotate_extrude
>>> ring = rotate_extrude(Circle(0.25).translate((1, 0)))   # a torus
>>> ring.bounds
((-1.25, -1.25, -0.25), (1.25, 1.25, 0.25))
>>> post = linear_extrude(Rectangle((1, 1), center=True), height=3, twist=90)
>>> post.bounds[1][2]
3.0
"""
from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

import implicitvox as iv
from implicitvox import Expr, validate, x, y, z

from .facets import FULL_SWEEP_START, polygonal_radius
from .protocol import NotAMesh, NotAPolytope, NotFlat
from .solid import Bounds, Solid, Union
from .triangulate import triangulate

__all__ = ["Circle", "Rectangle", "Polygon", "pieces_polygon", "linear_extrude",
           "rotate_extrude", "LinearExtrude", "RotateExtrude", "AXIS_SLACK"]

#: a 2D shape of rotate_extrude crosses the axis when its bounds reach past x = 0 by
#: more than this share of their reach on either side (bounds are rounded outward by
#: far less: a shape touching the axis stays on one side)
AXIS_SLACK = 1e-9


class Shape2D(Solid):
    dim = 2


class Circle(Shape2D):
    """Disc of radius ``r`` about the origin."""

    scene_type = "circle"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``r``."""
        return cls(read.num(node, path, "r"))

    curved = True

    def outlines(self) -> list[np.ndarray]:
        """A true circle has none."""
        raise NotFlat("a true circle has no outline (facet it first, as OpenSCAD does: "
                      "read_openscad(..., facets='openscad'))")

    def __init__(self, r: float = 1.0):
        self.r = validate.positive_number(r, "r")

    @property
    def expr(self) -> Expr:
        return iv.hypot(x, y) - self.r

    @property
    def bounds(self) -> Bounds:
        return (-self.r, -self.r, 0.0), (self.r, self.r, 0.0)

    def __repr__(self) -> str:
        return f"Circle(r={self.r})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "circle", "r": self.r}


class Rectangle(Shape2D):
    """Rectangle of ``size``, from the origin corner or centred."""

    scene_type = "rectangle"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``size [2]``, ``center`` (optional)."""
        return cls(read.array(node, path, "size", (2,)), center=read.flag(node, path, "center"))

    def __init__(self, size: Sequence[float] = (1, 1), center: bool = False):
        s = np.asarray(size, dtype=np.float64).reshape(-1)
        if s.shape == (1,):
            s = np.repeat(s, 2)
        if s.shape != (2,) or not np.all(s > 0) or not np.all(np.isfinite(s)):
            raise ValueError(f"size must be 2 positive numbers, got {size!r}")
        self.size, self.centered = s, bool(center)

    @property
    def expr(self) -> Expr:
        lo = -self.size / 2 if self.centered else np.zeros(2)
        c, h = lo + self.size / 2, self.size / 2
        return iv.max(abs(x - c[0]) - h[0], abs(y - c[1]) - h[1])

    @property
    def bounds(self) -> Bounds:
        lo = -self.size / 2 if self.centered else np.zeros(2)
        hi = lo + self.size
        return (float(lo[0]), float(lo[1]), 0.0), (float(hi[0]), float(hi[1]), 0.0)

    def __repr__(self) -> str:
        return f"Rectangle(size={self.size.tolist()}, center={self.centered})"

    def outlines(self) -> list[np.ndarray]:
        """Its 4 corners, counter-clockwise."""
        lo = -self.size / 2 if self.centered else np.zeros(2)
        hi = lo + self.size
        return [np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])]

    def polytope_vertices(self, convex: bool, pieces: Any) -> np.ndarray:
        """Its 4 corners at z = 0."""
        lo = -self.size / 2 if self.centered else np.zeros(2)
        hi = lo + self.size
        return np.array([[lo[0], lo[1], 0], [hi[0], lo[1], 0], [hi[0], hi[1], 0],
                         [lo[0], hi[1], 0]], dtype=np.float64)

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "rectangle", "size": self.size.tolist(), "center": self.centered}


def _convex_either_way(poly: np.ndarray) -> bool:
    """Never turning right, or never turning left (within rounding)."""
    d = np.roll(poly, -1, axis=0) - poly
    cross = d[:, 0] * np.roll(d, -1, axis=0)[:, 1] - d[:, 1] * np.roll(d, -1, axis=0)[:, 0]
    scale = np.abs(d).max() ** 2
    return bool(np.all(cross >= -1e-12 * scale) or np.all(cross <= 1e-12 * scale))


def _convex(poly: np.ndarray) -> bool:
    """Counter-clockwise and never turning right."""
    d1 = np.roll(poly, -1, axis=0) - poly
    d2 = np.roll(d1, -1, axis=0)
    return bool(np.all(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] >= 0))


#: nesting of pockets in pockets at most for :func:`_hull_tree` (a spiral nests deeper;
#: it then takes the triangulation with seams)
MAX_POCKET_DEPTH = 64


def _hull_tree(poly: np.ndarray, lid: bool = False, depth: int = 0) -> Optional[Expr]:
    """The function of a simple counter-clockwise polygon from its convex hull and
    its pockets, each pocket from its own hull and pockets (Tor and
    Middleditch's convex difference tree): ``max(hull, -pocket, ...)``.

    The lines are the polygon's own edges and the lids (hull edges closing a
    pocket). A pocket's function omits its lid (``lid=True``: the closing edge
    from the last point to the first): the parent's hull holds that side
    already, and the pocket, open across its lid, is then positive on it, so
    ``max(hull, -pocket)`` is positive on the lid, where the hull alone is 0.
    The function is therefore zero only on the polygon's outline, negative
    inside and positive outside, and, having no inner seams, its interval
    extension proves boxes inside or outside away from the outline (a
    triangulation's ``min`` over triangles is 0 along every inner edge).
    None when pockets nest deeper than :data:`MAX_POCKET_DEPTH`.
    """
    from scipy.spatial import ConvexHull, QhullError
    if depth > MAX_POCKET_DEPTH:
        return None
    n = len(poly)
    try:
        corners = sorted(ConvexHull(poly).vertices.tolist())      # in the outline's order
    except QhullError:
        return None
    terms = []
    pockets = []
    for k, i in enumerate(corners):
        j = corners[(k + 1) % len(corners)]
        if lid and i == n - 1 and j == 0:
            continue                              # the lid this pocket is open across
        terms.append(_edge(poly[i], poly[j]))
        chain = np.arange(i, j + 1) if j > i else np.r_[np.arange(i, n), np.arange(0, j + 1)]
        if len(chain) > 2:
            pocket = poly[chain[::-1]]            # outside the polygon: counter-clockwise
            if _area(pocket) > 0:
                pockets.append(pocket)
    for pocket in pockets:
        inner = _max_of_edges(pocket, range(len(pocket)), closed=False) \
            if _convex(pocket) else _hull_tree(pocket, lid=True, depth=depth + 1)
        if inner is None:
            return None
        terms.append(-inner)
    return iv.max(*terms) if len(terms) > 1 else terms[0]


def _edge(p: np.ndarray, q: np.ndarray) -> Expr:
    """The distance outward of the line from ``p`` to ``q`` (the inside on its left)."""
    n = np.array([q[1] - p[1], p[0] - q[0]])
    n /= np.linalg.norm(n)
    return iv.affine(n, (x - p[0], y - p[1]))


def _area(poly: np.ndarray) -> float:
    return 0.5 * float(np.sum(poly[:, 0] * np.roll(poly[:, 1], -1)
                              - np.roll(poly[:, 0], -1) * poly[:, 1]))


def _seams(poly: np.ndarray, triangles: list) -> list[np.ndarray]:
    """A convex quadrilateral over each inner edge of a triangulation, inside the
    polygon, holding the edge's open segment in its interior.

    The minimum of the triangles' functions alone is 0 all along an inner edge
    (both triangles' functions vanish there): the polygon's function would be
    zero inside it, and every voxel on the edge would look like surface. An
    inner edge AB between triangles ABC and ABD gets the quadrilateral
    A C B M, with M on the line from C through AB's midpoint, halfway between
    AB and the far side of ABD: its diagonals AB and CM cross, so it is convex,
    its half ABC is the first triangle and its half ABM lies in the second, so
    it lies in the polygon, and the edge's open segment is inside it. With
    these pieces the minimum is negative everywhere inside the polygon and zero
    only on its outline (a triangulation without added points has no inner
    vertex), and a box across an inner edge is proved inside by one piece.
    """
    opposite: dict[tuple[int, int], list[int]] = {}
    for tri in triangles:
        for k in range(3):
            a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
            opposite.setdefault((min(a, b), max(a, b)), []).append(c)
    quads = []
    for (a, b), apexes in opposite.items():
        if len(apexes) != 2:
            continue                              # an outline edge
        c, d = apexes
        mid = (poly[a] + poly[b]) / 2
        direction = mid - poly[c]
        reach = np.inf                            # how far along it the triangle ABD goes
        for p, q, other in ((poly[a], poly[d], poly[b]), (poly[d], poly[b], poly[a])):
            normal = np.array([q[1] - p[1], p[0] - q[0]])
            if np.dot(normal, other - p) > 0:
                normal = -normal                  # pointing away from the triangle
            speed = float(np.dot(normal, direction))
            if speed > 0:
                reach = min(reach, float(np.dot(normal, p - mid)) / speed)
        if not np.isfinite(reach) or reach <= 0:
            continue
        quad = np.array([poly[a], poly[c], poly[b], mid + 0.5 * reach * direction])
        area = np.sum(quad[:, 0] * np.roll(quad[:, 1], -1) - np.roll(quad[:, 0], -1) * quad[:, 1])
        quads.append(quad if area > 0 else quad[::-1])
    return quads


def _max_of_edges(poly: np.ndarray, order, closed: bool = True) -> Expr:
    """``max`` over the edges of a convex counter-clockwise polygon of the distance
    outward (without the closing edge, from the last point to the first, unless
    ``closed``)."""
    idx = list(order)
    edges = []
    for k in range(len(idx) if closed else len(idx) - 1):
        p, q = poly[idx[k]], poly[idx[(k + 1) % len(idx)]]
        n = np.array([q[1] - p[1], p[0] - q[0]])
        length = np.linalg.norm(n)
        if length == 0:
            continue
        n /= length
        edges.append(n[0] * (x - p[0]) + n[1] * (y - p[1]))
    return iv.max(*edges) if len(edges) > 1 else edges[0]


def _given_pieces(pieces: Sequence, n_paths: int) -> list[tuple[int, list[int]]]:
    """``pieces`` checked: every path once, as an outline or as a hole of one."""
    out = [(int(k), [int(h) for h in holes]) for k, holes in pieces]
    used = sorted([k for k, _ in out] + [h for _, hs in out for h in hs])
    if used != list(range(n_paths)):
        raise ValueError(f"pieces must name each of the {n_paths} paths once, as an outline "
                         "or a hole")
    return out


def _even_odd_pieces(points: np.ndarray, paths: list[list[int]]) -> list[tuple[int, list[int]]]:
    """Nest non-crossing paths by containment (a path is inside another when most of
    its vertices are: a shared vertex does not decide) and pair each even-depth path
    with the paths one level deeper directly inside it."""
    from skimage.measure import points_in_poly
    n = len(paths)
    inside = np.zeros((n, n), dtype=bool)             # inside[a, b]: path a lies in path b
    for b_, outline in enumerate(paths):
        poly = points[outline]
        for a_, path in enumerate(paths):
            if a_ != b_:
                inside[a_, b_] = points_in_poly(points[path], poly).mean() > 0.5
    depth = inside.sum(axis=1)
    pieces = []
    for k in np.flatnonzero(depth % 2 == 0):
        holes = [int(h) for h in np.flatnonzero(inside[:, k] & (depth == depth[k] + 1))]
        pieces.append((int(k), holes))
    return pieces


class Polygon(Shape2D):
    """A polygon from ``points`` (k, 2); ``paths`` (lists of point indices) are filled as
    OpenSCAD fills them, even-odd: a point is inside when an odd number of paths
    enclose it (an outline, its holes, islands in the holes, ...).

    Each path's region is a union of its ear-clipping triangles; paths are
    nested by containment (they must not cross, as OpenSCAD's own polygons do
    not), and each path at an even depth minus the paths directly inside it is
    one piece of the region (:attr:`pieces`): its function is exact in sign.
    Where the nesting is known (Clipper's tree of outlines, whose rings may touch
    at a vertex, where containment by vertices cannot tell), pass it as
    ``pieces=[(outline, [holes]), ...]`` (path indices).

    Examples
    --------
    An outline, a hole in it and an island in the hole (the dot of an "i" in an "o"):

    >>> square = lambda c, h: [[c - h, c - h], [c + h, c - h], [c + h, c + h], [c - h, c + h]]
    >>> p = Polygon(square(0, 3) + square(0, 2) + square(0, 1),
    ...             [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]])
    >>> p.pieces
    [(0, [1]), (2, [])]
    """

    scene_type = "polygon"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``points [[2]...]``, ``paths [[ints]...]`` (optional)."""
        return cls(read.array(node, path, "points", (None, 2)),
                   read.index_lists(node, path, "paths"))

    def __init__(self, points: Any, paths: Optional[Sequence[Sequence[int]]] = None, *,
                 pieces: Optional[Sequence[tuple[int, Sequence[int]]]] = None):
        pts = np.asarray(points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3 or not np.all(np.isfinite(pts)):
            raise ValueError("points must be at least 3 finite (x, y) pairs")
        if paths is None:
            paths = [list(range(len(pts)))]
        self.points = pts
        self.paths = [list(map(int, p)) for p in paths]
        for i, p in enumerate(self.paths):
            if len(p) < 3 or min(p) < 0 or max(p) >= len(pts):
                raise ValueError(f"paths[{i}] must list at least 3 indices into points")
        self._regions = [self._path_expr(p) for p in self.paths]
        #: the region as pieces ``(path, [paths directly inside it])``: each path at an
        #: even depth of the nesting, minus those one level deeper inside it
        self.pieces = _even_odd_pieces(pts, self.paths) if pieces is None else \
            _given_pieces(pieces, len(self.paths))

    def _path_expr(self, path: list[int]) -> Expr:
        poly = self.points[path]
        area = 0.5 * np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
        if area == 0:
            raise ValueError("polygon has zero area")
        if area < 0:
            poly = poly[::-1]
        if _convex(poly):                     # one piece: no inner edges to loosen intervals
            return _max_of_edges(poly, range(len(poly)))
        tree = _hull_tree(poly)
        if tree is not None:
            return tree
        triangles = triangulate(poly)
        pieces = [_max_of_edges(poly, t) for t in triangles]
        pieces += [_max_of_edges(quad, range(4)) for quad in _seams(poly, triangles)]
        return iv.min(*pieces) if len(pieces) > 1 else pieces[0]

    @property
    def expr(self) -> Expr:
        pieces = [iv.max(self._regions[outer], *[-self._regions[h] for h in holes])
                  if holes else self._regions[outer] for outer, holes in self.pieces]
        return pieces[0] if len(pieces) == 1 else iv.min(*pieces)

    @property
    def bounds(self) -> Bounds:
        used = self.points[sorted({i for k, _ in self.pieces for i in self.paths[k]})]
        lo, hi = used.min(axis=0), used.max(axis=0)
        return (float(lo[0]), float(lo[1]), 0.0), (float(hi[0]), float(hi[1]), 0.0)

    def __repr__(self) -> str:
        return f"Polygon({len(self.points)} points, {len(self.paths)} paths)"

    def outlines(self) -> list[np.ndarray]:
        """Its paths' points."""
        return [self.points[p] for p in self.paths]

    def polytope_vertices(self, convex: bool, pieces: Any) -> np.ndarray:
        """The points its pieces use, at z = 0; with ``convex``, of one convex outline."""
        if convex and (len(self.pieces) != 1 or self.pieces[0][1] or
                       not _convex_either_way(self.points[self.paths[self.pieces[0][0]]])):
            raise NotAPolytope("a non-convex polygon in a Minkowski sum (its convex "
                               "decomposition is not built: split it into convex parts)")
        used = sorted({i for k, _ in self.pieces for i in self.paths[k]})
        p = self.points[used]
        return np.column_stack([p, np.zeros(len(p))])

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "polygon", "points": self.points.tolist(), "paths": self.paths}


def pieces_polygon(pieces: Sequence[tuple[Any, Sequence[Any]]]) -> Polygon:
    """A :class:`Polygon` of a region given in parts ``(outline, [holes])`` ((k, 2)
    arrays, as :func:`csg.clipper2d.region_pieces` gives them): its nesting is
    taken as given, not found again by containment.

    >>> square = lambda c, h: [[c - h, c - h], [c + h, c - h], [c + h, c + h], [c - h, c + h]]
    >>> pieces_polygon([(square(0, 3), [square(0, 2)]), (square(0, 1), [])]).pieces
    [(0, [1]), (2, [])]
    """
    rings, parts = [], []
    for outer, holes in pieces:
        k = len(rings)
        rings += [np.asarray(r, dtype=np.float64) for r in (outer, *holes)]
        parts.append((k, list(range(k + 1, len(rings)))))
    if not rings:
        raise ValueError("a polygon needs at least one outline")
    starts = np.cumsum([0] + [len(r) for r in rings])
    return Polygon(np.concatenate(rings),
                   [list(range(a, b)) for a, b in zip(starts[:-1], starts[1:])], pieces=parts)


def _as_2d(shape: Solid) -> Solid:
    if not isinstance(shape, Solid) or shape.dim != 2:
        raise ValueError(f"extrusions take a 2D shape (Circle, Rectangle, Polygon, ...), got "
                         f"{type(shape).__name__}")
    return shape


def _radii(shape: Solid) -> tuple[float, float]:
    """Bounds on the distances from the origin of a 2D shape's points: nearest and
    farthest, from the boxes of a union's children (the corners, and the box's
    distance, 0 where it holds the origin)."""
    if isinstance(shape, Union):
        parts = [_radii(c) for c in shape.children]
        return min(p[0] for p in parts), max(p[1] for p in parts)
    lo, hi = np.array(shape.bounds[0][:2]), np.array(shape.bounds[1][:2])
    far = float(np.max(np.hypot(*np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]]))))
    gap = np.maximum(np.maximum(lo, -hi), 0.0)       # the origin's distance to the box
    return float(np.hypot(*gap)), far


class LinearExtrude(Solid):
    """See :func:`linear_extrude`."""

    scene_type = "linear_extrude"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``height``, ``twist``, ``scale [2]``, ``center``, ``child NODE``."""
        return cls(read.child(node, path, depth), read.num(node, path, "height"),
                   read.num(node, path, "twist", 0.0),
                   read.array(node, path, "scale", (2,), [1.0, 1.0]),
                   read.flag(node, path, "center"))

    def __init__(self, shape: Solid, height: float, twist: float = 0.0, scale: Any = 1.0,
                 center: bool = False):
        self._children = (_as_2d(shape),)
        self.height = validate.positive_number(height, "height")
        self.twist = float(twist)
        s = np.broadcast_to(np.asarray(scale, dtype=np.float64), (2,)).copy()
        if not np.all(s >= 0) or not np.all(np.isfinite(s)):
            raise ValueError(f"scale must be >= 0 (one number or two), got {scale!r}")
        self.scale_top = s
        self.centered = bool(center)
        if not math.isfinite(self.twist):
            raise ValueError(f"twist must be finite, got {twist!r}")

    @property
    def children(self):
        return self._children

    @property
    def _z0(self) -> float:
        return -self.height / 2 if self.centered else 0.0

    @property
    def expr(self) -> Expr:
        h, z0 = self.height, self._z0
        t = (z - z0) / h                                  # 0 at the bottom, 1 at the top
        # a section point p sits at S(t) R(t) p (turned by -twist t, then scaled, as in
        # OpenSCAD): undo the scale, then the turn
        u, v = x, y
        sx, sy = (1 + (self.scale_top[0] - 1) * t), (1 + (self.scale_top[1] - 1) * t)
        if self.scale_top[0] != 1:
            u = u / sx
        if self.scale_top[1] != 1:
            v = v / sy
        if self.twist != 0:
            a = -math.radians(self.twist) * t
            u, v = iv.cos(a) * u + iv.sin(a) * v, -iv.sin(a) * u + iv.cos(a) * v
        section = self._children[0].expr.remap(x=u, y=v)
        if (self.twist == 0 and np.all(self.scale_top == 1)) or self._children[0].bounds is None:
            return iv.max(section, z0 - z, z - (z0 + h))
        # The solid lies within the annulus (cone) of the section's radii: the sign is the
        # same, but the intervals reject what the turned, rescaled section cannot (undoing
        # a scale near 0 is unbounded: every box at a pointed top would be kept).
        near, far = _radii(self._children[0])
        # (widened by a relative 2**-20: a box in the solid whose corner touches the
        # annulus, as a square's corners touch it along the edges they sweep, keeps its
        # state whatever the rounding of the bound)
        near, far = near * (1.0 - 2.0 ** -20), far * (1.0 + 2.0 ** -20)
        grow, shrink = float(np.max(self.scale_top)) - 1.0, float(np.min(self.scale_top)) - 1.0
        rho = iv.sqrt(x * x + y * y)
        bounds = [rho - (far * (1.0 + grow * t) if grow else far)]
        if near > 0:
            bounds.append((near * (1.0 + shrink * t) if shrink else near) - rho)
        return iv.max(section, *bounds, z0 - z, z - (z0 + h))

    @property
    def _reach(self) -> float:
        """The section's farthest point from the axis (a bound)."""
        return _radii(self._children[0])[1]

    @property
    def bounds(self) -> Bounds:
        b = self._children[0].bounds
        if b is None:
            return None
        lo, hi = np.array(b[0][:2]), np.array(b[1][:2])
        s = np.maximum(self.scale_top, 1.0)
        if self.twist != 0:                      # any rotation: the disc of the farthest corner
            r = self._reach
            lo, hi = np.array([-r, -r]), np.array([r, r])
        lo, hi = np.minimum(lo * s, lo), np.maximum(hi * s, hi)
        z0 = self._z0
        return (float(lo[0]), float(lo[1]), z0), (float(hi[0]), float(hi[1]), z0 + self.height)

    def __repr__(self) -> str:
        return (f"linear_extrude({self._children[0]!r}, height={self.height}, "
                f"twist={self.twist}, scale={self.scale_top.tolist()}, center={self.centered})")

    def polytope_vertices(self, convex: bool, pieces: Any) -> np.ndarray:
        """Its section's vertices at the bottom and, scaled, at the top (a twist is
        curved); with ``convex``, of a section of one convex piece."""
        if self.twist != 0:
            raise NotAPolytope("a twisted linear_extrude is curved: its hull is no polytope "
                               "(facet it first: read_openscad(..., facets='openscad'))",
                               curved=True)
        if convex and len(pieces(self.children[0], True)) != 1:
            raise NotAPolytope("an extrusion of several pieces in a Minkowski sum "
                               "(split it into one extrusion per convex piece)")
        flat = np.concatenate(pieces(self.children[0], False))
        z0 = -self.height / 2 if self.centered else 0.0
        bottom = np.column_stack([flat, np.full(len(flat), z0)])
        top = np.column_stack([flat * self.scale_top, np.full(len(flat), z0 + self.height)])
        return np.concatenate([bottom, top])

    def closed_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """None here: a straight extrusion of OpenSCAD's is a prism (:class:`csg.prism.Prism`)."""
        raise NotAMesh(f"a {type(self).__name__} has no triangle mesh here (polyhedra, "
                       "imported meshes, surfaces, boxes and faceted primitives have)",
                       curved=True)

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "linear_extrude", "height": self.height, "twist": self.twist,
                "scale": self.scale_top.tolist(), "center": self.centered,
                "child": self.children[0].scene_node()}


class RotateExtrude(Solid):
    """See :func:`rotate_extrude`."""

    scene_type = "rotate_extrude"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``angle``, ``sectors`` (optional int), ``child NODE``."""
        return cls(read.child(node, path, depth), read.num(node, path, "angle", 360.0),
                   read.integer(node, path, "sectors", None))

    def __init__(self, shape: Solid, angle: float = 360.0, sectors: Optional[int] = None):
        self._children = (_as_2d(shape),)
        self.angle = float(angle)
        self.sectors = None if sectors is None else int(sectors)
        if self.sectors is not None and self.sectors < 1:
            raise ValueError(f"sectors must be >= 1, got {sectors!r}")
        if not (0 < abs(self.angle) <= 360):
            raise ValueError(f"angle must be in (0, 360] degrees (or negative), got {angle!r}")
        b = shape.bounds
        # beyond the bounds' outward rounding: a circle touching the axis (a horn torus,
        # OpenSCAD's test model horn-torus.scad) has bounds a hair across it
        slack = AXIS_SLACK * max(abs(b[0][0]), abs(b[1][0])) if b is not None else 0.0
        if b is not None and b[0][0] < -slack and slack < b[1][0]:
            raise ValueError("the 2D shape of rotate_extrude must lie on one side of the axis "
                             "(x >= 0); it crosses x = 0")

    @property
    def children(self):
        return self._children

    @property
    def expr(self) -> Expr:
        shape = self._children[0]
        b = shape.bounds
        if self.sectors is None:
            rho = iv.hypot(x, y)
        else:                                 # OpenSCAD's facets: planar trapezoid sectors
            full = abs(self.angle) >= 360
            rho = polygonal_radius(self.sectors, 360.0 if full else self.angle,
                                   FULL_SWEEP_START if full else 0.0)
        radial = rho if b is None or b[1][0] > 0 else -rho     # a shape at x <= 0 sweeps too
        solid = _mirrored(shape).expr.remap(x=radial, y=z)
        if abs(self.angle) >= 360:
            return solid
        return iv.max(solid, self._wedge())

    def _wedge(self) -> Expr:
        a = math.radians(abs(self.angle))
        flip = -1.0 if self.angle < 0 else 1.0
        yy = flip * y
        start = -yy                                            # theta >= 0: y >= 0
        end = math.cos(a) * yy - math.sin(a) * x                # theta <= a: right of the ray
        return iv.max(start, end) if a <= math.pi else iv.min(start, end)

    @property
    def bounds(self) -> Bounds:
        b = self._children[0].bounds
        if b is None:
            return None
        r = max(abs(b[0][0]), abs(b[1][0]))
        return (-r, -r, b[0][1]), (r, r, b[1][1])

    def __repr__(self) -> str:
        return f"rotate_extrude({self._children[0]!r}, angle={self.angle})"

    def closed_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """None here: it sweeps its section round."""
        raise NotAMesh(f"a {type(self).__name__} has no triangle mesh here (polyhedra, "
                       "imported meshes, surfaces, boxes and faceted primitives have)",
                       curved=True)

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        node = {"type": "rotate_extrude", "angle": self.angle,
                "child": self.children[0].scene_node()}
        if self.sectors is not None:
            node["sectors"] = self.sectors
        return node


def _mirrored(shape: Solid) -> Solid:
    """A profile with edges on the axis, joined to its mirror image across it (the
    same where it is swept: x >= 0 or x <= 0), so that those edges are inside it.

    Swept about the axis, a profile's edge on x = 0 is no surface (the solid is
    on both sides of it), but the profile's function is 0 there: every voxel on
    the axis would look like surface. Joined to its mirror image, the edge is
    inside the profile. Done for a rectangle and for a polygon of one outline
    whose points on the axis are consecutive; other profiles are returned as
    they are.
    """
    b = shape.bounds
    if b is None or (b[0][0] != 0 and b[1][0] != 0):
        return shape
    if isinstance(shape, Rectangle):
        width = shape.size[0]
        lo = np.zeros(2) if not shape.centered else -shape.size / 2
        size = np.array([2 * width, shape.size[1]])
        centre = np.array([0.0, lo[1] + shape.size[1] / 2])
        return Polygon(centre + size / 2 * np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]))
    if not isinstance(shape, Polygon) or len(shape.paths) != 1:
        return shape
    pts = shape.points[shape.paths[0]]
    on_axis = pts[:, 0] == 0
    n = len(pts)
    if on_axis.sum() < 2 or on_axis.all():
        return shape
    # rotate the outline so that it starts just after its run of points on the axis
    starts = [k for k in range(n) if on_axis[k - 1] and not on_axis[k]]
    if len(starts) != 1:
        return shape                          # several runs on the axis: left as it is
    outline = np.roll(pts, -starts[0], axis=0)
    run = int(on_axis.sum())
    if not np.roll(on_axis, -starts[0])[-run:].all():
        return shape
    side = outline[:-run]                     # off the axis, from the run's end to its start
    first, last = outline[-1], outline[-run]  # the run's ends: the axis edge last -> first
    mirror = side[::-1] * np.array([-1.0, 1.0])
    return Polygon(np.concatenate([[first], side, [last], mirror]))


def linear_extrude(shape: Solid, height: float, twist: float = 0.0, scale: Any = 1.0,
                   center: bool = False) -> Solid:
    """Extrude a 2D shape along z to ``height`` (OpenSCAD's ``linear_extrude``).

    ``twist`` degrees (clockwise going up), ``scale`` of the top section (one
    number or per axis), ``center`` puts the solid at ``-height/2 .. height/2``.
    """
    return LinearExtrude(shape, height, twist, scale, center)


def rotate_extrude(shape: Solid, angle: float = 360.0) -> Solid:
    """Sweep a 2D shape (in ``x >= 0``) about the z axis by ``angle`` degrees,
    counter-clockwise from the +x axis (OpenSCAD's ``rotate_extrude``)."""
    return RotateExtrude(shape, angle)


def union2d(*shapes: Solid) -> Solid:
    return Union(*shapes)
