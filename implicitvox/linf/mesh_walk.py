"""Nearest triangles in compiled code: Varadhan §4.1's culled hierarchy walk, one point at a time.

:class:`~implicitvox.linf.triangle_mesh.TriangleMesh` keeps a bounding volume
hierarchy (triangles in Morton order, leaves of a few, each level's boxes the
union of two of the level below). For each query point :func:`nearest_distances`
walks it depth first from the root, the nearer child first, and drops a node
whose box lies farther than the least distance found so far: the box's
distance is a lower bound for every triangle under it, and the distances found
are upper bounds of the answer (Varadhan §4.1's culling by lower and upper
bounds, the upper bound tightened as the walk goes). At a leaf, the exact
distance to each triangle. The walk starts from the previous point's nearest
triangle, whose distance is the first upper bound: neighbouring samples have
nearly the same nearest features (§4.2), so the points of a brick, given in
order, each walk little more than their own neighbourhood.

The nearest triangle is never culled (each box holding it lies no farther
than it), so the answer is the minimum of the exact distances over the
triangles kept, each computed from the triangle's row of projected axes
(:mod:`implicitvox.linf.triangle_axes`: the 13 separating axes of
:func:`implicitvox.linf.polyhedron.triangle_distance`, operation for
operation, so the same float) or :func:`triangle_euclidean` (the closest point
of :func:`implicitvox.linf.euclidean.triangle_distance`, Ericson's regions).
In the max norm a box's distance never exceeds the distance of a triangle in
it, in floats too (both are ``max(lo - p, p - hi) / w`` over ends ordered the
same way, and rounding is monotone); the Euclidean walk keeps a box within a
few ulps over the best, which the two formulas' roundings cannot cross.

Examples
--------
>>> import numpy as np
>>> tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
>>> float(triangle_linf(0.25, 0.25, 2.0, 1.0, 1.0, 1.0, tri[0]))
2.0
>>> float(triangle_euclidean(0.25, 0.25, 2.0, tri[0]))
2.0
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from .triangle_axes import ROW, axis_rows, box_gap, fill_row, linf_below

__all__ = ["triangle_linf", "triangle_euclidean", "nearest_distances", "warm_up",
           "EUCLIDEAN_SLACK",
           "GROUP", "MAX_CANDIDATES"]

#: the Euclidean walk keeps a box up to this relative amount farther than the best
#: distance (its box and triangle distances round differently)
EUCLIDEAN_SLACK = 1e-12
#: consecutive points that share their candidate triangles (the samples of a brick)
GROUP = 32
#: candidates a group may have; a group with more walks point by point
MAX_CANDIDATES = 4096


@njit(**COMPILE)
def _linf(p, w, r, bound):
    """The weighted max-norm distance from ``p`` to the triangle of row ``r`` where it
    is below ``bound`` (:func:`implicitvox.linf.triangle_axes.linf_below`)."""
    box = box_gap(p[0], p[1], p[2], w[0], w[1], w[2], r)
    return linf_below(p[0], p[1], p[2], w[0], w[1], w[2], r, box, bound)


@njit(**COMPILE)
def triangle_linf(px, py, pz, wx, wy, wz, t):
    """Weighted max-norm distance from ``(px, py, pz)`` to triangle ``t`` (3, 3):
    :func:`implicitvox.linf.polyhedron.triangle_distance` for one point."""
    r = np.empty(ROW)
    fill_row(t, r)
    return _linf(np.array([px, py, pz]), np.array([wx, wy, wz]), r, np.inf)


@njit(**COMPILE)
def _segment(p0, p1, p2, a, b):
    """Euclidean distance from ``(p0, p1, p2)`` to the segment ``a b`` (rows of ``t``)."""
    d0, d1, d2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    dd = d0 * d0 + d1 * d1 + d2 * d2
    s = ((p0 - a[0]) * d0 + (p1 - a[1]) * d1 + (p2 - a[2]) * d2) / dd if dd > 0 else 0.0
    s = min(max(s, 0.0), 1.0)
    x0 = p0 - (a[0] + s * d0)
    x1 = p1 - (a[1] + s * d1)
    x2 = p2 - (a[2] + s * d2)
    return math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)


@njit(**COMPILE)
def triangle_euclidean(p0, p1, p2, t):
    """Euclidean distance from ``(p0, p1, p2)`` to triangle ``t`` (3, 3), by the
    closest point's region (Ericson, *Real-Time Collision Detection*, §5.1.5)."""
    a, b, c = t[0], t[1], t[2]
    ab0, ab1, ab2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    ac0, ac1, ac2 = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    ap0, ap1, ap2 = p0 - a[0], p1 - a[1], p2 - a[2]
    bp0, bp1, bp2 = p0 - b[0], p1 - b[1], p2 - b[2]
    cp0, cp1, cp2 = p0 - c[0], p1 - c[1], p2 - c[2]
    d1 = ab0 * ap0 + ab1 * ap1 + ab2 * ap2
    d2 = ac0 * ap0 + ac1 * ap1 + ac2 * ap2
    d3 = ab0 * bp0 + ab1 * bp1 + ab2 * bp2
    d4 = ac0 * bp0 + ac1 * bp1 + ac2 * bp2
    d5 = ab0 * cp0 + ab1 * cp1 + ab2 * cp2
    d6 = ac0 * cp0 + ac1 * cp1 + ac2 * cp2
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    best = min(min(_segment(p0, p1, p2, a, b), _segment(p0, p1, p2, b, c)),
               _segment(p0, p1, p2, c, a))
    denom = va + vb + vc
    if va >= 0 and vb >= 0 and vc >= 0 and denom > 0:
        v, u = vb / denom, vc / denom
        x0 = (a[0] + ab0 * v + ac0 * u) - p0
        x1 = (a[1] + ab1 * v + ac1 * u) - p1
        x2 = (a[2] + ab2 * v + ac2 * u) - p2
        best = min(math.sqrt(x0 * x0 + x1 * x1 + x2 * x2), best)
    return best


