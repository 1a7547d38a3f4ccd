"""The ray crossings of :class:`implicitvox.triangles.crossings.RayWinding`, compiled.

Per pair (a point ``q``, a triangle whose shadow on the ``yz`` plane has area),
the signed crossing of the ray ``q + t e_x`` (``t > 0``) with the triangle: the
three ``orient2d`` signs of ``(q_y, q_z)`` against the shadow's edges (a zero
settled by simulation of simplicity, as the array path settles it), then the
``orient3d`` sign of ``q`` against the triangle's plane - with the floating-point
filters of :mod:`implicitvox.triangles.tribox_kernels`. A pair whose answer needs
a sign the filters cannot certify is :data:`~implicitvox.triangles.tribox_kernels.UNSURE`,
for the exact array path; every other answer is the array path's.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from .tribox_kernels import UNSURE, det2_filtered, plane_filtered

__all__ = ["crossing_pairs"]


@njit(**COMPILE)
def _crossings(v, normal_sign, planes, tri, q, out):
    for k in range(tri.size):
        t = tri[k]
        sx = normal_sign[t, 0]
        y, z = q[k, 1], q[k, 2]
        answer = 0
        unsure = False
        inside = True
        for e in range(3):
            a1, a2 = v[t, e, 1], v[t, e, 2]
            b1, b2 = v[t, (e + 1) % 3, 1], v[t, (e + 1) % 3, 2]
            s = det2_filtered(a1, a2, b1, b2, a1, a2, y, z)
            if s == UNSURE:
                unsure = True
                continue
            if s == 0:              # q + (eps, eps^2) in (y, z)
                dz = b2 - a2
                if dz != 0.0:
                    s = -1 if dz > 0.0 else 1
                else:
                    dy = b1 - a1
                    s = 1 if dy > 0.0 else (-1 if dy < 0.0 else 0)
            if s != sx:
                inside = False
                break
        if inside:
            if unsure:
                answer = UNSURE
            else:
                ahead = plane_filtered(v, planes, t, q[k, 0], y, z)
                if ahead == UNSURE:
                    answer = UNSURE
                elif ahead == -sx:
                    answer = sx
        out[k] = answer


def crossing_pairs(triangles, tri: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Per pair, the signed crossing (``normal_sign[tri, 0]`` or 0) of the ray from
    point ``q[k]`` along ``+x`` with triangle ``tri[k]`` of ``triangles`` (a
    :class:`~implicitvox.triangles.tribox.Triangles`; its shadow has area), or
    :data:`~implicitvox.triangles.tribox_kernels.UNSURE` for the exact path.

    Returns
    -------
    ndarray of int8, (m,)
    """
    out = np.empty(len(tri), dtype=np.int8)
    if len(tri):
        _crossings(triangles.v, triangles.normal_sign, triangles.planes.rows,
                   np.ascontiguousarray(tri, dtype=np.int64),
                   np.ascontiguousarray(q, dtype=np.float64), out)
    return out
