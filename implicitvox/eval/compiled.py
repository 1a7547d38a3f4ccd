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
from .pruning import FIRST, RELATIVE_GAP, SECOND
from .tape import Tape

__all__ = ["CompiledTape", "encode", "compiled_tape", "once_per_tape", "evaluate_boxes", "run_row",
           "is_domain",
           "OPS", "BLOCK"]

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
#: (the mesher runs each cell's tape several times, and the level-3 sponge at 256 has
#: about 18,000 of them: a smaller cache emptied and refilled itself)
_ENCODED_LIMIT = 1 << 16


def compiled_tape(tape: Tape) -> Optional[CompiledTape]:
    """:func:`encode`, once per tape object (the last :data:`_ENCODED_LIMIT` kept)."""
    return once_per_tape(_ENCODED, _ENCODED_LIMIT, tape, encode)


def once_per_tape(cache: dict, limit: int, tape: Tape, build):
    """``build(tape)``, kept in ``cache`` by the tape object (emptied past ``limit``
    entries; holding the tape keeps its id unique)."""
    found = cache.get(id(tape))
    if found is not None and found[0] is tape:
        return found[1]
    if len(cache) >= limit:
        cache.clear()
    built = build(tape)
    cache[id(tape)] = (tape, built)
    return built


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
    rows = len(tape.code)
    _evaluate(tape.code, tape.params, tape.branch, tape.constant_registers, tape.constant_lo,
              tape.constant_hi, tape.inputs, tape.output, lo, hi, flo, fhi, record, choices,
              np.empty((tape.n_registers, BLOCK)), np.empty((tape.n_registers, BLOCK)),
              np.zeros(BLOCK, dtype=np.bool_), np.zeros(BLOCK, dtype=np.bool_),
              np.zeros((max(rows, 1), BLOCK), dtype=np.int8))
    return flo, fhi


@njit(**COMPILE)
def _evaluate(code, params, branch, creg, clo, chi, inputs, output, lo, hi, flo, fhi, record,
              choices, rlo, rhi, empty, outside, block_choices):
    """:func:`evaluate_boxes` in blocks of :data:`BLOCK` boxes, each instruction by
    :func:`run_row` over a block (masks 0: the boxes in slot 0). (Loops, not slice
    assignments, and buffers from the caller: they compile in a fraction of the time.)"""
    rows = code.shape[0]
    n = lo.shape[1]
    zero = np.int64(0)
    for s in range(0, n, BLOCK):
        m = min(BLOCK, n - s)
        for k in range(creg.size):
            for j in range(m):
                rlo[creg[k], j] = clo[k]
                rhi[creg[k], j] = chi[k]
        for a in range(3):
            r = inputs[a]
            if r >= 0:
                for j in range(m):
                    rlo[r, j] = lo[a, s + j]
                    rhi[r, j] = hi[a, s + j]
        for j in range(m):
            empty[j] = False
        for i in range(rows):
            op = np.int64(code[i, 0])
            run_row(op, np.int64(code[i, 1]), np.int64(code[i, 2]),
                    np.int64(max(code[i, 3], 0)), np.int64(max(code[i, 4], 0)), zero, zero,
                    zero, zero, np.int64(i), params[i, 0], params[i, 1], params[i, 2],
                    np.int64(m), rlo, rhi, outside, block_choices)
            if is_domain(op):
                for j in range(m):
                    empty[j] |= outside[j]
        for j in range(m):
            if empty[j]:
                flo[s + j], fhi[s + j] = np.inf, -np.inf
            else:
                flo[s + j], fhi[s + j] = rlo[output, j], rhi[output, j]
        if record:
            for i in range(rows):
                if branch[i] >= 0:
                    for j in range(m):
                        choices[branch[i], s + j] = block_choices[i, j]


@njit(**COMPILE)
def is_domain(op):
    """Is ``op`` a domain operation (its argument may lie wholly outside its domain)?"""
    return op == SQRT or op == LOG or op == ASIN or op == ACOS or op == POWR


