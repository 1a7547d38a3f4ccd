"""Bézier patches and their flat pieces with a certified distance (Stolte §4.2).

Stolte voxelizes a patch by De Casteljau subdivision until each sub-patch's
control net fits in a voxel, then outputs the voxels its convex hull meets.
That needs many subdivisions (a sub-patch must shrink below a voxel
everywhere) and still outputs the voxels around each tiny hull. Our stop
condition is flatness instead of size:

* a sub-patch with control points ``C_ij`` (degree ``m x n``) differs from the
  bilinear patch of its corners by at most ``max_ij |C_ij - L_ij|`` per axis,
  where ``L_ij`` is that bilinear patch at ``(i/m, j/n)`` (Bernstein
  polynomials reproduce bilinear functions, and a patch is a convex
  combination of its control points);
* the bilinear patch differs from its two corner triangles ``(P00, P10, P11)``,
  ``(P00, P11, P01)`` by at most ``|P00 - P10 - P01 + P11| / 4`` per axis;
* the computed control points differ from the exact sub-patch's by at most
  ``E``, tracked through each halving step (``E += degree * u * max|C|``,
  ``u = 2**-53``; each De Casteljau average rounds once).

So the exact patch lies within ``D = deviation + twist / 4 + E`` (widened for
the rounding of these sums) of the two triangles. A sub-patch stops when
``D <= flatness * voxel_size`` on every axis; its triangles, each grown by
``D``, are voxelized exactly (:class:`~implicitvox.triangles.tribox.Triangles` with a
dilation; :func:`implicitvox.voxelize_bezier`). Every voxel the patch meets is output - a guarantee, not an
estimate - and large flat regions stop early as large triangles.

Examples
--------
>>> import numpy as np
>>> import implicitvox as iv
>>> u, v = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4), indexing="ij")
>>> saddle = iv.BezierPatch(np.stack([u, v, (u - 0.5) * (v - 0.5)], axis=-1))
>>> saddle.degree
(3, 3)
>>> np.allclose(saddle.evaluate(0.5, 0.5), [0.5, 0.5, 0.0])
True
>>> vox = iv.voxelize_bezier([saddle], resolution=16)
>>> vox.count > 256
True
"""
from __future__ import annotations

import os
from typing import Any, Iterable, Optional

import numpy as np

from ..interval.rounding import up_nonneg

__all__ = ["BezierPatch", "utah_teapot", "bezier_triangles"]

_U = 2.0 ** -53
#: subdivision levels at most (then the patch is covered with a wider dilation)
MAX_SPLITS = 24


