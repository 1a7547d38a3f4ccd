"""Exact signs of the box tests' determinants in floating-point expansions, compiled.

The compiled filters of :mod:`implicitvox.triangles.tribox_kernels` certify a
determinant's sign when it clears Shewchuk's error bound. At an exact tie - a
box corner on a triangle's plane or edge line, common when the model's
coordinates and the grid's are round numbers - the float value is 0 and no
bound clears it. There the sign is computed exactly, as Shewchuk's adaptive
predicates do (J. R. Shewchuk, *Adaptive Precision Floating-Point Arithmetic
and Fast Robust Geometric Predicates*, 1997): each difference of coordinates
must be exact (its ``Two-Sum`` error 0, as it is on a lattice), each product
of differences is split into exact parts (``Two-Product`` by Veltkamp's
splitting, no fused multiply-add), the parts are summed into a nonoverlapping
expansion (``Grow-Expansion``), and the sign of the expansion is the sign of
its largest part. Where a difference is not exact, or a factor lies outside
``[2**-200, 2**200]`` (so that no product, nor its rounding error, can underflow
or overflow), the
answer is :data:`UNSURE` and the caller goes to its exact integer path.

Examples
--------
>>> det2_exact(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.1, 0.1)   # 0.1 is on the line y = x
0
>>> det2_exact(0.0, 0.0, 3.0, 1.0, 0.0, 0.0, 0.3, 0.1)   # 0.3 is not 3 * 0.1
1
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE

__all__ = ["UNSURE", "det2_exact", "orient3d_exact", "SAFE_LOW", "SAFE_HIGH"]

#: a sign the floating-point stages could not give (the caller's exact path decides)
UNSURE = 2
#: factors within [SAFE_LOW, SAFE_HIGH] (or zero) multiply, three at a time, exactly
SAFE_LOW = 2.0 ** -200
SAFE_HIGH = 2.0 ** 200
_SPLITTER = 134217729.0          # 2**27 + 1: Veltkamp's split of a 53-bit significand
#: parts of the largest expansion here (six triple products, four parts each)
_PARTS = 32


@njit(inline="always", **COMPILE)
def _two_sum(a, b):
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@njit(inline="always", **COMPILE)
def _split(a):
    c = _SPLITTER * a
    high = c - (c - a)
    return high, a - high


@njit(inline="always", **COMPILE)
def _two_product(a, b):
    x = a * b
    ahi, alo = _split(a)
    bhi, blo = _split(b)
    return x, alo * blo - (((x - ahi * bhi) - alo * bhi) - ahi * blo)


@njit(inline="always", **COMPILE)
def _exact_difference(a, b):
    """``a - b`` if it is exact and a safe factor (or zero), else NaN."""
    d, err = _two_sum(a, -b)
    if err != 0.0:
        return np.nan
    m = abs(d)
    if d != 0.0 and not (SAFE_LOW <= m <= SAFE_HIGH):
        return np.nan
    return d


@njit(inline="always", **COMPILE)
def _grow(e, n, b):
    """Add ``b`` to the expansion ``e[:n]`` (Shewchuk's Grow-Expansion); its new length."""
    q = b
    for i in range(n):
        q, h = _two_sum(q, e[i])
        e[i] = h
    e[n] = q
    return n + 1


@njit(inline="always", **COMPILE)
def _sign(e, n):
    for i in range(n - 1, -1, -1):
        if e[i] != 0.0:
            return 1 if e[i] > 0.0 else -1
    return 0


@njit(inline="always", **COMPILE)
def _add_product(e, n, p, q, negate):
    """Add ``+-p * q`` (two parts) to the expansion."""
    h, l = _two_product(p, q)
    if negate:
        h, l = -h, -l
    n = _grow(e, n, l)
    return _grow(e, n, h)


@njit(inline="always", **COMPILE)
def _add_triple(e, n, p, q, r, negate):
    """Add ``+-p * q * r`` (four parts) to the expansion."""
    h, l = _two_product(q, r)
    n = _add_product(e, n, p, l, negate)
    return _add_product(e, n, p, h, negate)


@njit(**COMPILE)
def det2_exact(a0, a1, b0, b1, p0, p1, q0, q1):
    """Sign of ``(b0 - a0)(q1 - p1) - (b1 - a1)(q0 - p0)`` exactly, or :data:`UNSURE`
    (a difference not exact, or a factor out of the safe range)."""
    f0 = _exact_difference(b0, a0)
    f1 = _exact_difference(b1, a1)
    g0 = _exact_difference(q0, p0)
    g1 = _exact_difference(q1, p1)
    if f0 != f0 or f1 != f1 or g0 != g0 or g1 != g1:
        return UNSURE
    e = np.empty(4)
    n = _add_product(e, 0, f0, g1, False)
    n = _add_product(e, n, f1, g0, True)
    return _sign(e, n)


@njit(**COMPILE)
def orient3d_exact(a0, a1, a2, b0, b1, b2, c0, c1, c2, d0, d1, d2):
    """Sign of ``det[b - a, c - a, d - a]`` exactly, or :data:`UNSURE` (as
    :func:`det2_exact`)."""
    bx = _exact_difference(b0, a0)
    by = _exact_difference(b1, a1)
    bz = _exact_difference(b2, a2)
    cx = _exact_difference(c0, a0)
    cy = _exact_difference(c1, a1)
    cz = _exact_difference(c2, a2)
    dx = _exact_difference(d0, a0)
    dy = _exact_difference(d1, a1)
    dz = _exact_difference(d2, a2)
    for v in (bx, by, bz, cx, cy, cz, dx, dy, dz):
        if v != v:
            return UNSURE
    e = np.empty(_PARTS)
    n = _add_triple(e, 0, bx, cy, dz, False)
    n = _add_triple(e, n, bx, cz, dy, True)
    n = _add_triple(e, n, by, cz, dx, False)
    n = _add_triple(e, n, by, cx, dz, True)
    n = _add_triple(e, n, bz, cx, dy, False)
    n = _add_triple(e, n, bz, cy, dx, True)
    return _sign(e, n)
