"""Outward rounding for interval endpoints.

numpy cannot set the FPU rounding mode, so every interval kernel computes its
endpoints in round-to-nearest and then widens them outward by at least
``ulps`` floats:

* after a correctly rounded IEEE 754 operation (``+ - * /`` and ``sqrt``) the
  exact result lies between the computed one and its neighbouring float, so
  one float outward (``ulps=1``) is enough;
* numpy's transcendental functions (``exp, log, sin, cos, tan, arctan, arcsin,
  arccos, arctan2``) are *not* correctly rounded. glibc documents errors of at
  most 1-2 ulp for these and numpy's SIMD (SVML) paths at most 4 ulp, so they
  are widened by :data:`TRANSCENDENTAL_ULPS`; ``power`` and ``hypot`` (glibc:
  < 1 ulp) by :data:`POW_ULPS`. ``tests/test_rounding.py`` measures numpy's
  error against mpmath at 40 digits and checks it stays below the margin.
  numpy's float64 ``sin`` and ``cos`` call scalar libm (8-16 ns per value
  here, against 1.4 for its SIMD ``tan``), so the interval kernels compute
  them from ``tan`` instead and widen by :data:`SIN_ULPS` and
  :data:`COS_ULPS`, bounds derived from ``TRANSCENDENTAL_ULPS`` (the point
  evaluator keeps numpy's own).

How: ``np.nextafter`` is exact but costs 5-30 times an addition (it calls libm
per element), so the widening is arithmetic. For a normal float ``a`` the
product ``|a| * 2**-52`` is at least one ulp of ``a`` and below two, so
``a - k * |a| * 2**-52``, rounded to nearest, is at least ``k`` floats below
``a`` (and at most ``2k + 1``). Subtracting the smallest subnormal
``2**-1074`` more covers zero and subnormal results (where the relative step
vanishes). A lower endpoint that overflowed to ``+inf`` becomes the largest
float (the exact value is finite and above it) and an upper one at ``-inf``
the most negative, so endpoints never turn into NaN. Two exact zeros are kept
exact: a computed sum of 0 (:func:`down_sum`; an addition that underflows is
exact) and a product or quotient with an exact ``[0, 0]`` operand, so a
gradient's zero components stay zero and do not grow into subnormal widths,
which compiled code pays about a hundred cycles for at every operation. When the sign of the
result is known (``>= 0``), :func:`down_nonneg` and :func:`up_nonneg` do the
same in fewer passes.

The kernels in :mod:`implicitvox.interval.kernels` call these functions through the
module (``rounding.down``), so a test can switch rounding off and show that
the enclosure then fails on crafted inputs.

Examples
--------
>>> import numpy as np
>>> from implicitvox.interval import rounding
>>> a = np.array([0.1 + 0.7, 0.0, -np.inf, np.inf])
>>> lo, hi = rounding.down(a), rounding.up(a)
>>> bool(np.all(lo[:2] < a[:2]) and np.all(a[:2] < hi[:2]))
True
>>> lo[3] == np.finfo(float).max, hi[2] == -np.finfo(float).max
(np.True_, np.True_)
"""
from __future__ import annotations

import numpy as np

from .filled import filled_like

__all__ = ["down", "up", "down_nonneg", "up_nonneg", "down_sum", "up_sum", "limits",
           "TRANSCENDENTAL_ULPS", "POW_ULPS",
           "SIN_ULPS", "COS_ULPS", "EPS", "LIMITS"]

