"""Interval derivative rules: enclosures of the gradient over a box.

Each rule takes the argument value intervals ``(lo, hi)`` (arrays ``(n,)``),
the argument gradient intervals (arrays ``(3, n)``) and the result's value
interval, and returns the result's gradient interval plus a boolean array of
lanes where the mean value theorem does not hold over the box (a domain
boundary, a pole, the ``atan2`` branch cut, a ``floor`` jump) or ``None``.

The rules are the chain rule written with the outward-rounded kernels of
:mod:`implicitvox.interval`, so they enclose every derivative value. For the
Lipschitz but non-smooth ``abs``, ``min`` and ``max`` the rule returns the
hull of the one-sided gradients (Clarke's generalized gradient), for which
Lebourg's mean value theorem holds.
"""
from __future__ import annotations

import numpy as np

from . import interval as I

__all__ = ["RULES"]


def _hull(alo, ahi, blo, bhi):
    return np.minimum(alo, blo), np.maximum(ahi, bhi)


def _d_add(v, g, out, p):
    return I.i_add(*g[0], *g[1]), None


def _d_sub(v, g, out, p):
    return I.i_sub(*g[0], *g[1]), None


def _d_mul(v, g, out, p):
    left = I.i_mul(*g[0], *v[1])
    right = I.i_mul(*v[0], *g[1])
    return I.i_add(*left, *right), None


def _d_div(v, g, out, p):
    num = I.i_sub(*g[0], *I.i_mul(*out, *g[1]))
    return I.i_div(*num, *v[1]), None


def _d_square(v, g, out, p):
    return I.i_mul(*I.i_mulc(*v[0], 2.0), *g[0]), None


def _d_powi(v, g, out, p):
    if p == 0:
        zero = np.zeros_like(g[0][0])
        return (zero, zero), None
    factor = I.i_mulc(*I.i_powi(*v[0], p - 1), float(p))
    return I.i_mul(*factor, *g[0]), None


def _d_powr(v, g, out, p):
    lo, hi, _ = I.i_powr(*v[0], p - 1.0)
    return I.i_mul(*I.i_mulc(lo, hi, p), *g[0]), ~(v[0][0] > 0.0)


def _d_sqrt(v, g, out, p):
    return I.i_div(*g[0], *I.i_mulc(*out, 2.0)), ~(v[0][0] > 0.0)


def _d_abs(v, g, out, p):
    alo, ahi = v[0]
    glo, ghi = g[0]
    m = np.maximum(-glo, ghi)
    lo = np.where(alo >= 0.0, glo, np.where(ahi <= 0.0, -ghi, -m))
    hi = np.where(alo >= 0.0, ghi, np.where(ahi <= 0.0, -glo, m))
    return (lo, hi), None


def _d_exp(v, g, out, p):
    return I.i_mul(*out, *g[0]), None


def _d_log(v, g, out, p):
    return I.i_div(*g[0], *v[0]), ~(v[0][0] > 0.0)


def _d_sin(v, g, out, p):
    return I.i_mul(*I.i_cos(*v[0]), *g[0]), None


def _d_cos(v, g, out, p):
    return I.i_mul(*I.i_neg(*I.i_sin(*v[0])), *g[0]), None


def _d_tan(v, g, out, p):
    slope = I.i_addc(*I.i_square(*out), 1.0)
    return I.i_mul(*slope, *g[0]), ~(np.isfinite(out[0]) & np.isfinite(out[1]))


def _d_atan(v, g, out, p):
    return I.i_div(*g[0], *I.i_addc(*I.i_square(*v[0]), 1.0)), None


def _inverse_sqrt_one_minus_square(a):
    lo, hi, _ = I.i_sqrt(*I.i_rsubc(*I.i_square(*a), 1.0))
    return lo, hi


def _d_asin(v, g, out, p):
    inside = (v[0][0] > -1.0) & (v[0][1] < 1.0)
    return I.i_div(*g[0], *_inverse_sqrt_one_minus_square(v[0])), ~inside


def _d_acos(v, g, out, p):
    inside = (v[0][0] > -1.0) & (v[0][1] < 1.0)
    return I.i_neg(*I.i_div(*g[0], *_inverse_sqrt_one_minus_square(v[0]))), ~inside


def _d_atan2(v, g, out, p):
    (ylo, yhi), (xlo, xhi) = v
    num = I.i_sub(*I.i_mul(xlo, xhi, *g[0]), *I.i_mul(ylo, yhi, *g[1]))
    den = I.i_add(*I.i_square(xlo, xhi), *I.i_square(ylo, yhi))
    cut = (xlo <= 0.0) & (ylo <= 0.0) & (yhi >= 0.0)  # as in i_atan2: jump or origin
    return I.i_div(*num, *den), cut


