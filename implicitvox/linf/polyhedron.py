"""Max-norm distance to convex polytopes, half-spaces and triangles (Varadhan §3.1.1-§3.1.2, §3.3.1).

The weighted max-norm ball around ``p`` is the box ``B(p, t) = p + t [-w, w]``.
For a point outside a convex polytope ``P`` the distance is the smallest
``t`` at which ``B(p, t)`` touches ``P``. Below it the two convex sets are
disjoint, so one axis of the separating axis theorem separates them: a box
normal, a face normal of ``P``, or a box axis crossed with an edge of ``P``.
Along an axis ``u`` they are apart while ``u.p + t h_w(u) < min_P u.x``, so

    D(p) = max over candidate axes u (both signs) of (min_P u.x - u.p) / h_w(u),

a maximum of finitely many closed forms (any other direction gives a lower
value, so extra candidates are harmless). Inside ``P`` the box first leaves
``P`` through a face plane: ``D(p) = -min_f (d_f - n_f.p) / h_w(n_f)``.
A triangle is a flat polytope (unsigned: its distance is ``max(0, ...)``).

Examples
--------
>>> import numpy as np
>>> cube = ConvexPolyhedron.from_points(np.array([[x, y, z] for x in (0, 1) for y in (0, 1)
...                                              for z in (0, 1)], dtype=float))
>>> cube.distance(np.array([[2.0, 0.5, 0.5], [0.5, 0.5, 0.5], [3.0, 4.0, -1.0]])).tolist()
[1.0, -0.5, 3.0]
"""
from __future__ import annotations

from typing import Any, NamedTuple, Optional

import numpy as np

from .. import expr as ex
from .box_tests import Primitive
from .euclidean import triangle_distance as triangle_euclidean
from .norm import as_points, as_weights, in_blocks
from .products import dot
from .. import batches

__all__ = ["ConvexPolyhedron", "HalfSpace", "ConvexHullFaces", "convex_hull_faces",
           "triangle_distance", "CHUNK"]

#: points per block (memory: points x axes)
CHUNK = batches.LINF_POINTS


def _unique_directions(u: np.ndarray) -> np.ndarray:
    """Unit directions without zeros and without (anti)parallel duplicates."""
    n = np.linalg.norm(u, axis=1)
    u = u[n > 1e-12 * max(float(n.max()) if len(n) else 1.0, 1e-300)]
    u = u / np.linalg.norm(u, axis=1, keepdims=True)
    # one sign per direction (the other is added later), then drop duplicates
    first = np.argmax(np.abs(u) > 1e-12, axis=1)
    u = u * np.sign(u[np.arange(len(u)), first])[:, None]
    key = np.round(u, 12)
    _, keep = np.unique(key, axis=0, return_index=True)
    return u[np.sort(keep)]


def _signed_units(u: np.ndarray) -> Optional[list[tuple[int, int]]]:
    """``(coordinate, sign)`` of each row of ``u`` if every row is a signed unit vector
    (its other components zero), else None."""
    out = []
    for row in u:
        hot = np.flatnonzero(row != 0)
        if len(hot) != 1 or abs(row[hot[0]]) != 1.0:
            return None
        out.append((int(hot[0]), 1 if row[hot[0]] > 0 else -1))
    return out


class ConvexHullFaces(NamedTuple):
    """The faces of a convex hull: one plane per facet, and only its true edges."""
    normals: np.ndarray      #: (F, 3) outward unit normals, one per facet
    offsets: np.ndarray      #: (F,) ``normals . x <= offsets`` inside
    vertices: np.ndarray     #: (m, 3) the hull's vertices
    edges: np.ndarray        #: (E, 3) edge vectors between facets of different planes


