"""Exact winding numbers of closed triangle meshes by signed ray crossings.

For a point ``p`` off the surface, the winding number of a closed, oriented
mesh is the signed count of the triangles the ray ``p + t e_x`` (``t > 0``)
crosses: ``+1`` where it leaves through a triangle facing ``+x``, ``-1``
where it enters. Each test is a sign of exact predicates
(:mod:`implicitvox.triangles.predicates`):

* the ray meets the triangle's shadow on the ``yz`` plane: three ``orient2d``
  signs equal to the shadow's orientation. Rays through a shadow's edge or
  vertex are settled by simulation of simplicity - the point is moved by
  ``(eps, eps**2)`` in ``(y, z)`` - so each crossing is counted exactly once;
* the crossing lies ahead (``t > 0``): the ``orient3d`` sign of ``p`` against
  the triangle is opposite to the sign of its normal's ``x`` component.

Only the triangles whose shadow's box holds ``(p_y, p_z)`` are tested (a
uniform grid on the ``yz`` plane), so a query costs a few tests, not one per
triangle; the tests run compiled (:mod:`implicitvox.triangles.crossing_kernels`,
floating-point filters), the pairs they cannot certify on the exact array path.
For open meshes use the generalized winding number
(:mod:`implicitvox.triangles.winding`) instead.

Examples
--------
>>> import numpy as np
>>> import pyvista as pv
>>> from implicitvox.triangles.inputs import as_triangles
>>> v, f = as_triangles(pv.Cube())
>>> RayWinding(v[f])(np.array([[0.0, 0.0, 0.0], [-0.2, 0.3, 0.3], [2.0, 0.0, 0.0]])).tolist()
[1, 1, 0]
"""
from __future__ import annotations

import numpy as np

from .predicates import det2_sign, orient3d_sign
from .ranges import buckets, expand_boxes, gather, grid_cells
from .tribox import Triangles

__all__ = ["RayWinding", "CELLS_PER_ROOT", "face_groups"]

#: grid cells per axis over the square root of the triangle count: more cells, fewer
#: candidate triangles per query and more (cell, triangle) entries (measured on a
#: faceted sphere, 896 triangles: 2 gives ~3 candidates per point and 4x the speed of 0.5)
CELLS_PER_ROOT = 2.0


