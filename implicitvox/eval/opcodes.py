"""The opcode table: one row per operation, read by every evaluator.

Each :class:`Opcode` row carries

* ``point(args, param)`` - numpy values from numpy argument values;
* ``interval(los, his, param)`` - an outward-rounded enclosure
  (:mod:`implicitvox.interval.kernels`); rows with ``domain=True`` also return a
  boolean "empty" array (the argument lies wholly outside the domain);
* ``derivative(vals, grads, out, param)`` - forward-mode rule: the gradient
  of the result (shape ``(3, n)``) from the argument values and gradients;
* ``reference(args, param)`` - the exact value with mpmath at the working
  precision, or ``None`` where the operation is undefined. Tests use it as the
  oracle; nothing on a hot path calls it;
* ``interval_derivative`` - the interval chain rule
  (:mod:`implicitvox.interval.derivatives`), for the mean value form;
* ``float32`` and ``float32_params(param)`` - whether the interval kernel
  handles float32 ends, and whether float32 holds the row's parameter
  (:mod:`implicitvox.eval.float32_tapes`); ``constant_operand`` rows take a
  scalar parameter that becomes a two-float32 interval when it is not exact.

*Oracle* rows (the sweeps, ``oracle=True``) have no kernels of their own: the
instruction's parameter is a compiled sweep (:mod:`implicitvox.eval.oracles`)
that each evaluator drives, passing itself in.

A new operation is one new row (libfive's ``opcode.hpp`` works the same way).

Examples
--------
>>> from implicitvox.eval.opcodes import OPCODES
>>> OPCODES["sin"].arity
1
>>> sorted(name for name, op in OPCODES.items() if op.domain)
['acos', 'asin', 'log', 'powr', 'repeat', 'repeat_polar', 'sqrt']
>>> sorted(name for name, op in OPCODES.items() if op.oracle)
['repeat', 'repeat_polar']
>>> sorted(name for name, op in OPCODES.items() if op.choice)
['abs', 'max', 'min']
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..lazy import mpmath
from ..interval import derivatives
from ..interval import kernels
from ..interval.float32 import exact_in_float32, in_float32_range

__all__ = ["Opcode", "OPCODES", "opcode", "PERIODIC_LIMIT", "EXP_LIMIT"]

#: periodic functions of larger arguments have no mpmath reference
PERIODIC_LIMIT = 1e15
#: nor exp of larger arguments
EXP_LIMIT = 1e4


@dataclass(frozen=True)
class Opcode:
    """One row of the opcode table (see the module docstring)."""

    name: str
    arity: int
    point: Callable[..., Any] | None
    interval: Callable[..., Any] | None
    derivative: Callable[..., Any] | None
    reference: Callable[..., Any] | None
    #: interval chain rule (:mod:`implicitvox.interval.derivatives`), for the mean value form
    interval_derivative: Callable[..., Any] | None
    domain: bool = False
    #: interval kernel exact (no rounding): neg, abs, min, max, floor
    exact: bool = False
    #: made by the tape (an operation with an exact constant operand), not the DSL
    internal: bool = False
    #: the interval kernel handles float32 ends (its rounding and constants)
    float32: bool = False
    #: does float32 hold the parameter (rows with one)?
    float32_params: Callable[[Any], bool] = lambda param: True
    #: the parameter is a scalar operand, a two-float32 interval when not exact
    constant_operand: bool = False
    #: driven by the evaluators through its parameter (:mod:`implicitvox.eval.oracles`)
    oracle: bool = False
    #: the mpmath reference is not evaluated beyond this argument magnitude (it would
    #: need pi or ln 2 to thousands of digits); the value is then "not checked"
    reference_limit: float | None = None
    #: a branch over a box: which operand decides (min, max) or which sign (abs) can
    #: be settled by the operands' enclosures (:mod:`implicitvox.eval.pruning`)
    choice: bool = False

    def __reduce__(self):
        """Pickled by name: a tape sent to a worker process (:mod:`implicitvox.parallel`)
        finds the same row of :data:`OPCODES` there (its kernels are lambdas)."""
        return (opcode, (self.name,))


def opcode(name: str) -> Opcode:
    """The row of :data:`OPCODES` called ``name``."""
    return OPCODES[name]


def _un(f):
    return lambda a, p: f(a[0])


def _bin(f):
    return lambda a, p: f(a[0], a[1])


def _iun(f):
    return lambda lo, hi, p: f(lo[0], hi[0])


def _ibin(f):
    return lambda lo, hi, p: f(lo[0], hi[0], lo[1], hi[1])


def _mp_guard(f):
    """mpmath reference that maps a domain error or complex result to None."""
    def ref(a, p):
        try:
            v = f(a, p)
        except (ValueError, ZeroDivisionError):
            return None
        if v is None or isinstance(v, mpmath.mpc) or mpmath.isnan(v):
            return None
        return v
    return ref


def _mp_floor(a, p):
    return mpmath.floor(a[0])


def _point_powi(a, p):
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        return np.power(a[0], float(p))


def _point_powr(a, p):
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        return np.power(np.where(a[0] < 0.0, np.nan, a[0]), p)


def _d_powi(v, g, out, p):
    if p == 0:
        return g[0] * 0.0
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        return (p * np.power(v[0], float(p - 1))) * g[0]


def _d_powr(v, g, out, p):
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        return (p * np.power(v[0], p - 1.0)) * g[0]


def _d_div(v, g, out, p):
    return (g[0] - out * g[1]) / v[1]


def _d_atan2(v, g, out, p):
    yv, xv = v
    return (xv * g[0] - yv * g[1]) / (xv * xv + yv * yv)


def _d_minmax(pick_first):
    def rule(v, g, out, p):
        return np.where(pick_first(v[0], v[1]), g[0], g[1])
    return rule


def _mp_powr(a, p):
    if a[0] < 0:
        return None
    if a[0] == 0:
        return mpmath.mpf(0) if p > 0 else mpmath.inf
    return mpmath.power(a[0], mpmath.mpf(p))


def _mp_powi(a, p):
    if a[0] == 0 and p < 0:
        return None
    return a[0] ** p


def _mp_log(a, p):
    if a[0] < 0:
        return None
    return mpmath.log(a[0]) if a[0] > 0 else mpmath.ninf


def _mp_domain(name, lo, hi):
    """mpmath's ``name`` on ``[lo, hi]`` (``"inf"`` for no upper end), None outside."""
    def ref(a, p):
        top = mpmath.inf if hi == "inf" else hi
        return getattr(mpmath, name)(a[0]) if lo <= a[0] <= top else None
    return ref


