"""Point evaluator: one numpy pass per tape instruction over a batch of points."""
from __future__ import annotations

import numpy as np

from .tape import Tape
from .. import batches

__all__ = ["evaluate_points", "apply_point"]

CHUNK = batches.POINTS


def evaluate_points(tape: Tape, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray) -> np.ndarray:
    """Values of the taped function at the points ``(xs[i], ys[i], zs[i])``.

    ``xs, ys, zs`` are 1-D float arrays of one length. Outside a function's
    domain the value is NaN, as numpy computes it.
    """
    n = xs.shape[0]
    if n > CHUNK:
        return np.concatenate([_evaluate(tape, xs[s:s + CHUNK], ys[s:s + CHUNK], zs[s:s + CHUNK])
                               for s in range(0, n, CHUNK)])
    return _evaluate(tape, xs, ys, zs)


def _evaluate(tape, xs, ys, zs):
    n = xs.shape[0]
    if tape.undefined:
        return np.full(n, np.nan)
    regs: list = [None] * tape.n_registers
    for name, column in (("x", xs), ("y", ys), ("z", zs)):
        if tape.inputs[name] >= 0:
            regs[tape.inputs[name]] = column
    for c in tape.constants:
        regs[c.register] = np.float64(c.value)
    with np.errstate(all="ignore"):
        for ins in tape.instructions:
            regs[ins.out] = apply_point(ins.op, tuple(regs[a] for a in ins.args), ins.param)
    return np.array(np.broadcast_to(regs[tape.output], (n,)), dtype=np.float64)


def apply_point(op, args: tuple, param):
    """One instruction's point values: the row's kernel, or its oracle driven
    by this evaluator."""
    return param.point(args, evaluate_points) if op.oracle else op.point(args, param)
