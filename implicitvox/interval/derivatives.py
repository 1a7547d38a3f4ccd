"""Interval derivative rules: enclosures of the gradient over a box.

Each rule takes the argument value intervals ``(lo, hi)`` (arrays ``(n,)``),
the argument gradient intervals (arrays ``(3, n)``) and the result's value
interval, and returns the result's gradient interval plus a boolean array of
lanes where the mean value theorem does not hold over the box (a domain
boundary, a pole, the ``atan2`` branch cut, a ``floor`` jump) or ``None``.

The rules are the chain rule written with the outward-rounded kernels of
:mod:`implicitvox.interval.kernels`, so they enclose every derivative value. For the
Lipschitz but non-smooth ``abs``, ``min`` and ``max`` the rule returns the
hull of the one-sided gradients (Clarke's generalized gradient), for which
Lebourg's mean value theorem holds.
"""
from __future__ import annotations

import numpy as np

from . import kernels

__all__ = ["d_abs", "d_acos", "d_add", "d_addc", "d_asin", "d_atan", "d_atan2", "d_cos", "d_distance", "d_div", "d_divc", "d_elevation", "d_exp", "d_floor", "d_hypot", "d_log", "d_max", "d_min", "d_mul", "d_mulc", "d_neg", "d_periodic_angle", "d_powi", "d_powr", "d_radius", "d_rsubc", "d_sin", "d_sqrt", "d_square", "d_sub", "d_tan"]


def _hull(alo, ahi, blo, bhi):
    return np.minimum(alo, blo), np.maximum(ahi, bhi)


def d_add(v, g, out, p):
    return kernels.i_add(*g[0], *g[1]), None


def d_sub(v, g, out, p):
    return kernels.i_sub(*g[0], *g[1]), None


def d_mul(v, g, out, p):
    left = kernels.i_mul(*g[0], *v[1])
    right = kernels.i_mul(*v[0], *g[1])
    return kernels.i_add(*left, *right), None


def d_div(v, g, out, p):
    num = kernels.i_sub(*g[0], *kernels.i_mul(*out, *g[1]))
    return kernels.i_div(*num, *v[1]), None


def d_square(v, g, out, p):
    return kernels.i_mul(*kernels.i_mulc(*v[0], 2.0), *g[0]), None


def d_powi(v, g, out, p):
    if p == 0:
        zero = np.zeros_like(g[0][0])
        return (zero, zero), None
    factor = kernels.i_mulc(*kernels.i_powi(*v[0], p - 1), float(p))
    return kernels.i_mul(*factor, *g[0]), None


def d_powr(v, g, out, p):
    lo, hi, _ = kernels.i_powr(*v[0], p - 1.0)
    return kernels.i_mul(*kernels.i_mulc(lo, hi, p), *g[0]), ~(v[0][0] > 0.0)


def d_sqrt(v, g, out, p):
    return kernels.i_div(*g[0], *kernels.i_mulc(*out, 2.0)), ~(v[0][0] > 0.0)


def d_abs(v, g, out, p):
    alo, ahi = v[0]
    glo, ghi = g[0]
    m = np.maximum(-glo, ghi)
    lo = np.where(alo >= 0.0, glo, np.where(ahi <= 0.0, -ghi, -m))
    hi = np.where(alo >= 0.0, ghi, np.where(ahi <= 0.0, -glo, m))
    return (lo, hi), None


def d_exp(v, g, out, p):
    return kernels.i_mul(*out, *g[0]), None


def d_log(v, g, out, p):
    return kernels.i_div(*g[0], *v[0]), ~(v[0][0] > 0.0)


def d_sin(v, g, out, p):
    return kernels.i_mul(*kernels.i_cos(*v[0]), *g[0]), None


def d_cos(v, g, out, p):
    return kernels.i_mul(*kernels.i_neg(*kernels.i_sin(*v[0])), *g[0]), None


def d_tan(v, g, out, p):
    slope = kernels.i_addc(*kernels.i_square(*out), 1.0)
    return kernels.i_mul(*slope, *g[0]), ~(np.isfinite(out[0]) & np.isfinite(out[1]))


def d_atan(v, g, out, p):
    return kernels.i_div(*g[0], *kernels.i_addc(*kernels.i_square(*v[0]), 1.0)), None


def _inverse_sqrt_one_minus_square(a):
    lo, hi, _ = kernels.i_sqrt(*kernels.i_rsubc(*kernels.i_square(*a), 1.0))
    return lo, hi


def d_asin(v, g, out, p):
    inside = (v[0][0] > -1.0) & (v[0][1] < 1.0)
    return kernels.i_div(*g[0], *_inverse_sqrt_one_minus_square(v[0])), ~inside


