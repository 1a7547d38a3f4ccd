"""Values and gradients at points on the pruned tapes of a pool (and on one tape), in
compiled code.

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

A single :class:`~implicitvox.eval.tape.Tape` runs the same way
(:func:`tape_arrays` lays it out as one pool tape): :func:`tape_gradients`, and
:func:`crossing_points`, the mesher's bisection of sign changes on cell edges
(:mod:`implicitvox.meshing.edges`), step for step.

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
from dataclasses import dataclass
from typing import Optional

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from .compiled import compiled_tape, once_per_tape
from .compiled import (ABS, ADD, ADDC, DISTANCE, DIV, DIVC, FLOOR, HYPOT, MAX, MIN, MUL, MULC,
                       NEG, RADIUS, RSUBC, SQRT, SQUARE, SUB)
from .tape import Tape
from .tape_pool import (ARG_A, ARG_B, ARG_C, OP, OUT, OUTPUT, ROW, ROWS, START, VALUE,
                        TapePool)

__all__ = ["pool_gradients", "pool_values", "pool_crossings", "check_runs", "takes_pool",
           "tape_arrays", "tape_gradients", "crossing_points", "TapeArrays", "POINT_OPS",
           "numpy_minimum", "numpy_maximum"]

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
    check_runs(counts, n)
    values, grads = np.empty(n), np.empty((3, n))
    if pool.undefined:
        values[:], grads[:] = np.nan, np.nan
        return values, grads
    registers = pool.registers
    _run(pool.rows, pool.tapes, pool.params, pool.is_constant, pool.constant_value,
         pool.inputs, np.ascontiguousarray(tapes, dtype=np.int64),
         np.ascontiguousarray(counts, dtype=np.int64),
         np.ascontiguousarray(xs, dtype=np.float64), np.ascontiguousarray(ys, dtype=np.float64),
         np.ascontiguousarray(zs, dtype=np.float64), values, grads,
         np.empty(registers), np.empty((3, registers)), 3)
    return values, grads


def check_runs(counts: np.ndarray, n: int) -> None:
    """Raise ``ValueError`` unless runs of ``counts`` rows cover exactly ``n`` rows."""
    if int(np.sum(counts)) != n:
        raise ValueError(f"the runs cover {int(np.sum(counts))} rows, not {n}")


def pool_values(pool: TapePool, tapes: np.ndarray, counts: np.ndarray, xs: np.ndarray,
                ys: np.ndarray, zs: np.ndarray) -> Optional[np.ndarray]:
    """The values of :func:`pool_gradients` alone (the same floats, without the
    derivatives), or None (:func:`takes_pool`)."""
    if not takes_pool(pool):
        return None
    check_runs(counts, len(xs))
    values = np.empty(len(xs))
    if pool.undefined:
        values[:] = np.nan
        return values
    registers = pool.registers
    _run(pool.rows, pool.tapes, pool.params, pool.is_constant, pool.constant_value,
         pool.inputs, np.ascontiguousarray(tapes, dtype=np.int64),
         np.ascontiguousarray(counts, dtype=np.int64), np.ascontiguousarray(xs, dtype=np.float64),
         np.ascontiguousarray(ys, dtype=np.float64), np.ascontiguousarray(zs, dtype=np.float64),
         values, np.empty((3, 0)), np.empty(registers), np.empty((3, registers)), 0)
    return values


def pool_crossings(pool: TapePool, tapes: np.ndarray, counts: np.ndarray, a: np.ndarray,
                   b: np.ndarray, steps: int) -> Optional[np.ndarray]:
    """:func:`crossing_points` on edges ``a -> b`` (n, 3) in runs of pool tapes (the
    first ``counts[0]`` edges on ``tapes[0]``, ...): the same points as on each
    tape built alone, or None (:func:`takes_pool`, or an undefined pool)."""
    if not takes_pool(pool) or pool.undefined:
        return None
    check_runs(counts, len(a))
    a = np.ascontiguousarray(a, dtype=np.float64)
    points = np.empty_like(a)
    registers = pool.registers
    _bisect_runs(pool.rows, pool.tapes, pool.params, pool.is_constant, pool.constant_value,
                 pool.inputs, np.ascontiguousarray(tapes, dtype=np.int64),
                 np.ascontiguousarray(counts, dtype=np.int64), a,
                 np.ascontiguousarray(b, dtype=np.float64), int(steps), points,
                 np.empty(registers), np.empty((3, registers)))
    return points


@dataclass(frozen=True)
class TapeArrays:
    """A tape laid out as one pool tape (:func:`tape_arrays`)."""

    #: (length, ROW) int32: the pool's row layout, VALUE the row's own index
    rows: np.ndarray
    length: int
    #: the output register
    output: int
    #: (length, 3): each row's parameters
    params: np.ndarray
    #: per register: a constant? its point value, and its enclosure
    is_constant: np.ndarray
    constant_value: np.ndarray
    constant_lo: np.ndarray
    constant_hi: np.ndarray
    #: (3,) the registers of x, y, z (-1: unused)
    inputs: np.ndarray


_ARRAYS: dict[int, tuple[Tape, Optional[TapeArrays]]] = {}
#: (the mesher runs each cell's tape several times, and the level-3 sponge at 256 has
#: about 18,000 of them: a smaller cache emptied and refilled itself)
_ARRAYS_LIMIT = 1 << 16


def tape_arrays(tape: Tape) -> Optional[TapeArrays]:
    """A :class:`~implicitvox.eval.tape.Tape` as one pool tape's arrays, or None when it holds an operation this module does not run (or a sweep); laid
    out once per tape object (the last :data:`_ARRAYS_LIMIT` kept)."""
    return once_per_tape(_ARRAYS, _ARRAYS_LIMIT, tape, _lay_out)


def _lay_out(tape: Tape) -> Optional[TapeArrays]:
    encoded = compiled_tape(tape)
    if encoded is None or tape.undefined or \
            not all(int(op) in POINT_OPS for op in np.unique(encoded.code[:, 0])):
        return None
    n = len(encoded.code)
    rows = np.zeros((max(n, 1), ROW), dtype=np.int32)
    rows[:n, OP], rows[:n, OUT] = encoded.code[:, 0], encoded.code[:, 1]
    rows[:n, ARG_A], rows[:n, ARG_B], rows[:n, ARG_C] = encoded.code[:, 2:5].T
    rows[:n, VALUE] = np.arange(n)
    registers = max(tape.n_registers, 1)
    is_constant = np.zeros(registers, dtype=np.bool_)
    constant_value = np.zeros(registers)
    constant_lo, constant_hi = np.zeros(registers), np.zeros(registers)
    for c in tape.constants:
        is_constant[c.register], constant_value[c.register] = True, c.value
        constant_lo[c.register], constant_hi[c.register] = c.lo, c.hi
    params = encoded.params if n else np.zeros((1, 3))
    return TapeArrays(rows, n, int(encoded.output), params, is_constant, constant_value,
                      constant_lo, constant_hi, encoded.inputs)


def tape_gradients(tape: Tape, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray
                   ) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """:func:`~implicitvox.eval.gradient.evaluate_gradients` of one tape, compiled
    (bit for bit the same), or None (:func:`tape_arrays`)."""
    arrays = tape_arrays(tape)
    if arrays is None:
        return None
    rows, n, output, params = arrays.rows, arrays.length, arrays.output, arrays.params
    is_constant, constant_value, inputs = arrays.is_constant, arrays.constant_value, arrays.inputs
    count = len(xs)
    values, grads = np.empty(count), np.empty((3, count))
    one = np.zeros((1, 5), dtype=np.int64)
    one[0, START], one[0, ROWS], one[0, OUTPUT] = 0, n, output
    registers = is_constant.size
    _run(rows, one, params, is_constant, constant_value, inputs, np.zeros(1, dtype=np.int64),
         np.array([count], dtype=np.int64), *(np.ascontiguousarray(v, dtype=np.float64)
                                              for v in (xs, ys, zs)),
         values, grads, np.empty(registers), np.empty((3, registers)), 3)
    return values, grads


def crossing_points(tape: Tape, a: np.ndarray, b: np.ndarray, steps: int
                    ) -> Optional[np.ndarray]:
    """The bisection of :func:`implicitvox.meshing.edges.crossings` on edges
    ``a -> b`` (n, 3), compiled (the same points, bit for bit), or None
    (:func:`tape_arrays`)."""
    arrays = tape_arrays(tape)
    if arrays is None:
        return None
    rows, n, output, params = arrays.rows, arrays.length, arrays.output, arrays.params
    is_constant, constant_value, inputs = arrays.is_constant, arrays.constant_value, arrays.inputs
    a = np.ascontiguousarray(a, dtype=np.float64)
    points = np.empty_like(a)
    registers = is_constant.size
    _bisect(rows, 0, n, output, params, is_constant, constant_value, inputs, a,
            np.ascontiguousarray(b, dtype=np.float64), int(steps), points,
            np.empty(registers), np.empty((3, registers)))
    return points


@njit(**COMPILE)
def numpy_minimum(a, b):
    """numpy's minimum (NaN propagates; of equal values, the second)."""
    return a if (a < b or a != a) else b


