"""Generalized winding numbers of triangle meshes (Jacobson et al., SIGGRAPH 2013).

``w(p) = sum over triangles of the solid angle they subtend at p / (4 pi)``,
each solid angle by Van Oosterom and Strackee's formula
``tan(Omega / 2) = det[a b c] / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|)``
with ``a, b, c`` the vertices relative to ``p``. For a closed, consistently
oriented mesh ``w`` is the number of times the surface winds around ``p``
(1 inside, 0 outside); for a mesh with holes it varies smoothly and
``w > 1/2`` is the usual inside test.

Examples
--------
>>> import numpy as np
>>> import pyvista as pv
>>> from implicitvox.triangles.inputs import as_triangles
>>> v, f = as_triangles(pv.Cube())
>>> np.round(winding_numbers(np.array([[0.0, 0, 0], [2.0, 0, 0]]), v[f]), 6).tolist()
[1.0, 0.0]
"""
from __future__ import annotations

import numpy as np

__all__ = ["winding_numbers"]


def winding_numbers(points: np.ndarray, triangles: np.ndarray,
                    block: int = 1 << 22) -> np.ndarray:
    """Winding numbers ``(n,)`` of the triangles ``(t, 3, 3)`` at ``points (n, 3)``.

    Work is done in blocks of about ``block`` point-triangle pairs.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    tri = np.asarray(triangles, dtype=np.float64)
    out = np.zeros(len(points))
    if not len(tri):
        return out
    step = max(1, block // len(tri))
    for s in range(0, len(points), step):
        p = points[s:s + step, None, None, :]             # (k, 1, 1, 3)
        d = tri[None] - p                                 # (k, t, 3, 3)
        a, b, c = d[..., 0, :], d[..., 1, :], d[..., 2, :]
        la, lb, lc = (np.sqrt(np.einsum("...i,...i", u, u)) for u in (a, b, c))
        det = np.einsum("...i,...i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("...i,...i", a, b) * lc
               + np.einsum("...i,...i", b, c) * la + np.einsum("...i,...i", c, a) * lb)
        out[s:s + step] = np.arctan2(det, den).sum(axis=1) / (2 * np.pi)
    return out
