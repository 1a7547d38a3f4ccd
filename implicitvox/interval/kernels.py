"""Vectorized interval kernels on ``(lo, hi)`` arrays, rounded outward.

Every kernel takes the endpoint arrays of its arguments and returns the
endpoint arrays of an interval that holds every value the operation takes
over the argument boxes *in exact real arithmetic* (Stolte §2, "inclusion
functions"; the monotone-piece rules are Duff's and Snyder's). The rules:

Rounding
    After a correctly rounded IEEE 754 operation (``+ - * /``, ``sqrt``) each
    endpoint moves one ulp outward (:func:`rounding.down`, :func:`rounding.up`).
    After numpy's transcendentals (``exp log sin cos tan atan asin acos atan2``)
    it moves :data:`rounding.TRANSCENDENTAL_ULPS` ulps, after ``power``
    :data:`rounding.POW_ULPS`. ``sin`` and ``cos`` are computed from ``tan``
    (:func:`sin_values`, :func:`cos_values`) and move :data:`rounding.SIN_ULPS`
    and :data:`rounding.COS_ULPS`. ``neg, abs, min, max, floor`` are exact
    and not widened.
Tight cases
    ``square`` and even integer powers clamp at 0 over intervals holding 0;
    ``sin``/``cos`` return exactly 1 or -1 when the interval holds an interior
    extremum (found with a conservative slack, so a near miss widens rather
    than loses the extremum); ``tan`` over an interval holding a pole gives
    ``(-inf, inf)``; ``atan2`` takes the extreme corner angles of a box that
    neither holds the origin nor meets the negative x axis (the branch cut) and
    ``[-pi, pi]`` (rounded out) otherwise; division by an interval holding 0
    gives the hull ``(-inf, inf)``.
Domains
    ``sqrt``, ``log``, ``powr`` (``x >= 0``) and ``asin``, ``acos``
    (``-1 <= x <= 1``) over an interval partly outside the domain enclose the
    values on the part inside. Wholly outside, the kernel reports the lane as
    *empty* (the third returned array) and returns a finite placeholder so the
    rest of the tape computes without NaN; the evaluator returns the empty
    interval ``(+inf, -inf)`` for such lanes, which the subdivision reads as
    "no surface here" (the function is undefined, as numpy's NaN says).
Infinities and NaN
    Inputs never hold NaN (the evaluator refuses them). Endpoints may be
    infinite; ``0 * inf`` and ``inf / inf`` corner products are ignored with
    ``fmin``/``fmax`` (the other corners bound the range), and a lower endpoint
    rounded down from ``+inf`` becomes the largest float, so an endpoint
    computed from such intervals is never NaN.

Examples
--------
>>> import numpy as np
>>> from implicitvox.interval import kernels as iv
>>> lo, hi = iv.i_sin(np.array([0.0]), np.array([3.0]))
>>> float(lo[0]) < 0.0 < 1.0 == float(hi[0])
True
"""
from __future__ import annotations

import numpy as np

from . import rounding
from .filled import filled_like

__all__ = [
    "i_add", "i_sub", "i_mul", "i_div", "i_neg", "i_addc", "i_rsubc", "i_mulc", "i_divc", "i_square", "i_powi", "i_powr",
    "i_sqrt", "i_abs", "i_exp", "i_log", "i_sin", "i_cos", "i_tan", "i_atan",
    "i_asin", "i_acos", "i_atan2", "i_hypot", "i_min", "i_max", "i_floor",
    "i_distance", "mignitude", "magnitude", "PI_UP", "HALF_PI_UP",
]

T = rounding.TRANSCENDENTAL_ULPS
P = rounding.POW_ULPS
INF = np.inf
#: Upper bounds of pi and pi/2 (the doubles ``np.pi`` and ``np.pi/2`` lie below).
PI_UP = float(np.nextafter(np.pi, INF))
HALF_PI_UP = float(np.nextafter(np.pi / 2, INF))
_TWO_PI = 2.0 * np.pi
_TINY = rounding.LIMITS[np.dtype(np.float64)][1]   # the smallest subnormal double


