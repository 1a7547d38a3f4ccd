"""The mean value form's value and gradient enclosures in compiled code.

:func:`implicitvox.eval.mean_value.evaluate_interval_gradients` runs a tape's
interval chain rules (:mod:`implicitvox.interval.derivatives`) as numpy calls
over small batches of boxes; the mesher asks it for thousands of pruned tapes,
a few boxes each, and the Python around each call costs more than the
arithmetic. :func:`tape_interval_gradients` runs the same rules box by box in
Numba, on the compiled interval rules (:mod:`implicitvox.interval.rules`, bit
for bit the array kernels), for the tapes
:mod:`implicitvox.eval.pool_gradients` lays out (correctly rounded operations,
``min``, ``max``, ``abs``, ``floor`` and the distance forms): the same
enclosures, bit for bit, and the same lanes where the mean value theorem fails
(a ``sqrt`` at or below 0, a ``floor`` jump). Other tapes get None, and the
array code runs.

Examples
--------
>>> import numpy as np
>>> from implicitvox import x, y, z, sqrt
>>> from implicitvox.eval.tape import build_tape
>>> tape = build_tape(sqrt(x * x + y * y + z * z) - 1.0)
>>> lo, hi = np.array([[3.0], [0.0], [4.0]]), np.array([[3.5], [0.5], [4.5]])
>>> vlo, vhi, glo, ghi, valid = tape_interval_gradients(tape, lo, hi)
>>> bool(vlo[0] <= 4.0 and vhi[0] >= 5.0 - 1.0), bool(glo[0, 0] <= 0.6 <= ghi[0, 0]), valid.tolist()
(True, True, [True])
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from numba import njit

from ..interval.rules import (COMPILE, i_abs, i_add, i_addc, i_distance, i_div, i_divc,
                              i_floor, i_hypot, i_max, i_min, i_mul, i_mulc, i_neg, i_radius,
                              i_rsubc, i_sqrt, i_square, i_sub)
from .compiled import (ABS, ADD, ADDC, DISTANCE, DIV, DIVC, FLOOR, HYPOT, MAX, MIN, MUL, MULC,
                       NEG, RADIUS, RSUBC, SQRT, SQUARE, SUB)
from .pool_gradients import numpy_maximum, numpy_minimum, tape_arrays
from .tape import Tape
from .tape_pool import ARG_A, ARG_B, ARG_C, OP, OUT, VALUE

__all__ = ["tape_interval_gradients"]


def tape_interval_gradients(tape: Tape, lo, hi) -> Optional[tuple]:
    """:func:`~implicitvox.eval.mean_value.evaluate_interval_gradients` of ``tape``
    over the boxes ``lo, hi`` (sequences of 3 arrays ``(n,)``, or ``(3, n)``), in
    compiled code: ``(vlo, vhi, glo, ghi, valid)``; None for a tape it does not
    run."""
    arrays = tape_arrays(tape)
    if arrays is None:
        return None
    lo = np.ascontiguousarray(np.asarray(lo, dtype=np.float64).reshape(3, -1))
    hi = np.ascontiguousarray(np.asarray(hi, dtype=np.float64).reshape(3, -1))
    n = lo.shape[1]
    vlo, vhi = np.empty(n), np.empty(n)
    glo, ghi = np.empty((3, n)), np.empty((3, n))
    valid = np.ones(n, dtype=np.bool_)
    registers = arrays.is_constant.size
    _run(arrays.rows, arrays.length, arrays.output, arrays.params, arrays.is_constant,
         arrays.constant_lo, arrays.constant_hi, arrays.inputs, lo, hi, vlo, vhi, glo, ghi,
         valid, np.empty(registers), np.empty(registers), np.empty((3, registers)),
         np.empty((3, registers)))
    return vlo, vhi, glo, ghi, valid


@njit(**COMPILE)
def _chain3(ul, uh, vl, vh, wl, wh, a, b, c, o, ol, oh, gl, gh):
    """The gradient of a distance ``out`` from its offsets ``u, v, w`` along the
    arguments ``a, b, c``: ``((u ga + v gb) + w gc) / out`` (derivatives.d_distance,
    d_radius), into register ``o``."""
    for d in range(3):
        l0, h0 = i_mul(ul, uh, gl[d, a], gh[d, a])
        l1, h1 = i_mul(vl, vh, gl[d, b], gh[d, b])
        l2, h2 = i_mul(wl, wh, gl[d, c], gh[d, c])
        l0, h0 = i_add(l0, h0, l1, h1)
        l0, h0 = i_add(l0, h0, l2, h2)
        gl[d, o], gh[d, o] = i_div(l0, h0, ol, oh)


@njit(**COMPILE)
def _run(rows, length, output, params, is_constant, constant_lo, constant_hi, inputs, lo, hi,
         vlo, vhi, glo, ghi, valid, rl, rh, gl, gh):
    for i in range(lo.shape[1]):
        ok = True
        for f in range(is_constant.size):
            if is_constant[f]:
                rl[f], rh[f] = constant_lo[f], constant_hi[f]
                for d in range(3):
                    gl[d, f] = gh[d, f] = 0.0
        for axis in range(3):
            k = inputs[axis]
            if k >= 0:
                rl[k], rh[k] = lo[axis, i], hi[axis, i]
                for d in range(3):
                    gl[d, k] = gh[d, k] = 1.0 if d == axis else 0.0
        for j in range(length):
            row = rows[j]
            op, o, a, b, c = row[OP], row[OUT], row[ARG_A], row[ARG_B], row[ARG_C]
            p = params[row[VALUE]]
            al, ah = rl[a], rh[a]
            if op == ADD:
                ol, oh = i_add(al, ah, rl[b], rh[b])
                for d in range(3):
                    gl[d, o], gh[d, o] = i_add(gl[d, a], gh[d, a], gl[d, b], gh[d, b])
            elif op == SUB:
                ol, oh = i_sub(al, ah, rl[b], rh[b])
                for d in range(3):
                    gl[d, o], gh[d, o] = i_sub(gl[d, a], gh[d, a], gl[d, b], gh[d, b])
            elif op == MUL:
                bl, bh = rl[b], rh[b]
                ol, oh = i_mul(al, ah, bl, bh)
                for d in range(3):
                    l0, h0 = i_mul(gl[d, a], gh[d, a], bl, bh)
                    l1, h1 = i_mul(al, ah, gl[d, b], gh[d, b])
                    gl[d, o], gh[d, o] = i_add(l0, h0, l1, h1)
            elif op == DIV:
                bl, bh = rl[b], rh[b]
                ol, oh = i_div(al, ah, bl, bh)
                for d in range(3):
                    l0, h0 = i_mul(ol, oh, gl[d, b], gh[d, b])
                    l1, h1 = i_sub(gl[d, a], gh[d, a], l0, h0)
                    gl[d, o], gh[d, o] = i_div(l1, h1, bl, bh)
            elif op == NEG:
                ol, oh = i_neg(al, ah)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_neg(gl[d, a], gh[d, a])
            elif op == SQUARE:
                ol, oh = i_square(al, ah)
                tl, th = i_mulc(al, ah, 2.0)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_mul(tl, th, gl[d, a], gh[d, a])
            elif op == SQRT:
                ol, oh, empty = i_sqrt(al, ah)
                ok = ok and not empty and al > 0.0
                tl, th = i_mulc(ol, oh, 2.0)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_div(gl[d, a], gh[d, a], tl, th)
            elif op == ABS:
                ol, oh = i_abs(al, ah)
                for d in range(3):
                    g0, g1 = gl[d, a], gh[d, a]
                    m = numpy_maximum(-g0, g1)
                    if al >= 0.0:
                        gl[d, o], gh[d, o] = g0, g1
                    elif ah <= 0.0:
                        gl[d, o], gh[d, o] = -g1, -g0
                    else:
                        gl[d, o], gh[d, o] = -m, m
            elif op == MIN or op == MAX:
                bl, bh = rl[b], rh[b]
                if op == MIN:
                    ol, oh = i_min(al, ah, bl, bh)
                    a_wins, b_wins = ah < bl, bh < al
                else:
                    ol, oh = i_max(al, ah, bl, bh)
                    a_wins, b_wins = al > bh, bl > ah
                for d in range(3):
                    if a_wins:
                        gl[d, o], gh[d, o] = gl[d, a], gh[d, a]
                    elif b_wins:
                        gl[d, o], gh[d, o] = gl[d, b], gh[d, b]
                    else:
                        gl[d, o] = numpy_minimum(gl[d, a], gl[d, b])
                        gh[d, o] = numpy_maximum(gh[d, a], gh[d, b])
            elif op == ADDC:
                ol, oh = i_addc(al, ah, p[0])
                for d in range(3):
                    gl[d, o], gh[d, o] = gl[d, a], gh[d, a]
            elif op == RSUBC:
                ol, oh = i_rsubc(al, ah, p[0])
                for d in range(3):
                    gl[d, o], gh[d, o] = i_neg(gl[d, a], gh[d, a])
            elif op == MULC:
                ol, oh = i_mulc(al, ah, p[0])
                for d in range(3):
                    gl[d, o], gh[d, o] = i_mulc(gl[d, a], gh[d, a], p[0])
            elif op == DIVC:
                ol, oh = i_divc(al, ah, p[0])
                for d in range(3):
                    gl[d, o], gh[d, o] = i_divc(gl[d, a], gh[d, a], p[0])
            elif op == DISTANCE:
                bl, bh, cl, ch = rl[b], rh[b], rl[c], rh[c]
                ol, oh = i_distance(al, ah, bl, bh, cl, ch, p[0], p[1], p[2])
                x0l, x0h = i_addc(al, ah, -p[0])
                x1l, x1h = i_addc(bl, bh, -p[1])
                x2l, x2h = i_addc(cl, ch, -p[2])
                _chain3(x0l, x0h, x1l, x1h, x2l, x2h, a, b, c, o, ol, oh, gl, gh)
            elif op == HYPOT:
                bl, bh = rl[b], rh[b]
                ol, oh = i_hypot(al, ah, bl, bh)
                for d in range(3):
                    l0, h0 = i_mul(al, ah, gl[d, a], gh[d, a])
                    l1, h1 = i_mul(bl, bh, gl[d, b], gh[d, b])
                    l0, h0 = i_add(l0, h0, l1, h1)
                    gl[d, o], gh[d, o] = i_div(l0, h0, ol, oh)
            elif op == RADIUS:
                bl, bh, cl, ch = rl[b], rh[b], rl[c], rh[c]
                ol, oh = i_radius(al, ah, bl, bh, cl, ch)
                _chain3(al, ah, bl, bh, cl, ch, a, b, c, o, ol, oh, gl, gh)
            else:                                   # FLOOR
                ol, oh = i_floor(al, ah)
                ok = ok and np.floor(al) == np.floor(ah)
                for d in range(3):
                    gl[d, o] = gh[d, o] = 0.0
            rl[o], rh[o] = ol, oh
        vlo[i], vhi[i] = rl[output], rh[output]
        for d in range(3):
            glo[d, i], ghi[d, i] = gl[d, output], gh[d, output]
        valid[i] = ok