def convex_hull_faces(points: Any) -> ConvexHullFaces:
    """The planes and edges of the convex hull of ``points`` (n, 3).

    Qhull merges coplanar facets and hands them out triangulated, every triangle
    of a facet with the facet's own (bit-equal) equation: those duplicates are
    dropped, and so are the triangulation's diagonals inside a facet (an edge
    whose two triangles have the same equation). A 30-gon prism has 32 planes
    and 90 edges instead of 116 triangles and 174 triangle edges; the max over
    the planes, and the separating axes built from them, are unchanged.

    Raises
    ------
    ValueError
        The points span no volume.

    Examples
    --------
    >>> import numpy as np
    >>> cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    >>> faces = convex_hull_faces(cube)
    >>> len(faces.normals), len(faces.edges) // 2        # each edge seen from both sides
    (6, 12)
    """
    from scipy.spatial import ConvexHull, QhullError
    pts = as_points(points)
    try:
        hull = ConvexHull(pts)
    except QhullError as err:
        raise ValueError(f"the points span no volume: {str(err).splitlines()[0]}") from None
    eq, simp, nb = hull.equations, hull.simplices, hull.neighbors
    planes = np.unique(eq, axis=0, return_index=True)[1]
    planes = eq[np.sort(planes)]
    edges = []
    for k in range(3):                     # the edge opposite vertex k, shared with nb[:, k]
        crease = np.any(eq != eq[nb[:, k]], axis=1)
        edges.append(pts[simp[crease, (k + 2) % 3]] - pts[simp[crease, (k + 1) % 3]])
    return ConvexHullFaces(planes[:, :3], -planes[:, 3], pts[hull.vertices],
                           np.concatenate(edges))


