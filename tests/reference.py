"""Reference evaluators for tests: exact values with mpmath, and mpmath's ``iv`` context."""
from __future__ import annotations

import mpmath
from mpmath import iv

from implicitvox.expr import Expr
from implicitvox.opcodes import OPCODES

DPS = 60
#: periodic functions of larger arguments are not checked pointwise (mpmath would
#: need pi to thousands of digits); the per-opcode tests cover them up to 1e15.
PERIODIC_LIMIT = mpmath.mpf(10) ** 15
_PERIODIC = {"sin", "cos", "tan"}
#: exp of larger arguments is not checked pointwise either (mpmath would need
#: ln 2 to as many digits); the per-opcode tests cover exp on [-800, 800].
EXP_LIMIT = mpmath.mpf(10) ** 4


def mp_value(expr: Expr, point, dps: int = DPS):
    """Exact (to ``dps`` digits) value of ``expr`` at ``point``; None where undefined."""
    with mpmath.workdps(dps):
        vals = {}
        coords = dict(zip("xyz", (c if isinstance(c, mpmath.mpf) else mpmath.mpf(float(c)) for c in point)))
        for node in expr.walk():
            if node.op == "var":
                v = coords[node.param]
            elif node.op == "const":
                v = mpmath.mpf(node.param)
            else:
                args = [vals[id(a)] for a in node.args]
                if any(a is None for a in args):
                    v = None
                elif node.op in _PERIODIC and abs(args[0]) > PERIODIC_LIMIT:
                    v = None
                elif node.op == "exp" and abs(args[0]) > EXP_LIMIT:
                    v = None
                else:
                    v = OPCODES[node.op].reference(args, node.param)
            vals[id(node)] = v
        return vals[id(expr)]


def contains(lo: float, hi: float, value) -> bool:
    """``lo <= value <= hi`` compared exactly (floats convert to mpf exactly)."""
    return mpmath.mpf(lo) <= value <= mpmath.mpf(hi)


def _iv_endpoints(f, a):
    return iv.mpf([f(a.a), f(a.b)])


IV_OPS = {
    "add": lambda a, p: a[0] + a[1],
    "sub": lambda a, p: a[0] - a[1],
    "mul": lambda a, p: a[0] * a[1],
    "div": lambda a, p: a[0] / a[1],
    "neg": lambda a, p: -a[0],
    "square": lambda a, p: a[0] ** 2,
    "powi": lambda a, p: a[0] ** p,
    "exp": lambda a, p: iv.exp(a[0]),
    "sin": lambda a, p: iv.sin(a[0]),
    "cos": lambda a, p: iv.cos(a[0]),
    "abs": lambda a, p: abs(a[0]),
    "min": lambda a, p: iv.mpf([min(a[0].a, a[1].a), min(a[0].b, a[1].b)]),
    "max": lambda a, p: iv.mpf([max(a[0].a, a[1].a), max(a[0].b, a[1].b)]),
}


def iv_interval(expr: Expr, lo, hi, dps: int = 40):
    """mpmath ``iv`` natural interval extension of ``expr`` over a box (ops in IV_OPS)."""
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
        vals[id(node)] = v
    return vals[id(expr)]