@njit(**COMPILE)
def numpy_maximum(a, b):
    """numpy's maximum (NaN propagates; of equal values, the second)."""
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
def _at_point(rows, first, length, output, params, is_constant, constant_value, inputs, x, y, z,
              val, grad, dims):
    """The value of the tape of rows ``first .. first + length`` at ``(x, y, z)``; its
    gradient left in ``grad[:, output]`` with ``dims = 3`` (``dims = 0``: values only)."""
    for f in range(is_constant.size):
        if is_constant[f]:
            val[f] = constant_value[f]
            for d in range(dims):
                grad[d, f] = 0.0
    for axis in range(3):
        k = inputs[axis]
        if k >= 0:
            val[k] = x if axis == 0 else (y if axis == 1 else z)
            for d in range(dims):
                grad[d, k] = 1.0 if d == axis else 0.0
    for j in range(first, first + length):
        row = rows[j]
        op, o, a, b, c = row[OP], row[OUT], row[ARG_A], row[ARG_B], row[ARG_C]
        p = params[row[VALUE]]
        va = val[a]
        if op == ADD:
            out = va + val[b]
            for d in range(dims):
                grad[d, o] = grad[d, a] + grad[d, b]
        elif op == SUB:
            out = va - val[b]
            for d in range(dims):
                grad[d, o] = grad[d, a] - grad[d, b]
        elif op == MUL:
            vb = val[b]
            out = va * vb
            for d in range(dims):
                grad[d, o] = grad[d, a] * vb + va * grad[d, b]
        elif op == DIV:
            vb = val[b]
            out = va / vb
            for d in range(dims):
                grad[d, o] = (grad[d, a] - out * grad[d, b]) / vb
        elif op == NEG:
            out = -va
            for d in range(dims):
                grad[d, o] = -grad[d, a]
        elif op == SQUARE:
            out = va * va
            for d in range(dims):
                grad[d, o] = (2.0 * va) * grad[d, a]
        elif op == SQRT:
            out = np.sqrt(va)
            for d in range(dims):
                grad[d, o] = grad[d, a] / (2.0 * out)
        elif op == ABS:
            out = abs(va)
            s = _sign(va)
            for d in range(dims):
                grad[d, o] = s * grad[d, a]
        elif op == MIN or op == MAX:
            vb = val[b]
            if op == MIN:
                out = numpy_minimum(va, vb)
                first_ = va <= vb
            else:
                out = numpy_maximum(va, vb)
                first_ = va >= vb
            for d in range(dims):
                grad[d, o] = grad[d, a] if first_ else grad[d, b]
        elif op == ADDC:
            out = va + p[0]
            for d in range(dims):
                grad[d, o] = grad[d, a]
        elif op == RSUBC:
            out = p[0] - va
            for d in range(dims):
                grad[d, o] = -grad[d, a]
        elif op == MULC:
            out = va * p[0]
            for d in range(dims):
                grad[d, o] = p[0] * grad[d, a]
        elif op == DIVC:
            out = va / p[0]
            for d in range(dims):
                grad[d, o] = grad[d, a] / p[0]
        elif op == DISTANCE:
            u0, u1, u2 = va - p[0], val[b] - p[1], val[c] - p[2]
            total = u0 * u0 + u1 * u1
            total = total + u2 * u2
            out = np.sqrt(total)
            for d in range(dims):
                grad[d, o] = ((u0 * grad[d, a] + u1 * grad[d, b]) + u2 * grad[d, c]) / out
        elif op == HYPOT:
            vb = val[b]
            out = math.hypot(va, vb)
            for d in range(dims):
                grad[d, o] = (va * grad[d, a] + vb * grad[d, b]) / out
        elif op == RADIUS:
            vb, vc = val[b], val[c]
            out = math.hypot(math.hypot(va, vb), vc)
            for d in range(dims):
                grad[d, o] = ((va * grad[d, a] + vb * grad[d, b]) + vc * grad[d, c]) / out
        else:                                   # FLOOR
            out = np.floor(va)
            for d in range(dims):
                grad[d, o] = grad[d, a] * 0.0
        val[o] = out
    return val[output]