class ConvexPolyhedron(Primitive):
    """A bounded convex polytope: ``n_f . x <= d_f`` with its vertices and edges.

    Use :meth:`from_points` (convex hull) or :meth:`from_planes`.
    """

    def __init__(self, normals: np.ndarray, offsets: np.ndarray, vertices: np.ndarray,
                 edges: np.ndarray):
        length = np.linalg.norm(normals, axis=1)
        self.normals = normals / length[:, None]
        self.offsets = offsets / length
        self.vertices = np.asarray(vertices, dtype=np.float64)
        box = np.eye(3)
        cross = np.cross(box[:, None, :], np.asarray(edges, dtype=np.float64)[None]).reshape(-1, 3)
        u = _unique_directions(np.concatenate([box, self.normals, cross]))
        self.axes = np.concatenate([u, -u])                    # (A, 3)
        proj = dot(self.vertices, self.axes.T)                     # (m, A)
        self.low = proj.min(axis=0)                             # min_P u.x per axis
        #: the axes without their opposites, and the two rows of ``low``: ``-u . p`` is
        #: ``u . p`` negated, exactly (rounding to nearest is symmetric)
        self.half_axes = u
        self.low_plus, self.low_minus = self.low[:len(u)], self.low[len(u):]
        self._facets = None                                     # hull triangles, on demand
        #: for a box along the axes (every normal and axis a signed unit vector): each
        #: face's and axis's (coordinate, sign), so the distance reads columns
        self._axis_aligned = _signed_units(self.normals), _signed_units(self.half_axes)
        if self._axis_aligned[0] is None or self._axis_aligned[1] is None:
            self._axis_aligned = None

    @classmethod
    def from_points(cls, points: Any) -> "ConvexPolyhedron":
        """The convex hull of ``points`` (n, 3), which must span a volume."""
        return cls(*convex_hull_faces(points))

    @classmethod
    def from_planes(cls, normals: Any, offsets: Any) -> "ConvexPolyhedron":
        """The intersection of half-spaces ``normals . x <= offsets`` (bounded)."""
        from scipy.optimize import linprog
        from scipy.spatial import HalfspaceIntersection
        n = np.asarray(normals, dtype=np.float64)
        d = np.asarray(offsets, dtype=np.float64)
        # an interior point: the centre of the largest inscribed ball (a linear programme)
        norm = np.linalg.norm(n, axis=1)
        res = linprog(np.r_[0, 0, 0, -1], A_ub=np.c_[n, norm], b_ub=d,
                      bounds=[(None, None)] * 3 + [(0, None)])
        if res.status != 0 or res.x[3] <= 0:
            raise ValueError("the planes bound no volume (or an unbounded one)")
        hs = HalfspaceIntersection(np.c_[n, -d], res.x[:3])
        return cls.from_points(hs.intersections)

    def transformed(self, matrix: np.ndarray) -> "ConvexPolyhedron":
        """The polytope under an affine 4 x 4 map."""
        return ConvexPolyhedron.from_points(self.vertices @ matrix[:3, :3].T + matrix[:3, 3])

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        """Signed weighted max-norm distance (negative inside)."""
        p = as_points(points)
        w = as_weights(weights, len(p))
        return in_blocks(self._distance, p, w, CHUNK)

    def _distance(self, p: np.ndarray, w: np.ndarray) -> np.ndarray:
        if self._axis_aligned is not None:
            return self._box_distance(p, w)
        from .polyhedron_kernels import convex_distances     # (loads Numba: not at import)
        out = np.empty(len(p))
        convex_distances(np.ascontiguousarray(p, dtype=np.float64),
                         np.ascontiguousarray(np.broadcast_to(w, p.shape), dtype=np.float64),
                         self.normals, self.offsets, self.half_axes, self.low_plus,
                         self.low_minus, out)
        return out

    def distance_by_arrays(self, points: Any, weights: Any = None) -> np.ndarray:
        """:meth:`distance` in array code (whole-array numpy over the faces and axes):
        the oracle its compiled kernel
        (:func:`implicitvox.linf.polyhedron_kernels.convex_distances`) is tested
        against."""
        p = as_points(points)
        w = as_weights(weights, len(p))
        return in_blocks(self._array_distance, p, w, CHUNK)

    def _array_distance(self, p: np.ndarray, w: np.ndarray) -> np.ndarray:
        slack = self.offsets[None, :] - dot(p, self.normals.T)             # (n, F), >= 0 inside
        inside = np.all(slack >= 0, axis=1)
        # the octants of one level share their half-widths: the reach of the box
        # along each face and axis is then one row (the same numbers, broadcast)
        shared = len(w) > 1 and bool((w == w[0]).all())
        if shared:
            w = w[:1]
        out = np.empty(len(p))
        rows = np.flatnonzero(inside)
        if len(rows):
            h_faces = dot(w if shared else w[rows], np.abs(self.normals).T)  # (n or 1, F)
            out[rows] = -np.min(slack[rows] / h_faces, axis=1)
        rows = np.flatnonzero(~inside)
        if len(rows):
            # each axis u and its opposite -u at once: low_u - u.p and low_-u + u.p
            h_axes = dot(w if shared else w[rows], np.abs(self.half_axes).T)  # (n or 1, U)
            q = dot(p[rows], self.half_axes.T)                                # (n, U)
            out[rows] = np.maximum(np.max((self.low_plus[None, :] - q) / h_axes, axis=1),
                                   np.max((self.low_minus[None, :] + q) / h_axes, axis=1))
        return out

    def _box_distance(self, p: np.ndarray, w: np.ndarray) -> np.ndarray:
        """:meth:`_distance` of a box along the axes, by columns: the same operations on
        the same numbers (a product with a signed unit vector is a coordinate or its
        negation, exactly), so the same bits, without the (n, F) products."""
        faces, axes = self._axis_aligned
        column = [p[:, a] for a in range(3)]
        weight = [w[:, a] for a in range(3)]
        inside = None
        depth = None
        for (a, sign), offset in zip(faces, self.offsets):
            slack = offset - column[a] if sign > 0 else offset + column[a]
            inside = slack >= 0 if inside is None else inside & (slack >= 0)
            slack /= weight[a]
            depth = slack if depth is None else np.minimum(depth, slack)
        reach = None
        for (a, sign), plus, minus in zip(axes, self.low_plus, self.low_minus):
            q = column[a] if sign > 0 else -column[a]
            far = np.maximum((plus - q) / weight[a], (minus + q) / weight[a])
            reach = far if reach is None else np.maximum(reach, far)
        return np.where(inside, -depth, reach)

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Signed Euclidean distance: inside, to the nearest face plane (exact for a
        convex solid); outside, to the nearest triangle of the hull's boundary."""
        p = as_points(points)
        return in_blocks(lambda q, _w: self._euclidean(q), p, np.ones((len(p), 3)), CHUNK)

    def _euclidean(self, p: np.ndarray) -> np.ndarray:
        if self._facets is None:
            from scipy.spatial import ConvexHull
            self._facets = self.vertices[ConvexHull(self.vertices).simplices]
        excess = dot(p, self.normals.T) - self.offsets[None, :]          # (n, F), <= 0 inside
        d_in = np.max(excess, axis=1)
        out = d_in > 0
        d = d_in.copy()
        if out.any():
            q = p[out]
            rows = np.repeat(np.arange(len(q)), len(self._facets))
            tri = np.tile(self._facets, (len(q), 1, 1))
            d[out] = triangle_euclidean(q[rows], tri).reshape(len(q), -1).min(axis=1)
        return d

    @property
    def expr(self):
        """``max_f (n_f . x - d_f)``: the implicit function (a Shape for the voxelizer)."""
        terms = [n[0] * ex.x + n[1] * ex.y + n[2] * ex.z - d
                 for n, d in zip(self.normals, self.offsets)]
        return ex.max(*terms)

    @property
    def bounds(self):
        return tuple(self.vertices.min(0).tolist()), tuple(self.vertices.max(0).tolist())