class BezierPatch:
    """A tensor-product Bézier patch of degree ``m x n``.

    Parameters
    ----------
    control_points : array_like, (m + 1, n + 1, 3)
        The control net, ``m, n >= 1`` (a bicubic patch is 4 x 4 x 3).
    """

    def __init__(self, control_points: Any):
        try:
            c = np.array(control_points, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError("control_points must be an (m + 1, n + 1, 3) array of numbers") \
                from None
        if c.ndim != 3 or c.shape[2] != 3 or c.shape[0] < 2 or c.shape[1] < 2:
            raise ValueError("control_points must have shape (m + 1, n + 1, 3) with m, n >= 1, "
                             f"got {c.shape}")
        if not np.all(np.isfinite(c)):
            i, j, _ = np.argwhere(~np.isfinite(c))[0]
            raise ValueError(f"control_points[{i}, {j}] is {c[i, j].tolist()}: must be finite")
        c.setflags(write=False)
        self.control_points = c

    @property
    def degree(self) -> tuple[int, int]:
        return self.control_points.shape[0] - 1, self.control_points.shape[1] - 1

    @property
    def bounds(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The control net's box (it holds the patch)."""
        c = self.control_points.reshape(-1, 3)
        return tuple(c.min(0).tolist()), tuple(c.max(0).tolist())

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        """Points ``(..., 3)`` at parameters ``u, v`` in ``[0, 1]`` (broadcast)."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=np.float64),
                                   np.asarray(v, dtype=np.float64))
        m, n = self.degree
        bu = _bernstein(m, u.ravel())                                    # (N, m + 1)
        bv = _bernstein(n, v.ravel())                                    # (N, n + 1)
        rows = (bu @ self.control_points.reshape(m + 1, -1)).reshape(-1, n + 1, 3)
        return np.einsum("pj,pjk->pk", bv, rows).reshape(u.shape + (3,))

    def sample(self, n: int, rng: Optional[np.random.Generator] = None) -> np.ndarray:
        """``n`` points at uniformly random parameters."""
        rng = rng or np.random.default_rng()
        return self.evaluate(rng.random(n), rng.random(n))

    def __repr__(self) -> str:
        return f"BezierPatch(degree={self.degree})"


def _bernstein(m: int, t: np.ndarray) -> np.ndarray:
    from math import comb
    k = np.arange(m + 1)
    t = t[..., None]
    return np.array([comb(m, i) for i in k], dtype=np.float64) * t ** k * (1 - t) ** (m - k)


def _split(c: np.ndarray, e: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """De Casteljau at 1/2 along ``axis`` (1: u, 2: v) of nets ``c (k, m+1, n+1, 3)``.

    Returns both halves and their rounding-error bound."""
    c = np.moveaxis(c, axis, 1)
    deg = c.shape[1] - 1
    left = np.empty_like(c)
    right = np.empty_like(c)
    row = c
    left[:, 0] = row[:, 0]
    right[:, deg] = row[:, deg]
    for r in range(1, deg + 1):
        row = 0.5 * (row[:, :-1] + row[:, 1:])
        left[:, r] = row[:, 0]
        right[:, deg - r] = row[:, -1]
    big = np.abs(c).reshape(len(c), -1).max(axis=1)
    e_new = up_nonneg(e + up_nonneg(deg * _U * (big + e)), 2)
    return np.moveaxis(left, 1, axis), np.moveaxis(right, 1, axis), e_new


def _flatness(c: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Per-axis distance bound ``(k, 3)`` from the exact sub-patches to their two
    corner triangles (see the module docstring)."""
    m, n = c.shape[1] - 1, c.shape[2] - 1
    p00, p10, p01, p11 = c[:, 0, 0], c[:, m, 0], c[:, 0, n], c[:, m, n]
    s = (np.arange(m + 1) / m)[None, :, None, None]
    t = (np.arange(n + 1) / n)[None, None, :, None]
    bilinear = ((1 - s) * (1 - t) * p00[:, None, None] + s * (1 - t) * p10[:, None, None]
                + (1 - s) * t * p01[:, None, None] + s * t * p11[:, None, None])
    deviation = np.abs(c - bilinear).max(axis=(1, 2))
    twist = np.abs(p00 - p10 - p01 + p11) / 4
    big = np.abs(c).max(axis=(1, 2))
    # the float sums above are off by a few ulps of |c| each: 16 u |c| covers them
    return up_nonneg(deviation + twist + e[:, None] + 16 * _U * big, 2)


def bezier_triangles(patches: Iterable[BezierPatch], tolerance: Any,
                     max_splits: int = MAX_SPLITS) -> tuple[np.ndarray, np.ndarray]:
    """Triangles ``(t, 3, 3)`` and dilations ``(t, 3)`` that cover the patches.

    Each patch is split by De Casteljau until it lies within ``tolerance``
    (per axis) of its two corner triangles, or ``max_splits`` times; every
    point of every patch lies within the dilation of some triangle.
    """
    tol = np.asarray(tolerance, dtype=np.float64)
    groups: dict[tuple[int, int], list[np.ndarray]] = {}
    for p in patches:
        groups.setdefault(p.degree, []).append(p.control_points)
    tris, dils = [], []
    for nets in groups.values():
        c = np.stack(nets)
        e = np.zeros(len(c))
        for split in range(max_splits + 1):
            d = _flatness(c, e)
            done = np.all(d <= tol, axis=1) | (split == max_splits)
            if done.any():
                cd, dd = c[done], d[done]
                m, n = cd.shape[1] - 1, cd.shape[2] - 1
                p00, p10, p01, p11 = cd[:, 0, 0], cd[:, m, 0], cd[:, 0, n], cd[:, m, n]
                tris += [np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)]
                dils += [dd, dd]
            c, e = c[~done], e[~done]
            if not len(c):
                break
            # split in u and in v: four sub-patches
            a, b, e = _split(c, e, 1)
            c = np.concatenate([a, b])
            e = np.concatenate([e, e])
            a, b, e = _split(c, e, 2)
            c = np.concatenate([a, b])
            e = np.concatenate([e, e])
    if not tris:
        return np.zeros((0, 3, 3)), np.zeros((0, 3))
    return np.concatenate(tris), np.concatenate(dils)


def utah_teapot() -> list[BezierPatch]:
    """Martin Newell's Utah teapot (1975, public domain): 32 bicubic patches, z up.

    Examples
    --------
    >>> patches = utah_teapot()
    >>> len(patches), patches[0].degree
    (32, (3, 3))
    """
    path = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data", "utah_teapot.txt")
    rows = np.loadtxt(path, comments="#")
    return [BezierPatch(r.reshape(4, 4, 3)) for r in rows]