def where_set(mask, value: float, a, owned: bool = False):
    """``np.where(mask, value, a)``, computed by putting ``value`` into a copy of
    ``a`` (into ``a`` itself if ``owned``) at the indices where ``mask``
    holds: the same values, several times faster when few lanes are set, as
    for the extrema and cuts of small boxes (``np.where`` and masked copies
    run a branch per lane)."""
    if isinstance(a, np.ndarray) and a.ndim and a.shape == np.shape(mask):
        out = a if owned and a.flags.c_contiguous else np.array(a, order="C")
        if mask.any():
            out.reshape(-1)[np.flatnonzero(mask)] = value
        return out
    return np.where(mask, value, a)


def mignitude(lo, hi):
    """Smallest ``|v|`` over ``[lo, hi]`` (0 when the interval holds 0)."""
    m = np.maximum(lo, -hi)
    return np.maximum(m, filled_like(0.0, m))


def magnitude(lo, hi):
    """Largest ``|v|`` over ``[lo, hi]``."""
    return np.maximum(-lo, hi)


# -- the four operations ------------------------------------------------------
def i_add(alo, ahi, blo, bhi):
    """``a + b``; a computed end of 0 is exact and stays (:func:`rounding.down_sum`)."""
    return rounding.down_sum(alo + blo), rounding.up_sum(ahi + bhi)


def i_sub(alo, ahi, blo, bhi):
    return rounding.down_sum(alo - bhi), rounding.up_sum(ahi - blo)


def i_addc(alo, ahi, c: float):
    """``a + c`` for an exact constant ``c`` (``a - c`` is ``a + (-c)``)."""
    return rounding.down_sum(alo + c), rounding.up_sum(ahi + c)


def i_rsubc(alo, ahi, c: float):
    """``c - a`` for an exact constant ``c``."""
    return rounding.down_sum(c - ahi), rounding.up_sum(c - alo)


def _zero(alo, ahi):
    """Where ``[alo, ahi]`` is exactly 0: a product or quotient with it is exactly 0."""
    return (np.asanyarray(alo) == 0.0) & (np.asanyarray(ahi) == 0.0)


def _exact_zeros(lo, hi, zero):
    """``lo, hi`` with 0 where ``zero`` (a product or quotient of an exact 0)."""
    if np.any(zero):
        lo, hi = np.where(zero, 0.0, lo), np.where(zero, 0.0, hi)
    return lo, hi


def i_mulc(alo, ahi, c: float):
    """``a * c`` for an exact constant ``c`` (Stolte §2: the order of the bounds
    follows the sign of ``c``)."""
    if c >= 0.0:
        with np.errstate(invalid="ignore"):
            lo, hi = alo * c, ahi * c
        if c == 0.0:  # 0 * inf
            return np.zeros_like(lo), np.zeros_like(hi)
    else:
        lo, hi = ahi * c, alo * c
    return _exact_zeros(rounding.down(lo), rounding.up(hi), _zero(alo, ahi))


def i_divc(alo, ahi, c: float):
    """``a / c`` for an exact non-zero constant ``c`` (overflow gives the infinity
    the rounded-outward quotient holds)."""
    with np.errstate(over="ignore"):
        lo, hi = (alo / c, ahi / c) if c > 0.0 else (ahi / c, alo / c)
    return _exact_zeros(rounding.down(lo), rounding.up(hi), _zero(alo, ahi))


def i_neg(alo, ahi):
    return -ahi, -alo


def _hull4(p1, p2, p3, p4):
    # fmin/fmax skip the NaN of a 0*inf or inf/inf corner; the others bound the range.
    lo = np.fmin(np.fmin(p1, p2), np.fmin(p3, p4))
    hi = np.fmax(np.fmax(p1, p2), np.fmax(p3, p4))
    return lo, hi


