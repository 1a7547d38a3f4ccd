"""Robust octree subdivision: interval arithmetic on a frontier of octants.

Stolte §2 (Fig. 1): evaluate the inclusion function over an octant; if the
interval excludes 0 the surface does not pass through it and the octant is
rejected, otherwise it is subdivided, down to the voxel level. Every octant
is one of

* EMPTY - ``flo > 0`` (or the function is undefined over it): outside;
* FULL - ``fhi < 0``: inside the solid, kept as one coarse octant (interior);
* AMBIGUOUS - neither: subdivided; at the target depth, a surface voxel.

Since each inclusion function encloses the exact range, an octant the
surface meets is never EMPTY or FULL: no surface voxel is ever missed.

The frontier is processed as a stack of chunks of octants (at most
``chunk`` octants, one interval evaluation each), deepest first, so memory
stays bounded by ``8 * chunk * depth`` octants whatever the resolution. Each
chunk is an independent set of subtrees (the unit a parallel driver hands
out; Stolte §5.2). Octants travel as Morton codes (a child is ``parent << 3
| slot``), so the surface voxels come out ready for the pointer octree, and
the interval evaluation runs in float32 where
:func:`implicitvox.octree.level_dtype.interval_dtype` allows it (about 3 times
faster, still rounded outward).
"""
from __future__ import annotations

import functools
from typing import Optional

import numpy as np

from ..eval.function import Function
from ..eval.interval import evaluate_intervals
from ..eval.pruning import Pruner
from ..eval.tape import Tape
from .frontier import Frontier
from .grid import Grid
from .guard import MemoryGuard
from .level_dtype import level_dtype
from ..interval.float32 import outward_float32
from ..eval.float32_tapes import supports_float32
from ..expr.shape import AMBIGUOUS, FULL, Octants
from .. import batches
from .octants import (RECHECK, ROOT_CODE, Progress, PrunedTapes, Subdivision, axes, by_tapes,
                      classify, classify_root, inside_children, pack, runs_compiled, states,
                      suspect_voxels, tighten, unpack)

__all__ = ["subdivide", "Subdivision", "classify", "classify_children", "suspect_voxels",
           "recheck_voxels", "prunes_at", "CHUNK", "RECHECK", "PRUNE_EVERY", "PRUNE_MIN_BELOW",
           "PRUNE_MIN_LENGTH"]

#: octants classified per interval evaluation
CHUNK = batches.FRONTIER
#: tapes are pruned every PRUNE_EVERY levels, down to PRUNE_MIN_BELOW levels above the
#: voxels (:func:`prunes_at`)
PRUNE_EVERY = 2
PRUNE_MIN_BELOW = 3
#: tapes shorter than this are not pruned further (:func:`prunes_at`)
PRUNE_MIN_LENGTH = 128


_BROADCAST = [(1, 1, 2, -1), (1, 2, 1, -1), (2, 1, 1, -1)]

# Octants on the stack are Morton codes (uint64, :mod:`implicitvox.octree.morton`): a
# child is ``parent << 3 | slot``, selecting kept children gathers one integer
# per octant, and the surface voxels come out ready for the octree.
_SLOTS = np.arange(8, dtype=np.uint64)
_THREE = np.uint64(3)


