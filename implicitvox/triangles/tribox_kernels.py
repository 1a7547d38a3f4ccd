"""The box-triangle test of :mod:`implicitvox.triangles.tribox` in compiled code.

Each pair (a triangle, a closed box) runs the separating-axis test of the
array path - the same axes, the same determinants, the same floating-point
filters (Shewchuk's a-priori bounds ``4e`` for ``det2`` and ``8e`` for
``orient3d``, see :mod:`implicitvox.triangles.predicates`) - in one compiled
loop, with no array per stage. Where a filter cannot certify a sign, the
sign is computed exactly in floating-point expansions
(:mod:`implicitvox.triangles.expansions`: exact where the coordinates'
differences are, as on a lattice: the ties of round models on round grids);
where that cannot be done either, the pair's answer is :data:`UNSURE` and the
caller settles it on the exact path (Python integers). Every answer given here
is the exact one, so the result is the array path's, bit for bit.

Two exact rules spare the later stages their most frequent visitors, products
that are zero for axis-aligned input (a cube's faces on a voxel grid):

* ``det2``: a product with a factor that is exactly zero (a float difference
  is zero iff its operands are equal) is zero; both zero, the sign is 0.
* ``orient3d`` against a fixed plane: a normal component whose two minor
  products are exactly zero, without underflow (the plane is "filtered"), is
  zero; where every term has a zero normal component or a zero difference,
  the sign is 0.

Examples
--------
>>> import numpy as np
>>> from implicitvox.triangles.tribox import Triangles
>>> t = Triangles(np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]]))
>>> lo = np.array([[0.2, 0.2, -1.0], [0.51, 0.5, -1.0], [0.5, 0.5, -1.0]])
>>> meet_pairs(t, np.array([0, 0, 0]), lo, lo + 1.0).tolist()   # meets, misses, touches
[1, 0, 1]
>>> tiny = Triangles(t.v * 2.0 ** -1000)         # products underflow: the exact path's
>>> meet_pairs(tiny, np.array([0]), lo[2:] * 2.0 ** -1000, (lo[2:] + 1) * 2.0 ** -1000)
array([2], dtype=int8)
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from .expansions import UNSURE, det2_exact, orient3d_exact

__all__ = ["UNSURE", "det2_filtered", "plane_filtered", "meet_pair", "meet_pairs",
           "meet_any_pairs", "plane_side_pairs", "settled"]


_EPS = 2.0 ** -53
_DET2_BOUND = 4.0 * _EPS
_DET3_BOUND = 8.0 * _EPS
_TINY = 2.0 ** -900
_INF = np.inf


@njit(**COMPILE)
def det2_filtered(a0, a1, b0, b1, p0, p1, q0, q1):
    """Sign of ``(b0 - a0)(q1 - p1) - (b1 - a1)(q0 - p0)``, or UNSURE."""
    f0 = b0 - a0
    f1 = b1 - a1
    g0 = q0 - p0
    g1 = q1 - p1
    if (f0 == 0.0 or g1 == 0.0) and (f1 == 0.0 or g0 == 0.0):
        return 0
    left = f0 * g1
    right = f1 * g0
    det = left - right
    bound = _DET2_BOUND * (abs(left) + abs(right))
    if abs(det) > bound and bound > _TINY and bound < _INF:
        return 1 if det > 0.0 else -1
    return det2_exact(a0, a1, b0, b1, p0, p1, q0, q1)


@njit(inline="always", **COMPILE)
def plane_filtered(v, planes, t, d0, d1, d2):
    """Sign of ``orient3d`` of triangle ``t`` (corners ``v[t]``) against point ``d``,
    or UNSURE (``planes``: the rows of
    :attr:`implicitvox.triangles.predicates.FixedPlanes.rows`)."""
    dx = d0 - planes[t, 0]
    dy = d1 - planes[t, 1]
    dz = d2 - planes[t, 2]
    n0, n1, n2 = planes[t, 3], planes[t, 4], planes[t, 5]
    w0, w1, w2 = planes[t, 6], planes[t, 7], planes[t, 8]
    if planes[t, 9] != 0.0:
        if (w0 == 0.0 or dx == 0.0) and (w1 == 0.0 or dy == 0.0) and (w2 == 0.0 or dz == 0.0):
            return 0
        det = n0 * dx + n1 * dy + n2 * dz
        bound = _DET3_BOUND * (w0 * abs(dx) + w1 * abs(dy) + w2 * abs(dz))
        if abs(det) > bound and bound > _TINY and bound < _INF:
            return 1 if det > 0.0 else -1
    return orient3d_exact(v[t, 0, 0], v[t, 0, 1], v[t, 0, 2], v[t, 1, 0], v[t, 1, 1],
                          v[t, 1, 2], v[t, 2, 0], v[t, 2, 1], v[t, 2, 2], d0, d1, d2)


@njit(inline="always", **COMPILE)
def _side(v, planes, normal_sign, t, lo, hi, k):
    """:meth:`Triangles.plane_sides` of pair ``k``: 1, -1, 0, or UNSURE."""
    p0 = normal_sign[t, 0] >= 0
    p1 = normal_sign[t, 1] >= 0
    p2 = normal_sign[t, 2] >= 0
    s = plane_filtered(v, planes, t, lo[k, 0] if p0 else hi[k, 0], lo[k, 1] if p1 else hi[k, 1],
               lo[k, 2] if p2 else hi[k, 2])
    if s == UNSURE:
        return UNSURE
    if s > 0:
        return 1
    s = plane_filtered(v, planes, t, hi[k, 0] if p0 else lo[k, 0], hi[k, 1] if p1 else lo[k, 1],
               hi[k, 2] if p2 else lo[k, 2])
    if s == UNSURE:
        return UNSURE
    return -1 if s < 0 else 0


@njit(inline="always", **COMPILE)
def _shadow_inside(v, t, n, lo, hi, k, j, l):
    """The box's shadow on plane ``(j, l)`` lies in the triangle's (orientation
    ``sign n``, nonzero); False where a filter is unsure (it is only a quick
    accept)."""
    for e in range(3):
        aj, al = v[t, e, j], v[t, e, l]
        bj, bl = v[t, (e + 1) % 3, j], v[t, (e + 1) % 3, l]
        up_l = bj - aj > 0.0
        up_j = bl - al > 0.0
        q_l = lo[k, l] if up_l == (n > 0) else hi[k, l]
        q_j = lo[k, j] if up_j != (n > 0) else hi[k, j]
        s = det2_filtered(aj, al, bj, bl, aj, al, q_j, q_l)
        if s == UNSURE or (s < 0 if n > 0 else s > 0):
            return False
    return True


@njit(inline="always", **COMPILE)
def _edge_axis(aj, al, bj, bl, wj, wl, n, loj, lol, hij, hil):
    """Edge ``a -> b`` (third vertex ``w``; the triangle's normal component
    along the box axis has sign ``n``), projected on the plane ``(j, l)`` of
    the box ``[lo, hi]``: 0 where it separates, 1 where not, or UNSURE."""
    up_l = bj - aj > 0.0
    up_j = bl - al > 0.0
    # the box's corner where s(q) is least, the triangle's projection [0, s(w)]
    q_l = lol if up_l else hil
    q_j = hij if up_j else loj
    if n > 0:
        s = det2_filtered(aj, al, bj, bl, wj, wl, q_j, q_l)
    else:
        s = det2_filtered(aj, al, bj, bl, aj, al, q_j, q_l)
    if s == UNSURE:
        sure = False
    elif s > 0:
        return 0
    else:
        sure = True
    q_l = hil if up_l else lol
    q_j = loj if up_j else hij
    if n < 0:
        s = det2_filtered(aj, al, bj, bl, wj, wl, q_j, q_l)
    else:
        s = det2_filtered(aj, al, bj, bl, aj, al, q_j, q_l)
    if s == UNSURE:
        return UNSURE
    if s < 0:
        return 0
    return 1 if sure else UNSURE


@njit(inline="always", **COMPILE)
def _edge_axes(v, normal_sign, t, lo, hi, k):
    """The 9 edge axes: 0 where one separates, 1 where none does, UNSURE where
    none separates surely and a filter failed."""
    x0, y0, z0 = v[t, 0, 0], v[t, 0, 1], v[t, 0, 2]
    x1, y1, z1 = v[t, 1, 0], v[t, 1, 1], v[t, 1, 2]
    x2, y2, z2 = v[t, 2, 0], v[t, 2, 1], v[t, 2, 2]
    lx, ly, lz = lo[k, 0], lo[k, 1], lo[k, 2]
    hx, hy, hz = hi[k, 0], hi[k, 1], hi[k, 2]
    # box axis x: the plane (y, z); y: (z, x); z: (x, y)
    rx = _plane_edges(y0, z0, y1, z1, y2, z2, normal_sign[t, 0], ly, lz, hy, hz)
    if rx == 0:
        return 0
    ry = _plane_edges(z0, x0, z1, x1, z2, x2, normal_sign[t, 1], lz, lx, hz, hx)
    if ry == 0:
        return 0
    rz = _plane_edges(x0, y0, x1, y1, x2, y2, normal_sign[t, 2], lx, ly, hx, hy)
    if rz == 0:
        return 0
    return UNSURE if UNSURE in (rx, ry, rz) else 1


@njit(inline="always", **COMPILE)
def _plane_edges(a0, a1, b0, b1, c0, c1, n, lo0, lo1, hi0, hi1):
    """The three edge axes of one box axis: the triangle ``a, b, c`` and the box
    projected on the plane normal to it (coordinates ``0, 1``), the triangle's
    normal component along the axis of sign ``n``: 0 where an edge separates, 1
    where none does, UNSURE where none surely does and a filter failed."""
    r = _edge_axis(a0, a1, b0, b1, c0, c1, n, lo0, lo1, hi0, hi1)
    if r == 0:
        return 0
    unsure = r == UNSURE
    r = _edge_axis(b0, b1, c0, c1, a0, a1, n, lo0, lo1, hi0, hi1)
    if r == 0:
        return 0
    unsure = unsure or r == UNSURE
    r = _edge_axis(c0, c1, a0, a1, b0, b1, n, lo0, lo1, hi0, hi1)
    if r == 0:
        return 0
    return UNSURE if unsure or r == UNSURE else 1


@njit(inline="always", **COMPILE)
def meet_pair(v, tlo, thi, normal_sign, axis, planes, t, lo, hi, glo, ghi, k):
    """Pair ``k`` (triangle ``t``; box ``[lo, hi]``, grown by the dilation
    ``[glo, ghi]``): 1, 0 or UNSURE."""
    for i in range(3):
        if tlo[t, i] > hi[k, i] or thi[t, i] < lo[k, i]:
            return 0
    for c in range(3):
        if (glo[k, 0] <= v[t, c, 0] <= ghi[k, 0] and glo[k, 1] <= v[t, c, 1] <= ghi[k, 1]
                and glo[k, 2] <= v[t, c, 2] <= ghi[k, 2]):
            return 1
    side = _side(v, planes, normal_sign, t, glo, ghi, k)
    if side == 1 or side == -1:
        return 0
    if side == 0 and axis[t] >= 0:
        i = axis[t]
        if _shadow_inside(v, t, normal_sign[t, i], glo, ghi, k, (i + 1) % 3, (i + 2) % 3):
            return 1
    answer = _edge_axes(v, normal_sign, t, glo, ghi, k)
    # no edge axis separates; the plane's may, where its sign was unsure
    return UNSURE if answer == 1 and side == UNSURE else answer


@njit(**COMPILE)
def _meet_any_kernel(v, tlo, thi, normal_sign, axis, planes, tri, lo, hi, glo, ghi, start,
                     groups, pairs):
    for g in range(start.size - 1):
        result = 0
        for k in range(start[g], start[g + 1]):
            pairs[k] = meet_pair(v, tlo, thi, normal_sign, axis, planes, tri[k], lo, hi,
                                 glo, ghi, k)
            if pairs[k] == 1:
                result = 1
                break
            if pairs[k] == UNSURE:
                result = UNSURE
        groups[g] = result


@njit(**COMPILE)
def _side_kernel(v, planes, normal_sign, tri, lo, hi, out):
    for k in range(tri.size):
        out[k] = _side(v, planes, normal_sign, tri[k], lo, hi, k)


def _kernel_arguments(triangles, tri, lo, hi) -> tuple:
    tri = np.ascontiguousarray(tri, dtype=np.int64)
    lo = np.ascontiguousarray(lo, dtype=np.float64)
    hi = np.ascontiguousarray(hi, dtype=np.float64)
    glo, ghi = triangles.grown(tri, lo, hi)
    return (triangles.v, triangles.lo, triangles.hi, triangles.normal_sign, triangles.axis,
            triangles.planes.rows, tri, lo, hi, np.ascontiguousarray(glo),
            np.ascontiguousarray(ghi))


def meet_pairs(triangles, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per pair, whether triangle ``tri[k]`` of ``triangles`` (a
    :class:`~implicitvox.triangles.tribox.Triangles`) meets the closed box
    ``[lo[k], hi[k]]``: 1 it does, 0 it does not, :data:`UNSURE` for the exact path.

    Parameters
    ----------
    triangles : Triangles
    tri : ndarray of int, (m,)
    lo, hi : ndarray, (m, 3)

    Returns
    -------
    ndarray of int8, (m,)
    """
    return meet_any_pairs(triangles, tri, lo, hi, np.arange(len(tri) + 1))[1]