def i_mul(alo, ahi, blo, bhi):
    with np.errstate(invalid="ignore"):
        lo, hi = _hull4(alo * blo, alo * bhi, ahi * blo, ahi * bhi)
    # an exact 0 operand (all four corners 0 * inf too): the product is exactly 0
    return _exact_zeros(rounding.down(lo), rounding.up(hi), _zero(alo, ahi) | _zero(blo, bhi))


def i_div(alo, ahi, blo, bhi):
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        lo, hi = _hull4(alo / blo, alo / bhi, ahi / blo, ahi / bhi)
    holds_zero = (blo <= 0.0) & (bhi >= 0.0)
    lo, hi = _exact_zeros(rounding.down(lo), rounding.up(hi), _zero(alo, ahi))
    lo = np.where(holds_zero, -INF, lo)
    hi = np.where(holds_zero, INF, hi)
    return lo, hi


# -- powers and roots -----------------------------------------------------------
def i_square(alo, ahi):
    mig = mignitude(alo, ahi)
    mag = magnitude(alo, ahi)
    mig *= mig
    mag *= mag
    return rounding.down_nonneg(mig), rounding.up_nonneg(mag)


def i_powi(alo, ahi, n: int):
    """``x ** n`` for an integer ``n`` (negative: the reciprocal of ``x ** -n``)."""
    if n == 0:
        return np.ones_like(alo), np.ones_like(ahi)
    if n == 1:
        return alo, ahi
    if n == 2:
        return i_square(alo, ahi)
    if n < 0:
        plo, phi = i_powi(alo, ahi, -n)
        one = np.ones_like(plo)
        return i_div(one, one, plo, phi)
    with np.errstate(over="ignore"):
        if n % 2 == 0:
            lo = np.power(mignitude(alo, ahi), n)
            hi = np.power(magnitude(alo, ahi), n)
            return rounding.down_nonneg(lo, P), rounding.up_nonneg(hi, P)
        return rounding.down(np.power(alo, n), P), rounding.up(np.power(ahi, n), P)


def i_powr(alo, ahi, p: float):
    """``x ** p`` for a real, non-integral ``p``; defined for ``x >= 0``."""
    empty = ahi < 0.0
    a = np.maximum(alo, 0.0)
    b = np.maximum(ahi, 0.0)
    with np.errstate(over="ignore", divide="ignore"):
        if p > 0:
            lo, hi = np.power(a, p), np.power(b, p)
        else:
            lo, hi = np.power(b, p), np.power(a, p)
    return rounding.down_nonneg(lo, P), rounding.up_nonneg(hi, P), empty


def i_sqrt(alo, ahi):
    empty = ahi < 0.0
    lo = np.sqrt(np.maximum(alo, 0.0))
    hi = np.sqrt(np.maximum(ahi, 0.0))
    return rounding.down_nonneg(lo), rounding.up_nonneg(hi), empty


def i_abs(alo, ahi):
    return mignitude(alo, ahi), magnitude(alo, ahi)


def i_hypot(alo, ahi, blo, bhi):
    lo = _norm(mignitude(alo, ahi), mignitude(blo, bhi))
    hi = _norm(magnitude(alo, ahi), magnitude(blo, bhi))
    return rounding.down_nonneg(lo, P), rounding.up_nonneg(hi, P)


# -- exponential and logarithm -----------------------------------------------------
def i_exp(alo, ahi):
    with np.errstate(over="ignore"):
        return rounding.down_nonneg(np.exp(alo), T), rounding.up_nonneg(np.exp(ahi), T)


def i_log(alo, ahi):
    empty = ahi < 0.0
    with np.errstate(divide="ignore"):
        lo = np.log(np.maximum(alo, 0.0))
        hi = np.log(np.maximum(ahi, 0.0))
    return rounding.down(lo, T), rounding.up(hi, T), empty


