"""Compiled loops of dual contouring (:mod:`.contour`): sign-change edges, one row per
distinct edge, the leaves around an edge.

Cells and edges are in *fine units*: integer coordinates on the finest level of the
adaptive grid, where a leaf at level ``l`` is ``2**(depth - l)`` units wide. An edge
is ``(start, axis, length)``; the leaves that list it share its start point, axis
and length, so that triple names it whichever leaf found it.

Examples
--------
>>> import numpy as np
>>> corners = np.array([[-1.0, 1, 1, 1, 1, 1, 1, 1]])       # corner 0 inside only
>>> leaf, start, axis, length, low_inside = changed_edges(
...     corners, np.array([0], np.int8), np.zeros((1, 3), np.int64), 0)
>>> axis.tolist(), start.tolist(), bool(low_inside.all())
([0, 1, 2], [[0, 0, 0], [0, 0, 0], [0, 0, 0]], True)
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from ..octree.morton_kernels import encode_one

__all__ = ["changed_edges", "unique_edges", "edge_cells", "find_leaf", "find_leaves",
           "quad_triangles", "EDGE_START", "EDGE_END", "EDGE_AXIS"]

#: the 12 cell edges as start corner, end corner and axis, the start the lower end
#: (corner ``c`` at offset ``(c & 1, c >> 1 & 1, c >> 2 & 1)``)
EDGE_START = np.array([c for a in range(3) for c in range(8) if not (c >> a) & 1],
                      dtype=np.int64)
EDGE_AXIS = np.array([a for a in range(3) for c in range(8) if not (c >> a) & 1],
                     dtype=np.int64)
EDGE_END = EDGE_START | (1 << EDGE_AXIS)
for _table in (EDGE_START, EDGE_AXIS, EDGE_END):
    _table.flags.writeable = False
#: the four cells around an edge, counter-clockwise about its axis: the offsets
#: ``(du, dv)`` of a probe beside the edge's midpoint along the next two axes
QUADRANTS = np.array([(-1, -1), (0, -1), (0, 0), (-1, 0)], dtype=np.int64)
QUADRANTS.flags.writeable = False


@njit(**COMPILE)
def _changes(corners, i, e):
    return (corners[i, EDGE_START[e]] < 0) != (corners[i, EDGE_END[e]] < 0)


@njit(**COMPILE)
def changed_edges(corners, levels, coords, depth):
    """Every (leaf, edge) whose ends have opposite signs (``f < 0`` at one end), leaf
    by leaf: ``(leaf, start (r, 3), axis, length, low_inside)`` in fine units;
    ``low_inside``: ``f < 0`` at the edge's lower end."""
    n = corners.shape[0]
    count = 0
    for i in range(n):
        for e in range(12):
            if _changes(corners, i, e):
                count += 1
    leaf = np.empty(count, np.int64)
    start = np.empty((count, 3), np.int64)
    axis = np.empty(count, np.int64)
    length = np.empty(count, np.int64)
    low_inside = np.empty(count, np.bool_)
    r = 0
    for i in range(n):
        size = np.int64(1) << (depth - np.int64(levels[i]))
        for e in range(12):
            if not _changes(corners, i, e):
                continue
            c = EDGE_START[e]
            leaf[r] = i
            for a in range(3):
                start[r, a] = (coords[i, a] + ((c >> a) & 1)) * size
            axis[r] = EDGE_AXIS[e]
            length[r] = size
            low_inside[r] = corners[i, c] < 0
            r += 1
    return leaf, start, axis, length, low_inside


@njit(**COMPILE)
def _log2(length):
    """The exponent of a power of 2: the levels an edge of this length lies above the
    finest."""
    k = 0
    while (np.int64(1) << k) < length:
        k += 1
    return k


@njit(**COMPILE)
def _tag(axis, length):
    """Axis and length of an edge in one number."""
    return np.uint64(axis + 4 * _log2(length))


