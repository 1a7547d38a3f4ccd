"""Interval evaluator: one pass of interval kernels per tape instruction over a batch of boxes.

Domain operations report lanes whose argument lies wholly outside their
domain; the function is undefined over such a box and the evaluator returns
the empty interval ``(+inf, -inf)`` for it (read as "no surface here").
"""
from __future__ import annotations

import numpy as np

from ..interval import kernels
from ..interval.float32 import exact_in_float32, float32_bounds, outward_float32
from .pruning import settle, settle_in_tree
from .tape import Tape
from .. import batches

__all__ = ["evaluate_intervals", "apply_op", "CHUNK"]

#: boxes per pass: the working set of a tape (a few dozen arrays) stays in cache
CHUNK = batches.BOXES


def evaluate_intervals(tape: Tape, lo: tuple[np.ndarray, np.ndarray, np.ndarray],
                       hi: tuple[np.ndarray, np.ndarray, np.ndarray], dtype=np.float64,
                       native: bool = False, choices: np.ndarray | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Enclosures ``(flo, fhi)`` of the taped function over boxes.

    Parameters
    ----------
    lo, hi : tuple of three arrays
        The box corners by axis: box ``i`` is
        ``[lo[0][i], hi[0][i]] x [lo[1][i], hi[1][i]] x [lo[2][i], hi[2][i]]``.
        No NaN, ``lo <= hi`` (the caller checks). The arrays may have any
        shapes that broadcast together with a common last axis: the
        subdivision passes the children of ``m`` octants as ``x`` bounds of
        shape ``(1, 1, 2, m)``, ``y`` of ``(1, 2, 1, m)`` and ``z`` of
        ``(2, 1, 1, m)``, so a subexpression of ``x`` alone is computed on 2
        boxes per octant instead of 8 (broadcasting does the rest; the long
        axis is innermost, where numpy's loops are fast).
    dtype : float64 or float32
        What the kernels compute in. float32 (only for tapes that
        :func:`implicitvox.octree.level_dtype.interval_dtype` allows) rounds the boxes
        outward to float32 first (bounds already in float32 are taken as they
        are); the enclosures are returned as float64, unless ``native``.
    native : bool, default: False
        Return the enclosures in ``dtype`` (float32 ends are exact in
        float64, so only the conversion is saved).
    choices : ndarray of int8, optional
        Shape ``(len(tape.branches),) + broadcast shape``: filled with the
        choice of each branch instruction over each box
        (:func:`implicitvox.eval.pruning.settle`), for the pruned tapes of
        the boxes' subtrees.

    Returns
    -------
    flo, fhi : ndarray
        Of the broadcast shape.
    """
    shape = np.broadcast_shapes(*(a.shape for a in lo), *(a.shape for a in hi))
    columns = shape[-1] if shape else 1
    per_column = max(1, int(np.prod(shape[:-1], dtype=np.int64))) if shape else 1
    step = max(1, CHUNK // per_column)
    single = np.dtype(dtype) == np.float32
    if single:   # float32 bounds are exact as they are
        lo, hi = zip(*((a, b) if _is_float32(a) and _is_float32(b) else outward_float32(a, b)
                       for a, b in zip(lo, hi)))
    result = np.float32 if single and native else np.float64
    flo, fhi = np.empty(shape, dtype=result), np.empty(shape, dtype=result)
    if columns <= step:
        _evaluate(tape, lo, hi, single, flo, fhi, choices)
        return flo, fhi
    for s in range(0, columns, step):   # in passes of `step` columns
        part = np.s_[..., s:s + step]
        _evaluate(tape, tuple(c[part] for c in lo), tuple(c[part] for c in hi), single,
                  flo[part], fhi[part], None if choices is None else choices[part])
    return flo, fhi


def _is_float32(a) -> bool:
    return getattr(a, "dtype", None) == np.float32


def apply_op(op, param, lo: tuple, hi: tuple, single: bool = False):
    """One instruction's kernel on argument bounds ``lo, hi`` (float32 arrays
    when ``single``). In float32, ``addc, rsubc, mulc`` whose constant float32
    cannot hold run as the operation on the constant's two-float32 interval."""
    if op.oracle:
        return param.interval(lo, hi, evaluate_intervals)
    if single and op.constant_operand and not exact_in_float32(param):
        clo, chi = float32_bounds(param)
        if op.name == "addc":
            return kernels.i_add(lo[0], hi[0], clo, chi)
        if op.name == "rsubc":
            return kernels.i_sub(clo, chi, lo[0], hi[0])
        return kernels.i_mul(lo[0], hi[0], clo, chi)
    return op.interval(lo, hi, param)


def _evaluate(tape, lo, hi, single: bool, flo: np.ndarray, fhi: np.ndarray,
              choices: np.ndarray | None = None) -> None:
    """The enclosures over one pass of boxes, written into ``flo, fhi`` (and the
    branch choices into ``choices``). A branch of a min tree (max tree) is
    settled against the tree's whole minimum (:func:`settle_in_tree`), which the
    tree's root computes after its branches: so such a tape runs twice, once for
    the roots' bounds and once for the choices."""
    if choices is not None:
        choices[...] = 0
    if tape.undefined:
        flo[...], fhi[...] = np.inf, -np.inf
        return
    trees = tape.choice_trees if choices is not None else ()
    totals = None
    if any(t >= 0 for t in trees):
        roots = {t for t in trees if t >= 0}
        totals = {}
        _run(tape, lo, hi, single, flo, fhi, None, None, roots, totals)
    _run(tape, lo, hi, single, flo, fhi, choices, totals)


def _run(tape, lo, hi, single: bool, flo: np.ndarray, fhi: np.ndarray,
         choices: np.ndarray | None, totals: dict | None = None, roots: set | None = None,
         kept: dict | None = None) -> None:
    """One run of the tape (see :func:`_evaluate`): with ``roots``, the bound of
    each root instruction its tree is settled against goes into ``kept``; with
    ``totals`` (those bounds), the branches of trees are settled against them."""
    trees = tape.choice_trees if totals is not None else ()
    shape = flo.shape
    branch = 0
    dtype = np.float32 if single else np.float64
    rlo: list = [None] * tape.n_registers
    rhi: list = [None] * tape.n_registers
    for axis, name in enumerate("xyz"):
        r = tape.inputs[name]
        if r >= 0:
            rlo[r], rhi[r] = lo[axis], hi[axis]
    for c in tape.constants:
        if single:
            rlo[c.register], rhi[c.register] = float32_bounds(c.lo)[0], float32_bounds(c.hi)[1]
        else:
            rlo[c.register], rhi[c.register] = np.float64(c.lo), np.float64(c.hi)
    empty = None
    with np.errstate(all="ignore"):
        for i, ins in enumerate(tape.instructions):
            args_lo, args_hi = tuple(rlo[a] for a in ins.args), tuple(rhi[a] for a in ins.args)
            if ins.op.choice and choices is not None:
                root = trees[branch] if totals is not None else -1
                if root >= 0:
                    np.copyto(choices[branch], settle_in_tree(ins.op.name, args_lo, args_hi,
                                                              totals[root], dtype))
                else:
                    np.copyto(choices[branch], settle(ins.op.name, args_lo, args_hi, dtype))
                branch += 1
            result = apply_op(ins.op, ins.param, args_lo, args_hi, single)
            if roots is not None and i in roots:      # a min tree's minimum is its upper bound
                kept[i] = result[1] if ins.op.name == "min" else result[0]
            if ins.op.domain:
                result, lane_empty = result[:2], result[2]
                empty = lane_empty if empty is None else (empty | lane_empty)
            rlo[ins.out], rhi[ins.out] = result
    out_lo, out_hi = rlo[tape.output], rhi[tape.output]
    if flo.dtype == np.float32 and not (_is_float32(out_lo) and _is_float32(out_hi)):
        out_lo, out_hi = outward_float32(np.asarray(out_lo, dtype=np.float64),
                                         np.asarray(out_hi, dtype=np.float64))
    np.copyto(flo, out_lo)   # broadcast (and cast to float64 unless native)
    np.copyto(fhi, out_hi)
    if empty is not None:
        empty = np.broadcast_to(empty, shape)
        flo[empty] = np.inf
        fhi[empty] = -np.inf