# -- trigonometry -------------------------------------------------------------------
def _holds_phase(q_lo, q_hi, phase: float):
    """Does ``[q_lo, q_hi]`` (in periods, already widened by the slack of
    :func:`_in_periods`) hold a point ``u`` with ``u - phase`` an integer?

    Conservative: the slack covers the rounding of the conversion to periods,
    so a point just outside may count as inside (a wider, still valid
    interval), never the reverse. Beyond about 1e12 periods from 0 the slack
    exceeds one period and every interval holds every phase.
    """
    return ~(np.floor(q_hi - phase) < np.ceil(q_lo - phase))   # NaN (inf - inf): held


def _in_periods(alo, ahi, period: float):
    """``[alo, ahi]`` in periods, widened by a slack of ``s (1 + |u|)`` periods,
    ``s`` = 1e-12 in float64 and 2**-20 in float32, far above the few roundings
    of the conversion and of :func:`_holds_phase` (an infinite end gives an
    infinite slack: every phase is held)."""
    u_lo = alo * (1.0 / period)
    u_hi = ahi * (1.0 / period)
    rel = 2.0 ** -20 if u_lo.dtype == np.float32 else 1e-12
    slack = np.maximum(-u_lo, u_hi)        # the larger |u| (u_lo <= u_hi)
    slack *= rel
    slack += rel
    return u_lo - slack, u_hi + slack


def sin_values(a):
    """``sin(a)`` from the half-angle tangent: ``2 t / (1 + t**2)``, ``t = tan(a / 2)``.

    numpy's float64 ``sin`` calls scalar libm; its ``tan`` is vectorized and
    about 6 times faster here, so the interval kernels use this. The relative
    condition number of ``t -> 2 t / (1 + t**2)`` is ``|1 - t**2| / (1 + t**2)
    <= 1``, so the result is within :data:`rounding.SIN_ULPS` floats of the
    exact sine everywhere, near the zeros too (there ``tan`` is near 0 or near
    a pole, and accurate in both). ``t**2`` never overflows: no double comes
    closer to an odd multiple of pi/2 than about 1e-19 times itself, so
    ``|tan|`` stays below about 1e19. Below 2**-1021 the halving rounds, by
    up to one subnormal float of the result; :func:`_periodic` covers it.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.array([0.0, 0.5, 3.0, -1e6])
    >>> bool(np.all(np.abs(sin_values(a) - np.sin(a)) <= 1e-15))
    True
    """
    t = np.tan(a * 0.5)
    return (t + t) / (1.0 + t * t)


def cos_values(a):
    """``cos(a)`` from tangents, within :data:`rounding.COS_ULPS` floats.

    Where ``|tan a| > 1`` (``|cos a| < 1/sqrt(2)``) it is ``sin(a) / tan(a)``,
    relatively accurate near the zeros of the cosine; elsewhere the half-angle
    form ``(1 - t**2) / (1 + t**2)``, ``t = tan(a / 2)``, which is accurate
    to a few floats of 1 and so of the cosine there (see
    :data:`rounding.COS_ULPS`).

    Examples
    --------
    >>> import numpy as np
    >>> a = np.array([0.0, 1.5707963, 3.0, -1e6])
    >>> bool(np.all(np.abs(cos_values(a) - np.cos(a)) <= 1e-15 * np.abs(np.cos(a)) + 1e-300))
    True
    """
    t = np.tan(a)
    half = np.tan(a * 0.5)
    half_sq = half * half
    near_one = (1.0 - half_sq) / (1.0 + half_sq)
    with np.errstate(invalid="ignore", divide="ignore"):   # 0 / 0 at a = 0: not taken
        near_zero = ((half + half) / (1.0 + half_sq)) / t
    return np.where(np.abs(t) > 1.0, near_zero, near_one)


