"""The mean value form: a second-order-tight enclosure for small boxes.

The natural interval extension (one kernel per operation) overestimates by
an amount proportional to the box width: ``f = A - r`` gets the width of
``A`` plus the width of ``r`` even where the two move together. The mean
value form

    f(box) ⊆ f(c) + Σ_i  ∂f/∂x_i(box) · [-r_i, r_i]

(``c`` the box centre, ``r_i`` the half widths) overestimates by an amount
proportional to the width squared, so on voxel-sized boxes it is much
tighter. Both are enclosures; the voxelizer intersects them. ``f(c)`` is the
interval of ``f`` over the degenerate box ``[c, c]`` (rounded outward), and
the gradient enclosure comes from the interval chain rules of
:mod:`implicitvox.interval.derivatives`; lanes where the mean value theorem
fails over the box (domain boundary, pole, branch cut, jump) keep the
natural enclosure.

This is a standard device of interval analysis (Moore, *Interval Analysis*,
1966; the centred forms of Krawczyk and Neumaier); Stolte's report notes the
overestimation of large boxes (§1) - the mean value form answers it on the
small ones.
"""
from __future__ import annotations

import numpy as np

from ..interval import rounding
from .interval import apply_op, evaluate_intervals
from .tape import Tape

__all__ = ["evaluate_interval_gradients", "array_interval_gradients", "mean_value_enclosure"]


def evaluate_interval_gradients(tape: Tape, lo, hi):
    """Value and gradient enclosures over boxes.

    Returns ``(vlo, vhi, glo, ghi, valid)``: value intervals ``(n,)``,
    gradient intervals ``(3, n)``, and where the mean value theorem holds.
    Tapes the compiled kernel runs go there
    (:mod:`implicitvox.eval.mean_value_kernels`: the same enclosures, bit for
    bit), the others to :func:`array_interval_gradients`.
    """
    if len({np.shape(c) for c in lo} | {np.shape(c) for c in hi}) == 1:
        from .mean_value_kernels import tape_interval_gradients   # (loads Numba)
        compiled = tape_interval_gradients(tape, lo, hi)
        if compiled is not None:
            return compiled
    return array_interval_gradients(tape, lo, hi)


def array_interval_gradients(tape: Tape, lo, hi):
    """:func:`evaluate_interval_gradients` on the array evaluator: numpy calls per
    instruction over every box (the oracle of the compiled kernel, and the path
    of the tapes it does not run: libm functions, sweeps)."""
    n = lo[0].shape[0]
    valid = np.ones(n, dtype=bool)
    rv: list = [None] * tape.n_registers
    rg: list = [None] * tape.n_registers
    zero = np.zeros((3, 1))
    for axis, name in enumerate("xyz"):
        r = tape.inputs[name]
        if r >= 0:
            unit = np.zeros((3, 1))
            unit[axis] = 1.0
            rv[r], rg[r] = (lo[axis], hi[axis]), (unit, unit)
    for c in tape.constants:
        rv[c.register], rg[c.register] = (np.float64(c.lo), np.float64(c.hi)), (zero, zero)
    with np.errstate(all="ignore"):
        for ins in tape.instructions:
            args = tuple(rv[a] for a in ins.args)
            result = apply_op(ins.op, ins.param, tuple(a[0] for a in args),
                              tuple(a[1] for a in args))
            if ins.op.domain:
                result, empty = result[:2], result[2]
                valid &= ~np.broadcast_to(empty, (n,))
            arg_grads = tuple(rg[a] for a in ins.args)
            if ins.op.oracle:
                grad, bad = ins.param.interval_derivative(args, arg_grads, result,
                                                          evaluate_interval_gradients)
            else:
                grad, bad = ins.op.interval_derivative(args, arg_grads, result, ins.param)
            if bad is not None:
                valid &= ~np.broadcast_to(bad, (n,))
            rv[ins.out], rg[ins.out] = result, grad
    vlo, vhi = (np.broadcast_to(v, (n,)) for v in rv[tape.output])
    glo, ghi = (np.broadcast_to(g, (3, n)) for g in rg[tape.output])
    return vlo, vhi, glo, ghi, valid


def mean_value_enclosure(tape: Tape, lo, hi, natural=None, chunk: int = 1 << 13
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Enclosures of ``f`` over boxes: natural extension ∩ mean value form.

    ``natural`` is the natural enclosure ``(flo, fhi)`` if already computed.
    """
    n = lo[0].shape[0]
    flo, fhi = natural if natural is not None else evaluate_intervals(tape, lo, hi)
    if tape.undefined or n == 0:
        return flo, fhi
    out_lo, out_hi = np.array(flo, dtype=np.float64), np.array(fhi, dtype=np.float64)
    for s in range(0, n, chunk):
        part = slice(s, s + chunk)
        mlo, mhi, keep = _mean_value_form(tape, tuple(c[part] for c in lo),
                                          tuple(c[part] for c in hi))
        out_lo[part] = np.where(keep, np.maximum(out_lo[part], mlo), out_lo[part])
        out_hi[part] = np.where(keep, np.minimum(out_hi[part], mhi), out_hi[part])
    return out_lo, out_hi


def _mean_value_form(tape: Tape, lo, hi):
    n = lo[0].shape[0]
    centre = tuple(0.5 * (a + b) for a, b in zip(lo, hi))
    radius = [rounding.up_nonneg(np.maximum(c - a, b - c)) for a, b, c in zip(lo, hi, centre)]
    clo, chi = evaluate_intervals(tape, centre, centre)
    _, _, glo, ghi, valid = evaluate_interval_gradients(tape, lo, hi)
    spread = np.zeros(n)
    for axis in range(3):
        slope = np.maximum(-glo[axis], ghi[axis])            # max |df/dx_axis| over the box
        spread = rounding.up_nonneg(spread + rounding.up_nonneg(slope * radius[axis]))
    with np.errstate(invalid="ignore"):
        mlo = rounding.down(clo - spread)
        mhi = rounding.up(chi + spread)
    keep = valid & np.isfinite(spread) & (clo <= chi) & ~np.isnan(mlo) & ~np.isnan(mhi)
    return mlo, mhi, keep
