"""Gradient evaluator: forward-mode derivatives, one pass per tape instruction.

Each register holds a value array ``(n,)`` and a gradient array ``(3, n)``;
every opcode row's ``derivative`` rule maps argument values and gradients to
the result's gradient. ``min``/``max`` take the gradient of the chosen branch,
``abs`` and ``floor`` their one-sided (almost-everywhere) derivatives.
"""
from __future__ import annotations

import numpy as np

from .point import apply_point
from .tape import Tape

__all__ = ["evaluate_gradients"]


def evaluate_gradients(tape: Tape, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Values ``(n,)`` and gradients ``(3, n)`` at the points ``(xs, ys, zs)``."""
    n = xs.shape[0]
    if tape.undefined:
        return np.full(n, np.nan), np.full((3, n), np.nan)
    vals: list = [None] * tape.n_registers
    grads: list = [None] * tape.n_registers
    for axis, (name, column) in enumerate((("x", xs), ("y", ys), ("z", zs))):
        r = tape.inputs[name]
        if r >= 0:
            unit = np.zeros((3, 1))
            unit[axis] = 1.0
            vals[r], grads[r] = column, unit
    zero = np.zeros((3, 1))
    for c in tape.constants:
        vals[c.register], grads[c.register] = np.float64(c.value), zero
    with np.errstate(all="ignore"):
        for ins in tape.instructions:
            args = tuple(vals[a] for a in ins.args)
            arg_grads = tuple(grads[a] for a in ins.args)
            out = apply_point(ins.op, args, ins.param)
            if ins.op.oracle:
                grads[ins.out] = ins.param.derivative(args, arg_grads, out, evaluate_gradients)
            else:
                grads[ins.out] = ins.op.derivative(args, arg_grads, out, ins.param)
            vals[ins.out] = out
    value = np.array(np.broadcast_to(vals[tape.output], (n,)), dtype=np.float64)
    grad = np.array(np.broadcast_to(grads[tape.output], (3, n)), dtype=np.float64)
    return value, grad