def meet_any_pairs(triangles, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                   start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per group of pairs ``start[g]:start[g + 1]`` (a voxel and its candidate
    triangles), whether one of its triangles meets its box, testing a group's
    pairs in order only until one does.

    Returns
    -------
    groups : ndarray of int8, (len(start) - 1,)
        1 (a pair meets), 0 (none does) or :data:`UNSURE` (none surely does, and
        some pair is unsure).
    pairs : ndarray of int8, (m,)
        Each tested pair's answer (1, 0, :data:`UNSURE`); 0 for pairs not tested.
    """
    groups = np.empty(max(len(start) - 1, 0), dtype=np.int8)
    pairs = np.zeros(len(tri), dtype=np.int8)
    if len(groups):
        _meet_any_kernel(*_kernel_arguments(triangles, tri, lo, hi),
                         np.ascontiguousarray(start, dtype=np.int64), groups, pairs)
    return groups, pairs


def plane_side_pairs(triangles, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per pair, where the closed box ``[lo[k], hi[k]]`` lies against the plane of
    triangle ``tri[k]`` (as :meth:`~implicitvox.triangles.tribox.Triangles.plane_sides`:
    1, -1, 0), or :data:`UNSURE` for the exact path.

    Returns
    -------
    ndarray of int8, (m,)
    """
    tri = np.ascontiguousarray(tri, dtype=np.int64)
    out = np.empty(len(tri), dtype=np.int8)
    if len(tri):
        _side_kernel(triangles.v, triangles.planes.rows, triangles.normal_sign, tri,
                     np.ascontiguousarray(lo, dtype=np.float64),
                     np.ascontiguousarray(hi, dtype=np.float64), out)
    return out


def settled(answers: np.ndarray, exact, *columns: np.ndarray) -> np.ndarray:
    """``answers`` (a compiled kernel's, per pair) with each :data:`UNSURE` one replaced
    by ``exact`` (the exact array path) of that pair's ``columns``.

    >>> settled(np.array([1, UNSURE, 0], dtype=np.int8), lambda x: x > 5, np.arange(3) * 4)
    array([1, 0, 0], dtype=int8)
    """
    unsure = np.flatnonzero(answers == UNSURE)
    if len(unsure):
        answers = answers.copy()
        answers[unsure] = exact(*(c[unsure] for c in columns))
    return answers
