"""The mean value form's value and gradient enclosures in compiled code.

:func:`implicitvox.eval.mean_value.evaluate_interval_gradients` runs a tape's
interval chain rules (:mod:`implicitvox.interval.derivatives`) as numpy calls
over small batches of boxes; the mesher asks it for thousands of pruned tapes,
a few boxes each, and the certified distance search for millions of boxes, and
the Python around each call costs more than the arithmetic.
:func:`tape_interval_gradients` runs the same rules box by box in Numba, on the
compiled interval rules (:mod:`implicitvox.interval.rules`, the one compiled
source of every interval rule), with the same lanes where the mean value
theorem fails (a domain boundary, a pole, the ``atan2`` cut, a ``floor`` jump).

By default it takes the tapes whose enclosures cannot depend on whose code
computes them (the operations of
:data:`implicitvox.eval.pool_gradients.POINT_OPS`: correctly rounded
arithmetic, ``min``, ``max``, ``abs``, ``floor``, ``hypot`` and the distance
forms), and its enclosures equal the array evaluator's bit for bit; others get
None, and the array code runs. With ``libm=True`` it takes every tape compiled
code runs (``sin``, ``exp``, ``atan2``, the coordinate forms, ...): the rules
whose compiled and array kernels call different libm code (``sin``, ``cos``,
the periodic angle) then give enclosures that differ from the array
evaluator's in the last bits, each rounded outward by its own kernel's
measured error (:mod:`implicitvox.interval.rounding`).

Examples
--------
>>> import numpy as np
>>> from implicitvox import x, y, z, sqrt
>>> from implicitvox.eval.tape import build_tape
>>> tape = build_tape(sqrt(x * x + y * y + z * z) - 1.0)
>>> lo, hi = np.array([[3.0], [0.0], [4.0]]), np.array([[3.5], [0.5], [4.5]])
>>> vlo, vhi, glo, ghi, valid = tape_interval_gradients(tape, lo, hi)
>>> bool(vlo[0] <= 4.0 <= vhi[0]), bool(glo[0, 0] <= 0.6 <= ghi[0, 0]), valid.tolist()
(True, True, [True])
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from numba import njit

from ..interval.rules import (COMPILE, i_abs, i_acos, i_add, i_addc, i_asin, i_atan, i_atan2,
                              i_cos, i_distance, i_div, i_divc, i_elevation, i_exp, i_floor,
                              i_hypot, i_log, i_max, i_min, i_mul, i_mulc, i_neg, i_powi,
                              i_powr, i_radius, i_rsubc, i_sin, i_sqrt, i_square, i_sub, i_tan,
                              periodic_angle_argument)
from .compiled import (ABS, ACOS, ADD, ADDC, ASIN, ATAN, ATAN2, COS, DISTANCE, DIV, DIVC,
                       ELEVATION, EXP, HYPOT, LOG, MAX, MIN, MUL, MULC, NEG,
                       PERIODIC_ANGLE, POWI, POWR, RADIUS, RSUBC, SIN, SQRT, SQUARE, SUB, TAN,
                       compiled_tape)
from .pool_gradients import POINT_OPS, check_runs, numpy_maximum, numpy_minimum, takes_pool
from .tape import Tape
from .tape_pool import OUTPUT, ROWS, START, VALUE, TapePool

__all__ = ["tape_interval_gradients", "pool_interval_gradients"]


def tape_interval_gradients(tape: Tape, lo, hi, *, libm: bool = False, closed: bool = False
                            ) -> Optional[tuple]:
    """:func:`~implicitvox.eval.mean_value.evaluate_interval_gradients` of ``tape``
    over the boxes ``lo, hi`` (sequences of 3 arrays ``(n,)``, or ``(3, n)``), in
    compiled code: ``(vlo, vhi, glo, ghi, valid)``; None for a tape it does not
    run (a sweep, an undefined tape, or, unless ``libm``, an operation outside
    :data:`~implicitvox.eval.pool_gradients.POINT_OPS`: see the module
    docstring).

    The gradient enclosure holds the (Clarke generalized) gradients wherever the
    mean value theorem needs them: on the open segments between points of the
    box. With ``closed=True`` it holds them at every point of the closed box, and a
    box is valid only where ``f`` is Lipschitz around each of its points: an
    ``abs`` whose argument touches 0 on a face takes the hull of both sides, and a
    ``floor`` with a jump on a face makes the box invalid (the certified distance
    search prunes boxes by the gradients at their points).
    """
    encoded = compiled_tape(tape)
    if encoded is None or tape.undefined:
        return None
    if not libm and not all(int(op) in POINT_OPS for op in np.unique(encoded.code[:, 0])):
        return None
    lo = np.ascontiguousarray(np.asarray(lo, dtype=np.float64).reshape(3, -1))
    hi = np.ascontiguousarray(np.asarray(hi, dtype=np.float64).reshape(3, -1))
    n = lo.shape[1]
    vlo, vhi = np.empty(n), np.empty(n)
    glo, ghi = np.empty((3, n)), np.empty((3, n))
    valid = np.ones(n, dtype=np.bool_)
    registers = max(encoded.n_registers, 1)
    run_gradients(encoded.code, encoded.params, encoded.constant_registers, encoded.constant_lo,
                  encoded.constant_hi, encoded.inputs, encoded.output, lo, hi, vlo, vhi, glo,
                  ghi, valid, closed, np.empty(registers), np.empty(registers),
                  np.empty((3, registers)), np.empty((3, registers)))
    return vlo, vhi, glo, ghi, valid


def pool_interval_gradients(pool: TapePool, tapes: np.ndarray, counts: np.ndarray, lo, hi
                            ) -> Optional[tuple]:
    """:func:`tape_interval_gradients` over boxes ``lo, hi`` ``(3, n)`` in runs of the
    pool's tapes (the first ``counts[0]`` boxes on pool tape ``tapes[0]``, ...),
    run on the pool's rows without building each tape: the same enclosures, bit for
    bit; None where :func:`tape_interval_gradients` gives None (an operation outside
    :data:`~implicitvox.eval.pool_gradients.POINT_OPS`, an undefined pool)."""
    if not takes_pool(pool) or pool.undefined:
        return None
    lo = np.ascontiguousarray(np.asarray(lo, dtype=np.float64).reshape(3, -1))
    hi = np.ascontiguousarray(np.asarray(hi, dtype=np.float64).reshape(3, -1))
    n = lo.shape[1]
    check_runs(counts, n)
    vlo, vhi = np.empty(n), np.empty(n)
    glo, ghi = np.empty((3, n)), np.empty((3, n))
    valid = np.ones(n, dtype=np.bool_)
    rows = pool.rows[:max(pool.rows_used, 1)]
    row_params = pool.params[rows[:, VALUE]]
    creg = np.flatnonzero(pool.is_constant)
    registers = pool.registers
    _run_pool(rows, row_params, pool.tapes, creg, pool.constant_lo[creg],
              pool.constant_hi[creg], pool.inputs, np.ascontiguousarray(tapes, dtype=np.int64),
              np.ascontiguousarray(counts, dtype=np.int64), lo, hi, vlo, vhi, glo, ghi, valid,
              np.empty(registers), np.empty(registers), np.empty((3, registers)),
              np.empty((3, registers)))
    return vlo, vhi, glo, ghi, valid


@njit(**COMPILE)
def _run_pool(rows, row_params, pool_tapes, creg, clo, chi, inputs, tapes, counts, lo, hi, vlo,
              vhi, glo, ghi, valid, rl, rh, gl, gh):
    start = 0
    for r in range(tapes.size):
        t = tapes[r]
        first, length = pool_tapes[t, START], pool_tapes[t, ROWS]
        end = start + counts[r]
        run_gradients(rows[first:first + length], row_params[first:first + length], creg, clo,
                      chi, inputs, pool_tapes[t, OUTPUT], lo[:, start:end], hi[:, start:end],
                      vlo[start:end], vhi[start:end], glo[:, start:end], ghi[:, start:end],
                      valid[start:end], False, rl, rh, gl, gh)
        start = end


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
def _scale(sl, sh, a, o, gl, gh):
    """``g_o = [s] * g_a``: the chain rule of a function of one argument."""
    for d in range(3):
        gl[d, o], gh[d, o] = i_mul(sl, sh, gl[d, a], gh[d, a])


@njit(**COMPILE)
def _angle_rate(yl, yh, xl, xh, a_y, a_x, scaled, sl, sh, o, gl, gh):
    """``g_o = (x g_y - y g_x) / (x² + y²)``, the chain rule through the angle
    ``atan2(y, x)`` (derivatives.d_atan2), times ``[s]`` if ``scaled``
    (derivatives.d_periodic_angle)."""
    dl, dh = i_add(*i_square(xl, xh), *i_square(yl, yh))
    for d in range(3):
        l0, h0 = i_mul(xl, xh, gl[d, a_y], gh[d, a_y])
        l1, h1 = i_mul(yl, yh, gl[d, a_x], gh[d, a_x])
        l0, h0 = i_div(*i_sub(l0, h0, l1, h1), dl, dh)
        gl[d, o], gh[d, o] = i_mul(sl, sh, l0, h0) if scaled else (l0, h0)


@njit(**COMPILE)
def _holds_origin(al, ah, bl, bh):
    return al <= 0.0 and ah >= 0.0 and bl <= 0.0 and bh >= 0.0


@njit(**COMPILE)
def run_gradients(code, params, creg, clo, chi, inputs, output, lo, hi, vlo, vhi, glo, ghi,
                  valid, closed, rl, rh, gl, gh):
    """Box by box, each instruction's value enclosure (its rule of
    :mod:`implicitvox.interval.rules`) and gradient enclosure (the chain rule of
    :mod:`implicitvox.interval.derivatives`, written with the same rules), over the
    rows of a :class:`~implicitvox.eval.compiled.CompiledTape`; ``valid`` is False
    where the mean value theorem fails over the box or a domain operation's
    argument lies wholly outside its domain (``closed``: see
    :func:`tape_interval_gradients`)."""
    for i in range(lo.shape[1]):
        ok = True
        for k in range(creg.size):
            f = creg[k]
            rl[f], rh[f] = clo[k], chi[k]
            for d in range(3):
                gl[d, f] = gh[d, f] = 0.0
        for axis in range(3):
            k = inputs[axis]
            if k >= 0:
                rl[k], rh[k] = lo[axis, i], hi[axis, i]
                for d in range(3):
                    gl[d, k] = gh[d, k] = 1.0 if d == axis else 0.0
        for j in range(code.shape[0]):
            op, o, a, b, c = code[j, 0], code[j, 1], code[j, 2], code[j, 3], code[j, 4]
            p0 = params[j, 0]
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
                _scale(*i_mulc(al, ah, 2.0), a, o, gl, gh)
            elif op == POWI:
                n = int(p0)
                ol, oh = i_powi(al, ah, n)
                if n == 0:
                    for d in range(3):
                        gl[d, o] = gh[d, o] = 0.0
                else:
                    _scale(*i_mulc(*i_powi(al, ah, n - 1), p0), a, o, gl, gh)
            elif op == POWR:
                ol, oh, empty = i_powr(al, ah, p0)
                ok = ok and not empty and al > 0.0
                sl, sh, _ = i_powr(al, ah, p0 - 1.0)
                _scale(*i_mulc(sl, sh, p0), a, o, gl, gh)
            elif op == SQRT:
                ol, oh, empty = i_sqrt(al, ah)
                ok = ok and not empty and al > 0.0
                tl, th = i_mulc(ol, oh, 2.0)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_div(gl[d, a], gh[d, a], tl, th)
            elif op == EXP:
                ol, oh = i_exp(al, ah)
                _scale(ol, oh, a, o, gl, gh)
            elif op == LOG:
                ol, oh, empty = i_log(al, ah)
                ok = ok and not empty and al > 0.0
                for d in range(3):
                    gl[d, o], gh[d, o] = i_div(gl[d, a], gh[d, a], al, ah)
            elif op == SIN:
                ol, oh = i_sin(al, ah)
                _scale(*i_cos(al, ah), a, o, gl, gh)
            elif op == COS:
                ol, oh = i_cos(al, ah)
                _scale(*i_neg(*i_sin(al, ah)), a, o, gl, gh)
            elif op == TAN:
                ol, oh = i_tan(al, ah)
                ok = ok and np.isfinite(ol) and np.isfinite(oh)
                _scale(*i_addc(*i_square(ol, oh), 1.0), a, o, gl, gh)
            elif op == ATAN:
                ol, oh = i_atan(al, ah)
                tl, th = i_addc(*i_square(al, ah), 1.0)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_div(gl[d, a], gh[d, a], tl, th)
            elif op == ASIN or op == ACOS:
                if op == ASIN:
                    ol, oh, empty = i_asin(al, ah)
                else:
                    ol, oh, empty = i_acos(al, ah)
                ok = ok and not empty and al > -1.0 and ah < 1.0
                tl, th, _ = i_sqrt(*i_rsubc(*i_square(al, ah), 1.0))
                for d in range(3):
                    l0, h0 = i_div(gl[d, a], gh[d, a], tl, th)
                    gl[d, o], gh[d, o] = (l0, h0) if op == ASIN else i_neg(l0, h0)
            elif op == ATAN2:
                bl, bh = rl[b], rh[b]
                ol, oh = i_atan2(al, ah, bl, bh)
                ok = ok and not (bl <= 0.0 and al <= 0.0 and ah >= 0.0)
                _angle_rate(al, ah, bl, bh, a, b, False, 1.0, 1.0, o, gl, gh)
            elif op == PERIODIC_ANGLE:
                bl, bh = rl[b], rh[b]
                k, phase = params[j, 1], params[j, 2]
                # (rules.i_periodic_angle, its argument shared with the slope's)
                tl, th = periodic_angle_argument(al, ah, bl, bh, k, phase)
                ok = ok and not _holds_origin(al, ah, bl, bh)
                if p0 == 1.0:                            # cos: the slope is -sin
                    ol, oh = i_cos(tl, th)
                    sl, sh = i_neg(*i_sin(tl, th))
                else:
                    ol, oh = i_sin(tl, th)
                    sl, sh = i_cos(tl, th)
                _angle_rate(al, ah, bl, bh, a, b, True, *i_mulc(sl, sh, k), o, gl, gh)
            elif op == ELEVATION:
                bl, bh, cl, ch = rl[b], rh[b], rl[c], rh[c]
                ol, oh = i_elevation(al, ah, bl, bh, cl, ch)
                ok = ok and not (_holds_origin(al, ah, bl, bh) and cl <= 0.0 and ch >= 0.0)
                ql, qh = i_hypot(al, ah, bl, bh)
                dl, dh = i_add(*i_square(ql, qh), *i_square(cl, ch))
                for d in range(3):
                    l0, h0 = i_mul(al, ah, gl[d, a], gh[d, a])
                    l1, h1 = i_mul(bl, bh, gl[d, b], gh[d, b])
                    l0, h0 = i_div(*i_add(l0, h0, l1, h1), ql, qh)          # d rho
                    l1, h1 = i_sub(*i_mul(ql, qh, gl[d, c], gh[d, c]), *i_mul(cl, ch, l0, h0))
                    gl[d, o], gh[d, o] = i_div(l1, h1, dl, dh)
            elif op == ABS:
                ol, oh = i_abs(al, ah)
                for d in range(3):
                    g0, g1 = gl[d, a], gh[d, a]
                    m = numpy_maximum(-g0, g1)
                    if al > 0.0 or (al == 0.0 and not closed):
                        gl[d, o], gh[d, o] = g0, g1
                    elif ah < 0.0 or (ah == 0.0 and not closed):
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
                ol, oh = i_addc(al, ah, p0)
                for d in range(3):
                    gl[d, o], gh[d, o] = gl[d, a], gh[d, a]
            elif op == RSUBC:
                ol, oh = i_rsubc(al, ah, p0)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_neg(gl[d, a], gh[d, a])
            elif op == MULC:
                ol, oh = i_mulc(al, ah, p0)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_mulc(gl[d, a], gh[d, a], p0)
            elif op == DIVC:
                ol, oh = i_divc(al, ah, p0)
                for d in range(3):
                    gl[d, o], gh[d, o] = i_divc(gl[d, a], gh[d, a], p0)
            elif op == DISTANCE:
                bl, bh, cl, ch = rl[b], rh[b], rl[c], rh[c]
                ol, oh = i_distance(al, ah, bl, bh, cl, ch, p0, params[j, 1], params[j, 2])
                x0l, x0h = i_addc(al, ah, -p0)
                x1l, x1h = i_addc(bl, bh, -params[j, 1])
                x2l, x2h = i_addc(cl, ch, -params[j, 2])
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
                ok = ok and np.floor(al) == np.floor(ah) and \
                    not (closed and (np.floor(al) == al or np.floor(ah) == ah))
                for d in range(3):
                    gl[d, o] = gh[d, o] = 0.0
            rl[o], rh[o] = ol, oh
        vlo[i], vhi[i] = rl[output], rh[output]
        for d in range(3):
            glo[d, i], ghi[d, i] = gl[d, output], gh[d, output]
        valid[i] = ok
