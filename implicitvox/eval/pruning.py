"""Tapes pruned per region: the branches a box has settled, dropped for its whole subtree.

Over a box where one operand of ``min(a, b)`` lies wholly below the other
(``a``'s upper bound below ``b``'s lower bound), ``min(a, b) = a`` at every
point of the box and of every sub-box, so ``b`` and everything only ``b``
reads can be dropped for the subtree (libfive's and Fidget's "min/max
choices"; Keeter, *Massively Parallel Rendering of Complex Closed-Form
Implicit Surfaces*, SIGGRAPH 2020, §3). Likewise ``max``, and ``abs`` of an
argument of one sign becomes the argument or its negation. A CSG union of a
thousand parts then costs, near any one voxel, about what the few parts near
it cost.

The steps, each its own function:

* :func:`settle` - the choice of one branch instruction over boxes, from its
  operands' enclosures (the interval evaluator records it,
  :func:`implicitvox.eval.interval.evaluate_intervals` with ``choices=``);
* :func:`simplify` - the shorter tape for one vector of choices: settled
  branches aliased to their winner, dead instructions removed, registers
  reallocated (:func:`implicitvox.eval.tape.allocate`);
* :class:`Pruner` - the boxes of a chunk grouped by their choices, one tape
  per group, cached by choice signature and by content so equal subtrees
  share one tape.

**Nothing changes in the result.** Over a sub-box, the enclosures of ``a``
and ``b`` lie within those over the box (inclusion isotonicity: every kernel
is built from monotone, outward-rounded operations), so a branch settled
over a box stays settled, and the natural extension ``i_min(a, b)`` with
``a`` dominant returns ``a``'s enclosure exactly (``min`` and ``max`` are exact
kernels). The pruned tape therefore computes, bit for bit, what the whole
tape computes over every box of the subtree, and at every point in it
(point values and gradients pick the same branch). Two guards keep this true
where isotonicity holds only up to an ulp (libm's transcendental functions
are faithfully, not correctly, rounded; a float32 child's box is rounded
outward): a choice needs a gap of :data:`RELATIVE_GAP` times the operands'
magnitudes and widths, and a branch whose dropped operand reads a domain
operation (``sqrt``, ``log``, a sweep: an operation that can make the whole
function undefined over a box) is never dropped, since the whole tape's
"undefined" verdict would then be lost.

Examples
--------
>>> import numpy as np
>>> from implicitvox import x, y, min
>>> from implicitvox.eval.tape import build_tape
>>> tape = build_tape(min(x - 1.0, y * y))
>>> [ins.op.name for ins in tape.instructions]
['addc', 'square', 'min']
>>> [ins.op.name for ins in simplify(tape, [FIRST]).instructions]
['addc']
"""
from __future__ import annotations

from collections import OrderedDict
from typing import Optional, Sequence

import numpy as np

from .opcodes import OPCODES
from .tape import Tape, Value, allocate

__all__ = ["settle", "settle_in_tree", "simplify", "Pruner", "UNDECIDED", "FIRST", "SECOND", "RELATIVE_GAP",
           "CALL_COST", "MAX_SIGNATURES", "RUN"]

#: choices: both operands may still win; the first wins (``abs``: the argument
#: is positive); the second wins (``abs``: negative)
UNDECIDED, FIRST, SECOND = 0, 1, 2
#: the gap a choice needs, relative to the sum of the magnitudes of the operands'
#: ends (which bounds their widths too), by the float type the enclosures were
#: computed in (a few hundred ulps)
RELATIVE_GAP = {np.dtype(np.float64): 2.0 ** -30, np.dtype(np.float32): 2.0 ** -14}
#: the fixed cost of evaluating a tape over a batch, per instruction, in
#: box-instructions (numpy's per-call overhead against its per-element cost;
#: measured in tests/benchmarks/bench_pruning.py)
CALL_COST = 30000
#: distinct choice vectors up to which boxes are grouped by them
MAX_SIGNATURES = 16
#: boxes per run beyond that (see :meth:`Pruner.groups`)
RUN = 64
_NEG = OPCODES["neg"]


def settle(name: str, lo: tuple, hi: tuple, dtype) -> np.ndarray:
    """The choice (int8: UNDECIDED, FIRST or SECOND) of a ``min``, ``max`` or
    ``abs`` instruction over boxes, from its operands' enclosures ``lo, hi``
    (arrays of one broadcast shape, in ``dtype``).

    Examples
    --------
    >>> import numpy as np
    >>> settle("min", (np.array([0.0, 0.0]), np.array([2.0, 0.5])),
    ...        (np.array([1.0, 1.0]), np.array([3.0, 1.5])), np.float64)
    array([1, 0], dtype=int8)
    """
    gap = RELATIVE_GAP[np.dtype(dtype)]
    with np.errstate(all="ignore"):   # empty (inf, -inf) and unbounded operands: NaN gaps
        if name == "abs":
            alo, ahi = lo[0], hi[0]
            margin = np.add(np.abs(alo), np.abs(ahi), dtype=dtype)
            margin *= gap
            positive = np.asarray(alo > margin).view(np.int8)
            return positive + 2 * np.asarray(ahi < -margin).view(np.int8)
        (alo, blo), (ahi, bhi) = lo, hi
        # gap times the sum of the ends' magnitudes (the operands' shapes may differ)
        margin = np.add(np.abs(alo), np.abs(blo), dtype=dtype)
        margin += np.abs(ahi)
        margin += np.abs(bhi)
        margin *= gap
        a_below = np.asarray(ahi + margin < blo).view(np.int8)
        b_below = np.asarray(bhi + margin < alo).view(np.int8)
    if name == "max":
        a_below, b_below = b_below, a_below
    return a_below + b_below + b_below


