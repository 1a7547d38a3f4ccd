"""Compiled loops of :mod:`implicitvox.fields.mesh_band`: bricks' triangle lists, the scatter.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from ..linf.mesh_walk import EUCLIDEAN_SLACK, triangle_euclidean
from ..linf.triangle_axes import box_side, linf_below
from .brick_kernels import BRICK, brick_row

__all__ = ["centre_range", "brick_triangles", "scatter_bricks"]

_BITS = 3


@njit(**COMPILE)
def centre_range(lo, hi, centres, margin):
    """``(first, last)``: the samples whose centres (sorted) lie within ``margin`` of
    ``[lo, hi]`` on one axis (none when ``first > last``)."""
    first = np.searchsorted(centres, lo - margin)
    last = np.searchsorted(centres, hi + margin, side="right") - 1
    return first, last


@njit(**COMPILE)
def _each_pair(rows, keys, centres, margin, count, start, triangles):
    """Every (brick, triangle) pair: counted into ``count``, or, given ``start``,
    written to ``triangles`` (``start`` advanced as they go)."""
    lo = np.empty(3, dtype=np.int64)
    hi = np.empty(3, dtype=np.int64)
    for t in range(rows.shape[0]):
        empty = False
        for a in range(3):
            first, last = centre_range(rows[t, a], rows[t, 3 + a], centres[a], margin[a])
            lo[a], hi[a] = first >> _BITS, last >> _BITS
            empty = empty or first > last
        if empty:
            continue
        for i in range(lo[0], hi[0] + 1):
            for j in range(lo[1], hi[1] + 1):
                for k in range(lo[2], hi[2] + 1):
                    b = brick_row(keys, i, j, k)
                    if b < 0:
                        continue
                    if count.size:
                        count[b] += 1
                    else:
                        triangles[start[b]] = t
                        start[b] += 1


@njit(**COMPILE)
def brick_triangles(rows, keys, origins, centres, margin):
    """:func:`implicitvox.fields.mesh_band.brick_triangles` (``origins``: each brick's
    first voxel index; ``centres``: the samples' coordinates per axis)."""
    n = keys.size
    count = np.zeros(n, dtype=np.int64)
    none = np.zeros(0, dtype=np.int64)
    _each_pair(rows, keys, centres, margin, count, none, none)
    start = np.zeros(n + 1, dtype=np.int64)
    start[1:] = np.cumsum(count)
    cursor = start[:-1].copy()
    triangles = np.empty(start[n], dtype=np.int64)
    _each_pair(rows, keys, centres, margin, none, cursor, triangles)
    middle = np.empty(3)
    for b in range(n):                     # nearest to the brick's middle first
        for a in range(3):
            c = centres[a]
            o = origins[b, a]
            middle[a] = 0.5 * (c[o] + c[min(o + BRICK - 1, c.size - 1)])
        s, e = start[b], start[b + 1]
        gaps = np.empty(e - s)
        for j in range(s, e):
            t = triangles[j]
            gap = 0.0
            for a in range(3):
                gap = max(gap, max(rows[t, a] - middle[a], middle[a] - rows[t, 3 + a]))
            gaps[j - s] = gap
        triangles[s:e] = triangles[s:e][np.argsort(gaps, kind="mergesort")]
    return start, triangles


@njit(**COMPILE)
def _side(r, a, p, w, euclidean):
    """The box gap's term along axis ``a``: max-norm (:func:`box_side`), or squared."""
    if euclidean:
        g = max(max(r[a] - p, p - r[3 + a]), 0.0)
        return g * g
    return box_side(r, a, p, w)


@njit(**COMPILE)
def scatter_bricks(b0, b1, start, triangles, rows, tri, origins, centres, w, margin,
                   euclidean, steps, unit, values):
    """Bricks ``b0`` to ``b1``: each listed triangle's exact distance (max-norm, or
    Euclidean), where below the value held, into ``values[b - b0]`` at the samples
    within ``margin`` of its box (samples to skip hold -inf). A triangle whose box
    lies farther than the value held is skipped (the Euclidean box a relative
    :data:`~implicitvox.linf.mesh_walk.EUCLIDEAN_SLACK` farther: its distance and
    the triangle's round differently).

    With ``steps`` (per sample, voxels to the nearest surface voxel; empty: none),
    a sample starts from the bound ``unit[0] * (steps + 1/2) + unit[1]`` instead
    of the value held, and is left at inf where no triangle came below it."""
    keep = 1.0 + EUCLIDEAN_SLACK
    cx, cy, cz = centres
    w0, w1, w2 = w[0], w[1], w[2]
    s0 = np.empty(BRICK)
    s1 = np.empty(BRICK)
    s2 = np.empty(BRICK)
    bounded = steps.shape[0] > 0
    for b in range(b0, b1):
        o0, o1, o2 = origins[b, 0], origins[b, 1], origins[b, 2]
        out = values[b - b0]
        if bounded:
            _start_bounds(out, steps[b], unit, 1.0)
        for j in range(start[b], start[b + 1]):
            t = triangles[j]
            r = rows[t]
            # the brick's samples within reach of the triangle's box, per axis, and
            # their gaps to it along the axis
            f0, l0 = _local_range(r[0], r[3], cx, o0, margin[0])
            if f0 > l0:
                continue
            f1, l1 = _local_range(r[1], r[4], cy, o1, margin[1])
            if f1 > l1:
                continue
            f2, l2 = _local_range(r[2], r[5], cz, o2, margin[2])
            if f2 > l2:
                continue
            for i in range(f0, l0 + 1):
                s0[i] = _side(r, 0, cx[o0 + i], w0, euclidean)
            for i in range(f1, l1 + 1):
                s1[i] = _side(r, 1, cy[o1 + i], w1, euclidean)
            for i in range(f2, l2 + 1):
                s2[i] = _side(r, 2, cz[o2 + i], w2, euclidean)
            for i0 in range(f0, l0 + 1):
                p0 = cx[o0 + i0]
                for i1 in range(f1, l1 + 1):
                    p1 = cy[o1 + i1]
                    g1 = s0[i0] + s1[i1] if euclidean else max(s0[i0], s1[i1])
                    for i2 in range(f2, l2 + 1):
                        best = out[i0, i1, i2]
                        if best <= 0.0:                 # nothing nearer, or not a sample
                            continue
                        if euclidean:
                            limit = best * keep
                            if g1 + s2[i2] > limit * limit:
                                continue
                            d = triangle_euclidean(p0, p1, cz[o2 + i2], tri[t])
                        else:
                            box = max(g1, s2[i2])       # box_gap's float
                            if box >= best:
                                continue
                            d = linf_below(p0, p1, cz[o2 + i2], w0, w1, w2, r, box, best)
                        if d < best:
                            out[i0, i1, i2] = d
        if bounded:
            _start_bounds(out, steps[b], unit, -1.0)


@njit(**COMPILE)
def _start_bounds(out, steps, unit, way):
    """``way`` 1: the samples to compute (``out > 0``) start from their bound; -1: those
    still at it (no triangle came below) go to inf."""
    for i in range(BRICK):
        for j in range(BRICK):
            for k in range(BRICK):
                if out[i, j, k] > 0.0:
                    bound = unit[0] * (steps[i, j, k] + 0.5) + unit[1]
                    if way > 0:
                        out[i, j, k] = bound
                    elif out[i, j, k] >= bound:
                        out[i, j, k] = np.inf


@njit(**COMPILE)
def _local_range(lo, hi, centres, o, margin):
    """:func:`centre_range` among the brick's samples ``o .. o + 7`` (offsets): the first
    and last whose centres lie within ``margin`` of ``[lo, hi]`` (a scan of at most
    eight; none when ``first > last``)."""
    n = min(BRICK, centres.size - o)
    below = lo - margin
    above = hi + margin
    first = 0
    while first < n and centres[o + first] < below:
        first += 1
    last = n - 1
    while last >= first and centres[o + last] > above:
        last -= 1
    return first, last