@njit(**COMPILE)
def _triangle_euclidean(p, t):
    return triangle_euclidean(p[0], p[1], p[2], t)


@njit(**COMPILE)
def _box_gap(lo, hi, node, p, w, euclidean):
    """How far box ``node`` lies from ``p``: weighted max norm, or Euclidean."""
    if euclidean:
        total = 0.0
        for a in range(3):
            g = max(max(lo[node, a] - p[a], p[a] - hi[node, a]), 0.0)
            total += g * g
        return math.sqrt(total)
    gap = 0.0
    for a in range(3):
        gap = max(gap, max(max(lo[node, a] - p[a], p[a] - hi[node, a]), 0.0) / w[a])
    return gap


@njit(**COMPILE)
def _walk(p, w, best, last, box_lo, box_hi, first, sizes, tri, axes, order, leaf, euclidean,
          slack,
 stack_level, stack_node, stack_gap):
    """The culled walk for one point from the upper bound ``best`` (the distance to
    triangle ``last``, or inf and -1): ``(distance, nearest triangle, exact
    distances computed)``."""
    depth = sizes.size
    exact = 0
    stack_level[0], stack_node[0], stack_gap[0] = 0, 0, 0.0
    top = 1
    while top > 0:
        top -= 1
        level, node, gap = stack_level[top], stack_node[top], stack_gap[top]
        if gap > best * slack:
            continue
        if level == depth - 1:                          # a leaf: its triangles
            for j in range(leaf * node, min(leaf * (node + 1), order.size)):
                k = order[j]
                d = _triangle_euclidean(p, tri[k]) if euclidean else _linf(p, w, axes[k], best)
                exact += 1
                if d < best:
                    best, last = d, k
            continue
        below = level + 1
        near, far = 2 * node, 2 * node + 1
        g_near = _box_gap(box_lo, box_hi, first[below] + near, p, w, euclidean)
        g_far = np.inf if far >= sizes[below] else \
            _box_gap(box_lo, box_hi, first[below] + far, p, w, euclidean)
        if g_far < g_near:
            near, far, g_near, g_far = far, near, g_far, g_near
        if g_far <= best * slack:
            stack_level[top], stack_node[top], stack_gap[top] = below, far, g_far
            top += 1
        if g_near <= best * slack:
            stack_level[top], stack_node[top], stack_gap[top] = below, near, g_near
            top += 1
    return best, last, exact