@njit(**COMPILE)
def unique_edges(start, axis, length):
    """One row per distinct edge: ``(first, inverse, code)``, ``first`` the rows
    where each edge first appears (in that order), ``inverse`` each row's edge and
    ``code`` the Morton code of each edge's start (open addressing on
    the code, the axis and the length)."""
    r = start.shape[0]
    size = 16
    while size < 2 * r:
        size *= 2
    mask = np.uint64(size - 1)
    slots = np.full(size, -1, np.int64)
    codes = np.empty(r, np.uint64)
    tags = np.empty(r, np.uint64)
    inverse = np.empty(r, np.int64)
    first = np.empty(r, np.int64)
    m = 0
    for i in range(r):
        code = encode_one(start[i, 0], start[i, 1], start[i, 2])
        tag = _tag(axis[i], length[i])
        codes[i] = code
        tags[i] = tag
        h = ((code ^ (tag << np.uint64(58))) * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(20)
        s = h & mask
        while True:
            j = slots[s]
            if j < 0:
                slots[s] = m
                first[m] = i
                inverse[i] = m
                m += 1
                break
            f = first[j]
            if codes[f] == code and tags[f] == tag:
                inverse[i] = j
                break
            s = (s + np.uint64(1)) & mask
    first = first[:m].copy()
    return first, inverse, codes[first]


@njit(**COMPILE)
def find_leaf(starts, ends, shape, i, j, k):
    """The position in ``starts`` (the leaves' first finest-level codes, sorted; a
    leaf covers ``[starts, ends)``) of the leaf holding finest cell ``(i, j, k)``, or
    -1 (outside the grid, or no leaf there)."""
    if i < 0 or j < 0 or k < 0 or i >= shape[0] or j >= shape[1] or k >= shape[2]:
        return -1
    code = encode_one(i, j, k)
    at = np.searchsorted(starts, code, side="right") - 1
    if at >= 0 and code < ends[at]:
        return at
    return -1


@njit(**COMPILE)
def find_leaves(starts, ends, shape, fine):
    """:func:`find_leaf` of each row of ``fine`` (n, 3)."""
    out = np.empty(fine.shape[0], np.int64)
    for r in range(fine.shape[0]):
        out[r] = find_leaf(starts, ends, shape, fine[r, 0], fine[r, 1], fine[r, 2])
    return out


@njit(**COMPILE)
def _split(starts, levels, depth, i, j, k, level):
    """Whether the cell at ``level`` holding finest cell ``(i, j, k)`` has leaves below
    it (it was split): a leaf deeper than ``level`` starts in its run of codes."""
    shift = np.uint64(3 * (depth - level))
    code = encode_one(max(i, 0), max(j, 0), max(k, 0))
    low = (code >> shift) << shift
    lo = np.searchsorted(starts, low, side="left")
    hi = np.searchsorted(starts, low + (np.uint64(1) << shift), side="left")
    if hi - lo >= 2:
        return True
    return hi - lo == 1 and levels[lo] > level


@njit(**COMPILE)
def edge_cells(start, axis, length, starts, ends, index, levels, shape, depth):
    """The leaves around each edge (``(m, 4)``, counter-clockwise about its axis, -1
    where none), whether the edge is *minimal* (all four found, none finer than the
    edge's own cells) and whether it is *unmatched* (a cell missing, not because a
    finer neighbour split it: the grid's boundary).

    The four probes are the finest cells beside the edge's midpoint, one per
    quadrant; ``starts, ends, index, levels`` describe the leaves sorted by their first
    finest-level code (:class:`implicitvox.meshing.contour.Locator`)."""
    m = start.shape[0]
    around = np.full((m, 4), -1, np.int64)
    minimal = np.zeros(m, np.bool_)
    unmatched = np.zeros(m, np.bool_)
    probe = np.empty((4, 3), np.int64)
    for e in range(m):
        a = axis[e]
        u = (a + 1) % 3
        v = (a + 2) % 3
        size = length[e]
        level = depth - _log2(size)
        complete = True
        within = True
        for q in range(4):
            for d in range(3):
                probe[q, d] = start[e, d]
            probe[q, a] += size // 2
            probe[q, u] += QUADRANTS[q, 0]
            probe[q, v] += QUADRANTS[q, 1]
            at = find_leaf(starts, ends, shape, probe[q, 0], probe[q, 1], probe[q, 2])
            if at < 0:
                complete = False
            else:
                around[e, q] = index[at]
                if levels[at] > level:
                    within = False
        if not within:
            continue
        if complete:
            minimal[e] = True
            continue
        unmatched[e] = True
        for q in range(4):
            if around[e, q] < 0 and _split(starts, levels, depth, probe[q, 0], probe[q, 1],
                                           probe[q, 2], level):
                unmatched[e] = False
    return around, minimal, unmatched


@njit(**COMPILE)
def _length2(vertex, a, b):
    d0 = vertex[a, 0] - vertex[b, 0]
    d1 = vertex[a, 1] - vertex[b, 1]
    d2 = vertex[a, 2] - vertex[b, 2]
    return d0 * d0 + d1 * d1 + d2 * d2


@njit(**COMPILE)
def quad_triangles(quads, vertex):
    """Quads (cyclic cell indices, ``(q, 4)``) to triangles: each split along its
    shorter diagonal (the first triangles of all quads, then their second ones), a
    quad with one cell twice (a coarse cell beside two finer ones) one triangle
    (after those), a quad with fewer than three cells none."""
    q = quads.shape[0]
    full = 0
    single = 0
    for i in range(q):
        repeats = 0
        for k in range(4):
            repeats += quads[i, k] == quads[i, (k + 1) % 4]
        if repeats == 0:
            full += 1
        elif repeats == 1:
            single += 1
    out = np.empty((2 * full + single, 3), np.int64)
    f = 0
    t = 2 * full
    for i in range(q):
        a, b, c, d = quads[i, 0], quads[i, 1], quads[i, 2], quads[i, 3]
        repeats = (a == b) + (b == c) + (c == d) + (d == a)
        if repeats == 0:
            if math.sqrt(_length2(vertex, a, c)) <= math.sqrt(_length2(vertex, b, d)):
                out[f, 0], out[f, 1], out[f, 2] = a, b, c
                out[full + f, 0], out[full + f, 1], out[full + f, 2] = a, c, d
            else:
                out[f, 0], out[f, 1], out[f, 2] = b, c, d
                out[full + f, 0], out[full + f, 1], out[full + f, 2] = b, d, a
            f += 1
        elif repeats == 1:
            k = 0
            for j in range(4):
                if quads[i, j] != quads[i, (j + 1) % 4]:
                    out[t, k] = quads[i, j]
                    k += 1
            t += 1
    return out
