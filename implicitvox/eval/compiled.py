"""The compiled tape: a :class:`~implicitvox.eval.tape.Tape` as arrays, and its
interval interpreter in Numba.

:func:`encode` turns a tape into flat arrays (one row per instruction: opcode
number, output register, three argument registers; a row of three float
parameters), which compiled code reads without touching a Python object.
:func:`evaluate_boxes` runs the tape over boxes, one box at a time, each
instruction through its rule in :mod:`implicitvox.interval.rules` (the one
compiled source of every interval rule). A box on which a domain operation's
argument lies wholly outside its domain gets the empty interval
``(+inf, -inf)``, as from :func:`implicitvox.eval.interval.evaluate_intervals`.

Sweeps (the oracle rows ``repeat`` and ``repeat_polar``) drive a child tape
through Python: a tape holding one has no compiled form (:func:`encode`
returns None).

Examples
--------
>>> import numpy as np
>>> from implicitvox import x, y, z, sqrt
>>> from implicitvox.eval.tape import build_tape
>>> compiled = encode(build_tape(sqrt(x**2 + y**2 + z**2) - 1.0))
>>> lo = np.array([[0.0, 2.0], [0.0, 0.0], [0.0, 0.0]])
>>> flo, fhi = evaluate_boxes(compiled, lo, lo + 0.5)
>>> bool(flo[0] <= -1.0 and fhi[0] >= np.sqrt(0.75) - 1.0), bool(flo[1] > 0.0)
(True, True)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from numba import njit

from ..interval.rules import (COMPILE, i_abs, i_acos, i_add, i_addc, i_asin, i_atan, i_atan2,
                              i_cos, i_distance, i_div, i_divc, i_elevation, i_exp, i_floor,
                              i_hypot, i_log, i_max, i_min, i_mul, i_mulc, i_neg,
                              i_periodic_angle, i_powi, i_powr, i_radius, i_rsubc, i_sin, i_sqrt,
                              i_square, i_sub, i_tan)
from .pruning import FIRST, RELATIVE_GAP, SECOND, UNDECIDED
from .tape import Tape

__all__ = ["CompiledTape", "encode", "compiled_tape", "evaluate_boxes", "OPS", "BLOCK"]

#: boxes per block: each instruction runs over a block before the next one (its
#: registers, two floats per box and register, stay in the core's cache)
BLOCK = 512
#: the gap a min/max choice needs (pruning.RELATIVE_GAP in float64)
GAP = RELATIVE_GAP[np.dtype(np.float64)]

#: the operations compiled code knows, by number (the row's ``op`` column)
OPS = ("add", "sub", "mul", "div", "neg", "square", "powi", "powr", "sqrt", "abs", "exp",
       "log", "sin", "cos", "tan", "atan", "asin", "acos", "atan2", "hypot", "min", "max",
       "addc", "rsubc", "mulc", "divc", "radius", "distance", "elevation", "periodic_angle",
       "floor")
_ID = {name: k for k, name in enumerate(OPS)}
(ADD, SUB, MUL, DIV, NEG, SQUARE, POWI, POWR, SQRT, ABS, EXP, LOG, SIN, COS, TAN, ATAN, ASIN,
 ACOS, ATAN2, HYPOT, MIN, MAX, ADDC, RSUBC, MULC, DIVC, RADIUS, DISTANCE, ELEVATION,
 PERIODIC_ANGLE, FLOOR) = range(len(OPS))


@dataclass(frozen=True, eq=False)
class CompiledTape:
    """A tape as arrays (see :func:`encode`)."""

    #: (n, 5) int32: opcode number (:data:`OPS`), output register, argument registers
    #: (-1 past the arity)
    code: np.ndarray
    #: (n, 3) float64: the parameter (a constant operand; the exponent; a distance's
    #: centre; a periodic angle's function (0 sin, 1 cos), multiplier and offset)
    params: np.ndarray
    n_registers: int
    #: constants: registers, and the ends of their enclosures
    constant_registers: np.ndarray
    constant_lo: np.ndarray
    constant_hi: np.ndarray
    #: (3,) int32: the registers of x, y, z (-1: unused)
    inputs: np.ndarray
    output: int
    undefined: bool
    #: (n,) int32: per instruction, its index among the branches (min, max, abs), or -1
    branch: np.ndarray
    #: the positions of the branch instructions (Tape.branches)
    branches: tuple

    def __len__(self) -> int:
        return len(self.code)


def _params(name: str, param) -> tuple[float, float, float]:
    if name in ("addc", "rsubc", "mulc", "divc", "powr"):
        return float(param), 0.0, 0.0
    if name == "powi":
        return float(int(param)), 0.0, 0.0
    if name == "distance":
        return tuple(float(c) for c in param)
    if name == "periodic_angle":
        fn, k, c = param
        return (1.0 if fn == "cos" else 0.0), float(k), float(c)
    return 0.0, 0.0, 0.0


def encode(tape: Tape) -> Optional[CompiledTape]:
    """The arrays of ``tape``, or None if it holds an operation compiled code does
    not run (a sweep)."""
    n = len(tape.instructions)
    code = np.full((n, 5), -1, dtype=np.int32)
    branch = np.full(n, -1, dtype=np.int32)
    branch[list(tape.branches)] = np.arange(len(tape.branches), dtype=np.int32)
    params = np.zeros((n, 3), dtype=np.float64)
    for i, ins in enumerate(tape.instructions):
        op = _ID.get(ins.op.name)
        if op is None:
            return None
        code[i, 0], code[i, 1] = op, ins.out
        code[i, 2:2 + len(ins.args)] = ins.args
        params[i] = _params(ins.op.name, ins.param)
    return CompiledTape(
        code, params, tape.n_registers,
        np.array([c.register for c in tape.constants], dtype=np.int32),
        np.array([c.lo for c in tape.constants], dtype=np.float64),
        np.array([c.hi for c in tape.constants], dtype=np.float64),
        np.array([tape.inputs[name] for name in "xyz"], dtype=np.int32),
        tape.output, tape.undefined, branch, tape.branches)


_ENCODED: dict[int, tuple[Tape, Optional[CompiledTape]]] = {}
_ENCODED_LIMIT = 4096


def compiled_tape(tape: Tape) -> Optional[CompiledTape]:
    """:func:`encode`, once per tape object (the last :data:`_ENCODED_LIMIT` kept)."""
    found = _ENCODED.get(id(tape))
    if found is not None and found[0] is tape:
        return found[1]
    if len(_ENCODED) >= _ENCODED_LIMIT:
        _ENCODED.clear()
    encoded = encode(tape)
    _ENCODED[id(tape)] = (tape, encoded)      # (holding the tape keeps its id unique)
    return encoded


def evaluate_boxes(tape: CompiledTape, lo: np.ndarray, hi: np.ndarray,
                   choices: Optional[np.ndarray] = None) -> tuple[np.ndarray, np.ndarray]:
    """Enclosures ``(flo, fhi)`` of the compiled ``tape`` over boxes.

    ``lo, hi``: float64 arrays (3, n), box ``i`` being ``[lo[:, i], hi[:, i]]``;
    no NaN, ``lo <= hi`` (unchecked: the callers check). ``choices``: an int8
    array ``(len(tape.branches), n)`` to fill with each branch instruction's
    choice over each box (:func:`implicitvox.eval.pruning.settle`).
    """
    lo = np.ascontiguousarray(lo, dtype=np.float64)
    hi = np.ascontiguousarray(hi, dtype=np.float64)
    n = lo.shape[1]
    flo, fhi = np.empty(n), np.empty(n)
    record = choices is not None
    if not record:
        choices = np.zeros((0, 0), dtype=np.int8)
    elif choices.shape != (len(tape.branches), n):
        raise ValueError(f"choices must have the shape {(len(tape.branches), n)}, "
                         f"not {choices.shape}")
    if tape.undefined:
        flo[:], fhi[:] = np.inf, -np.inf
        choices[...] = 0
        return flo, fhi
    _evaluate(tape.code, tape.params, tape.branch, tape.n_registers, tape.constant_registers,
              tape.constant_lo, tape.constant_hi, tape.inputs, tape.output, lo, hi, flo, fhi,
              record, choices)
    return flo, fhi


@njit(**COMPILE)
def _evaluate(code, params, branch, n_registers, creg, clo, chi, inputs, output, lo, hi,
              flo, fhi, record, choices):
    """:func:`evaluate_boxes` in blocks of :data:`BLOCK` boxes."""
    rlo = np.empty((n_registers, BLOCK))
    rhi = np.empty((n_registers, BLOCK))
    empty = np.empty(BLOCK, dtype=np.bool_)
    block_choices = np.zeros((choices.shape[0] if record else 0, BLOCK), dtype=np.int8)
    n = lo.shape[1]
    for s in range(0, n, BLOCK):
        m = min(BLOCK, n - s)
        _load(creg, clo, chi, inputs, lo[:, s:s + m], hi[:, s:s + m], rlo, rhi)
        _run_block(code, params, branch, rlo, rhi, m, empty, record, block_choices)
        _store(rlo[output], rhi[output], empty, m, flo[s:s + m], fhi[s:s + m])
        if record:
            choices[:, s:s + m] = block_choices[:, :m]


@njit(**COMPILE)
def _load(creg, clo, chi, inputs, lo, hi, rlo, rhi):
    """The constants and the boxes' coordinates into their registers."""
    m = lo.shape[1]
    for k in range(creg.size):
        rlo[creg[k], :m] = clo[k]
        rhi[creg[k], :m] = chi[k]
    for a in range(3):
        r = inputs[a]
        if r >= 0:
            rlo[r, :m] = lo[a]
            rhi[r, :m] = hi[a]