@njit(**COMPILE)
def _gap_boxes(lo, hi, node, glo, ghi, w, euclidean):
    """How far box ``node`` lies from the box ``glo, ghi`` (weights ``w``)."""
    total = 0.0
    for a in range(3):
        g = max(max(lo[node, a] - ghi[a], glo[a] - hi[node, a]), 0.0)
        if euclidean:
            total += g * g
        else:
            total = max(total, g / w[a])
    return math.sqrt(total) if euclidean else total


@njit(**COMPILE)
def _candidates(glo, ghi, w, reach, box_lo, box_hi, first, sizes, order, leaf, euclidean,
                stack_level, stack_node, found):
    """The triangles under the boxes within ``reach`` of the box ``glo, ghi`` into
    ``found``; their number, or -1 past its room."""
    depth = sizes.size
    count = 0
    stack_level[0], stack_node[0] = 0, 0
    top = 1
    while top > 0:
        top -= 1
        level, node = stack_level[top], stack_node[top]
        if _gap_boxes(box_lo, box_hi, first[level] + node, glo, ghi, w, euclidean) > reach:
            continue
        if level == depth - 1:
            for j in range(leaf * node, min(leaf * (node + 1), order.size)):
                if count == found.size:
                    return -1
                found[count] = order[j]
                count += 1
            continue
        for child in (2 * node + 1, 2 * node):
            if child < sizes[level + 1]:
                stack_level[top], stack_node[top] = level + 1, child
                top += 1
    return count


