"""Values and gradients at points on the pruned tapes of a pool, in compiled code.

The compiled subdivision leaves each surface voxel with a tape of a
:class:`~implicitvox.eval.tape_pool.TapePool` (thousands of short tapes on a
many-part model). Building each as a Python :class:`~implicitvox.eval.tape.Tape`
and running :func:`~implicitvox.eval.gradient.evaluate_gradients` on its few
voxels costs far more than the arithmetic; :func:`pool_gradients` runs the
pool's rows directly, point by point, with forward-mode derivatives (Stolte §2:
normals from the gradient).

The rules are those of :mod:`implicitvox.eval.opcodes` (the ``derivative``
column), operation for operation, so values and gradients equal
:func:`~implicitvox.eval.gradient.evaluate_gradients`'s bit for bit. Only
operations whose results cannot depend on whose code computes them are taken:
those IEEE 754 rounds correctly (``+ - * /``, ``sqrt``, ``min``, ``max``,
``abs``, ``floor`` and the constant-operand and distance forms) and ``hypot``
(with ``radius``), which numpy and Numba both take from the C library. A pool
with any other (``sin``, ``exp``, ``pow``, ...: numpy may use its own SIMD
code) returns None, and its caller uses the array evaluator.

Examples
--------
>>> import numpy as np
>>> from implicitvox import x, y, z, sqrt
>>> from implicitvox.eval.tape import build_tape
>>> from implicitvox.eval.tape_pool import TapePool
>>> pool = TapePool(build_tape(sqrt(x * x + y * y + z * z) - 1.0))
>>> values, grads = pool_gradients(pool, np.array([0]), np.array([1]), np.array([3.0]),
...                                np.array([0.0]), np.array([4.0]))
>>> values.tolist(), grads[:, 0].tolist()
([4.0], [0.6, 0.0, 0.8])
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from .compiled import (ABS, ADD, ADDC, DISTANCE, DIV, DIVC, FLOOR, HYPOT, MAX, MIN, MUL, MULC,
                       NEG, RADIUS, RSUBC, SQRT, SQUARE, SUB)
from .tape_pool import ARG_A, ARG_B, ARG_C, OP, OUT, OUTPUT, ROWS, START, VALUE, TapePool

__all__ = ["pool_gradients", "takes_pool", "POINT_OPS"]

#: the operations :func:`pool_gradients` runs (numbers of :data:`implicitvox.eval.compiled.OPS`)
POINT_OPS = frozenset((ADD, SUB, MUL, DIV, NEG, SQUARE, SQRT, ABS, MIN, MAX, ADDC, RSUBC, MULC,
                       DIVC, DISTANCE, FLOOR, HYPOT, RADIUS))


def takes_pool(pool: TapePool) -> bool:
    """Does :func:`pool_gradients` run every operation of ``pool``'s tapes? (Its base
    tape holds every operation a pruned tape may hold, and ``neg``.)"""
    used = pool.rows[:int(pool.tapes[0, ROWS]), OP]
    return all(int(op) in POINT_OPS for op in np.unique(used))


def pool_gradients(pool: TapePool, tapes: np.ndarray, counts: np.ndarray, xs: np.ndarray,
                   ys: np.ndarray, zs: np.ndarray) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """Values ``(n,)`` and gradients ``(3, n)`` at the points ``(xs, ys, zs)``: the
    first ``counts[0]`` on pool tape ``tapes[0]``, the next ``counts[1]`` on
    ``tapes[1]``, and so on; None when the pool holds an operation this does not
    run (:func:`takes_pool`)."""
    if not takes_pool(pool):
        return None
    n = len(xs)
    if int(np.sum(counts)) != n:
        raise ValueError(f"the runs cover {int(np.sum(counts))} points, not {n}")
    values, grads = np.empty(n), np.empty((3, n))
    if pool.undefined:
        values[:], grads[:] = np.nan, np.nan
        return values, grads
    registers = int(pool.tapes[:len(pool), 4].max()) if len(pool) else 0
    _run(pool.rows, pool.tapes, pool.params, pool.is_constant, pool.constant_value,
         pool.inputs, np.ascontiguousarray(tapes, dtype=np.int64),
         np.ascontiguousarray(counts, dtype=np.int64),
         np.ascontiguousarray(xs, dtype=np.float64), np.ascontiguousarray(ys, dtype=np.float64),
         np.ascontiguousarray(zs, dtype=np.float64), values, grads,
         np.empty(max(registers, pool.fixed, 1)), np.empty((3, max(registers, pool.fixed, 1))))
    return values, grads


@njit(**COMPILE)
def _minimum(a, b):
    """numpy's minimum (NaN propagates; of equal values, the second)."""
    return a if (a < b or a != a) else b