def _mp_div(a, p):
    return None if a[1] == 0 else a[0] / a[1]


def _mp_atan2(a, p):
    if a[0] == 0 and a[1] == 0:
        return mpmath.mpf(0)
    return mpmath.atan2(a[0], a[1])


def _d_elevation(v, g, o, p):
    u, w = np.hypot(v[0], v[1]), v[2]
    du = (v[0] * g[0] + v[1] * g[1]) / u
    return (u * g[2] - w * du) / (u * u + w * w)


def _mp_elevation(a, p):
    rho = mpmath.sqrt(a[0] ** 2 + a[1] ** 2)
    return mpmath.mpf(0) if rho == 0 and a[2] == 0 else mpmath.atan2(a[2], rho)


def _point_periodic_angle(a, p):
    fn, k, c = p
    return (np.sin if fn == "sin" else np.cos)(k * np.arctan2(a[0], a[1]) + c)


def _d_periodic_angle(v, g, o, p):
    fn, k, c = p
    vv, uu = v
    angle = k * np.arctan2(vv, uu) + c
    slope = np.cos(angle) if fn == "sin" else -np.sin(angle)
    return slope * k * (uu * g[0] - vv * g[1]) / (uu * uu + vv * vv)


def _mp_periodic_angle(a, p):
    fn, k, c = p
    angle = mpmath.mpf(0) if a[0] == 0 and a[1] == 0 else mpmath.atan2(a[0], a[1])
    return (mpmath.sin if fn == "sin" else mpmath.cos)(k * angle + c)


def _point_distance(a, p):
    # the unfused tape's order exactly: ((a0 - c0)^2 + (a1 - c1)^2) + (a2 - c2)^2
    total = np.square(a[0] - p[0]) + np.square(a[1] - p[1])
    total = total + np.square(a[2] - p[2])
    return np.sqrt(total)


def _d_distance(v, g, out, p):
    return ((v[0] - p[0]) * g[0] + (v[1] - p[1]) * g[1] + (v[2] - p[2]) * g[2]) / out


def _mp_distance(a, p):
    return mpmath.sqrt(sum((ai - mpmath.mpf(ci)) ** 2 for ai, ci in zip(a, p)))


def _row(name, arity, point, interval, derivative, reference, rule, **kw) -> Opcode:
    return Opcode(name, arity, point, interval, derivative, _mp_guard(reference), rule, **kw)


def _distance_fits(param) -> bool:
    return all(exact_in_float32(c) for c in param)


def _angle_fits(param) -> bool:
    _, k, c = param
    return exact_in_float32(k) and exact_in_float32(c)