@njit(**COMPILE)
def run_row(op, o, a, b, c, mo, ma, mb, mc, r, p0, p1, p2, n, rlo, rhi, outside, choices):
    """One instruction ``o <- op(a, b, c; p0, p1, p2)`` on the registers ``rlo, rhi``
    (rows: registers; columns: lanes ``s * n + q`` in 8 slots of ``n``), on the
    slots its mask ``mo`` tells apart (the subsets of ``mo``), each argument read at
    the slot of its own mask (``s & ma``); its choice (``min, max, abs``; row ``r``
    of ``choices``) and domain flag (``outside``) left at those slots too.

    The one interpreter of the compiled kernel: the subdivision runs it with the
    masks of the values over the 8 children of ``n`` octants
    (:mod:`implicitvox.octree.descend`), :func:`evaluate_boxes` with masks 0 over
    ``n`` boxes (slot 0 alone)."""
    if op == MIN:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                a0, a1, b0, b1 = rlo[a, sa + q], rhi[a, sa + q], rlo[b, sb + q], rhi[b, sb + q]
                margin = (abs(a0) + abs(b0) + abs(a1) + abs(b1)) * GAP
                choices[r, so + q] = FIRST * (a1 + margin < b0) + SECOND * (b1 + margin < a0)
                rlo[o, so + q], rhi[o, so + q] = i_min(a0, a1, b0, b1)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == MAX:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                a0, a1, b0, b1 = rlo[a, sa + q], rhi[a, sa + q], rlo[b, sb + q], rhi[b, sb + q]
                margin = (abs(a0) + abs(b0) + abs(a1) + abs(b1)) * GAP
                choices[r, so + q] = SECOND * (a1 + margin < b0) + FIRST * (b1 + margin < a0)
                rlo[o, so + q], rhi[o, so + q] = i_max(a0, a1, b0, b1)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ADDC:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_addc(rlo[a, sa + q], rhi[a, sa + q], p0)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == RSUBC:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_rsubc(rlo[a, sa + q], rhi[a, sa + q], p0)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == MULC:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_mulc(rlo[a, sa + q], rhi[a, sa + q], p0)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == DIVC:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_divc(rlo[a, sa + q], rhi[a, sa + q], p0)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == DISTANCE:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_distance(rlo[a, sa + q], rhi[a, sa + q],
                                                            rlo[b, sb + q], rhi[b, sb + q],
                                                            rlo[c, sc + q], rhi[c, sc + q], p0,
                                                            p1, p2)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ABS:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                a0, a1 = rlo[a, sa + q], rhi[a, sa + q]
                margin = (abs(a0) + abs(a1)) * GAP
                choices[r, so + q] = FIRST * (a0 > margin) + SECOND * (a1 < -margin)
                rlo[o, so + q], rhi[o, so + q] = i_abs(a0, a1)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == NEG:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_neg(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == SQUARE:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_square(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == EXP:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_exp(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == SIN:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_sin(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == COS:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_cos(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == TAN:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_tan(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ATAN:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_atan(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == FLOOR:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_floor(rlo[a, sa + q], rhi[a, sa + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ADD:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_add(rlo[a, sa + q], rhi[a, sa + q], rlo[b,
                                                       sb + q], rhi[b, sb + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == SUB:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_sub(rlo[a, sa + q], rhi[a, sa + q], rlo[b,
                                                       sb + q], rhi[b, sb + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == MUL:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_mul(rlo[a, sa + q], rhi[a, sa + q], rlo[b,
                                                       sb + q], rhi[b, sb + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == DIV:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_div(rlo[a, sa + q], rhi[a, sa + q], rlo[b,
                                                       sb + q], rhi[b, sb + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == HYPOT:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_hypot(rlo[a, sa + q], rhi[a, sa + q], rlo[b,
                                                         sb + q], rhi[b, sb + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ATAN2:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_atan2(rlo[a, sa + q], rhi[a, sa + q], rlo[b,
                                                         sb + q], rhi[b, sb + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == RADIUS:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_radius(rlo[a, sa + q], rhi[a, sa + q],
                                                          rlo[b, sb + q], rhi[b, sb + q],
                                                          rlo[c, sc + q], rhi[c, sc + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ELEVATION:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_elevation(rlo[a, sa + q], rhi[a, sa + q],
                                                             rlo[b, sb + q], rhi[b, sb + q],
                                                             rlo[c, sc + q], rhi[c, sc + q])
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == PERIODIC_ANGLE:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_periodic_angle(rlo[a, sa + q], rhi[a,
                                                                  sa + q], rlo[b, sb + q],
                                                                  rhi[b, sb + q], p0 != 0.0,
                                                                  p1, p2)
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == POWI:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q] = i_powi(rlo[a, sa + q], rhi[a, sa + q],
                                                        int(p0))
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == SQRT:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q], out_of_domain = i_sqrt(rlo[a, sa + q], rhi[a,
                                                                 sa + q])
                outside[so + q] = out_of_domain
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == LOG:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q], out_of_domain = i_log(rlo[a, sa + q], rhi[a,
                                                                      sa + q])
                outside[so + q] = out_of_domain
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ASIN:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q], out_of_domain = i_asin(rlo[a, sa + q], rhi[a,
                                                                 sa + q])
                outside[so + q] = out_of_domain
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == ACOS:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q], out_of_domain = i_acos(rlo[a, sa + q], rhi[a,
                                                                 sa + q])
                outside[so + q] = out_of_domain
            s = (s - mo) & mo
            if s == 0:
                break
    elif op == POWR:
        s = 0
        while True:                 # the subsets of mo: its slots
            so, sa, sb, sc = s * n, (s & ma) * n, (s & mb) * n, (s & mc) * n
            for q in range(n):
                rlo[o, so + q], rhi[o, so + q], out_of_domain = i_powr(rlo[a, sa + q], rhi[a,
                                                                 sa + q], p0)
                outside[so + q] = out_of_domain
            s = (s - mo) & mo
            if s == 0:
                break