@njit(**COMPILE)
def _run(rows, tapes_, params, is_constant, constant_value, inputs, tapes, counts, xs, ys, zs,
         values, grads, val, grad, dims):
    """The points in runs of pool tapes: values, and with ``dims = 3`` gradients."""
    start = 0
    for r in range(tapes.size):
        t = tapes[r]
        first, length, output = tapes_[t, START], tapes_[t, ROWS], tapes_[t, OUTPUT]
        for i in range(start, start + counts[r]):
            values[i] = _at_point(rows, first, length, output, params, is_constant,
                                  constant_value, inputs, xs[i], ys[i], zs[i], val, grad, dims)
            for d in range(dims):
                grads[d, i] = grad[d, output]
        start += counts[r]


@njit(**COMPILE)
def _bisect_runs(rows, tapes_, params, is_constant, constant_value, inputs, tapes, counts, a, b,
                 steps, points, val, grad):
    start = 0
    for r in range(tapes.size):
        t = tapes[r]
        end = start + counts[r]
        _bisect(rows, tapes_[t, START], tapes_[t, ROWS], tapes_[t, OUTPUT], params,
                is_constant, constant_value, inputs, a[start:end], b[start:end], steps,
                points[start:end], val, grad)
        start = end


@njit(**COMPILE)
def _bisect(rows, first, length, output, params, is_constant, constant_value, inputs, a, b,
            steps, points, val, grad):
    """:func:`implicitvox.meshing.edges.crossings`' bisection, edge by edge: the
    bracket of the sign change on ``a[i] -> b[i]`` halved ``steps`` times, its
    midpoint into ``points[i]`` (the same arithmetic, step for step)."""
    for i in range(a.shape[0]):
        d0, d1, d2 = b[i, 0] - a[i, 0], b[i, 1] - a[i, 1], b[i, 2] - a[i, 2]
        inside_a = _at_point(rows, first, length, output, params, is_constant, constant_value,
                             inputs, a[i, 0], a[i, 1], a[i, 2], val, grad, 0) < 0
        lo, hi = 0.0, 1.0
        for _ in range(steps):
            mid = 0.5 * (lo + hi)
            inside = _at_point(rows, first, length, output, params, is_constant,
                               constant_value, inputs, a[i, 0] + mid * d0, a[i, 1] + mid * d1,
                               a[i, 2] + mid * d2, val, grad, 0) < 0
            if inside == inside_a:
                lo = mid
            else:
                hi = mid
        mid = 0.5 * (lo + hi)
        points[i, 0] = a[i, 0] + mid * d0
        points[i, 1] = a[i, 1] + mid * d1
        points[i, 2] = a[i, 2] + mid * d2