def _extremum_flag(q_lo, q_hi, phase: float):
    """``>= 1`` where ``[q_lo, q_hi]`` (in periods, see :func:`_holds_phase`)
    holds a point ``u`` with ``u - phase`` an integer, ``<= -1`` where not,
    NaN (an infinite end) where every phase is held: as arithmetic, so that
    ``fmin``/``fmax`` apply it without a mask. ``floor(q_hi - phase) -
    ceil(q_lo - phase)`` is the number of such points less one, an integer."""
    flag = np.floor(q_hi - phase)
    flag -= np.ceil(q_lo - phase)
    flag *= 2.0
    flag += 1.0
    return flag


def _periodic(alo, ahi, fast, numpy_values, ulps: int, max_phase: float, min_phase: float):
    """``sin`` or ``cos`` over intervals: the end values, and 1 or -1 where an
    extremum lies inside. float64 ends come from ``fast`` (tangents, widened by
    ``ulps``); float32 ones from numpy's own float32 function, which is
    vectorized (widened by ``TRANSCENDENTAL_ULPS``)."""
    single = alo.dtype == np.float32
    with np.errstate(invalid="ignore", divide="ignore"):
        fa, fb = (numpy_values(alo), numpy_values(ahi)) if single else (fast(alo), fast(ahi))
        q_lo, q_hi = _in_periods(alo, ahi, _TWO_PI)
        top = _extremum_flag(q_lo, q_hi, max_phase)
        bottom = _extremum_flag(q_lo, q_hi, min_phase)
    if single:
        lo, hi = rounding.down(np.fmin(fa, fb), T), rounding.up(np.fmax(fa, fb), T)
    else:
        # one subnormal float more than rounding.down/up give: a halving below 2**-1021 rounds
        lo = rounding.down(np.fmin(fa, fb), ulps) - _TINY
        hi = rounding.up(np.fmax(fa, fb), ulps) + _TINY
    # hi: 1 where a maximum is held (flag >= 1, or NaN: fmin ignores it), else
    # min(hi, 1), which is >= -1 >= flag; lo likewise with the negated flag.
    # (An infinite end makes the flags NaN and the end values NaN, which
    # rounding.down/up have turned into the largest floats: the result is [-1, 1].)
    one = filled_like(1.0, top)
    hi = np.fmax(np.minimum(hi, one), np.fmin(top, one))
    bottom = np.negative(bottom)
    minus_one = filled_like(-1.0, bottom)
    lo = np.fmin(np.maximum(lo, minus_one), np.fmax(bottom, minus_one))
    return lo, hi


def i_sin(alo, ahi):
    return _periodic(alo, ahi, sin_values, np.sin, rounding.SIN_ULPS, 0.25, 0.75)


def i_cos(alo, ahi):
    return _periodic(alo, ahi, cos_values, np.cos, rounding.COS_ULPS, 0.0, 0.5)


def i_tan(alo, ahi):
    with np.errstate(invalid="ignore"):
        pole = _holds_phase(*_in_periods(alo, ahi, np.pi), 0.5)
    with np.errstate(invalid="ignore"):
        lo = rounding.down(np.tan(alo), T)
        hi = rounding.up(np.tan(ahi), T)
    return np.where(pole, -INF, lo), np.where(pole, INF, hi)


def i_atan(alo, ahi):
    lo = rounding.down(np.arctan(alo), T)
    hi = rounding.up(np.arctan(ahi), T)
    return np.maximum(lo, filled_like(-HALF_PI_UP, lo)), np.minimum(hi, filled_like(HALF_PI_UP, hi))


def i_asin(alo, ahi):
    empty = (ahi < -1.0) | (alo > 1.0)
    a = np.clip(alo, -1.0, 1.0)
    b = np.clip(ahi, -1.0, 1.0)
    return rounding.down(np.arcsin(a), T), rounding.up(np.arcsin(b), T), empty