def _oracle(name: str) -> Opcode:
    return Opcode(name, 3, None, None, None, None, None, domain=True, oracle=True)


_ROWS = [
    _row("add", 2, _bin(np.add), _ibin(kernels.i_add),
         lambda v, g, o, p: g[0] + g[1], lambda a, p: a[0] + a[1],
         rule=derivatives.d_add, float32=True),
    _row("sub", 2, _bin(np.subtract), _ibin(kernels.i_sub),
         lambda v, g, o, p: g[0] - g[1], lambda a, p: a[0] - a[1],
         rule=derivatives.d_sub, float32=True),
    _row("mul", 2, _bin(np.multiply), _ibin(kernels.i_mul),
         lambda v, g, o, p: g[0] * v[1] + v[0] * g[1], lambda a, p: a[0] * a[1],
         rule=derivatives.d_mul, float32=True),
    _row("div", 2, _bin(np.divide), _ibin(kernels.i_div), _d_div, _mp_div,
         rule=derivatives.d_div),
    _row("neg", 1, _un(np.negative), _iun(kernels.i_neg),
         lambda v, g, o, p: -g[0], lambda a, p: -a[0], exact=True,
         rule=derivatives.d_neg, float32=True),
    _row("square", 1, _un(np.square), _iun(kernels.i_square),
         lambda v, g, o, p: (2.0 * v[0]) * g[0], lambda a, p: a[0] * a[0],
         rule=derivatives.d_square, float32=True),
    _row("powi", 1, _point_powi, lambda lo, hi, p: kernels.i_powi(lo[0], hi[0], p),
         _d_powi, _mp_powi,
         rule=derivatives.d_powi),
    _row("powr", 1, _point_powr, lambda lo, hi, p: kernels.i_powr(lo[0], hi[0], p),
         _d_powr, _mp_powr, domain=True,
         rule=derivatives.d_powr),
    _row("sqrt", 1, _un(np.sqrt), _iun(kernels.i_sqrt),
         lambda v, g, o, p: g[0] / (2.0 * o), _mp_domain("sqrt", 0, "inf"),
         domain=True,
         rule=derivatives.d_sqrt, float32=True),
    _row("abs", 1, _un(np.abs), _iun(kernels.i_abs),
         lambda v, g, o, p: np.sign(v[0]) * g[0], lambda a, p: abs(a[0]), exact=True,
         rule=derivatives.d_abs, float32=True, choice=True),
    _row("exp", 1, _un(np.exp), _iun(kernels.i_exp),
         lambda v, g, o, p: o * g[0], lambda a, p: mpmath.exp(a[0]),
         rule=derivatives.d_exp, reference_limit=EXP_LIMIT, float32=True),
    _row("log", 1, _un(np.log), _iun(kernels.i_log),
         lambda v, g, o, p: g[0] / v[0], _mp_log, domain=True,
         rule=derivatives.d_log),
    _row("sin", 1, _un(np.sin), _iun(kernels.i_sin),
         lambda v, g, o, p: np.cos(v[0]) * g[0], lambda a, p: mpmath.sin(a[0]),
         rule=derivatives.d_sin, reference_limit=PERIODIC_LIMIT, float32=True),
    _row("cos", 1, _un(np.cos), _iun(kernels.i_cos),
         lambda v, g, o, p: -np.sin(v[0]) * g[0], lambda a, p: mpmath.cos(a[0]),
         rule=derivatives.d_cos, reference_limit=PERIODIC_LIMIT, float32=True),
    _row("tan", 1, _un(np.tan), _iun(kernels.i_tan),
         lambda v, g, o, p: (1.0 + o * o) * g[0], lambda a, p: mpmath.tan(a[0]),
         rule=derivatives.d_tan, reference_limit=PERIODIC_LIMIT),
    _row("atan", 1, _un(np.arctan), _iun(kernels.i_atan),
         lambda v, g, o, p: g[0] / (1.0 + v[0] * v[0]), lambda a, p: mpmath.atan(a[0]),
         rule=derivatives.d_atan),
    _row("asin", 1, _un(np.arcsin), _iun(kernels.i_asin),
         lambda v, g, o, p: g[0] / np.sqrt(1.0 - v[0] * v[0]),
         _mp_domain("asin", -1, 1), domain=True,
         rule=derivatives.d_asin),
    _row("acos", 1, _un(np.arccos), _iun(kernels.i_acos),
         lambda v, g, o, p: -g[0] / np.sqrt(1.0 - v[0] * v[0]),
         _mp_domain("acos", -1, 1), domain=True,
         rule=derivatives.d_acos),
    _row("atan2", 2, _bin(np.arctan2), _ibin(kernels.i_atan2), _d_atan2, _mp_atan2,
         rule=derivatives.d_atan2, float32=True),
    _row("hypot", 2, _bin(np.hypot), _ibin(kernels.i_hypot),
         lambda v, g, o, p: (v[0] * g[0] + v[1] * g[1]) / o,
         lambda a, p: mpmath.sqrt(a[0] * a[0] + a[1] * a[1]),
         rule=derivatives.d_hypot, float32=True),
    _row("min", 2, _bin(np.minimum), _ibin(kernels.i_min),
         _d_minmax(lambda a, b: a <= b), lambda a, p: min(a[0], a[1]), exact=True,
         rule=derivatives.d_min, float32=True, choice=True),
    _row("max", 2, _bin(np.maximum), _ibin(kernels.i_max),
         _d_minmax(lambda a, b: a >= b), lambda a, p: max(a[0], a[1]), exact=True,
         rule=derivatives.d_max, float32=True, choice=True),
    # Tape-made forms of + - * / with an exact constant operand (the parameter):
    # two products instead of four, no sign cases (Stolte §2's constant rule).
    _row("addc", 1, lambda a, p: a[0] + p, lambda lo, hi, p: kernels.i_addc(lo[0], hi[0], p),
         lambda v, g, o, p: g[0], lambda a, p: a[0] + p, internal=True,
         rule=derivatives.d_addc, float32=True, float32_params=in_float32_range,
         constant_operand=True),
    _row("rsubc", 1, lambda a, p: p - a[0], lambda lo, hi, p: kernels.i_rsubc(lo[0], hi[0], p),
         lambda v, g, o, p: -g[0], lambda a, p: p - a[0], internal=True,
         rule=derivatives.d_rsubc, float32=True, float32_params=in_float32_range,
         constant_operand=True),
    _row("mulc", 1, lambda a, p: a[0] * p, lambda lo, hi, p: kernels.i_mulc(lo[0], hi[0], p),
         lambda v, g, o, p: p * g[0], lambda a, p: a[0] * p, internal=True,
         rule=derivatives.d_mulc, float32=True, float32_params=in_float32_range,
         constant_operand=True),
    _row("divc", 1, lambda a, p: a[0] / p, lambda lo, hi, p: kernels.i_divc(lo[0], hi[0], p),
         lambda v, g, o, p: g[0] / p, lambda a, p: a[0] / p, internal=True,
         rule=derivatives.d_divc),
    # Coordinates (Stolte §4.1.2); arguments (u, v, w), w along the axis.
    _row("radius", 3, lambda a, p: np.hypot(np.hypot(a[0], a[1]), a[2]),
         lambda lo, hi, p: kernels.i_radius(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]),
         lambda v, g, o, p: (v[0] * g[0] + v[1] * g[1] + v[2] * g[2]) / o,
         lambda a, p: mpmath.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2),
         rule=derivatives.d_radius, float32=True),
    # The tape's fused sqrt((a - c0)^2 + (b - c1)^2 + (w - c2)^2); the parameter
    # is the centre (c0, c1, c2). Spheres, cylinders and blobs are made of it.
    _row("distance", 3, _point_distance,
         lambda lo, hi, p: kernels.i_distance(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], p),
         _d_distance, _mp_distance, internal=True,
         rule=derivatives.d_distance, float32=True, float32_params=_distance_fits),
    _row("elevation", 3, lambda a, p: np.arctan2(a[2], np.hypot(a[0], a[1])),
         lambda lo, hi, p: kernels.i_elevation(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]),
         _d_elevation, _mp_elevation,
         rule=derivatives.d_elevation, float32=True),
    _row("periodic_angle", 2, _point_periodic_angle,
         lambda lo, hi, p: kernels.i_periodic_angle(lo[0], hi[0], lo[1], hi[1], *p),
         _d_periodic_angle, _mp_periodic_angle, internal=True,
         rule=derivatives.d_periodic_angle, float32=True, float32_params=_angle_fits),
    # Replication sweeps (Stolte §3): the parameter is the compiled sweep.
    _oracle("repeat"),
    _oracle("repeat_polar"),
    _row("floor", 1, _un(np.floor), _iun(kernels.i_floor),
         lambda v, g, o, p: g[0] * 0.0, _mp_floor, exact=True,
         rule=derivatives.d_floor),
]

#: name -> :class:`Opcode`, the single table of operations.
OPCODES: dict[str, Opcode] = {row.name: row for row in _ROWS}
