"""A convex polytope's weighted max-norm distance in compiled code (Varadhan §3.1.2).

:meth:`implicitvox.linf.ConvexPolyhedron.distance`, one point at a time: inside,
``-min_f (d_f - n_f.p) / h_w(n_f)``; outside, the largest gap over the
candidate axes and their opposites. The operations are those of the array
path (:meth:`~implicitvox.linf.ConvexPolyhedron.distance_by_arrays`, the test
oracle), in its order (products summed left to right, as
:func:`implicitvox.linf.products.dot` does), so the results are the same
floats; a NaN (where a flat box's infinite weights meet) spreads as numpy's
``min`` and ``maximum`` spread it.

Examples
--------
>>> import numpy as np
>>> normals = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
>>> out = np.empty(1)
>>> convex_distances(np.array([[2.0, 0.5, 0.5]]), np.ones((1, 3)), normals, np.array(
...     [1.0, 0, 1, 0, 1, 0]), np.eye(3), np.zeros(3), np.full(3, -1.0), out)
>>> out.tolist()
[1.0]
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE

__all__ = ["convex_distances"]


@njit(**COMPILE)
def _least(a, b):
    """numpy's ``minimum``: NaN if either is."""
    if a != a or b != b:
        return np.nan
    return a if a <= b else b


@njit(**COMPILE)
def _most(a, b):
    """numpy's ``maximum``: NaN if either is."""
    if a != a or b != b:
        return np.nan
    return a if a >= b else b


@njit(**COMPILE)
def convex_distances(points, weights, normals, offsets, half_axes, low_plus, low_minus, out):
    """Signed weighted max-norm distances of ``points`` (n, 3) (weights (n, 3)) to the
    polytope ``normals . x <= offsets`` whose candidate axes are ``half_axes``
    (u, 3) with ``min_P u.x`` in ``low_plus`` and ``min_P -u.x`` in ``low_minus``,
    into ``out`` (n)."""
    for i in range(points.shape[0]):
        p0, p1, p2 = points[i, 0], points[i, 1], points[i, 2]
        w0, w1, w2 = weights[i, 0], weights[i, 1], weights[i, 2]
        inside = True
        for f in range(normals.shape[0]):
            slack = offsets[f] - ((p0 * normals[f, 0] + p1 * normals[f, 1])
                                  + p2 * normals[f, 2])
            if not slack >= 0:
                inside = False
                break
        if inside:
            depth = np.inf
            for f in range(normals.shape[0]):
                slack = offsets[f] - ((p0 * normals[f, 0] + p1 * normals[f, 1])
                                      + p2 * normals[f, 2])
                h = (w0 * abs(normals[f, 0]) + w1 * abs(normals[f, 1])) \
                    + w2 * abs(normals[f, 2])
                depth = _least(depth, slack / h)
            out[i] = -depth
            continue
        plus, minus = -np.inf, -np.inf
        for u in range(half_axes.shape[0]):
            a0, a1, a2 = half_axes[u, 0], half_axes[u, 1], half_axes[u, 2]
            h = (w0 * abs(a0) + w1 * abs(a1)) + w2 * abs(a2)
            q = (p0 * a0 + p1 * a1) + p2 * a2
            plus = _most(plus, (low_plus[u] - q) / h)
            minus = _most(minus, (low_minus[u] + q) / h)
        out[i] = _most(plus, minus)
