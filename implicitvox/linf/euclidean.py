"""Euclidean distances of the same primitives, for distance fields (Bærentzen §2, eq. 2).

The max-norm distances of this package answer the exact voxel test; a
distance field in the ordinary norm needs the Euclidean ones (the primitives'
``euclidean_distance`` methods: sphere, half-space, convex polyhedron, cylinder
and cone, ring torus, ellipsoid, triangle mesh). These are the kernels they share: closest points
on triangles (vectorized, Ericson's region tests) and on segments of a
meridian half-plane (solids of revolution: cylinders, cones, tori).

Examples
--------
>>> import numpy as np
>>> tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
>>> triangle_distance(np.array([[0.25, 0.25, 2.0]]), tri).tolist()
[2.0]
>>> segment_distance(np.array([[0.0, 1.0]]), np.array([[1.0, 0.0]]), np.array([[1.0, 2.0]])).tolist()
[1.0]
"""
from __future__ import annotations

import numpy as np

from .products import dot

__all__ = ["triangle_distance", "segment_distance", "meridian"]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def triangle_distance(points: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Euclidean distance from ``points[k]`` (n, 3) to triangle ``tri[k]`` (n, 3, 3).

    The closest point is found by the Voronoi regions of the vertices, edges
    and face (Ericson, *Real-Time Collision Detection*, §5.1.5), all lanes at
    once; a degenerate triangle gets the distance to its nearest edge."""
    p = np.asarray(points, dtype=np.float64)
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp = p - b
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    cp = p - c
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(invalid="ignore", divide="ignore"):
        denom = va + vb + vc
        v = vb / denom
        w = vc / denom
        face = a + ab * v[:, None] + ac * w[:, None]
    # the edges, each clamped: the nearest of the three covers every edge and vertex region
    best = np.minimum(np.minimum(_segment3(p, a, b), _segment3(p, b, c)), _segment3(p, c, a))
    inside = (va >= 0) & (vb >= 0) & (vc >= 0) & (denom > 0)
    to_face = np.linalg.norm(np.where(inside[:, None], face, p) - p, axis=1)
    return np.where(inside, np.minimum(to_face, best), best)


def _segment3(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    dd = _dot(d, d)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.where(dd > 0, _dot(p - a, d) / dd, 0.0), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


def segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distance from ``p[k]`` to segment ``a[k] b[k]`` in any dimension."""
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.where(dd > 0, np.einsum("ij,ij->i", p - a, d) / dd, 0.0), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)


def meridian(points: np.ndarray, centre: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """``(rho, s)`` (n, 2) of points about an axis through ``centre`` along the unit
    ``axis``: the distance from the axis and the height along it. A solid of
    revolution's nearest surface point lies in the point's meridian half-plane."""
    q = np.asarray(points, dtype=np.float64) - centre
    s = dot(q, axis)
    rho = np.linalg.norm(q - s[:, None] * axis, axis=1)
    return np.stack([rho, s], axis=1)