def _child_boxes(grid: Grid, level: int, parents: tuple[np.ndarray, ...], single: bool = False):
    """Per-axis bounds of the children of octants ``parents`` (per-axis
    coordinates), shaped to broadcast: ``x (1, 1, 2, m)``, ``y (1, 2, 1, m)``,
    ``z (2, 1, 1, m)``; the (2, 2, 2, m) result reshapes to ``(8, m)`` in
    child order ``x + 2y + 4z``. Children past the grid get degenerate boxes
    on its edge (they are dropped after). ``single``: float32 bounds rounded
    outward (the same values :func:`implicitvox.interval.float32.outward_float32`
    gives the float64 ones). Looked up in :func:`_child_edges` (one gather
    per axis and end) up to grids of ``_EDGE_TABLE_LIMIT`` voxels a side."""
    lo, hi = [], []
    for a in range(3):
        if grid.shape[a] < _EDGE_TABLE_LIMIT:
            low, high = _child_edges(grid, level, a, single)
            lo.append(np.take(low, parents[a], axis=1).reshape(_BROADCAST[a]))
            hi.append(np.take(high, parents[a], axis=1).reshape(_BROADCAST[a]))
        else:
            first, last = _child_edge_indices(grid, level, a, parents[a])
            low, high = grid.edge(a, first), grid.edge(a, last)
            if single:
                low, high = outward_float32(low, high)
            lo.append(low.reshape(_BROADCAST[a]))
            hi.append(high.reshape(_BROADCAST[a]))
    return tuple(lo), tuple(hi)


_HALVES = np.array([[0], [1]], dtype=np.int64)
#: voxels per axis up to which the child edges are tabulated (tables of at most
#: 2 * 2**15 values per level and axis)
_EDGE_TABLE_LIMIT = 1 << 16


def _child_edge_indices(grid: Grid, level: int, axis: int, parents: np.ndarray):
    """Voxel indices of the lower and upper edges (2, m) along ``axis`` of the
    two halves of octants at ``level`` with coordinates ``parents``, clamped
    to the grid."""
    scale = 1 << (grid.depth - level - 1)
    first = (np.asarray(parents, dtype=np.int64)[None, :] * 2 + _HALVES) * scale
    return np.minimum(first, grid.shape[axis]), np.minimum(first + scale, grid.shape[axis])