def i_acos(alo, ahi):
    empty = (ahi < -1.0) | (alo > 1.0)
    a = np.clip(alo, -1.0, 1.0)
    b = np.clip(ahi, -1.0, 1.0)
    return rounding.down_nonneg(np.arccos(b), T), rounding.up_nonneg(np.arccos(a), T), empty


def i_atan2(ylo, yhi, xlo, xhi):
    """``atan2(y, x)`` over the box ``[xlo, xhi] x [ylo, yhi]``.

    Off the origin and the negative x axis the angle is continuous and its
    level sets are rays from the origin, so over a box that avoids both its
    extremes are at corners (Stolte §4.1.2, the cases of Fig. 3): the least
    and greatest of the four corner angles. A box meeting the negative x
    axis (where numpy's atan2 jumps from pi to -pi, including y = +-0) or
    holding the origin gets ``[-pi, pi]``.
    """
    a1, a2 = np.arctan2(ylo, xlo), np.arctan2(ylo, xhi)
    a3, a4 = np.arctan2(yhi, xlo), np.arctan2(yhi, xhi)
    lo = rounding.down(np.minimum(np.minimum(a1, a2), np.minimum(a3, a4)), T)
    hi = rounding.up(np.maximum(np.maximum(a1, a2), np.maximum(a3, a4)), T)
    lo, hi = np.maximum(lo, filled_like(-PI_UP, lo)), np.minimum(hi, filled_like(PI_UP, hi))
    full = (xlo <= 0.0) & (ylo <= 0.0) & (yhi >= 0.0)
    return where_set(full, -PI_UP, lo, owned=True), where_set(full, PI_UP, hi, owned=True)


# -- exact operations ----------------------------------------------------------------
def i_min(alo, ahi, blo, bhi):
    return np.minimum(alo, blo), np.minimum(ahi, bhi)


def i_max(alo, ahi, blo, bhi):
    return np.maximum(alo, blo), np.maximum(ahi, bhi)


def i_floor(alo, ahi):
    return np.floor(alo), np.floor(ahi)


# -- coordinates (Stolte §4.1.2) ---------------------------------------------------------
def _norm(a, b, c=None):
    """``sqrt(a*a + b*b [+ c*c])`` for ``a, b, c >= 0``, with its rounding bound.

    The squares, the sums and the root, each rounded to nearest, leave a
    relative error below ``2**-52`` for two terms and ``2 * 2**-52`` for
    three; the callers widen by 2 and 3 floats. Where a square could
    overflow or underflow (outside ``1e-150 .. 1e150``; in float32 ``1e-18 ..
    1e18``) the slower ``hypot`` (libm, below 1 ulp) is used instead. That
    test runs per value only when the sums' extremes leave it open: sums
    within ``[4 / big**2, big**2 / 4]`` put every largest term in
    ``(1 / big, big)``.
    """
    total = a * a + b * b
    if c is not None:
        total = total + c * c
    out = np.sqrt(total)
    big = 1e18 if out.dtype == np.float32 else 1e150   # squares stay normal and finite
    if out.size and 4.0 / (big * big) <= total.min() and total.max() <= big * big / 4.0:
        return out
    top = np.maximum(a, b) if c is None else np.maximum(np.maximum(a, b), c)
    risky = (top > big) | ((top < 1.0 / big) & (top > 0.0))
    if np.any(risky):
        safe = np.hypot(a, b) if c is None else np.hypot(np.hypot(a, b), c)
        out = np.where(risky, safe, out)
    return out


def i_radius(ulo, uhi, vlo, vhi, wlo, whi):
    """Distance to the origin over a box: from its nearest to its farthest point."""
    lo = _norm(mignitude(ulo, uhi), mignitude(vlo, vhi), mignitude(wlo, whi))
    hi = _norm(magnitude(ulo, uhi), magnitude(vlo, vhi), magnitude(wlo, whi))
    return rounding.down_nonneg(lo, 3), rounding.up_nonneg(hi, 3)


