"""Compiled interval rules: one scalar function per operation, rounded outward.

Each rule takes the ends of its arguments' intervals as floats and returns the
ends of an interval that holds every value of the operation over them in exact
real arithmetic (Stolte §2, "inclusion functions"), compiled with Numba
(``@njit``) so that the compiled tape interpreter
(:mod:`implicitvox.eval.compiled`) calls it per box at machine speed.

The rules and their rounding argument are those of the array kernels in
:mod:`implicitvox.interval.kernels` (which document each case and stay as the
test oracle the rules are checked against), written for one interval:

* after a correctly rounded IEEE 754 operation (``+ - * /``, ``sqrt``) an end
  moves one float outward, after libm's ``pow`` and ``hypot``
  :data:`~implicitvox.interval.rounding.POW_ULPS` floats, after its other
  transcendental functions :data:`~implicitvox.interval.rounding.TRANSCENDENTAL_ULPS`
  (:func:`down`, :func:`up`: the same arithmetic widening as
  :func:`implicitvox.interval.rounding.down`, bit for bit);
* ``sin`` and ``cos`` take libm's own functions (here a scalar call is cheaper
  than the array kernels' tangent formulas), widened by ``TRANSCENDENTAL_ULPS``;
* ``neg, abs, min, max, floor`` are exact.

Numba compiles with LLVM's default floating-point semantics (no fast-math, so
no reassociation and no contraction of ``a * b + c`` into a fused
multiply-add): every operation rounds to nearest as written, which is what
the rounding argument assumes. ``error_model="numpy"``: a division by zero
gives an infinity, as in numpy, instead of raising.

Domain rules (``sqrt log powr asin acos``) also return ``empty``: the argument
lies wholly outside the domain (see :mod:`implicitvox.interval.kernels`).

Examples
--------
>>> from implicitvox.interval import rules
>>> lo, hi = rules.i_add(0.1, 0.1, 0.7, 0.7)      # 0.1 + 0.7 is inexact
>>> lo < 0.1 + 0.7 < hi
True
>>> rules.i_sin(0.0, 3.0)[1]
1.0
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from . import numba_cache
from .rounding import COS_ULPS, EPS, LIMITS, POW_ULPS, SIN_ULPS, TRANSCENDENTAL_ULPS

__all__ = [
    "down", "up", "down_nonneg", "up_nonneg", "down_sum", "up_sum",
    "i_add", "i_sub", "i_mul", "i_div", "i_neg", "i_addc", "i_rsubc", "i_mulc", "i_divc",
    "i_square", "i_powi", "i_powr", "i_sqrt", "i_abs", "i_exp", "i_log", "i_sin", "i_cos",
    "i_tan", "i_atan", "i_asin", "i_acos", "i_atan2", "i_hypot", "i_min", "i_max", "i_floor",
    "i_radius", "i_distance", "i_elevation", "i_periodic_angle", "periodic_angle_argument",
    "unwrapped_angle", "COMPILE",
]

def _probe() -> int:
    return 0


def _cache_available() -> bool:
    """Can Numba cache compiled code for this package? (Beside the sources, in the
    user's cache directory, or in ``NUMBA_CACHE_DIR``; Numba raises ``RuntimeError``
    at decoration when it finds no writable place, as in a read-only install
    under a read-only home.)"""
    try:
        njit(cache=True)(_probe)
    except RuntimeError:
        return False
    return True


# the cached kernels compiled from other sources than these are deleted first
numba_cache.refresh(Path(__file__).resolve().parents[1])

#: how every compiled function of the kernel is compiled: cached on disk where
#: Numba finds a writable place (else compiled in memory on every first use),
#: releasing the GIL, numpy's error model (no exception on a division by zero)
COMPILE = dict(cache=_cache_available(), nogil=True, error_model="numpy")

T = TRANSCENDENTAL_ULPS
P = POW_ULPS
_TINY = LIMITS[np.dtype(np.float64)][1]
_MAX = LIMITS[np.dtype(np.float64)][2]
INF = math.inf
PI_UP = float(np.nextafter(np.pi, INF))
HALF_PI_UP = float(np.nextafter(np.pi / 2, INF))
TWO_PI_UP = float(np.nextafter(2.0 * np.pi, INF))
_TWO_PI = 2.0 * np.pi
_PI = np.pi
# _norm: squares stay normal and finite within these
_NORM_BIG = 1e150
_NORM_LOW = 4.0 / (_NORM_BIG * _NORM_BIG)
_NORM_HIGH = _NORM_BIG * _NORM_BIG / 4.0
# i_distance (see kernels.i_distance)
_SQRT_MAX_DOWN = float(np.sqrt(np.finfo(np.float64).max)) * (1.0 - 2.0 ** -48)
_UNDERFLOW_ROOT = 2.0 ** -536
# sin/cos extremum test: the slack of kernels._in_periods in float64
_SLACK = 1e-12

# SIN_ULPS and COS_ULPS bound the array kernels' tangent formulas; the rules call
# libm's sin and cos, which TRANSCENDENTAL_ULPS bounds (tests/interval/test_rules.py)
assert SIN_ULPS >= T and COS_ULPS >= T


# -- rounding (rounding.py's arithmetic, one float) ------------------------------------
@njit(**COMPILE)
def down(a, ulps):
    """A value at least ``ulps`` floats below ``a`` (``+inf`` and NaN: the largest float)."""
    r = a - (abs(a) * (ulps * EPS) + _TINY)
    return r if r < _MAX else _MAX


@njit(**COMPILE)
def up(a, ulps):
    """A value at least ``ulps`` floats above ``a`` (``-inf`` and NaN: the most negative)."""
    r = a + (abs(a) * (ulps * EPS) + _TINY)
    return r if r > -_MAX else -_MAX


@njit(**COMPILE)
def down_nonneg(a, ulps):
    """:func:`down` for ``a >= 0``, clamped at 0."""
    r = a * (1.0 - ulps * EPS) - _TINY
    if r < 0.0:
        return 0.0
    if r > _MAX:
        return _MAX
    return r


@njit(**COMPILE)
def up_nonneg(a, ulps):
    """:func:`up` for ``a >= 0``."""
    return a * (1.0 + ulps * EPS) + _TINY


# numpy's minimum/maximum (NaN propagates) and fmin/fmax (NaN ignored)
@njit(**COMPILE)
def _maximum(a, b):
    return a if (a >= b or a != a) else b


@njit(**COMPILE)
def _minimum(a, b):
    return a if (a <= b or a != a) else b


@njit(**COMPILE)
def _fmax(a, b):
    return b if (a != a or b > a) else a


@njit(**COMPILE)
def _fmin(a, b):
    return b if (a != a or b < a) else a


@njit(**COMPILE)
def mignitude(lo, hi):
    """Smallest ``|v|`` over ``[lo, hi]``."""
    return _maximum(_maximum(lo, -hi), 0.0)


@njit(**COMPILE)
def magnitude(lo, hi):
    """Largest ``|v|`` over ``[lo, hi]``."""
    return _maximum(-lo, hi)


# -- the four operations ------------------------------------------------------------------
@njit(**COMPILE)
def down_sum(a):
    """rounding.down_sum: :func:`down` by one float, but a computed sum of 0 stays."""
    return a if a == 0.0 else down(a, 1)


@njit(**COMPILE)
def up_sum(a):
    """rounding.up_sum: :func:`up` by one float, but a computed sum of 0 stays."""
    return a if a == 0.0 else up(a, 1)


@njit(**COMPILE)
def i_add(alo, ahi, blo, bhi):
    return down_sum(alo + blo), up_sum(ahi + bhi)


@njit(**COMPILE)
def i_sub(alo, ahi, blo, bhi):
    return down_sum(alo - bhi), up_sum(ahi - blo)


@njit(**COMPILE)
def i_addc(alo, ahi, c):
    return down_sum(alo + c), up_sum(ahi + c)


@njit(**COMPILE)
def i_rsubc(alo, ahi, c):
    return down_sum(c - ahi), up_sum(c - alo)


@njit(**COMPILE)
def _is_zero(alo, ahi):
    return alo == 0.0 and ahi == 0.0


@njit(**COMPILE)
def i_mulc(alo, ahi, c):
    if c == 0.0 or _is_zero(alo, ahi):       # exactly 0 (0 * inf too)
        return 0.0, 0.0
    if c > 0.0:
        return down(alo * c, 1), up(ahi * c, 1)
    return down(ahi * c, 1), up(alo * c, 1)


@njit(**COMPILE)
def i_divc(alo, ahi, c):
    if _is_zero(alo, ahi):
        return 0.0, 0.0
    if c > 0.0:
        return down(alo / c, 1), up(ahi / c, 1)
    return down(ahi / c, 1), up(alo / c, 1)


@njit(**COMPILE)
def i_neg(alo, ahi):
    return -ahi, -alo


@njit(**COMPILE)
def i_mul(alo, ahi, blo, bhi):
    if _is_zero(alo, ahi) or _is_zero(blo, bhi):      # exactly 0 (0 * inf too)
        return 0.0, 0.0
    p1, p2, p3, p4 = alo * blo, alo * bhi, ahi * blo, ahi * bhi
    lo = _fmin(_fmin(p1, p2), _fmin(p3, p4))
    hi = _fmax(_fmax(p1, p2), _fmax(p3, p4))
    return down(lo, 1), up(hi, 1)


@njit(**COMPILE)
def i_div(alo, ahi, blo, bhi):
    if blo <= 0.0 <= bhi:
        return -INF, INF
    if _is_zero(alo, ahi):
        return 0.0, 0.0
    p1, p2, p3, p4 = alo / blo, alo / bhi, ahi / blo, ahi / bhi
    lo = _fmin(_fmin(p1, p2), _fmin(p3, p4))
    hi = _fmax(_fmax(p1, p2), _fmax(p3, p4))
    return down(lo, 1), up(hi, 1)


# -- powers and roots ----------------------------------------------------------------------
@njit(**COMPILE)
def i_square(alo, ahi):
    mig = mignitude(alo, ahi)
    mag = magnitude(alo, ahi)
    return down_nonneg(mig * mig, 1), up_nonneg(mag * mag, 1)


@njit(**COMPILE)
def _powi_positive(alo, ahi, n):
    if n == 1:
        return alo, ahi
    if n == 2:
        return i_square(alo, ahi)
    e = float(n)                         # libm pow, as np.power: not repeated products
    if n % 2 == 0:
        return (down_nonneg(math.pow(mignitude(alo, ahi), e), P),
                up_nonneg(math.pow(magnitude(alo, ahi), e), P))
    return down(math.pow(alo, e), P), up(math.pow(ahi, e), P)


@njit(**COMPILE)
def i_powi(alo, ahi, n):
    """``x ** n`` for an integer ``n`` (negative: the reciprocal of ``x ** -n``)."""
    if n == 0:
        return 1.0, 1.0
    if n > 0:
        return _powi_positive(alo, ahi, n)
    plo, phi = _powi_positive(alo, ahi, -n)
    return i_div(1.0, 1.0, plo, phi)


@njit(**COMPILE)
def i_powr(alo, ahi, p):
    """``x ** p`` for a real, non-integral ``p``; defined for ``x >= 0``."""
    a = _maximum(alo, 0.0)
    b = _maximum(ahi, 0.0)
    if p > 0:
        lo, hi = math.pow(a, p), math.pow(b, p)
    else:
        lo, hi = math.pow(b, p), math.pow(a, p)
    return down_nonneg(lo, P), up_nonneg(hi, P), ahi < 0.0


@njit(**COMPILE)
def i_sqrt(alo, ahi):
    lo = math.sqrt(_maximum(alo, 0.0))
    hi = math.sqrt(_maximum(ahi, 0.0))
    return down_nonneg(lo, 1), up_nonneg(hi, 1), ahi < 0.0


@njit(**COMPILE)
def i_abs(alo, ahi):
    return mignitude(alo, ahi), magnitude(alo, ahi)


@njit(**COMPILE)
def _norm2(a, b):
    """``sqrt(a*a + b*b)`` for ``a, b >= 0``, libm's ``hypot`` where a square could
    overflow or underflow (as :func:`implicitvox.interval.kernels._norm`)."""
    total = a * a + b * b
    if _NORM_LOW <= total <= _NORM_HIGH:
        return math.sqrt(total)
    top = _maximum(a, b)
    if top > _NORM_BIG or (0.0 < top < 1.0 / _NORM_BIG):
        return math.hypot(a, b)
    return math.sqrt(total)


@njit(**COMPILE)
def _norm3(a, b, c):
    total = a * a + b * b + c * c
    if _NORM_LOW <= total <= _NORM_HIGH:
        return math.sqrt(total)
    top = _maximum(_maximum(a, b), c)
    if top > _NORM_BIG or (0.0 < top < 1.0 / _NORM_BIG):
        return math.hypot(math.hypot(a, b), c)
    return math.sqrt(total)


@njit(**COMPILE)
def i_hypot(alo, ahi, blo, bhi):
    lo = _norm2(mignitude(alo, ahi), mignitude(blo, bhi))
    hi = _norm2(magnitude(alo, ahi), magnitude(blo, bhi))
    return down_nonneg(lo, P), up_nonneg(hi, P)


# -- exponential and logarithm ---------------------------------------------------------------
@njit(**COMPILE)
def i_exp(alo, ahi):
    return down_nonneg(math.exp(alo), T), up_nonneg(math.exp(ahi), T)


@njit(**COMPILE)
def _log0(a):
    """libm's log, with ``log(0) = -inf`` (Python's math.log raises there)."""
    return -INF if a == 0.0 else math.log(a)


@njit(**COMPILE)
def i_log(alo, ahi):
    lo = _log0(_maximum(alo, 0.0))
    hi = _log0(_maximum(ahi, 0.0))
    return down(lo, T), up(hi, T), ahi < 0.0


# -- trigonometry -------------------------------------------------------------------------------
@njit(**COMPILE)
def _in_periods(alo, ahi, period):
    """``[alo, ahi]`` in periods, widened by a slack (kernels._in_periods)."""
    u_lo = alo * (1.0 / period)
    u_hi = ahi * (1.0 / period)
    slack = _maximum(-u_lo, u_hi) * _SLACK + _SLACK
    return u_lo - slack, u_hi + slack


@njit(**COMPILE)
def _extremum_flag(q_lo, q_hi, phase):
    """>= 1 where a phase point is held, <= -1 where not, NaN: every phase held."""
    return (np.floor(q_hi - phase) - np.ceil(q_lo - phase)) * 2.0 + 1.0


@njit(**COMPILE)
def _periodic(alo, ahi, is_cos):
    """``sin`` (``cos``) over ``[alo, ahi]``: the end values, and 1 or -1 where an
    extremum lies inside (kernels._periodic)."""
    if math.isinf(alo) or math.isinf(ahi):
        return -1.0, 1.0
    if is_cos:
        fa, fb = math.cos(alo), math.cos(ahi)
        max_phase, min_phase = 0.0, 0.5
    else:
        fa, fb = math.sin(alo), math.sin(ahi)
        max_phase, min_phase = 0.25, 0.75
    q_lo, q_hi = _in_periods(alo, ahi, _TWO_PI)
    top = _extremum_flag(q_lo, q_hi, max_phase)
    bottom = _extremum_flag(q_lo, q_hi, min_phase)
    lo = down(_fmin(fa, fb), T)
    hi = up(_fmax(fa, fb), T)
    hi = _fmax(_minimum(hi, 1.0), _fmin(top, 1.0))
    lo = _fmin(_maximum(lo, -1.0), _fmax(-bottom, -1.0))
    return lo, hi


@njit(**COMPILE)
def i_sin(alo, ahi):
    return _periodic(alo, ahi, False)


@njit(**COMPILE)
def i_cos(alo, ahi):
    return _periodic(alo, ahi, True)


@njit(**COMPILE)
def i_tan(alo, ahi):
    q_lo, q_hi = _in_periods(alo, ahi, _PI)
    # a pole held, or an infinite end (NaN: held)
    if not (np.floor(q_hi - 0.5) < np.ceil(q_lo - 0.5)):
        return -INF, INF
    return down(math.tan(alo), T), up(math.tan(ahi), T)


@njit(**COMPILE)
def i_atan(alo, ahi):
    lo = down(math.atan(alo), T)
    hi = up(math.atan(ahi), T)
    return _maximum(lo, -HALF_PI_UP), _minimum(hi, HALF_PI_UP)


@njit(**COMPILE)
def _clip1(a):
    return -1.0 if a < -1.0 else (1.0 if a > 1.0 else a)


@njit(**COMPILE)
def i_asin(alo, ahi):
    empty = ahi < -1.0 or alo > 1.0
    return down(math.asin(_clip1(alo)), T), up(math.asin(_clip1(ahi)), T), empty


@njit(**COMPILE)
def i_acos(alo, ahi):
    empty = ahi < -1.0 or alo > 1.0
    return (down_nonneg(math.acos(_clip1(ahi)), T), up_nonneg(math.acos(_clip1(alo)), T),
            empty)


@njit(**COMPILE)
def i_atan2(ylo, yhi, xlo, xhi):
    """``atan2(y, x)`` over a box: ``[-pi, pi]`` (rounded out) on a box that holds the
    origin or meets the negative x axis (kernels.i_atan2), else the angles of the
    two corners where the extremes lie, two libm calls instead of four.

    Off the cut the angle is smooth, with ``d/dx = -y / r**2`` and ``d/dy = x /
    r**2``. Above the x axis (``y > 0``) it falls with ``x``, so its least value
    is on the side ``x = xhi`` and its greatest on ``x = xlo``, and along a side it
    rises with ``y`` where that ``x`` is positive and falls where it is negative;
    below the axis likewise with the roles of the sides swapped; a box straddling
    the axis (then ``x > 0``) rises with ``y`` and has its extremes at ``x = xlo``.
    Each computed corner angle is within ``TRANSCENDENTAL_ULPS`` of the exact
    extreme there, which the widening covers.
    """
    if xlo <= 0.0 and ylo <= 0.0 and yhi >= 0.0:
        return -PI_UP, PI_UP
    if ylo > 0.0:                       # above the x axis
        least = math.atan2(ylo, xhi) if xhi >= 0.0 else math.atan2(yhi, xhi)
        most = math.atan2(yhi, xlo) if xlo > 0.0 else math.atan2(ylo, xlo)
    elif yhi < 0.0:                     # below it
        least = math.atan2(ylo, xlo) if xlo >= 0.0 else math.atan2(yhi, xlo)
        most = math.atan2(yhi, xhi) if xhi > 0.0 else math.atan2(ylo, xhi)
    else:                               # across it, at x > 0
        least = math.atan2(ylo, xlo)
        most = math.atan2(yhi, xlo)
    return _maximum(down(least, T), -PI_UP), _minimum(up(most, T), PI_UP)


# -- exact operations ------------------------------------------------------------------------------
@njit(**COMPILE)
def i_min(alo, ahi, blo, bhi):
    return _minimum(alo, blo), _minimum(ahi, bhi)


@njit(**COMPILE)
def i_max(alo, ahi, blo, bhi):
    return _maximum(alo, blo), _maximum(ahi, bhi)


@njit(**COMPILE)
def i_floor(alo, ahi):
    return np.floor(alo), np.floor(ahi)   # (math.floor is an integer)


# -- coordinates (Stolte §4.1.2) -------------------------------------------------------------------
@njit(**COMPILE)
def i_radius(ulo, uhi, vlo, vhi, wlo, whi):
    lo = _norm3(mignitude(ulo, uhi), mignitude(vlo, vhi), mignitude(wlo, whi))
    hi = _norm3(magnitude(ulo, uhi), magnitude(vlo, vhi), magnitude(wlo, whi))
    return down_nonneg(lo, 3), up_nonneg(hi, 3)


@njit(**COMPILE)
def _offset_square_extents(alo, ahi, c):
    below = alo - c
    above = c - ahi
    near = _maximum(_maximum(below, above), 0.0)
    far = _minimum(below, above)
    return near * near, far * far


@njit(**COMPILE)
def i_distance(alo, ahi, blo, bhi, wlo, whi, c0, c1, c2):
    """Euclidean distance from ``(c0, c1, c2)`` over a box (kernels.i_distance)."""
    n0, f0 = _offset_square_extents(alo, ahi, c0)
    n1, f1 = _offset_square_extents(blo, bhi, c1)
    n2, f2 = _offset_square_extents(wlo, whi, c2)
    near = math.sqrt((n0 + n1) + n2)
    far = math.sqrt((f0 + f1) + f2)
    lo = near * (1.0 - 3.0 * EPS) - _UNDERFLOW_ROOT
    hi = far * (1.0 + 3.0 * EPS) + _UNDERFLOW_ROOT
    if lo < 0.0:
        lo = 0.0
    elif lo > _SQRT_MAX_DOWN:
        lo = _SQRT_MAX_DOWN
    return lo, hi


@njit(**COMPILE)
def i_elevation(ulo, uhi, vlo, vhi, wlo, whi):
    """Elevation ``atan2(w, hypot(u, v))`` over a box (kernels.i_elevation)."""
    rlo = down_nonneg(_norm2(mignitude(ulo, uhi), mignitude(vlo, vhi)), P)
    rhi = up_nonneg(_norm2(magnitude(ulo, uhi), magnitude(vlo, vhi)), P)
    lo = math.atan2(wlo, rhi if wlo >= 0.0 else rlo)
    hi = math.atan2(whi, rhi if whi < 0.0 else rlo)
    return _maximum(down(lo, T), -HALF_PI_UP), _minimum(up(hi, T), HALF_PI_UP)


@njit(**COMPILE)
def unwrapped_angle(vlo, vhi, ulo, uhi):
    """``atan2(v, u)`` over a box, unwrapped across the branch cut (kernels.angle_interval):
    valid modulo 2 pi."""
    if uhi < 0.0 and vlo <= 0.0 and vhi >= 0.0:
        lo = down(math.atan2(vhi, uhi), T)
        # v = +0 counts as the upper side: as -0 it gives -pi, unwrapped pi
        hi = up(up(math.atan2(math.copysign(vlo, -1.0), uhi), T) + TWO_PI_UP, 1)
        return lo, hi
    return i_atan2(vlo, vhi, ulo, uhi)


@njit(**COMPILE)
def periodic_angle_argument(vlo, vhi, ulo, uhi, k, c):
    """``k * atan2(v, u) + c`` over a box, unwrapped across the cut: the argument of
    :func:`i_periodic_angle` (whose ``sin`` and ``cos`` are then :func:`i_sin` and
    :func:`i_cos` of it)."""
    alo, ahi = unwrapped_angle(vlo, vhi, ulo, uhi)
    alo, ahi = i_mulc(alo, ahi, k)
    if c != 0.0:
        alo, ahi = i_addc(alo, ahi, c)
    return alo, ahi


@njit(**COMPILE)
def i_periodic_angle(vlo, vhi, ulo, uhi, is_cos, k, c):
    """``sin`` (``cos``) of ``k * atan2(v, u) + c``, ``k`` an integer, tight across the cut."""
    alo, ahi = periodic_angle_argument(vlo, vhi, ulo, uhi, k, c)
    return _periodic(alo, ahi, is_cos)