@functools.lru_cache(maxsize=256)
def _child_edges(grid: Grid, level: int, axis: int, single: bool
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The lower and upper edges along ``axis`` of the two halves of every
    octant at ``level`` (arrays (2, 2**level), by octant coordinate), in
    float64 or rounded outward to float32 (``single``)."""
    first, last = _child_edge_indices(grid, level, axis, np.arange(1 << level))
    low, high = grid.edge(axis, first), grid.edge(axis, last)
    if single:
        low, high = outward_float32(low, high)
    return low, high


def _childstates(tape: Tape, grid: Grid, level: int, parents: np.ndarray, dtype,
                  record: bool = False):
    """States (8, m) of the children of octants ``parents`` (Morton codes) at
    ``level``, child-major, EMPTY past the grid; their bounds (8 m), the
    number of children inside the grid, which are inside, and (``record``)
    the branch choices ``(len(tape.branches), 8 m)`` over them."""
    parent_axes = axes(parents)
    lo, hi = _child_boxes(grid, level, parent_axes, single=np.dtype(dtype) == np.float32)
    choices = np.empty((len(tape.branches), 2, 2, 2, len(parents)), dtype=np.int8) \
        if record else None
    flo, fhi = evaluate_intervals(tape, lo, hi, dtype, native=True, choices=choices)
    flo, fhi = flo.reshape(-1), fhi.reshape(-1)     # child-major: index = child * m + parent
    state = states(flo, fhi)
    classified = state.size
    inside = inside_children(grid, level + 1, parent_axes)
    if inside is not None:
        state *= inside
        classified = int(np.count_nonzero(inside))
    if record:
        choices = choices.reshape(len(tape.branches), -1)
    return state, flo, fhi, classified, inside, choices


def prunes_at(level: int, depth: int, length: int) -> bool:
    """Whether the choices over the children of octants at ``level`` are recorded to
    prune their subtrees' tapes of ``length`` instructions: every
    :data:`PRUNE_EVERY` levels, only where :data:`PRUNE_MIN_BELOW` levels at
    least lie below the children, and for tapes of :data:`PRUNE_MIN_LENGTH`
    instructions or more. Recording costs about a third of an evaluation, the
    deepest levels hold most boxes, and a short tape gains less than the
    smaller batches cost: pruning there would split the frontier into batches
    too small for numpy (measured in tests/benchmarks/bench_pruning.py)."""
    below = depth - level - 1
    return length >= PRUNE_MIN_LENGTH and below >= PRUNE_MIN_BELOW and below % PRUNE_EVERY == 0


def classify_children(tape: Tape, grid: Grid, level: int, parents: np.ndarray,
                      exact=None, mean_value: bool = False, dtype=np.float64,
                      full: bool = False, recheck: float = 0.0,
                      pruner: Optional[Pruner] = None, run: Optional[dict] = None
                      ) -> tuple[list, Optional[np.ndarray], list, int]:
    """The AMBIGUOUS children of octants at ``level`` (and the FULL ones if ``full``).

    ``parents`` and the children returned are Morton codes. One broadcast
    interval evaluation for all children (see :func:`_child_boxes`), in
    ``dtype``; the mean value form and the exact test then run on the
    AMBIGUOUS ones, as in :func:`classify`. At the voxel level, without an
    exact test, the AMBIGUOUS children that :func:`suspect_voxels` picks
    (``recheck`` > 0) are *suspects* (see :func:`recheck_voxels`), returned
    apart. With a ``pruner``, the children are grouped by the branch choices
    their enclosures settled, each group with its pruned tape (valid over the
    group's boxes; :mod:`implicitvox.eval.pruning`). Returns ``(ambiguous,
    full, suspects, classified)``: ``ambiguous`` and ``suspects`` lists of
    groups ``(codes, tape)``, ``full`` codes or None unless asked for,
    ``classified`` the number of boxes classified. ``run``: the subdivision's
    scratch space, for an exact test that takes the octants.
    """
    record = pruner is not None and bool(tape.branches) and prunes_at(level, grid.depth,
                                                                      len(tape))
    state, flo, fhi, classified, inside, choices = _childstates(tape, grid, level, parents,
                                                                 dtype, record)
    kids = ((parents << _THREE)[None, :] | _SLOTS[:, None]).reshape(-1)
    if mean_value or exact is not None:
        amb = np.flatnonzero(state == AMBIGUOUS)
        if amb.size:
            # the natural bounds are known: only the boxes are rebuilt, as columns
            box_lo, box_hi = grid.octant_boxes(level + 1, unpack(kids[amb]))
            octants = None if run is None else Octants(level + 1, kids[amb], run)
            state[amb] = tighten(tape, box_lo, box_hi, flo[amb].astype(np.float64),
                                  fhi[amb].astype(np.float64), state[amb], exact, mean_value,
                                  octants)
    ambiguous = state == AMBIGUOUS
    suspects: list = []

    def groups(mask: np.ndarray) -> list:
        which = np.flatnonzero(mask)
        if not len(which):
            return []
        if not record:
            return [(kids[which], tape)]
        return [(kids[members], pruned) for members, pruned in
                pruner.groups(tape, choices, which, kids[which], grid.depth - level - 1)]

    if recheck > 0.0 and exact is None and level + 1 == grid.depth:
        near_end = suspect_voxels(flo, fhi, len(parents), recheck, inside)
        near_end &= ambiguous
        suspects = groups(near_end)
        ambiguous &= ~near_end
    return (groups(ambiguous), kids[np.flatnonzero(state == FULL)] if full else None, suspects,
            classified)


def recheck_voxels(tape: Tape, grid: Grid, codes: np.ndarray, dtype
                   ) -> tuple[np.ndarray, np.ndarray, int]:
    """Settle suspect voxels (Morton codes at ``grid.depth``) on their 8 sub-voxels.

    A suspect (:func:`suspect_voxels`) is a voxel whose enclosure reaches 0
    only by the amount it overestimates the range of ``f`` (natural
    interval extensions converge linearly, Stolte §2), as predicted from its
    siblings. Its 8 halves, being smaller, get tighter enclosures: it
    stays AMBIGUOUS if one of them is, and is FULL (EMPTY) if all are, since
    any two halves share a point and a FULL one cannot touch an EMPTY one.
    This is ``subvoxel=1`` (Stolte's sub-voxel refinement) on the few voxels
    it can change: as sound, and cheap. ``dtype``: the voxels' float type;
    ``tape``: one valid over all the voxels (the function's, or their pruned one).
    Returns ``(still AMBIGUOUS, FULL, boxes classified)``.
    """
    fine = grid.finer(1)
    sub_dtype = level_dtype(fine, fine.depth) if np.dtype(dtype) == np.float32 else np.float64
    state, _, _, classified, _, _ = _childstates(tape, fine, grid.depth, codes, sub_dtype)
    state = state.reshape(8, -1)
    met = (state == AMBIGUOUS).any(axis=0)
    inside = (state == FULL).all(axis=0)
    return codes[met], codes[inside], classified


def subdivide(func: Function, grid: Grid, *, start: Optional[tuple[int, np.ndarray]] = None,
              interior: bool = False, exact=None, progress=None, chunk: int = CHUNK,
              mean_value: bool = False, exact_voxels=None,
              recheck: float = RECHECK, guard: Optional[MemoryGuard] = None,
              prune: bool = True, leaf_level: Optional[int] = None,
              until_level: Optional[int] = None,
              start_tapes: Optional[PrunedTapes] = None) -> Subdivision:
    """Classify octants from the root (or from ``start``) down to the voxels.

    Parameters
    ----------
    func : Function
        The compiled implicit function.
    grid : Grid
        The voxel grid; the octree has ``grid.depth`` levels below the root.
    start : (level, coords), optional
        AMBIGUOUS octants at ``level`` to continue from (default: classify the
        root). ``Voxels.refine`` passes the stored surface voxels.
    interior : bool, default: False
        Record FULL octants.
    exact : callable, optional
        The shape's exact box test, applied to interval-AMBIGUOUS octants.
    exact_voxels : callable, optional
        Its form for the target depth (default: ``exact``), which must decide
        every box (see :func:`implicitvox.expr.shape.voxel_classifier`).
    progress : callable, optional
        Called with the estimated share of work done, in [0, 1].
    chunk : int
        Octants classified per step (the children of ``chunk // 8`` parents).
    mean_value : bool, default: False
        Tighten AMBIGUOUS octants with the mean value form.
    recheck : float, default: RECHECK
        Strength of the recheck of suspect voxels on their 8 sub-voxels
        (:func:`suspect_voxels`, :func:`recheck_voxels`); 0 turns it off.
    guard : MemoryGuard, optional
        Asked after every step with the surface voxels kept and the octants
        pending or interior; it stops the run (``MemoryError``) past its budget.
    prune : bool, default: True
        Evaluate each subtree with the tape pruned by the branch choices its
        octants settled (:mod:`implicitvox.eval.pruning`); the result is
        bit-identical either way, only faster.
    leaf_level : int, optional
        The level whose tapes :attr:`Subdivision.tapes` reports (default: the
        voxels; the voxelizer's ``subvoxel`` runs pass the coarser voxels' level).
    until_level : int, optional
        Stop at this level (below ``grid.depth``): the AMBIGUOUS octants reached
        there are returned in :attr:`Subdivision.pending` instead of being
        subdivided. Each is an independent subtree; continuing from them
        (``start``) gives, together, exactly the serial run's voxels and
        interior (a box's state depends on the box alone).
    start_tapes : PrunedTapes, optional
        The pruned tapes of the ``start`` octants on the compiled kernel (a
        head run's :attr:`Subdivision.pending_tapes`): the subtrees continue on
        them instead of the whole tape (the same result, sooner). The array
        evaluator, which keeps no tapes between runs, ignores them.
    """
    if runs_compiled(func.tape, grid):
        from .descend import descend     # (loads Numba: not at import)
        return descend(func, grid, start=start, interior=interior, exact=exact,
                       progress=progress, chunk=chunk, mean_value=mean_value,
                       exact_voxels=exact_voxels, recheck=recheck, guard=guard, prune=prune,
                       leaf_level=leaf_level, until_level=until_level,
                       start_tapes=start_tapes)
    depth = grid.depth
    leaf_level = depth if leaf_level is None else leaf_level
    per_step = max(1, chunk // 8)
    if exact_voxels is None:
        exact_voxels = exact
    pruner = Pruner() if prune else None
    run: dict = {}          # the exact test's scratch space for this subdivision
    base = func.tape
    # the surface voxels as parts (codes, tape valid over their leaf_level octants)
    surface: list[tuple[np.ndarray, Tape]] = []
    interior_parts: dict[int, list[np.ndarray]] = {}
    # pending octants, with the tape valid over them and that of their leaf_level octant
    frontier = Frontier()
    evaluated = 0
    if start is None:
        evaluated = 1
        if classify_root(func, grid, exact, exact_voxels, mean_value, interior, interior_parts,
                         run):
            if depth == 0:
                surface.append((ROOT_CODE.copy(), base))
            else:
                frontier.push(0, ROOT_CODE.copy(), base, base if leaf_level == 0 else None)
    else:
        level0, coords0 = start
        frontier.push(level0, pack(coords0), base, base if level0 >= leaf_level else None)
    meter = Progress(progress, depth)
    single = supports_float32(base)
    voxel_dtype = level_dtype(grid, depth) if single else np.float64
    suspects: list[tuple[np.ndarray, Tape, Tape]] = []
    held_back: list[np.ndarray] = []     # octants reaching until_level
    pending = 0
    kept = sum(len(c) for c, _ in surface)
    held = len(frontier)   # pending and interior octant keys

    def settle_suspects() -> int:
        classified = 0
        for codes, tape, leaf_tape in by_tapes(suspects):
            met, full, count = recheck_voxels(tape, grid, codes, voxel_dtype)
            classified += count
            surface.append((met, leaf_tape))
            nonlocal kept
            kept += len(met)
            if interior and len(full):
                interior_parts.setdefault(depth, []).append(full)
        suspects.clear()
        return classified

    while frontier:
        level, parents, tape, leaf_tape = frontier.pop(per_step)
        held -= len(parents)
        ambiguous, full, suspect, classified = classify_children(
            tape, grid, level, parents, exact_voxels if level + 1 == depth else exact, mean_value,
            level_dtype(grid, level + 1) if single else np.float64, full=interior,
            recheck=recheck, pruner=pruner, run=run)
        if full is not None and len(full):
            interior_parts.setdefault(level + 1, []).append(full)
            held += len(full)
        for codes, pruned in suspect:   # rechecked in batches, for full-sized evaluations
            suspects.append((codes, pruned, pruned if level + 1 == leaf_level else leaf_tape))
            pending += len(codes)
        if suspects and (pending >= per_step or not frontier):
            classified += settle_suspects()
            pending = 0
        evaluated += classified
        meter.done += classified
        for codes, pruned in ambiguous:
            at_leaf = pruned if level + 1 == leaf_level else leaf_tape
            if level + 1 == depth:
                surface.append((codes, at_leaf))
                kept += len(codes)
            elif level + 1 == until_level:
                held_back.append(codes)
            else:
                frontier.push(level + 1, codes, pruned, at_leaf)
                held += len(codes)
        if guard is not None:
            guard.check(kept + pending, held)
        meter.report(frontier)
    if suspects:
        evaluated += settle_suspects()
    if progress is not None:
        progress(1.0)
    runs = [(codes, base if tape is None else tape) for codes, tape, _ in
            by_tapes([(c, t, t) for c, t in surface])]
    return Subdivision(
        codes=np.concatenate([c for c, _ in runs]) if runs else np.zeros(0, dtype=np.uint64),
        interior={lvl: unpack(np.sort(np.concatenate(parts)))   # Morton order: any schedule
                  for lvl, parts in sorted(interior_parts.items())},
        evaluated=evaluated, tapes=[(len(c), t) for c, t in runs],
        tapes_built=pruner.built if pruner is not None else 0,
        pending=np.sort(np.concatenate(held_back)) if held_back else
        np.zeros(0, dtype=np.uint64))