#: a lower bound of ``sqrt(MAX)``: the least distance whose squared sum overflows
_SQRT_MAX_DOWN = float(np.sqrt(np.finfo(np.float64).max)) * (1.0 - 2.0 ** -48)
#: above every rounding error that underflowing squares leave after the root
_UNDERFLOW_ROOT = 2.0 ** -536
#: (underflow root, sqrt max down) by float type (float32: squares lose 2**-150)
_DISTANCE_LIMITS = {False: (_UNDERFLOW_ROOT, _SQRT_MAX_DOWN),
                    True: (2.0 ** -74,
                           float(np.sqrt(np.float64(np.finfo(np.float32).max))) * (1.0 - 2.0 ** -20))}


def _offset_square_extents(alo, ahi, c: float):
    """Smallest and largest ``(a - c)**2`` over ``[alo, ahi]``, rounded to nearest.

    ``alo - c`` and ``c - ahi`` are rounded to nearest, which keeps their
    signs exact and their relative error below ``2**-53``; the nearest point
    is ``max(alo - c, c - ahi, 0)`` away from ``c``, the farthest
    ``-min(alo - c, c - ahi)``.
    """
    below = alo - c
    above = c - ahi
    near = np.maximum(below, above)
    near = np.maximum(near, filled_like(0.0, near))
    far = np.minimum(below, above)
    return near * near, far * far


def i_distance(alo, ahi, blo, bhi, wlo, whi, centre):
    """Euclidean distance from ``centre`` over the box ``[a] x [b] x [w]``.

    The tape's fused form of ``sqrt((a - c0)**2 + (b - c1)**2 + (w - c2)**2)``
    (spheres, cylinders, blobs): from the box's nearest point to its farthest,
    which is tighter than the operation-by-operation enclosure and rounds once
    instead of after every step. Rounding: each offset ``a - c`` carries a
    relative error of at most ``u = 2**-53`` (its sign is exact), each square
    ``3u``, the two sums ``5u`` and the root ``3.5u`` in all (first order), so
    the ends move 3 floats (``6u``) outward. Squares that underflow lose at
    most ``2**-1075`` each, ``2**-536`` after the root; a sum that overflows
    means a distance of at least :data:`_SQRT_MAX_DOWN`, where the lower end is
    clamped (the upper is then ``inf``).
    """
    c0, c1, c2 = centre
    n0, f0 = _offset_square_extents(alo, ahi, c0)
    n1, f1 = _offset_square_extents(blo, bhi, c1)
    n2, f2 = _offset_square_extents(wlo, whi, c2)
    near, far = np.sqrt((n0 + n1) + n2), np.sqrt((f0 + f1) + f2)
    eps = rounding.limits(near)[0]
    underflow_root, sqrt_max_down = _DISTANCE_LIMITS[near.dtype == np.float32]
    lo = near * (1.0 - 3.0 * eps) - underflow_root
    hi = far * (1.0 + 3.0 * eps) + underflow_root
    return np.clip(lo, 0.0, sqrt_max_down), hi