def settle_in_tree(name: str, lo: tuple, hi: tuple, total: np.ndarray, dtype) -> np.ndarray:
    """The choice of a ``min`` (``max``) instruction of a min tree (max tree,
    :attr:`implicitvox.eval.tape.Tape.choice_trees`) over boxes, against the
    whole tree: ``total`` is the upper (lower) bound of the tree's root, the
    n-ary ``min`` of all its leaves.

    An operand whose lower bound lies above ``total`` is above the minimum at
    every point of the box, and over every sub-box (the operand's bound only
    rises there, the total only falls): it is dropped, whichever operands it
    was bracketed with (:func:`settle` compares the two operands alone, so in a
    chain ``min(min(min(a, b), c), d)`` a part could only lose to the parts
    before it). The kept operands' minimum is the same, bit for bit (``min`` is
    exact). When both operands are dropped (the instruction's whole subtree is
    above the total, so its parent drops it too), the first is kept.

    Examples
    --------
    >>> import numpy as np
    >>> lo, hi = (np.array([5.0]), np.array([0.0])), (np.array([6.0]), np.array([1.0]))
    >>> settle_in_tree("min", lo, hi, np.array([0.5]), np.float64)   # the first is dropped
    array([2], dtype=int8)
    """
    gap = RELATIVE_GAP[np.dtype(dtype)]
    with np.errstate(all="ignore"):   # empty and unbounded operands: NaN comparisons
        if name == "min":
            a, b = lo
            total_up = total + gap * (np.abs(a) + np.abs(b) + 2 * np.abs(total))
            b_out = np.asarray(b > total_up)
            a_out = np.asarray(a > total_up) & ~b_out
        else:
            a, b = hi
            total_down = total - gap * (np.abs(a) + np.abs(b) + 2 * np.abs(total))
            b_out = np.asarray(b < total_down)
            a_out = np.asarray(a < total_down) & ~b_out
    return b_out.view(np.int8) + 2 * a_out.view(np.int8)


def simplify(tape: Tape, choices: Sequence[int], max_length: Optional[int] = None
             ) -> Optional[Tape]:
    """The tape with its settled branches resolved and dead instructions removed.

    ``choices[k]`` is the choice of instruction ``tape.branches[k]``. The
    kept instructions are the same operations on the same values, in the same
    order, so every value they compute is bit-identical; only the registers
    are renumbered. A choice whose dropped operand depends on a domain
    operation is ignored (see the module docstring). With ``max_length``,
    None when the pruned tape would be longer (nothing is built).
    """
    if tape.undefined or not np.any(choices):
        return tape if max_length is None or len(tape) <= max_length else None
    values, root, domain = tape.graph
    fixed = len(values) - len(tape)
    resolved = list(range(len(values)))
    negated = set()
    for k in np.flatnonzero(choices):
        v = fixed + tape.branches[k]
        args, choice = values[v].args, int(choices[k])
        if values[v].op.name == "abs":
            if choice == FIRST:
                resolved[v] = resolved[args[0]]
            else:
                negated.add(v)
        elif not domain[args[2 - choice]]:       # the loser is args[1] or args[0]
            resolved[v] = resolved[args[choice - 1]]
    live = bytearray(len(values))
    live[resolved[root]] = 1
    for v in range(len(values) - 1, fixed - 1, -1):
        if live[v]:
            for a in values[v].args:
                live[resolved[a]] = 1
    kept = [v for v in range(len(values)) if live[v]]
    if max_length is not None and len(kept) - sum(live[:fixed]) > max_length:
        return None
    index = {v: i for i, v in enumerate(kept)}
    graph = []
    for v in kept:
        value = values[v]
        if value.kind != "op":
            graph.append(value)
            continue
        args = tuple(index[resolved[a]] for a in value.args)
        graph.append(Value("op", op=_NEG, args=args) if v in negated else
                     Value("op", op=value.op, args=args, param=value.param))
    return allocate(graph, index[resolved[root]])   # (the root may be an input or constant)


