"""Exact evaluation with mpmath: the oracle the tests hold the kernels to.

Not on any hot path: one point at a time, at ``dps`` decimal digits.

Examples
--------
>>> from implicitvox import x, y, sin
>>> from implicitvox.eval.reference import mp_evaluate
>>> float(mp_evaluate(sin(x) * y, (1.0, 2.0, 0.0)))
1.682941969615793
"""
from __future__ import annotations

from typing import Any, Optional, Sequence

import mpmath

from .opcodes import EXP_LIMIT, OPCODES, PERIODIC_LIMIT
from .tape import compiled_oracle

__all__ = ["mp_evaluate", "apply_reference", "PERIODIC_LIMIT", "EXP_LIMIT"]

#: the opcode rows' limits (``Opcode.reference_limit``) as mpmath numbers
PERIODIC_LIMIT = mpmath.mpf(PERIODIC_LIMIT)
EXP_LIMIT = mpmath.mpf(EXP_LIMIT)


def mp_evaluate(expr: Any, point: Sequence[Any], dps: int = 60) -> Optional[Any]:
    """Value of ``expr`` at ``point`` to ``dps`` digits; None where undefined
    (or beyond the limits above)."""
    with mpmath.workdps(dps):
        coords = dict(zip("xyz", (c if isinstance(c, mpmath.mpf) else mpmath.mpf(float(c))
                                  for c in point)))
        vals: dict[int, Any] = {}
        for node in expr.walk():
            if node.op == "var":
                v = coords[node.param]
            elif node.op == "const":
                v = mpmath.mpf(node.param)
            else:
                args = [vals[id(a)] for a in node.args]
                if any(a is None for a in args):
                    v = None
                elif OPCODES[node.op].reference_limit is not None and \
                        abs(args[0]) > OPCODES[node.op].reference_limit:
                    v = None
                else:
                    v = apply_reference(OPCODES[node.op], args, node.param)
            vals[id(node)] = v
        return vals[id(expr)]


def apply_reference(op, args: list, param) -> Optional[Any]:
    """One operation's exact value at mpmath arguments (``None`` where undefined);
    an oracle row's parameter may be the expression's or the tape's."""
    if op.oracle:
        return compiled_oracle(op.name, param).reference(args, mp_evaluate)
    return op.reference(args, param)