def i_elevation(ulo, uhi, vlo, vhi, wlo, whi):
    """Elevation ``atan2(w, hypot(u, v))`` in ``[-pi/2, pi/2]`` over a box.

    ``rho = hypot(u, v)`` ranges over ``[rho_lo, rho_hi]`` independently of
    ``w``; the elevation grows with ``w`` and, for ``w > 0``, falls with
    ``rho`` (rises for ``w < 0``): the extremes are at the corners
    ``(rho_hi, w_lo)`` or ``(rho_lo, w_lo)``, and ``(rho_lo, w_hi)`` or
    ``(rho_hi, w_hi)``, by the sign of ``w`` (Stolte Fig. 5). A box holding
    the axis has ``rho_lo = 0``, giving ``+-pi/2`` as it should; the branch cut
    of ``atan2`` is never met because ``rho >= 0``.
    """
    rlo = rounding.down_nonneg(_norm(mignitude(ulo, uhi), mignitude(vlo, vhi)), P)
    rhi = rounding.up_nonneg(_norm(magnitude(ulo, uhi), magnitude(vlo, vhi)), P)
    # rho_hi where w >= 0 else rho_lo, and the reverse, chosen without np.where
    # (slow on mixed masks): 0 <= rho_lo <= rho_hi, and rho_lo is never -0
    lo = np.arctan2(wlo, np.fmax(rlo, rhi * (wlo >= 0.0)))
    hi = np.arctan2(whi, np.fmax(rlo, rhi * (whi < 0.0)))
    lo, hi = rounding.down(lo, T), rounding.up(hi, T)
    return np.maximum(lo, filled_like(-HALF_PI_UP, lo)), np.minimum(hi, filled_like(HALF_PI_UP, hi))


TWO_PI_UP = float(np.nextafter(2.0 * np.pi, INF))


def angle_interval(vlo, vhi, ulo, uhi):
    """``theta = atan2(v, u)`` over a box, unwrapped across the branch cut.

    Returns ``(lo, hi, whole)``. A box that straddles the negative ``u`` axis
    (the cut) gets ``[atan2(v_hi, u_hi), atan2(v_lo, u_hi) + 2 pi]``: an
    interval that holds every angle of the box *modulo 2 pi*, so it is valid
    only inside functions of period ``2 pi`` (``sin(k theta + c)`` with
    integer ``k``). ``whole`` marks boxes that hold the origin (every angle;
    their interval is ``[-pi, pi]``).
    """
    lo, hi = _unwrapped_angle(vlo, vhi, ulo, uhi)
    whole = (ulo <= 0.0) & (uhi >= 0.0) & (vlo <= 0.0) & (vhi >= 0.0)
    return lo, hi, whole


def _unwrapped_angle(vlo, vhi, ulo, uhi):
    lo, hi = i_atan2(vlo, vhi, ulo, uhi)
    cut = (uhi < 0.0) & (vlo <= 0.0) & (vhi >= 0.0)
    if np.any(cut):   # few boxes: computed on those alone
        flat = np.flatnonzero(cut)   # (np.nonzero is slow on many axes)
        where = np.unravel_index(flat, cut.shape)
        v_lo, v_hi, u_hi = (np.broadcast_to(a, cut.shape)[where] for a in (vlo, vhi, uhi))
        lo = np.array(np.broadcast_to(lo, cut.shape), order="C")
        hi = np.array(np.broadcast_to(hi, cut.shape), order="C")
        lo.reshape(-1)[flat] = rounding.down(np.arctan2(v_hi, u_hi), T)
        # v = +0 is on the upper side (atan2 gives +pi there): as -0 it gives -pi,
        # and the unwrapped end pi, not 3 pi
        hi.reshape(-1)[flat] = rounding.up(rounding.up(np.arctan2(np.copysign(v_lo, -1.0), u_hi), T)
                                    + TWO_PI_UP)
    return lo, hi


def i_periodic_angle(vlo, vhi, ulo, uhi, fn: str, k: float, c: float):
    """``sin`` or ``cos`` of ``k * atan2(v, u) + c`` for an integer ``k``, tight
    across the branch cut (see :func:`angle_interval`). A box holding the
    origin has the angle interval ``[-pi, pi]``, ``k`` times which holds a
    whole period for ``k != 0``: its enclosure is ``[-1, 1]`` without a test
    (and for ``k = 0`` the function is the constant it gives)."""
    alo, ahi = _unwrapped_angle(vlo, vhi, ulo, uhi)
    alo, ahi = i_mulc(alo, ahi, k)
    if c != 0.0:
        alo, ahi = i_addc(alo, ahi, c)
    return (i_sin if fn == "sin" else i_cos)(alo, ahi)