class Pruner:
    """Pruned tapes for groups of boxes, shared between equal choices.

    Parameters
    ----------
    limit : int
        Tapes kept in the cache (oldest dropped first; a dropped tape is
        rebuilt when asked for again).
    """

    def __init__(self, limit: int = 4096):
        self.limit = limit
        self._by_choices: OrderedDict = OrderedDict()
        self._by_content: dict = {}
        #: tapes built (cache misses), for the benchmarks
        self.built = 0

    def pruned(self, tape: Tape, choices: np.ndarray, max_length: Optional[int] = None
               ) -> Optional[Tape]:
        """``simplify(tape, choices, max_length)``, from the cache when seen before."""
        key = (id(tape), choices.tobytes())
        found = self._by_choices.get(key)
        if found is not None:
            parent, child, length = found
            if child is not None or (max_length is not None and length > max_length):
                self._by_choices.move_to_end(key)
                return child if max_length is None or length <= max_length else None
        child = simplify(tape, choices, max_length)
        if child is None:
            self._by_choices[key] = (tape, None, max_length + 1)   # at least that long
        else:
            self.built += 1
            child = self._by_content.setdefault(_content(child), child)
            self._by_choices[key] = (tape, child, len(child))
            # (the parent is kept alive in the entry, so its id stays unique)
        if len(self._by_choices) > self.limit:
            self._by_choices.popitem(last=False)
        if len(self._by_content) > self.limit:
            self._by_content.clear()
        return child

    def groups(self, tape: Tape, choices: np.ndarray, selected: np.ndarray,
               keys: Optional[np.ndarray] = None, levels_below: int = 0
               ) -> list[tuple[np.ndarray, Tape]]:
        """The ``selected`` boxes (indices into the columns of ``choices``, an
        int8 array (branches, boxes)) in groups, each with the tape pruned by
        the choices its boxes share.

        Each group is evaluated apart from then on, and an evaluation costs
        about :data:`CALL_COST` box-instructions per instruction on top of one
        per box and instruction; so a group must be large enough for its
        shorter tape to pay. The boxes are octants with ``levels_below`` levels
        of descendants to classify, about ``8 k (4**(J + 1) - 1) / 3`` boxes
        for ``k`` octants and ``J`` levels (Stolte §4.1.3's growth of 4 per
        level), in at least ``J + 1`` evaluations. Up to
        :data:`MAX_SIGNATURES` distinct choice vectors, the boxes are grouped
        by them, and a group gets its tape of ``l`` instructions instead of
        ``L`` when ``(L - l) boxes > CALL_COST l (J + 1)``. Beyond that
        (boxes in many regions), the boxes are
        taken in the order of ``keys`` (Morton codes: compact blocks of space)
        in runs of :data:`RUN` boxes, each pruned by the choices all its boxes
        share. Groups with one tape are merged.
        """
        if not tape.branches or not len(selected):
            return [(selected, tape)]
        columns = np.ascontiguousarray(choices[:, selected].T)
        signature = columns.view(np.dtype((np.void, columns.shape[1]))).ravel()
        unique, first, inverse = np.unique(signature, return_index=True, return_inverse=True)
        if len(unique) == 1:
            return [(selected, self.pruned(tape, columns[0]))]
        if len(unique) <= MAX_SIGNATURES:
            order = np.argsort(inverse, kind="stable")
            bounds = np.cumsum(np.bincount(inverse, minlength=len(unique)))[:-1]
            parts = [(members, columns[first[k]]) for k, members in
                     enumerate(np.split(order, bounds))]
        else:
            order = np.argsort(keys, kind="stable") if keys is not None else \
                np.arange(len(selected))
            parts = [(members, _agreed(columns[members]))
                     for members in np.split(order, np.arange(RUN, len(order), RUN))]
        by_tape: dict[int, tuple[list, Tape]] = {}
        rest: list[np.ndarray] = []
        calls = CALL_COST * (levels_below + 1)
        for members, shared in parts:
            # own tape when boxes (L - l) > calls l, boxes those of the subtrees
            boxes = 8 * len(members) * (4 ** (levels_below + 1) - 1) // 3
            longest = -(-boxes * len(tape) // (boxes + calls)) - 1
            child = self.pruned(tape, shared, longest) if longest >= 0 else None
            if child is not None:
                by_tape.setdefault(id(child), ([], child))[0].append(members)
            else:
                rest.append(members)
        if rest:
            members = np.concatenate(rest)
            child = self.pruned(tape, _agreed(columns[members]))
            by_tape.setdefault(id(child), ([], child))[0].append(members)
        return [(selected[np.sort(np.concatenate(parts)) if len(parts) > 1 else parts[0]], child)
                for parts, child in by_tape.values()]


def _agreed(columns: np.ndarray) -> np.ndarray:
    """The choices (rows: boxes) that all boxes share; UNDECIDED elsewhere."""
    return np.where((columns == columns[0]).all(axis=0), columns[0], UNDECIDED).astype(np.int8)


def _content(tape: Tape) -> tuple:
    """A key equal for tapes of the same instructions (parameters by identity:
    pruned tapes share their parent's parameter objects)."""
    return (tape.output, tape.n_registers, tape.undefined,
            tuple(sorted(tape.inputs.items())),
            tuple((c.register, c.value, c.lo, c.hi) for c in tape.constants),
            tuple((ins.op.name, ins.out, ins.args, id(ins.param)) for ins in tape.instructions))