#: floats of outward widening after numpy's transcendental functions.
TRANSCENDENTAL_ULPS = 4
#: floats after ``np.power`` (libm ``pow``) and ``np.hypot``.
POW_ULPS = 2
#: floats after sine from the half-angle tangent (:func:`implicitvox.interval.kernels.sin_values`):
#: ``tan`` is off by ``T`` floats, which the formula passes on at most once (its relative
#: condition number is at most 1), and its three rounded operations add 1.5.
SIN_ULPS = TRANSCENDENTAL_ULPS + 2
#: floats after cosine from tangents (:func:`implicitvox.interval.kernels.cos_values`): the sine
#: divided by ``tan x``, ``(T + 1.5) + T + 0.5``; where ``|tan x| <= 1`` the half-angle form
#: is off by at most ``T + 2.5`` floats of 1, which is ``sqrt(2) (T + 2.5) <= 2 T + 2``
#: floats of a cosine of at least ``1 / sqrt(2)`` (for ``T >= 3``).
COS_ULPS = 2 * TRANSCENDENTAL_ULPS + 2

#: the spacing of floats at 1 (one ulp of 1.0)
EPS = 2.0 ** -52
#: per float type: (spacing at 1, smallest subnormal, largest finite); the
#: interval kernels also run on float32 (:mod:`implicitvox.eval.float32_tapes`)
LIMITS = {np.dtype(np.float64): (EPS, 2.0 ** -1074, float(np.finfo(np.float64).max)),
          np.dtype(np.float32): (2.0 ** -23, 2.0 ** -149, float(np.finfo(np.float32).max))}
_F64 = LIMITS[np.dtype(np.float64)]


def limits(a) -> tuple[float, float, float]:
    """``(eps, tiny, max)`` of ``a``'s float type (float64 for anything else)."""
    return LIMITS.get(getattr(a, "dtype", None), _F64)


def down(a: np.ndarray, ulps: int = 1) -> np.ndarray:
    """A value at least ``ulps`` floats below ``a`` (``+inf`` -> largest float)."""
    step = np.asanyarray(np.abs(a))  # 0-d for scalars, so the in-place steps work
    eps, tiny, big = limits(step)
    step *= ulps * eps
    step += tiny
    with np.errstate(invalid="ignore"):
        out = np.subtract(a, step, out=step)     # inf - inf = NaN only for a = +inf
    return np.fmin(out, filled_like(big, out), out=out)   # NaN -> largest float


def up(a: np.ndarray, ulps: int = 1) -> np.ndarray:
    """A value at least ``ulps`` floats above ``a`` (``-inf`` -> most negative float)."""
    step = np.asanyarray(np.abs(a))
    eps, tiny, big = limits(step)
    step *= ulps * eps
    step += tiny
    with np.errstate(invalid="ignore"):
        out = np.add(a, step, out=step)
    return np.fmax(out, filled_like(-big, out), out=out)


def down_sum(a: np.ndarray) -> np.ndarray:
    """:func:`down` by one float for a computed sum or difference of two floats, but a
    sum of 0 stays 0: with gradual underflow an addition whose rounded result is 0
    is exact (a non-zero sum below the normal range is itself a float). So the
    exact zeros of a gradient (a coordinate a function does not depend on) stay
    exact, instead of growing into subnormal widths that every later operation
    pays for (a subnormal operand or result costs about a hundred cycles in
    compiled code)."""
    out = down(a)
    np.copyto(out, a, where=np.asanyarray(a) == 0)
    return out


def up_sum(a: np.ndarray) -> np.ndarray:
    """:func:`up` by one float for a computed sum, a sum of 0 staying 0 (see
    :func:`down_sum`)."""
    out = up(a)
    np.copyto(out, a, where=np.asanyarray(a) == 0)
    return out


def down_nonneg(a: np.ndarray, ulps: int = 1) -> np.ndarray:
    """:func:`down` for ``a >= 0``, clamped at 0 (the result is known non-negative)."""
    eps, tiny, big = limits(a)
    out = np.asanyarray(np.multiply(a, 1.0 - ulps * eps))
    out -= tiny
    return np.clip(out, 0.0, big, out=out)


def up_nonneg(a: np.ndarray, ulps: int = 1) -> np.ndarray:
    """:func:`up` for ``a >= 0``."""
    eps, tiny, _ = limits(a)
    out = np.multiply(a, 1.0 + ulps * eps)
    out += tiny
    return out
