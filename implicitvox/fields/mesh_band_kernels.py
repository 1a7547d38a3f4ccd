"""Compiled loops of :mod:`implicitvox.fields.mesh_band`: bricks' triangle lists, the scatter.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from ..linf.mesh_walk import EUCLIDEAN_SLACK, triangle_euclidean
from ..linf.triangle_axes import box_side, linf_below
from .brick_kernels import BRICK, brick_row

__all__ = ["brick_triangles", "scatter_bricks"]

_BITS = 3


@njit(**COMPILE)
def _sample_range(lo, hi, origin, h, reach, slack, size):
    """The voxels whose centres lie within ``reach`` of ``[lo, hi]`` on one axis (a
    few millionths of a voxel more), clipped to ``0 .. size - 1``."""
    first = math.ceil((lo - reach - origin) / h - 0.5 - slack)
    last = math.floor((hi + reach - origin) / h - 0.5 + slack)
    return max(first, 0), min(last, size - 1)


@njit(**COMPILE)
def _each_pair(rows, keys, origin, h, shape, reach, slack, count, start, triangles):
    """Every (brick, triangle) pair: counted into ``count``, or, given ``start``,
    written to ``triangles`` (``start`` advanced as they go)."""
    lo = np.empty(3, dtype=np.int64)
    hi = np.empty(3, dtype=np.int64)
    for t in range(rows.shape[0]):
        empty = False
        for a in range(3):
            first, last = _sample_range(rows[t, a], rows[t, 3 + a], origin[a], h[a], reach[a],
                                        slack, shape[a])
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
def brick_triangles(rows, keys, origins, origin, h, shape, reach, slack):
    """:func:`implicitvox.fields.mesh_band.brick_triangles` (``origins``: each brick's
    first voxel index)."""
    n = keys.size
    count = np.zeros(n, dtype=np.int64)
    none = np.zeros(0, dtype=np.int64)
    _each_pair(rows, keys, origin, h, shape, reach, slack, count, none, none)
    start = np.zeros(n + 1, dtype=np.int64)
    start[1:] = np.cumsum(count)
    cursor = start[:-1].copy()
    triangles = np.empty(start[n], dtype=np.int64)
    _each_pair(rows, keys, origin, h, shape, reach, slack, none, cursor, triangles)
    for b in range(n):                     # nearest to the brick's centre first
        s, e = start[b], start[b + 1]
        gaps = np.empty(e - s)
        for j in range(s, e):
            t = triangles[j]
            gap = 0.0
            for a in range(3):
                c = origin[a] + (origins[b, a] + 0.5 * BRICK) * h[a]
                gap = max(gap, max(rows[t, a] - c, c - rows[t, 3 + a]) / h[a])
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
def scatter_bricks(b0, b1, start, triangles, rows, tri, origins, cx, cy, cz, w, reach,
                   euclidean, values):
    """Bricks ``b0`` to ``b1``: each listed triangle's exact distance (max-norm, or
    Euclidean), where below the value held, into ``values[b - b0]`` at the samples
    within ``reach`` of its box (samples to skip hold -inf). A triangle whose box
    lies farther than the value held is skipped (the Euclidean box a relative
    :data:`~implicitvox.linf.mesh_walk.EUCLIDEAN_SLACK` farther: its distance and
    the triangle's round differently)."""
    slack = 1e-6
    keep = 1.0 + EUCLIDEAN_SLACK
    w0, w1, w2 = w[0], w[1], w[2]
    sides = np.empty(BRICK)
    for b in range(b0, b1):
        o0, o1, o2 = origins[b, 0], origins[b, 1], origins[b, 2]
        out = values[b - b0]
        for j in range(start[b], start[b + 1]):
            t = triangles[j]
            r = rows[t]
            # the brick's samples within reach of the triangle's box, per axis
            f0, l0 = _local_range(r[0], r[3], cx, o0, reach[0], slack)
            f1, l1 = _local_range(r[1], r[4], cy, o1, reach[1], slack)
            f2, l2 = _local_range(r[2], r[5], cz, o2, reach[2], slack)
            for i2 in range(f2, l2 + 1):
                sides[i2] = _side(r, 2, cz[o2 + i2], w2, euclidean)
            for i0 in range(f0, l0 + 1):
                p0 = cx[o0 + i0]
                g0 = _side(r, 0, p0, w0, euclidean)
                for i1 in range(f1, l1 + 1):
                    p1 = cy[o1 + i1]
                    g1 = _side(r, 1, p1, w1, euclidean)
                    g1 = g0 + g1 if euclidean else max(g0, g1)
                    row = out[i0, i1]
                    for i2 in range(f2, l2 + 1):
                        best = row[i2]
                        if best <= 0.0:                 # nothing nearer, or not a sample
                            continue
                        if euclidean:
                            limit = best * keep
                            if g1 + sides[i2] > limit * limit:
                                continue
                            d = triangle_euclidean(p0, p1, cz[o2 + i2], tri[t])
                        else:
                            box = max(g1, sides[i2])    # box_gap's float
                            if box >= best:
                                continue
                            d = linf_below(p0, p1, cz[o2 + i2], w0, w1, w2, r, box, best)
                        if d < best:
                            row[i2] = d


@njit(**COMPILE)
def _local_range(lo, hi, centres, o, reach, slack):
    """The samples ``o .. o + 7`` (offsets) whose centres lie within ``reach`` of
    ``[lo, hi]``, from the centres themselves (a slack of ``slack`` voxels)."""
    size = centres.size
    h = centres[1] - centres[0] if size > 1 else 1.0
    margin = reach + slack * abs(h)
    first, last = BRICK, -1
    for i in range(BRICK):
        if o + i >= size:
            break
        c = centres[o + i]
        if c >= lo - margin and c <= hi + margin:
            first = min(first, i)
            last = i
    return first, last
