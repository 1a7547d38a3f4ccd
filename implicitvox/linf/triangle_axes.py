"""A triangle's 13 separating axes, projected once: the max-norm distance in compiled code.

The weighted max-norm distance from a point ``p`` to a triangle is the
largest gap, over the 13 separating axes of a box and a triangle (Varadhan
§3.3.1; the three box normals, the triangle's normal, and the box axes crossed
with its three edges), between the triangle's projection and the box's
(:func:`implicitvox.linf.polyhedron.triangle_distance`, the array kernel).
What depends on the triangle alone (each axis and the triangle's interval
along it) is computed once per triangle into a row of :data:`ROW` numbers by
:func:`axis_rows`; a query then needs only its own projections. The
operations are those of the array kernel, in its order, so the distance is
the same float.

A row holds the triangle's box (``lo`` in 0-2, ``hi`` in 3-5), its normal
(6-8) and interval along it (9, 10), and for each edge ``k`` the three axes
``x × e_k``, ``y × e_k``, ``z × e_k`` (each two nonzero components ``ua, ub``
on the axes :data:`EDGE_AXES` names, and the interval): 4 numbers each from
column 11 on. Half-widths of the box along an axis depend on the weights,
and are formed per query (so one table serves any weights).

Examples
--------
>>> import numpy as np
>>> rows = axis_rows(np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]]))
>>> p = (0.25, 0.25, 2.0)
>>> gap = box_gap(*p, 1.0, 1.0, 1.0, rows[0])
>>> float(gap), float(linf_below(*p, 1.0, 1.0, 1.0, rows[0], gap, np.inf))
(2.0, 2.0)
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE

__all__ = ["ROW", "EDGE_AXES", "axis_rows", "fill_row", "box_side", "box_gap", "linf_below"]

#: numbers per triangle in :func:`axis_rows`' table
ROW = 47
#: the two coordinate axes of ``x × e``, ``y × e``, ``z × e`` (the third component is 0)
EDGE_AXES = ((1, 2), (0, 2), (0, 1))
_EDGES = 11                          # the first edge axis's column


@njit(**COMPILE)
def _fmax(a, b):
    """numpy's fmax: the larger, NaN ignored."""
    if a != a:
        return b
    if b != b:
        return a
    return a if a >= b else b


@njit(**COMPILE)
def _interval(ua, ub, a, b, t, r, at):
    """The triangle ``t``'s interval along ``(ua, ub)`` on axes ``a, b`` into ``r[at:at + 4]``."""
    d0 = (0.0 + ua * t[0, a]) + ub * t[0, b]
    d1 = (0.0 + ua * t[1, a]) + ub * t[1, b]
    d2 = (0.0 + ua * t[2, a]) + ub * t[2, b]
    r[at], r[at + 1] = ua, ub
    r[at + 2] = min(min(d0, d1), d2)
    r[at + 3] = max(max(d0, d1), d2)


@njit(**COMPILE)
def fill_row(t, r):
    """Triangle ``t`` (3, 3)'s row (see the module docstring) into ``r``."""
    for a in range(3):
        r[a] = min(min(t[0, a], t[1, a]), t[2, a])
        r[3 + a] = max(max(t[0, a], t[1, a]), t[2, a])
    e00, e01, e02 = t[1, 0] - t[0, 0], t[1, 1] - t[0, 1], t[1, 2] - t[0, 2]
    f0, f1, f2 = t[2, 0] - t[0, 0], t[2, 1] - t[0, 1], t[2, 2] - t[0, 2]
    n0 = e01 * f2 - e02 * f1
    n1 = e02 * f0 - e00 * f2
    n2 = e00 * f1 - e01 * f0
    d0 = ((0.0 + n0 * t[0, 0]) + n1 * t[0, 1]) + n2 * t[0, 2]
    d1 = ((0.0 + n0 * t[1, 0]) + n1 * t[1, 1]) + n2 * t[1, 2]
    d2 = ((0.0 + n0 * t[2, 0]) + n1 * t[2, 1]) + n2 * t[2, 2]
    r[6], r[7], r[8] = n0, n1, n2
    r[9] = min(min(d0, d1), d2)
    r[10] = max(max(d0, d1), d2)
    for k in range(3):
        k1 = (k + 1) % 3
        g0, g1, g2 = t[k1, 0] - t[k, 0], t[k1, 1] - t[k, 1], t[k1, 2] - t[k, 2]
        at = _EDGES + 12 * k
        _interval(-g2, g1, 1, 2, t, r, at)
        _interval(g2, -g0, 0, 2, t, r, at + 4)
        _interval(-g1, g0, 0, 1, t, r, at + 8)


@njit(**COMPILE)
def axis_rows(tri):
    """The table of rows of triangles ``tri`` (m, 3, 3): (m, :data:`ROW`)."""
    out = np.empty((tri.shape[0], ROW))
    for k in range(tri.shape[0]):
        fill_row(tri[k], out[k])
    return out


@njit(**COMPILE)
def box_side(r, a, p, w):
    """The gap along box normal ``a`` (of weight ``w``) from coordinate ``p``: a
    term of :func:`box_gap`, at least it when 0 is given first."""
    return _fmax(0.0, max(r[a] - p, p - r[3 + a]) / w)


@njit(**COMPILE)
def box_gap(p0, p1, p2, w0, w1, w2, r):
    """The gap along the box normals alone (the triangle's bounding box): a lower bound
    of the distance, and the first term of :func:`linf_below`; the larger of the
    three :func:`box_side` terms (the same float, in any grouping)."""
    return _fmax(_fmax(box_side(r, 0, p0, w0), box_side(r, 1, p1, w1)), box_side(r, 2, p2, w2))


@njit(**COMPILE)
def _along(r, at, pa, pb, wa, wb):
    """The gap along the edge axis at column ``at`` (components on axes ``a, b``)."""
    h = (0.0 + abs(r[at]) * wa) + abs(r[at + 1]) * wb
    q = (0.0 + r[at] * pa) + r[at + 1] * pb
    return max(r[at + 2] - q, q - r[at + 3]) / h if h > 0 else 0.0


@njit(**COMPILE)
def linf_below(p0, p1, p2, w0, w1, w2, r, box, bound):
    """The weighted max-norm distance from ``(p0, p1, p2)`` to the triangle of row ``r``
    where it is below ``bound``, else some value at least ``bound`` (the axes stop
    once one reaches it: the distance is their largest gap). ``box`` is
    :func:`box_gap`'s value for the same point."""
    best = box
    h = ((0.0 + abs(r[6]) * w0) + abs(r[7]) * w1) + abs(r[8]) * w2
    q = ((0.0 + r[6] * p0) + r[7] * p1) + r[8] * p2
    best = _fmax(best, max(r[9] - q, q - r[10]) / h if h > 0 else 0.0)
    if best >= bound:
        return best
    for k in range(3):
        at = _EDGES + 12 * k
        best = _fmax(best, _along(r, at, p1, p2, w1, w2))
        best = _fmax(best, _along(r, at + 4, p0, p2, w0, w2))
        best = _fmax(best, _along(r, at + 8, p0, p1, w0, w1))
        if best >= bound:
            return best
    return best