@njit(**COMPILE)
def nearest_distances(points, weights, box_lo, box_hi, first, sizes, tri, axes, order, leaf,
                      euclidean, out):
    """The distance from each of ``points`` (n, 3) to the nearest of the triangles
    ``tri`` (m, 3, 3) into ``out`` (n): weighted max norm (``weights`` (n, 3); the
    triangles' ``axes``, :func:`implicitvox.linf.triangle_axes.axis_rows`), or
    Euclidean. The hierarchy: level ``d``'s boxes are rows ``first[d]`` to
    ``first[d] + sizes[d]`` of ``box_lo, box_hi`` (the root level first), node
    ``i``'s children are ``2i, 2i + 1`` of the next level, and leaf ``i`` holds
    triangles ``order[leaf * i:leaf * (i + 1)]``. Returns the exact
    point-triangle distances computed (the work).

    The points go in groups of :data:`GROUP` consecutive ones (Varadhan §4.2:
    the samples of a brick share their candidates). The group's first point
    walks the hierarchy; its nearest triangle's distance to each point of the
    group bounds that point's answer, and the largest of them, ``reach``, bounds
    them all; the triangles under the boxes within ``reach`` of the group's box
    are the candidates of every point of the group (its nearest triangle lies
    within its answer of it, so within ``reach`` of the box), each tested by
    its own box first. A group whose candidates overflow :data:`MAX_CANDIDATES`
    (its points far apart) walks point by point."""
    n = points.shape[0]
    depth = sizes.size
    stack_level = np.empty(2 * depth + 2, dtype=np.int64)
    stack_node = np.empty(2 * depth + 2, dtype=np.int64)
    stack_gap = np.empty(2 * depth + 2)
    found = np.empty(MAX_CANDIDATES, dtype=np.int64)
    clo, chi = np.empty((3, MAX_CANDIDATES)), np.empty((3, MAX_CANDIDATES))
    gaps = np.empty(MAX_CANDIDATES)
    glo, ghi, gw = np.empty(3), np.empty(3), np.empty(3)
    slack = 1.0 + EUCLIDEAN_SLACK if euclidean else 1.0
    exact = 0
    seed = -1
    for g in range(0, n, GROUP):
        e = min(g + GROUP, n)
        best = np.inf
        if seed >= 0:          # the last group's nearest triangle: an upper bound to start from
            best = _triangle_euclidean(points[g], tri[seed]) if euclidean else \
                _linf(points[g], weights[g], axes[seed], np.inf)
            exact += 1
        best, seed, done = _walk(points[g], weights[g], best, seed, box_lo, box_hi, first,
                                 sizes, tri, axes, order, leaf, euclidean, slack, stack_level,
                                 stack_node, stack_gap)
        exact += done
        out[g] = best
        if e == g + 1:
            continue
        reach = 0.0
        for a in range(3):
            glo[a], ghi[a], gw[a] = np.inf, -np.inf, 0.0
        for i in range(g + 1, e):
            p, w = points[i], weights[i]
            d = _triangle_euclidean(p, tri[seed]) if euclidean else \
                _linf(p, w, axes[seed], np.inf)
            out[i] = d                                   # an upper bound, to be lowered
            reach = max(reach, d)
            for a in range(3):
                glo[a] = min(glo[a], p[a])
                ghi[a] = max(ghi[a], p[a])
                gw[a] = max(gw[a], w[a])
        exact += e - g - 1
        count = _candidates(glo, ghi, gw, reach * slack, box_lo, box_hi, first, sizes, order,
                            leaf, euclidean, stack_level, stack_node, found)
        if count < 0:                                    # spread out: point by point
            for i in range(g + 1, e):
                best, _, done = _walk(points[i], weights[i], out[i], seed, box_lo, box_hi,
                                      first, sizes, tri, axes, order, leaf, euclidean, slack,
                                      stack_level, stack_node, stack_gap)
                out[i] = best
                exact += done
            continue
        for c in range(count):         # the candidates' boxes, side by side
            k = found[c]
            for a in range(3):
                clo[a, c] = min(min(tri[k, 0, a], tri[k, 1, a]), tri[k, 2, a])
                chi[a, c] = max(max(tri[k, 0, a], tri[k, 1, a]), tri[k, 2, a])
        for i in range(g + 1, e):
            p, w = points[i], weights[i]
            # every candidate's box distance first (a loop the compiler vectorizes), then
            # the exact distance of the nearest box, then of each box still near enough
            nearest, least = 0, np.inf
            for c in range(count):
                if euclidean:
                    total = 0.0
                    for a in range(3):
                        v = max(max(clo[a, c] - p[a], p[a] - chi[a, c]), 0.0)
                        total += v * v
                    gaps[c] = total               # squared
                else:
                    v = 0.0
                    for a in range(3):
                        v = max(v, max(max(clo[a, c] - p[a], p[a] - chi[a, c]), 0.0) / w[a])
                    gaps[c] = v
            for c in range(count):
                if gaps[c] < least:
                    nearest, least = c, gaps[c]
            best = out[i]
            if euclidean:
                limit = best * slack
                limit = limit * limit
            else:
                limit = best
            for r in range(count + 1):
                c = nearest if r == 0 else r - 1
                if (r > 0 and c == nearest) or gaps[c] > limit:
                    continue
                k = found[c]
                if euclidean:
                    d = _triangle_euclidean(p, tri[k])
                else:
                    d = _linf(p, w, axes[k], best)
                exact += 1
                if d < best:
                    best = d
                    limit = best * slack * best * slack if euclidean else best
            out[i] = best
    return exact


def warm_up() -> None:
    """Compile the walk for both norms, or load it from Numba's on-disk cache (the
    test suite calls it before its workers start)."""
    tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]] * 2)
    points = np.zeros((3, 3))
    for euclidean in (False, True):
        nearest_distances(points, np.ones((3, 3)), tri[:, 0].copy(), tri[:, 1].copy(),
                          np.zeros(1, dtype=np.int64), np.ones(1, dtype=np.int64), tri,
                          axis_rows(tri), np.arange(2, dtype=np.int64), 2, euclidean,
                          np.empty(3))