@njit(**COMPILE)
def _store(out_lo, out_hi, empty, m, flo, fhi):
    for j in range(m):
        if empty[j]:
            flo[j], fhi[j] = np.inf, -np.inf
        else:
            flo[j], fhi[j] = out_lo[j], out_hi[j]


@njit(**COMPILE)
def _min_max_settled(alo, ahi, blo, bhi, out_lo, out_hi, m, out, is_max):
    """``min`` (``max``) over the block, and its choice (pruning.settle): FIRST where
    ``a`` wins with a gap, SECOND where ``b`` does."""
    first, second = (SECOND, FIRST) if is_max else (FIRST, SECOND)
    for j in range(m):      # branch-free (the outcomes are random)
        a0, a1, b0, b1 = alo[j], ahi[j], blo[j], bhi[j]
        margin = (abs(a0) + abs(b0) + abs(a1) + abs(b1)) * GAP
        out[j] = first * (a1 + margin < b0) + second * (b1 + margin < a0)
        if is_max:
            out_lo[j], out_hi[j] = i_max(a0, a1, b0, b1)
        else:
            out_lo[j], out_hi[j] = i_min(a0, a1, b0, b1)


@njit(**COMPILE)
def _settle_abs(alo, ahi, m, out):
    for j in range(m):
        margin = (abs(alo[j]) + abs(ahi[j])) * GAP
        out[j] = FIRST * (alo[j] > margin) + SECOND * (ahi[j] < -margin)