def d_acos(v, g, out, p):
    inside = (v[0][0] > -1.0) & (v[0][1] < 1.0)
    return kernels.i_neg(*kernels.i_div(*g[0], *_inverse_sqrt_one_minus_square(v[0]))), ~inside


def d_atan2(v, g, out, p):
    (ylo, yhi), (xlo, xhi) = v
    num = kernels.i_sub(*kernels.i_mul(xlo, xhi, *g[0]), *kernels.i_mul(ylo, yhi, *g[1]))
    den = kernels.i_add(*kernels.i_square(xlo, xhi), *kernels.i_square(ylo, yhi))
    cut = (xlo <= 0.0) & (ylo <= 0.0) & (yhi >= 0.0)  # as in i_atan2: jump or origin
    return kernels.i_div(*num, *den), cut


def d_hypot(v, g, out, p):
    num = kernels.i_add(*kernels.i_mul(*v[0], *g[0]), *kernels.i_mul(*v[1], *g[1]))
    return kernels.i_div(*num, *out), None


def d_min(v, g, out, p):
    (alo, ahi), (blo, bhi) = v
    hlo, hhi = _hull(*g[0], *g[1])
    a_wins, b_wins = ahi < blo, bhi < alo
    lo = np.where(a_wins, g[0][0], np.where(b_wins, g[1][0], hlo))
    hi = np.where(a_wins, g[0][1], np.where(b_wins, g[1][1], hhi))
    return (lo, hi), None


def d_max(v, g, out, p):
    (alo, ahi), (blo, bhi) = v
    hlo, hhi = _hull(*g[0], *g[1])
    a_wins, b_wins = alo > bhi, blo > ahi
    lo = np.where(a_wins, g[0][0], np.where(b_wins, g[1][0], hlo))
    hi = np.where(a_wins, g[0][1], np.where(b_wins, g[1][1], hhi))
    return (lo, hi), None


def d_floor(v, g, out, p):
    zero = np.zeros_like(g[0][0])
    return (zero, zero), np.floor(v[0][0]) != np.floor(v[0][1])


def d_radius(v, g, out, p):
    num = kernels.i_add(*kernels.i_add(*kernels.i_mul(*v[0], *g[0]), *kernels.i_mul(*v[1], *g[1])),
                  *kernels.i_mul(*v[2], *g[2]))
    return kernels.i_div(*num, *out), None


def d_distance(v, g, out, p):
    offsets = [kernels.i_addc(*vi, -ci) for vi, ci in zip(v, p)]
    num = kernels.i_add(*kernels.i_add(*kernels.i_mul(*offsets[0], *g[0]),
                                       *kernels.i_mul(*offsets[1], *g[1])),
                        *kernels.i_mul(*offsets[2], *g[2]))
    return kernels.i_div(*num, *out), None


def _holds_origin(*intervals):
    held = True
    for lo, hi in intervals:
        held = held & (lo <= 0.0) & (hi >= 0.0)
    return held


def d_elevation(v, g, out, p):
    u, vv, w = v
    rho = kernels.i_hypot(*u, *vv)
    drho = kernels.i_div(*kernels.i_add(*kernels.i_mul(*u, *g[0]), *kernels.i_mul(*vv, *g[1])),
                         *rho)
    num = kernels.i_sub(*kernels.i_mul(*rho, *g[2]), *kernels.i_mul(*w, *drho))
    den = kernels.i_add(*kernels.i_square(*rho), *kernels.i_square(*w))
    return kernels.i_div(*num, *den), _holds_origin(u, vv, w)


def d_periodic_angle(v, g, out, p):
    fn, k, c = p
    (vlo, vhi), (ulo, uhi) = v
    other = "cos" if fn == "sin" else "sin"
    slope = kernels.i_periodic_angle(vlo, vhi, ulo, uhi, other, k, c)
    if fn == "cos":
        slope = kernels.i_neg(*slope)
    dtheta = kernels.i_div(*kernels.i_sub(*kernels.i_mul(ulo, uhi, *g[0]),
                                          *kernels.i_mul(vlo, vhi, *g[1])),
                           *kernels.i_add(*kernels.i_square(ulo, uhi), *kernels.i_square(vlo, vhi)))
    return kernels.i_mul(*kernels.i_mulc(*slope, k), *dtheta), _holds_origin(v[0], v[1])


def d_neg(v, g, out, p):
    return kernels.i_neg(*g[0]), None


def d_addc(v, g, out, p):
    return g[0], None


def d_rsubc(v, g, out, p):
    return kernels.i_neg(*g[0]), None


def d_mulc(v, g, out, p):
    return kernels.i_mulc(*g[0], p), None


def d_divc(v, g, out, p):
    return kernels.i_divc(*g[0], p), None
