"""Compiled loops of the vertex splitting (:mod:`.manifold`): the edges of a triangle
list, the incidences grouped by edge, and the groups of joined corners.

Examples
--------
>>> import numpy as np
>>> edges, inc, counts = edge_table(np.array([[0, 1, 2], [2, 1, 3]]))
>>> edges.tolist(), inc.tolist(), counts.tolist()
([[0, 1], [1, 2], [0, 2], [1, 3], [2, 3]], [0, 1, 2, 1, 3, 4], [1, 2, 1, 1, 1])
>>> corner_groups(6, np.array([1, 2]), np.array([5, 3])).tolist()   # 1~5, 2~3
[0, 1, 2, 2, 3, 1]
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE

__all__ = ["edge_table", "by_edge", "corner_groups"]


@njit(**COMPILE)
def edge_table(faces):
    """The undirected edges of triangles ``faces`` (f, 3): ``(edges (e, 2), inc (3 f,),
    counts (e,))``, edges with sorted ends in the order they first appear; ``inc[3 t +
    k]`` the edge from corner ``k`` to corner ``k + 1`` of triangle ``t``; ``counts``
    the triangles at each edge (open addressing on the ends)."""
    nf = faces.shape[0]
    size = 16
    while size < 6 * nf:
        size *= 2
    mask = np.uint64(size - 1)
    slots = np.full(size, -1, np.int64)
    ends = np.empty((3 * nf, 2), np.int64)
    inc = np.empty(3 * nf, np.int64)
    counts = np.zeros(3 * nf, np.int64)
    m = 0
    for t in range(nf):
        for k in range(3):
            a = np.int64(faces[t, k])
            b = np.int64(faces[t, (k + 1) % 3])
            if b < a:
                a, b = b, a
            h = (np.uint64(a) * np.uint64(0x9E3779B97F4A7C15)
                 ^ np.uint64(b) * np.uint64(0xC2B2AE3D27D4EB4F)) >> np.uint64(17)
            s = h & mask
            while True:
                j = slots[s]
                if j < 0:
                    slots[s] = m
                    ends[m, 0] = a
                    ends[m, 1] = b
                    j = m
                    m += 1
                    break
                if ends[j, 0] == a and ends[j, 1] == b:
                    break
                s = (s + np.uint64(1)) & mask
            inc[3 * t + k] = j
            counts[j] += 1
    return ends[:m].copy(), inc, counts[:m].copy()


@njit(**COMPILE)
def by_edge(inc, counts):
    """The incidences grouped by edge, in order within each (a counting sort):
    ``(order, first)``, edge ``e``'s incidences ``order[first[e]:first[e] + counts[e]]``."""
    first = np.empty(counts.size, np.int64)
    total = 0
    for e in range(counts.size):
        first[e] = total
        total += counts[e]
    fill = first.copy()
    order = np.empty(inc.size, np.int64)
    for i in range(inc.size):
        e = inc[i]
        order[fill[e]] = i
        fill[e] += 1
    return order, first


@njit(**COMPILE)
def _root(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@njit(**COMPILE)
def corner_groups(n, a, b):
    """The connected components of ``n`` corners joined by pairs ``a[i] ~ b[i]``
    (union-find), numbered in the order of each component's first corner (as
    ``scipy.sparse.csgraph.connected_components`` numbers them)."""
    parent = np.arange(n)
    for i in range(a.size):
        ra = _root(parent, a[i])
        rb = _root(parent, b[i])
        if ra != rb:
            if ra < rb:
                parent[rb] = ra
            else:
                parent[ra] = rb
    label = np.empty(n, np.int64)
    number = np.full(n, -1, np.int64)
    count = 0
    for i in range(n):
        r = _root(parent, i)
        if number[r] < 0:
            number[r] = count
            count += 1
        label[i] = number[r]
    return label