@njit(**COMPILE)
def _run_block(code, params, branch, rlo, rhi, m, empty, record, choices):
    """Every instruction over the first ``m`` boxes of the block, one instruction at a
    time (a loop over boxes per instruction: dispatched once, vectorizable)."""
    empty[:m] = False
    for i in range(code.shape[0]):
        op = code[i, 0]
        lo_o, hi_o = rlo[code[i, 1]], rhi[code[i, 1]]
        lo_a, hi_a = rlo[code[i, 2]], rhi[code[i, 2]]
        lo_b, hi_b = rlo[max(code[i, 3], 0)], rhi[max(code[i, 3], 0)]
        lo_c, hi_c = rlo[max(code[i, 4], 0)], rhi[max(code[i, 4], 0)]
        p0, p1, p2 = params[i, 0], params[i, 1], params[i, 2]
        if op == MIN:
            if record:
                _min_max_settled(lo_a, hi_a, lo_b, hi_b, lo_o, hi_o, m, choices[branch[i]], False)
            else:
                for j in range(m):
                    lo_o[j], hi_o[j] = i_min(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == MAX:
            if record:
                _min_max_settled(lo_a, hi_a, lo_b, hi_b, lo_o, hi_o, m, choices[branch[i]], True)
            else:
                for j in range(m):
                    lo_o[j], hi_o[j] = i_max(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == ADDC:
            for j in range(m):
                lo_o[j], hi_o[j] = i_addc(lo_a[j], hi_a[j], p0)
        elif op == RSUBC:
            for j in range(m):
                lo_o[j], hi_o[j] = i_rsubc(lo_a[j], hi_a[j], p0)
        elif op == MULC:
            for j in range(m):
                lo_o[j], hi_o[j] = i_mulc(lo_a[j], hi_a[j], p0)
        elif op == DIVC:
            for j in range(m):
                lo_o[j], hi_o[j] = i_divc(lo_a[j], hi_a[j], p0)
        elif op == DISTANCE:
            for j in range(m):
                lo_o[j], hi_o[j] = i_distance(lo_a[j], hi_a[j], lo_b[j], hi_b[j], lo_c[j], hi_c[j],
                                              p0, p1, p2)
        elif op == NEG:
            for j in range(m):
                lo_o[j], hi_o[j] = i_neg(lo_a[j], hi_a[j])
        elif op == ABS:
            if record:    # first: the output may be the argument's register
                _settle_abs(lo_a, hi_a, m, choices[branch[i]])
            for j in range(m):
                lo_o[j], hi_o[j] = i_abs(lo_a[j], hi_a[j])
        elif op == SQUARE:
            for j in range(m):
                lo_o[j], hi_o[j] = i_square(lo_a[j], hi_a[j])
        elif op == EXP:
            for j in range(m):
                lo_o[j], hi_o[j] = i_exp(lo_a[j], hi_a[j])
        elif op == SIN:
            for j in range(m):
                lo_o[j], hi_o[j] = i_sin(lo_a[j], hi_a[j])
        elif op == COS:
            for j in range(m):
                lo_o[j], hi_o[j] = i_cos(lo_a[j], hi_a[j])
        elif op == TAN:
            for j in range(m):
                lo_o[j], hi_o[j] = i_tan(lo_a[j], hi_a[j])
        elif op == ATAN:
            for j in range(m):
                lo_o[j], hi_o[j] = i_atan(lo_a[j], hi_a[j])
        elif op == FLOOR:
            for j in range(m):
                lo_o[j], hi_o[j] = i_floor(lo_a[j], hi_a[j])
        elif op == ADD:
            for j in range(m):
                lo_o[j], hi_o[j] = i_add(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == SUB:
            for j in range(m):
                lo_o[j], hi_o[j] = i_sub(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == MUL:
            for j in range(m):
                lo_o[j], hi_o[j] = i_mul(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == DIV:
            for j in range(m):
                lo_o[j], hi_o[j] = i_div(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == HYPOT:
            for j in range(m):
                lo_o[j], hi_o[j] = i_hypot(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == ATAN2:
            for j in range(m):
                lo_o[j], hi_o[j] = i_atan2(lo_a[j], hi_a[j], lo_b[j], hi_b[j])
        elif op == RADIUS:
            for j in range(m):
                lo_o[j], hi_o[j] = i_radius(lo_a[j], hi_a[j], lo_b[j], hi_b[j], lo_c[j], hi_c[j])
        elif op == ELEVATION:
            for j in range(m):
                lo_o[j], hi_o[j] = i_elevation(lo_a[j], hi_a[j], lo_b[j], hi_b[j], lo_c[j], hi_c[j])
        elif op == PERIODIC_ANGLE:
            is_cos = p0 != 0.0
            for j in range(m):
                lo_o[j], hi_o[j] = i_periodic_angle(lo_a[j], hi_a[j], lo_b[j], hi_b[j], is_cos, p1, p2)
        elif op == POWI:
            n = int(p0)
            for j in range(m):
                lo_o[j], hi_o[j] = i_powi(lo_a[j], hi_a[j], n)
        elif op == SQRT:
            for j in range(m):
                lo_o[j], hi_o[j], outside = i_sqrt(lo_a[j], hi_a[j])
                empty[j] |= outside
        elif op == LOG:
            for j in range(m):
                lo_o[j], hi_o[j], outside = i_log(lo_a[j], hi_a[j])
                empty[j] |= outside
        elif op == ASIN:
            for j in range(m):
                lo_o[j], hi_o[j], outside = i_asin(lo_a[j], hi_a[j])
                empty[j] |= outside
        elif op == ACOS:
            for j in range(m):
                lo_o[j], hi_o[j], outside = i_acos(lo_a[j], hi_a[j])
                empty[j] |= outside
        elif op == POWR:
            for j in range(m):
                lo_o[j], hi_o[j], outside = i_powr(lo_a[j], hi_a[j], p0)
                empty[j] |= outside
