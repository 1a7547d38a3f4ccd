"""Reference evaluators for tests: exact values with mpmath, and mpmath's ``iv`` context."""
from __future__ import annotations

import mpmath
from mpmath import iv

from implicitvox.expr.nodes import Expr

from implicitvox.eval.reference import EXP_LIMIT, PERIODIC_LIMIT, mp_evaluate

DPS = 60


def mp_value(expr: Expr, point, dps: int = DPS):
    """Exact (to ``dps`` digits) value of ``expr`` at ``point``; None where undefined."""
    return mp_evaluate(expr, point, dps)


def contains(lo: float, hi: float, value) -> bool:
    """``lo <= value <= hi`` compared exactly (floats convert to mpf exactly)."""
    return mpmath.mpf(lo) <= value <= mpmath.mpf(hi)


def _iv_periodic(f, a):
    """iv.sin/cos, but [-1, 1] for arguments beyond 1e15 (mpmath would compute pi
    to thousands of digits; our kernel also returns [-1, 1] there)."""
    if max(abs(a.a), abs(a.b)) > PERIODIC_LIMIT:
        return iv.mpf([-1, 1])
    return f(a)


def _iv_exp(a):
    """iv.exp, refusing arguments beyond 1e4 (ln 2 to as many digits)."""
    if max(abs(a.a), abs(a.b)) > EXP_LIMIT:
        raise OverflowError("exp argument too large to compare")
    return iv.exp(a)


IV_OPS = {
    "add": lambda a, p: a[0] + a[1],
    "sub": lambda a, p: a[0] - a[1],
    "mul": lambda a, p: a[0] * a[1],
    "div": lambda a, p: a[0] / a[1],
    "neg": lambda a, p: -a[0],
    "square": lambda a, p: a[0] ** 2,
    "powi": lambda a, p: a[0] ** p,
    "exp": lambda a, p: _iv_exp(a[0]),
    "sin": lambda a, p: _iv_periodic(iv.sin, a[0]),
    "cos": lambda a, p: _iv_periodic(iv.cos, a[0]),
    "abs": lambda a, p: abs(a[0]),
    "min": lambda a, p: iv.mpf([min(a[0].a, a[1].a), min(a[0].b, a[1].b)]),
    "max": lambda a, p: iv.mpf([max(a[0].a, a[1].a), max(a[0].b, a[1].b)]),
}


class Unbounded(ArithmeticError):
    """An intermediate of ``iv_interval`` was unbounded (a division by an interval
    holding 0): mpmath's conventions (``0 * [-inf, inf] = [-inf, inf]``) and ours
    (``0``) differ from there on, even where a bounded function (``sin``) follows."""


def iv_interval(expr: Expr, lo, hi, dps: int = 40):
    """mpmath ``iv`` natural interval extension of ``expr`` over a box (ops in IV_OPS).

    Raises :class:`Unbounded` when an intermediate interval is not finite."""
    iv.dps = dps
    vals = {}
    box = {n: iv.mpf([float(a), float(b)]) for n, a, b in zip("xyz", lo, hi)}
    for node in expr.walk():
        if node.op == "var":
            v = box[node.param]
        elif node.op == "const":
            v = iv.mpf(node.param)
        elif node.op == "mul" and node.args[0].equals(node.args[1]):
            v = vals[id(node.args[0])] ** 2  # the tape rewrites a * a as square(a)
        else:
            v = IV_OPS[node.op]([vals[id(a)] for a in node.args], node.param)
        if not (mpmath.isfinite(v.a) and mpmath.isfinite(v.b)):
            raise Unbounded(f"{node.op} is unbounded over the box")
        vals[id(node)] = v
    return vals[id(expr)]
