"""Ear clipping of simple polygons (OpenSCAD polygons, extrusion caps).

Used by :mod:`csg.planar` (polygon regions) and :mod:`csg.facets` (the caps
of OpenSCAD's extruded meshes).

Examples
--------
>>> import numpy as np
>>> triangulate(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float))
[(3, 0, 1), (1, 2, 3)]
"""
from __future__ import annotations

import numpy as np

__all__ = ["triangulate", "MAX_POLYGON_POINTS"]

#: points per polygon at most: ear clipping here is quadratic in Python (4,000 points take
#: about 15 s); beyond, a C++ triangulator (mapbox-earcut) would be the way
MAX_POLYGON_POINTS = 4000


def triangulate(poly: np.ndarray) -> list[tuple[int, int, int]]:
    """Ear clipping of a simple polygon (counter-clockwise), vertex indices.

    Raises
    ------
    ValueError
        For a polygon that is not simple, or of more than :data:`MAX_POLYGON_POINTS`.
    """
    if len(poly) > MAX_POLYGON_POINTS:
        raise ValueError(f"a polygon of {len(poly):,} points is over the limit of "
                         f"{MAX_POLYGON_POINTS:,} (csg.triangulate.MAX_POLYGON_POINTS)")
    idx = list(range(len(poly)))
    out = []
    guard = 0
    while len(idx) > 3 and guard < 10 * len(poly) ** 2:
        guard += 1
        n = len(idx)
        for k in range(n):
            a, b, c = idx[k - 1], idx[k], idx[(k + 1) % n]
            pa, pb, pc = poly[a], poly[b], poly[c]
            cross = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0])
            if cross <= 0:
                continue
            others = [poly[i] for i in idx if i not in (a, b, c)]
            if any(_in_triangle(p, pa, pb, pc) for p in others):
                continue
            out.append((a, b, c))
            idx.pop(k)
            break
        else:
            raise ValueError("polygon is not simple (self-intersecting or degenerate)")
    if len(idx) == 3:
        out.append(tuple(idx))
    return out


def _in_triangle(p, a, b, c) -> bool:
    def side(u, v, w):
        return (v[0] - u[0]) * (w[1] - u[1]) - (v[1] - u[1]) * (w[0] - u[0])
    return side(a, b, p) >= 0 and side(b, c, p) >= 0 and side(c, a, p) >= 0
