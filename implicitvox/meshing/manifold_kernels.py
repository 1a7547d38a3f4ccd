"""Compiled loops of the vertex splitting (:mod:`.manifold`): the edges of a triangle
list, the incidences grouped by edge, and the groups of joined corners.

Examples
--------
>>> import numpy as np
>>> edges, inc, counts = edge_table(np.array([[0, 1, 2], [2, 1, 3]]))
>>> edges.tolist(), inc.tolist(), counts.tolist()
([[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]], [0, 2, 1, 2, 3, 4], [1, 1, 2, 1, 1])
>>> label, first = corner_groups(6, np.array([1, 2]), np.array([5, 3]))   # 1~5, 2~3
>>> label.tolist(), first.tolist()
([0, 1, 2, 2, 3, 1], [0, 1, 2, 4])
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE

__all__ = ["edge_table", "corner_joins", "by_edge", "corner_groups"]


@njit(**COMPILE)
def edge_table(faces):
    """The undirected edges of triangles ``faces`` (f, 3): ``(edges (e, 2), inc (3 f,),
    counts (e,))``, edges with sorted ends, ordered by their lower end, then as they
    first appear; ``inc[3 t + k]`` the edge from corner ``k`` to corner ``k + 1`` of
    triangle ``t``; ``counts`` the triangles at each edge. The incidences are
    bucketed by their lower end (a counting sort), and a bucket's few are matched
    by their upper end."""
    nf = faces.shape[0]
    n_vertices = 0
    for t in range(nf):
        for k in range(3):
            n_vertices = max(n_vertices, np.int64(faces[t, k]) + 1)
    low = np.empty(3 * nf, np.int64)
    high = np.empty(3 * nf, np.int64)
    offset = np.zeros(n_vertices + 1, np.int64)
    for t in range(nf):
        for k in range(3):
            a = np.int64(faces[t, k])
            b = np.int64(faces[t, (k + 1) % 3])
            i = 3 * t + k
            low[i], high[i] = min(a, b), max(a, b)
            offset[low[i] + 1] += 1
    for v in range(n_vertices):
        offset[v + 1] += offset[v]
    fill = offset[:-1].copy()
    bucket = np.empty(3 * nf, np.int64)
    for i in range(3 * nf):
        bucket[fill[low[i]]] = i
        fill[low[i]] += 1
    ends = np.empty((3 * nf, 2), np.int64)
    inc = np.empty(3 * nf, np.int64)
    counts = np.zeros(3 * nf, np.int64)
    m = 0
    for v in range(n_vertices):
        first_edge = m
        for p in range(offset[v], offset[v + 1]):
            i = bucket[p]
            j = first_edge
            while j < m and ends[j, 1] != high[i]:
                j += 1
            if j == m:
                ends[m, 0], ends[m, 1] = v, high[i]
                m += 1
            inc[i] = j
            counts[j] += 1
    return ends[:m].copy(), inc, counts[:m].copy()


@njit(**COMPILE)
def corner_joins(faces, i, j):
    """The corners two incidences on one edge join: incidence ``i`` runs from corner
    ``i`` to the next corner of its triangle, ``j`` the other way (or the same way,
    on a badly oriented pair); the corners at each end of the edge are joined
    (``(a, b)``, two pairs per pair of incidences)."""
    flat = faces.ravel()
    n = i.size
    a = np.empty(2 * n, np.int64)
    b = np.empty(2 * n, np.int64)
    for r in range(n):
        ci, cj = i[r], j[r]
        ei = 3 * (ci // 3) + (ci % 3 + 1) % 3               # the corner at i's end
        ej = 3 * (cj // 3) + (cj % 3 + 1) % 3
        a[r], a[n + r] = ci, ei
        b[r] = cj if flat[cj] == flat[ci] else ej
        b[n + r] = ej if flat[ej] == flat[ei] else cj
    return a, b


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
    ``scipy.sparse.csgraph.connected_components`` numbers them): each corner's
    component and each component's first corner."""
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
    first = np.empty(n, np.int64)
    count = 0
    for i in range(n):
        r = _root(parent, i)
        if number[r] < 0:
            number[r] = count
            first[count] = i
            count += 1
        label[i] = number[r]
    return label, first[:count].copy()