class HalfSpace(Primitive):
    """``n . x <= d``: signed distance ``(n.p - d) / h_w(n)`` (exactly, on both sides)."""

    def __init__(self, normal: Any, offset: float):
        n = np.asarray(normal, dtype=np.float64).reshape(3)
        if not np.any(n != 0) or not np.all(np.isfinite(n)):
            raise ValueError("normal must be finite and non-zero")
        self.normal, self.offset = n, float(offset)

    @property
    def expr(self):
        n = self.normal
        return n[0] * ex.x + n[1] * ex.y + n[2] * ex.z - self.offset

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        p = as_points(points)
        w = as_weights(weights, len(p))
        return (dot(p, self.normal) - self.offset) / dot(w, np.abs(self.normal))

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Signed Euclidean distance ``(n.p - d) / |n|``."""
        return (dot(as_points(points), self.normal) - self.offset) / np.linalg.norm(self.normal)



def triangle_distance(points: np.ndarray, tri: np.ndarray,
                      weights: Optional[np.ndarray] = None) -> np.ndarray:
    """Unsigned weighted max-norm distance from ``points[k]`` to triangle ``tri[k]`` (3, 3).

    The 13 separating axes of a box and a triangle (box normals, the normal,
    box axes crossed with the edges), each with both signs; degenerate axes
    (zero normal or edge) are skipped. Written per coordinate: a box axis
    crossed with an edge has one zero component.
    """
    p = np.asarray(points, dtype=np.float64)
    w = as_weights(weights, len(p))
    P = [p[:, a] for a in range(3)]
    V = [[tri[:, k, a] for a in range(3)] for k in range(3)]
    W = [w[:, a] for a in range(3)]
    best = np.zeros(len(p))
    with np.errstate(invalid="ignore", divide="ignore"):
        for a in range(3):                                    # box normals: the bounding box
            lo = np.minimum(np.minimum(V[0][a], V[1][a]), V[2][a])
            hi = np.maximum(np.maximum(V[0][a], V[1][a]), V[2][a])
            best = np.fmax(best, np.maximum(lo - P[a], P[a] - hi) / W[a])

        def along(u):                                        # u: 3 components (or 0)
            h = sum(np.abs(u[a]) * W[a] for a in range(3) if u[a] is not None)
            dots = [sum(u[a] * V[k][a] for a in range(3) if u[a] is not None) for k in range(3)]
            q = sum(u[a] * P[a] for a in range(3) if u[a] is not None)
            lo = np.minimum(np.minimum(dots[0], dots[1]), dots[2])
            hi = np.maximum(np.maximum(dots[0], dots[1]), dots[2])
            return np.where(h > 0, np.maximum(lo - q, q - hi) / h, 0.0)

        e = [[V[(k + 1) % 3][a] - V[k][a] for a in range(3)] for k in range(3)]
        f = [V[2][a] - V[0][a] for a in range(3)]
        normal = [e[0][1] * f[2] - e[0][2] * f[1], e[0][2] * f[0] - e[0][0] * f[2],
                  e[0][0] * f[1] - e[0][1] * f[0]]
        best = np.fmax(best, along(normal))
        for ed in e:                                          # e_i x edge
            best = np.fmax(best, along([None, -ed[2], ed[1]]))
            best = np.fmax(best, along([ed[2], None, -ed[0]]))
            best = np.fmax(best, along([-ed[1], ed[0], None]))
    return best