class RayWinding:
    """Winding numbers of a closed mesh ``(t, 3, 3)`` at points off its surface.

    A point *on* the surface gets an arbitrary but finite count; callers ask
    only about points known to be off it.
    """

    def __init__(self, triangles: np.ndarray):
        self.tris = triangles if isinstance(triangles, Triangles) else Triangles(triangles)
        t = self.tris
        keep = np.flatnonzero(t.normal_sign[:, 0] != 0)       # shadows with area
        self.index = keep
        lo, hi = t.lo[keep][:, 1:], t.hi[keep][:, 1:]
        self.lo2 = lo.min(axis=0) if len(keep) else np.zeros(2)
        span = (hi.max(axis=0) - self.lo2) if len(keep) else np.ones(2)
        span = np.where(span > 0, span, 1.0)
        self.cells = grid_cells(lo, hi, self.lo2, span, int(np.clip(
            round(CELLS_PER_ROOT * np.sqrt(max(len(keep), 1))), 1, 1024)))
        self.size = span / self.cells
        # a point is looked up in its own cell only; no slack is needed, since every
        # step of :meth:`_cell` is monotone in floating point (a rounded subtraction, a
        # rounded division by a positive number, floor, clip): a point inside a
        # shadow's box gets a cell inside the box's cell range
        first = self._cell(lo)
        last = self._cell(hi)
        tri, cell = expand_boxes(first, last)
        key = cell[:, 0] * self.cells + cell[:, 1]
        self.cell_tris, self.cell_start = buckets(key, keep[tri], self.cells ** 2)

    def _cell(self, p: np.ndarray) -> np.ndarray:
        c = np.floor((p - self.lo2) / self.size).astype(np.int64)
        return np.clip(c, 0, self.cells - 1)

    def of_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Winding numbers ``(n,)`` of closed boxes ``[lo, hi]`` known to be off the
        surface (no triangle meets them): constant over each box, and over each
        group of boxes joined by shared faces (:func:`face_groups`), so one corner
        per group is asked."""
        group, first = face_groups(lo, hi)
        return self(lo[first])[group]

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Winding numbers ``(n,)`` (ints) at ``points (n, 3)``."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        out = np.zeros(len(p), dtype=np.int64)
        if not len(self.index) or not len(p):
            return out
        key = self._cell(p[:, 1:]) @ np.array([self.cells, 1])
        pts, index = gather(self.cell_start[key], self.cell_start[key + 1] - self.cell_start[key])
        tri = self.cell_tris[index]
        t = self.tris
        q = p[pts]
        near = np.all((t.lo[tri][:, 1:] <= q[:, 1:]) & (t.hi[tri][:, 1:] >= q[:, 1:]), axis=1)
        pts, tri, q = pts[near], tri[near], q[near]
        from .crossing_kernels import crossing_pairs     # (loads Numba: not at import)
        from .tribox_kernels import settled
        crossing = settled(crossing_pairs(t, tri, q), self.crossings_by_arrays, tri, q)
        np.add.at(out, pts, crossing.astype(np.int64))
        return out

    def crossings_by_arrays(self, tri: np.ndarray, q: np.ndarray) -> np.ndarray:
        """The signed crossings (``normal_sign[tri, 0]`` or 0) of the rays from ``q``
        (m, 3) along ``+x`` with triangles ``tri``, over whole arrays, every sign
        exact: the path for the pairs the compiled filter leaves unsure, and the
        oracle the tests hold it to."""
        t = self.tris
        sx = t.normal_sign[tri, 0].astype(np.int64)
        v = t.v[tri]
        inside = np.ones(len(tri), dtype=bool)
        for k in range(3):
            a, b = v[:, k], v[:, (k + 1) % 3]
            s = det2_sign((a[:, 1], a[:, 2]), (b[:, 1], b[:, 2]), (a[:, 1], a[:, 2]),
                          (q[:, 1], q[:, 2])).astype(np.int64)
            # simulation of simplicity: q + (eps, eps^2) in (y, z)
            dz, dy = b[:, 2] - a[:, 2], b[:, 1] - a[:, 1]
            tie = np.where(dz != 0, -np.sign(dz), np.sign(dy)).astype(np.int64)
            s = np.where(s == 0, tie, s)
            inside &= s == sx
        ahead = orient3d_sign(v[:, 0], v[:, 1], v[:, 2], q).astype(np.int64) == -sx
        return np.where(inside & ahead, sx, 0)


def face_groups(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boxes ``[lo, hi]`` (n, 3) grouped by shared faces: ``group (n,)``, each box's
    group, and ``first``, one box of each group.

    Two boxes are joined where the upper face of one along an axis is, float for
    float, the lower face of the other (equal extents across, equal coordinate
    along): the union of two such closed boxes is connected. So over boxes that
    no surface meets, a group lies on one side of it. Boxes touching only along
    an edge, or meeting faces of different sizes, stay apart (a group too many
    is only a query too many).

    Examples
    --------
    >>> lo = np.array([[0., 0, 0], [1, 0, 0], [3, 0, 0]])
    >>> group, first = face_groups(lo, lo + 1)
    >>> group.tolist(), first.tolist()
    ([0, 0, 1], [0, 2])
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    n = len(lo)
    if n < 2:
        return np.zeros(n, dtype=np.int64), np.arange(n)
    lo, hi = lo + 0.0, hi + 0.0                              # -0.0 as 0.0: keys by bits
    rows, cols = [], []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        across = np.column_stack([lo[:, b], hi[:, b], lo[:, c], hi[:, c]])
        lower = np.column_stack([lo[:, a], across])
        upper = np.column_stack([hi[:, a], across])
        low_key, up_key = _face_hash(lower), _face_hash(upper)
        order = np.argsort(low_key)
        at = np.minimum(np.searchsorted(low_key[order], up_key), n - 1)
        other = order[at]
        # a hash is only a hint: the faces must be equal, float for float
        match = np.all(lower[other] == upper, axis=1)
        rows.append(np.flatnonzero(match))
        cols.append(other[match])
    r, c = np.concatenate(rows), np.concatenate(cols)
    graph = coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)), shape=(n, n))
    count, group = connected_components(graph, directed=False)
    first = np.full(count, n, dtype=np.int64)
    np.minimum.at(first, group, np.arange(n))
    return group.astype(np.int64), first


#: odd multipliers mixing a face's five coordinates (their bits) into one key
_MIX = np.array([0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9,
                 0xD6E8FEB86659FD93, 0xFF51AFD7ED558CCD], dtype=np.uint64)


def _face_hash(faces: np.ndarray) -> np.ndarray:
    """A 64-bit key per row of five floats (wrapping products of their bits)."""
    bits = np.ascontiguousarray(faces).view(np.uint64)
    with np.errstate(over="ignore"):
        key = (bits * _MIX).sum(axis=1, dtype=np.uint64)
        return key ^ (key >> np.uint64(29))