@njit(**COMPILE)
def _maximum(a, b):
    return a if (a > b or a != a) else b


@njit(**COMPILE)
def _sign(a):
    """numpy's sign (0 at either zero, NaN at NaN)."""
    if a > 0.0:
        return 1.0
    if a < 0.0:
        return -1.0
    return a if a != a else 0.0


@njit(**COMPILE)
def _run(rows, tapes_, params, is_constant, constant_value, inputs, tapes, counts, xs, ys, zs,
         values, grads, val, grad):
    fixed = is_constant.size
    start = 0
    for r in range(tapes.size):
        t = tapes[r]
        first, length, output = tapes_[t, START], tapes_[t, ROWS], tapes_[t, OUTPUT]
        for i in range(start, start + counts[r]):
            for f in range(fixed):
                if is_constant[f]:
                    val[f] = constant_value[f]
                    grad[0, f] = grad[1, f] = grad[2, f] = 0.0
            for axis in range(3):
                k = inputs[axis]
                if k >= 0:
                    val[k] = xs[i] if axis == 0 else (ys[i] if axis == 1 else zs[i])
                    grad[0, k] = grad[1, k] = grad[2, k] = 0.0
                    grad[axis, k] = 1.0
            for j in range(first, first + length):
                row = rows[j]
                op, o, a, b, c = row[OP], row[OUT], row[ARG_A], row[ARG_B], row[ARG_C]
                p = params[row[VALUE]]
                va = val[a]
                if op == ADD:
                    out = va + val[b]
                    for d in range(3):
                        grad[d, o] = grad[d, a] + grad[d, b]
                elif op == SUB:
                    out = va - val[b]
                    for d in range(3):
                        grad[d, o] = grad[d, a] - grad[d, b]
                elif op == MUL:
                    vb = val[b]
                    out = va * vb
                    for d in range(3):
                        grad[d, o] = grad[d, a] * vb + va * grad[d, b]
                elif op == DIV:
                    vb = val[b]
                    out = va / vb
                    for d in range(3):
                        grad[d, o] = (grad[d, a] - out * grad[d, b]) / vb
                elif op == NEG:
                    out = -va
                    for d in range(3):
                        grad[d, o] = -grad[d, a]
                elif op == SQUARE:
                    out = va * va
                    for d in range(3):
                        grad[d, o] = (2.0 * va) * grad[d, a]
                elif op == SQRT:
                    out = np.sqrt(va)
                    for d in range(3):
                        grad[d, o] = grad[d, a] / (2.0 * out)
                elif op == ABS:
                    out = abs(va)
                    s = _sign(va)
                    for d in range(3):
                        grad[d, o] = s * grad[d, a]
                elif op == MIN or op == MAX:
                    vb = val[b]
                    if op == MIN:
                        out = _minimum(va, vb)
                        first_ = va <= vb
                    else:
                        out = _maximum(va, vb)
                        first_ = va >= vb
                    for d in range(3):
                        grad[d, o] = grad[d, a] if first_ else grad[d, b]
                elif op == ADDC:
                    out = va + p[0]
                    for d in range(3):
                        grad[d, o] = grad[d, a]
                elif op == RSUBC:
                    out = p[0] - va
                    for d in range(3):
                        grad[d, o] = -grad[d, a]
                elif op == MULC:
                    out = va * p[0]
                    for d in range(3):
                        grad[d, o] = p[0] * grad[d, a]
                elif op == DIVC:
                    out = va / p[0]
                    for d in range(3):
                        grad[d, o] = grad[d, a] / p[0]
                elif op == DISTANCE:
                    u0, u1, u2 = va - p[0], val[b] - p[1], val[c] - p[2]
                    total = u0 * u0 + u1 * u1
                    total = total + u2 * u2
                    out = np.sqrt(total)
                    for d in range(3):
                        grad[d, o] = ((u0 * grad[d, a] + u1 * grad[d, b]) + u2 * grad[d, c]) / out
                elif op == HYPOT:
                    vb = val[b]
                    out = math.hypot(va, vb)
                    for d in range(3):
                        grad[d, o] = (va * grad[d, a] + vb * grad[d, b]) / out
                elif op == RADIUS:
                    vb, vc = val[b], val[c]
                    out = math.hypot(math.hypot(va, vb), vc)
                    for d in range(3):
                        grad[d, o] = ((va * grad[d, a] + vb * grad[d, b]) + vc * grad[d, c]) / out
                else:                                   # FLOOR
                    out = np.floor(va)
                    for d in range(3):
                        grad[d, o] = grad[d, a] * 0.0
                val[o] = out
            values[i] = val[output]
            for d in range(3):
                grads[d, i] = grad[d, output]
        start += counts[r]