def _d_hypot(v, g, out, p):
    num = I.i_add(*I.i_mul(*v[0], *g[0]), *I.i_mul(*v[1], *g[1]))
    return I.i_div(*num, *out), None


def _d_min(v, g, out, p):
    (alo, ahi), (blo, bhi) = v
    hlo, hhi = _hull(*g[0], *g[1])
    a_wins, b_wins = ahi < blo, bhi < alo
    lo = np.where(a_wins, g[0][0], np.where(b_wins, g[1][0], hlo))
    hi = np.where(a_wins, g[0][1], np.where(b_wins, g[1][1], hhi))
    return (lo, hi), None


def _d_max(v, g, out, p):
    (alo, ahi), (blo, bhi) = v
    hlo, hhi = _hull(*g[0], *g[1])
    a_wins, b_wins = alo > bhi, blo > ahi
    lo = np.where(a_wins, g[0][0], np.where(b_wins, g[1][0], hlo))
    hi = np.where(a_wins, g[0][1], np.where(b_wins, g[1][1], hhi))
    return (lo, hi), None


def _d_floor(v, g, out, p):
    zero = np.zeros_like(g[0][0])
    return (zero, zero), np.floor(v[0][0]) != np.floor(v[0][1])


def _d_radius(v, g, out, p):
    num = I.i_add(*I.i_add(*I.i_mul(*v[0], *g[0]), *I.i_mul(*v[1], *g[1])),
                  *I.i_mul(*v[2], *g[2]))
    return I.i_div(*num, *out), None


def _d_distance(v, g, out, p):
    offsets = [I.i_addc(*vi, -ci) for vi, ci in zip(v, p)]
    num = I.i_add(*I.i_add(*I.i_mul(*offsets[0], *g[0]), *I.i_mul(*offsets[1], *g[1])),
                  *I.i_mul(*offsets[2], *g[2]))
    return I.i_div(*num, *out), None


def _holds_origin(*intervals):
    held = True
    for lo, hi in intervals:
        held = held & (lo <= 0.0) & (hi >= 0.0)
    return held


def _d_elevation(v, g, out, p):
    u, vv, w = v
    rho = I.i_hypot(*u, *vv)
    drho = I.i_div(*I.i_add(*I.i_mul(*u, *g[0]), *I.i_mul(*vv, *g[1])), *rho)
    num = I.i_sub(*I.i_mul(*rho, *g[2]), *I.i_mul(*w, *drho))
    den = I.i_add(*I.i_square(*rho), *I.i_square(*w))
    return I.i_div(*num, *den), _holds_origin(u, vv, w)


def _d_periodic_angle(v, g, out, p):
    fn, k, c = p
    (vlo, vhi), (ulo, uhi) = v
    other = "cos" if fn == "sin" else "sin"
    slope = I.i_periodic_angle(vlo, vhi, ulo, uhi, other, k, c)
    if fn == "cos":
        slope = I.i_neg(*slope)
    dtheta = I.i_div(*I.i_sub(*I.i_mul(ulo, uhi, *g[0]), *I.i_mul(vlo, vhi, *g[1])),
                     *I.i_add(*I.i_square(ulo, uhi), *I.i_square(vlo, vhi)))
    return I.i_mul(*I.i_mulc(*slope, k), *dtheta), _holds_origin(v[0], v[1])


RULES = {
    "repeat": lambda v, g, o, p: p.interval_derivative(v, g, o, p),
    "repeat_polar": lambda v, g, o, p: p.interval_derivative(v, g, o, p),
    "radius": _d_radius, "distance": _d_distance, "elevation": _d_elevation, "periodic_angle": _d_periodic_angle,
    "add": _d_add, "sub": _d_sub, "mul": _d_mul, "div": _d_div,
    "neg": lambda v, g, o, p: (I.i_neg(*g[0]), None),
    "addc": lambda v, g, o, p: (g[0], None),
    "rsubc": lambda v, g, o, p: (I.i_neg(*g[0]), None),
    "mulc": lambda v, g, o, p: (I.i_mulc(*g[0], p), None),
    "divc": lambda v, g, o, p: (I.i_divc(*g[0], p), None),
    "square": _d_square, "powi": _d_powi, "powr": _d_powr, "sqrt": _d_sqrt, "abs": _d_abs,
    "exp": _d_exp, "log": _d_log, "sin": _d_sin, "cos": _d_cos, "tan": _d_tan, "atan": _d_atan,
    "asin": _d_asin, "acos": _d_acos, "atan2": _d_atan2, "hypot": _d_hypot,
    "min": _d_min, "max": _d_max, "floor": _d_floor,
}
