"""The compiled step of the subdivision: a chunk of octants, each with its own tape.

Stolte §2's step (classify the children of every pending octant; reject the
EMPTY ones, keep the FULL ones as interior, subdivide the AMBIGUOUS ones) in
Numba, for octants that each carry a tape of a :class:`~implicitvox.eval.tape_pool.TapePool`:

* the octants of a chunk are taken in runs that share a tape, in blocks of up to
  :data:`BLOCK_PARENTS`; the 8 children of a block's octants are evaluated
  together, one instruction at a time over the block (the rules of
  :mod:`implicitvox.interval.rules`, compiled once);
* an instruction is computed only on the children its value can differ on: a
  value of ``x`` alone takes 2 of the 8 child boxes of an octant, one of ``x``
  and ``y`` 4 (its axis mask; the array evaluator gets the same saving from
  broadcasting), ``min``, ``max``, ``abs`` and the domain operations too,
  whose choices and domain flags are read, per child, at the slot of its mask;
* every AMBIGUOUS child gets the tape pruned by the choices settled over it
  (:func:`implicitvox.eval.tape_pool.prune_tape`: at every level, per box, as
  libfive and Fidget do), its subtree's tape; ``prune=False`` keeps the
  parent's. The result is the same either way, bit for bit (the pruned tape
  computes what the whole tape computes over every sub-box).

The parents are taken sorted by tape (the returned ``order``), and the children
come out parent by parent in that order: child ``s`` (slot ``x + 2y + 4z``) of
the ``k``-th parent taken is ``8 k + s`` (sequential writes, whatever the tapes).

Examples
--------
>>> import numpy as np
>>> from implicitvox import x, y, z, sqrt
>>> from implicitvox.eval.tape import build_tape
>>> from implicitvox.eval.tape_pool import TapePool
>>> from implicitvox.octree.grid import Grid
>>> grid = Grid.from_bounds(((-1.0,) * 3, (1.0,) * 3), 8)
>>> descent = Descent(TapePool(build_tape(sqrt(x**2 + y**2 + z**2) - 0.5)), grid)
>>> order, state, flo, fhi, tapes, suspects, classified = descent.children(
...     0, np.zeros(1, np.uint64), np.zeros(1, np.int32))
>>> state.tolist()                 # every child of the root meets the sphere
[2, 2, 2, 2, 2, 2, 2, 2]
"""
from __future__ import annotations

import functools
from typing import Optional

import numpy as np
from numba import njit

from ..eval.compiled import ABS, MAX, MIN, is_domain, run_row
from ..eval.tape_pool import (ARG_A, ARG_B, ARG_C, MASK, MASK_A, MASK_B, MASK_C, OP, OUT,
                              OUTPUT, REGISTERS, ROOT, ROWS, START, VALUE, TapePool, prune_tape)
from ..eval.function import Function
from ..expr.shape import AMBIGUOUS, EMPTY, FULL, Octants
from ..interval.rules import COMPILE
from .grid import Grid
from .morton_kernels import compact
from .guard import MemoryGuard
from .octants import (MAX_SIDE, RECHECK, ROOT_CODE, Progress, PrunedTapes, Subdivision,
                      TapeRuns, classify_root, pack, tighten, unpack)
from .. import batches

__all__ = ["descend", "warm_up", "Descent", "Entries", "EntryFrontier", "BLOCK_PARENTS",
           "DERIVE_COST", "CHUNK"]

#: octants classified per step of the driver
CHUNK = batches.FRONTIER
_SLOTS = np.arange(8, dtype=np.uint64)


class Entries:
    """Octants with their tapes: Morton ``codes`` (uint64), pool ``tapes`` (int32)
    and ``leaves``, the tapes of their ancestors at the leaf level (-1: not
    reached yet)."""

    __slots__ = ("codes", "tapes", "leaves")

    def __init__(self, codes: np.ndarray, tapes, leaves):
        n = len(codes)
        self.codes = np.asarray(codes, dtype=np.uint64)
        self.tapes = _column(tapes, n)
        self.leaves = _column(leaves, n)

    def __len__(self) -> int:
        return len(self.codes)

    def take(self, which) -> "Entries":
        return Entries(self.codes[which], self.tapes[which], self.leaves[which])

    @staticmethod
    def join(parts: list) -> "Entries":
        if len(parts) == 1:
            return parts[0]
        return Entries(*(np.concatenate([getattr(p, k) for p in parts])
                         for k in ("codes", "tapes", "leaves")))


def _column(values, n: int) -> np.ndarray:
    """``values`` (or one value) as a writable int32 array of ``n``."""
    values = np.asarray(values, dtype=np.int32)
    return np.full(n, values, dtype=np.int32) if values.ndim == 0 else values


class EntryFrontier:
    """Pending octants (:class:`Entries`) by level, taken deepest first (the last
    pushed first), as the array subdivision's frontier
    (:mod:`implicitvox.octree.frontier`) holds them."""

    def __init__(self) -> None:
        self._levels: dict[int, list[Entries]] = {}
        self._count = 0

    def __len__(self) -> int:
        return self._count

    def __bool__(self) -> bool:
        return self._count > 0

    def push(self, level: int, entries: Entries) -> None:
        if len(entries):
            self._levels.setdefault(level, []).append(entries)
            self._count += len(entries)

    def pop(self, limit: int) -> tuple[int, Entries]:
        """Up to ``limit`` octants of the deepest level."""
        level = max(self._levels)
        parts = self._levels[level]
        taken, size = [], 0
        while parts and size < limit:
            part = parts.pop()
            if size + len(part) > limit:
                cut = limit - size
                parts.append(part.take(slice(cut, None)))
                part = part.take(slice(0, cut))
            taken.append(part)
            size += len(part)
        if not parts:
            del self._levels[level]
        self._count -= size
        return level, Entries.join(taken)

    def sizes(self):
        """``(level, octants)`` of every part pending (for :class:`Progress`)."""
        for level, parts in self._levels.items():
            for part in parts:
                yield level, len(part)

#: octants whose children are evaluated together (8 children each)
BLOCK_PARENTS = 64
#: what deriving a child's tape costs per row of its parent's, in row evaluations of
#: one box: a child gets its own tape when the rows its settled choices drop (at
#: least one each), times the boxes its subtree evaluates, exceed that cost (0:
#: wherever a choice is settled; read at every call). 1 was the fastest of 0, 1, 2,
#: 3, 10, 30 and 100 on the level-3 sponge, the unions of 100 and 1000 spheres, the
#: drilled plate and the gear (the count of rows dropped undercounts: a settled
#: choice drops its whole losing branch)
DERIVE_COST = 1
#: new tapes and rows the pool makes room for before a call (beyond them, a child
#: keeps its parent's tape: the pool grows before the next call)
TAPES_PER_CALL = 1 << 14
ROWS_PER_CALL = 1 << 17
#: until a call runs out of room, a call reserves at most this many times what the
#: last one added (children multiply by 8 at most, and share most of their tapes),
#: and at least room for :data:`RESERVE_TAPES` tapes
RESERVE_GROWTH = 16
RESERVE_TAPES = 64


def warm_up() -> None:
    """Compile the subdivision's functions (and the pool's gradients), or load them
    from Numba's on-disk cache: one small run through every compiled path (about 25 s the first time on a 2-core
    machine, a second once cached). The test suite calls it once before its
    workers start, so they load what it wrote instead of each compiling."""
    from ..expr import functions as fn
    from ..expr.nodes import x, y, z
    from ..eval.pool_gradients import pool_gradients
    parts = fn.min(fn.sqrt(x * x + y * y + z * z) - 0.5, fn.abs(x) - 0.3)
    found = descend(Function(fn.max(parts, -parts - 0.1)),
                    Grid.from_bounds(((-1.0,) * 3, (1.0,) * 3), 8), interior=True)
    runs = found.tapes
    pool_gradients(runs.pool, runs.ids[:1], np.ones(1, dtype=np.int64), *np.zeros((3, 1)))


def descend(func: Function, grid: Grid, *, start: Optional[tuple[int, np.ndarray]] = None,
            interior: bool = False, exact=None, progress=None, chunk: int = CHUNK,
            mean_value: bool = False, exact_voxels=None, recheck: float = RECHECK,
            guard: Optional[MemoryGuard] = None, prune: bool = True,
            leaf_level: Optional[int] = None, until_level: Optional[int] = None,
            start_tapes: Optional[PrunedTapes] = None) -> Subdivision:
    """:func:`implicitvox.octree.subdivide.subdivide` on the compiled kernel: the same
    options and result, every octant with its own tape (see the module).

    ``start_tapes``: the pool tapes of the ``start`` octants (a head run's
    :attr:`~implicitvox.octree.octants.Subdivision.pending_tapes`), which are
    then continued on their pruned tapes, in a copy of that pool; with
    ``until_level``, the result's ``pending_tapes`` are those of its pending
    octants (in its pool).

    The driver is the array subdivision's (Stolte §2 on a frontier of chunks,
    deepest level first, so memory stays bounded by ``8 * chunk * depth``
    octants); a chunk's children are classified by :class:`Descent`, and the
    AMBIGUOUS ones go to the exact test and the mean value form in Python, in
    batches, as before. Enclosures are float64 throughout.
    """
    depth = grid.depth
    leaf_level = depth if leaf_level is None else leaf_level
    per_step = max(1, chunk // 8)
    if exact_voxels is None:
        exact_voxels = exact
    if start_tapes is not None:
        if start is None or len(start_tapes) != len(start[1]):
            raise ValueError("start_tapes must give one tape per start octant")
        pool = start_tapes.pool.copy()
    else:
        pool = TapePool(func.tape)
    descent = Descent(pool, grid)
    fine = Descent(pool, grid.finer(1)) if recheck > 0.0 and exact_voxels is None else None
    run: dict = {}          # the exact test's scratch space for this subdivision
    surface: list[Entries] = []
    interior_parts: dict[int, list[np.ndarray]] = {}
    frontier = EntryFrontier()
    evaluated = 0
    if start is None:
        evaluated = 1
        if classify_root(func, grid, exact, exact_voxels, mean_value, interior, interior_parts,
                         run):
            entry = Entries(ROOT_CODE.copy(), 0, 0 if leaf_level == 0 else -1)
            if depth == 0:
                surface.append(entry)
            else:
                frontier.push(0, entry)
    else:
        level0, coords0 = start
        tapes0 = 0 if start_tapes is None else start_tapes.tapes
        frontier.push(level0, Entries(pack(coords0), tapes0,
                                      tapes0 if level0 >= leaf_level else -1))
    meter = Progress(progress, depth)
    suspects: list[Entries] = []
    held_back: list[Entries] = []        # octants reaching until_level
    pending = 0
    kept = sum(len(e) for e in surface)
    held = len(frontier)

    def settle_suspects() -> int:
        nonlocal kept
        entries = Entries.join(suspects)
        suspects.clear()
        order, state, _, _, _, _, classified = fine.children(depth, entries.codes, entries.tapes,
                                                             prune=False)
        state = state.reshape(-1, 8)
        entries = entries.take(order)
        met = entries.take((state == AMBIGUOUS).any(axis=1))
        surface.append(met)
        kept += len(met)
        if interior:
            full = entries.codes[(state == FULL).all(axis=1)]
            if len(full):
                interior_parts.setdefault(depth, []).append(full)
        return classified

    while frontier:
        level, parents = frontier.pop(per_step)
        held -= len(parents)
        child = level + 1
        test = exact_voxels if child == depth else exact
        rechecked = fine is not None and child == depth
        order, state, flo, fhi, child_tapes, near_end, classified = descent.children(
            level, parents.codes, parents.tapes, prune, recheck if rechecked else 0.0)
        parents = parents.take(order)
        kids = ((parents.codes << np.uint64(3))[:, None] | _SLOTS[None, :]).reshape(-1)
        if mean_value or test is not None:
            amb = np.flatnonzero(state == AMBIGUOUS)
            if amb.size:
                box_lo, box_hi = grid.octant_boxes(child, unpack(kids[amb]))
                octants = Octants(child, kids[amb], run)
                state[amb] = tighten(func.tape, box_lo, box_hi, flo[amb], fhi[amb], state[amb],
                                     test, mean_value, octants)
        if interior:
            full = kids[state == FULL]
            if len(full):
                interior_parts.setdefault(child, []).append(full)
                held += len(full)
        ambiguous = state == AMBIGUOUS
        if child == leaf_level:
            leaves = child_tapes
        elif child > leaf_level:
            leaves = np.repeat(parents.leaves, 8)
        else:
            leaves = np.full(len(kids), -1, dtype=np.int32)
        if rechecked:
            near_end &= ambiguous
            picked = np.flatnonzero(near_end)
            if len(picked):
                suspects.append(Entries(kids[picked], child_tapes[picked], leaves[picked]))
                pending += len(picked)
            ambiguous &= ~near_end
        if suspects and (pending >= per_step or not frontier):
            classified += settle_suspects()
            pending = 0
        evaluated += classified
        meter.done += classified
        picked = np.flatnonzero(ambiguous)
        entries = Entries(kids[picked], child_tapes[picked], leaves[picked])
        if child == depth:
            surface.append(entries)
            kept += len(entries)
        elif child == until_level:
            held_back.append(entries)
        else:
            frontier.push(child, entries)
            held += len(entries)
        if guard is not None:
            # (an entry is twice a key: its tapes ride along)
            guard.check(kept + pending, 2 * held, extra=pool.nbytes)
        meter.report(frontier)
    if suspects:
        evaluated += settle_suspects()
    if progress is not None:
        progress(1.0)
    found = Entries.join(surface) if surface else Entries(np.zeros(0, np.uint64), 0, 0)
    # runs of one leaf tape, in the order found (the children of a chunk come out by tape)
    leaf = found.leaves
    starts = np.flatnonzero(np.concatenate([[True], leaf[1:] != leaf[:-1]])) if len(leaf) \
        else np.zeros(0, dtype=np.int64)
    ids = leaf[starts]
    counts = np.diff(np.append(starts, len(leaf)))
    held = Entries.join(held_back) if held_back else None
    order = np.argsort(held.codes) if held is not None else None
    return Subdivision(
        codes=found.codes,
        interior={lvl: unpack(np.sort(np.concatenate(parts)))   # Morton order: any schedule
                  for lvl, parts in sorted(interior_parts.items())},
        evaluated=evaluated,
        tapes=TapeRuns(counts, lambda i: pool.tape(int(ids[i])), pool, ids),
        tapes_built=len(pool) - 1,
        pending=held.codes[order] if held is not None else np.zeros(0, dtype=np.uint64),
        pending_tapes=PrunedTapes(pool, held.tapes[order]) if held is not None else None)


class Descent:
    """Classifies the children of octants of ``grid`` carrying tapes of ``pool``."""

    def __init__(self, pool: TapePool, grid: Grid):
        if max(grid.shape) >= 2 * MAX_SIDE:   # (the recheck's grid is one level finer)
            raise ValueError(f"grids of at most {2 * MAX_SIDE - 1} voxels a side, "
                             f"not {grid.shape}")
        self.pool, self.grid = pool, grid
        #: rows and tapes the last call added to the pool, and whether a call has run
        #: out of room (:meth:`children` reserves by them)
        self.added = (0, 0)
        self.filled = False

    def _reserve(self, m: int, mean_rows: int) -> tuple[int, int]:
        """The tapes and rows to make room for before a call on ``m`` parents whose
        tapes have ``mean_rows`` rows: at most one new tape per child
        (:data:`TAPES_PER_CALL`, :data:`ROWS_PER_CALL` at most), but, until a call
        has run out of room, no more than :data:`RESERVE_GROWTH` times what the last
        call added: children share tapes, and a pool reserved for the worst case
        costs its pages (a 13 MiB copy per descent, a quarter of a small model's
        time). A call that runs out keeps the parents' tapes for the rest (the
        same voxels), and the next reserves for the worst case."""
        tapes = min(8 * m, TAPES_PER_CALL)
        rows = min(8 * m * mean_rows, ROWS_PER_CALL)
        if not self.filled:
            tapes = min(tapes, max(RESERVE_GROWTH * self.added[1], RESERVE_TAPES))
            rows = min(rows, max(RESERVE_GROWTH * self.added[0], RESERVE_TAPES * mean_rows))
        return tapes, rows

    @functools.lru_cache(maxsize=64)
    def _edges(self, level: int) -> tuple:
        """The lower and upper edges (2, 2**level) of the two halves of every octant at
        ``level`` along each axis, clamped to the grid, and the octants per axis at
        ``level + 1``."""
        grid = self.grid
        scale = 1 << (grid.depth - level - 1)
        octants = np.arange(1 << level, dtype=np.int64)
        tables = []
        for axis in range(3):
            first = (octants[None, :] * 2 + np.array([[0], [1]])) * scale
            low = np.minimum(first, grid.shape[axis])
            high = np.minimum(first + scale, grid.shape[axis])
            tables += [np.ascontiguousarray(grid.edge(axis, low)),
                       np.ascontiguousarray(grid.edge(axis, high))]
        limits = np.array([-(-n // scale) for n in grid.shape], dtype=np.int64)
        return tuple(tables) + (limits,)

    def children(self, level: int, parents: np.ndarray, tapes: np.ndarray, prune: bool = True,
                 recheck: float = 0.0) -> tuple:
        """The children of the octants ``parents`` (Morton codes at ``level``) with tapes
        ``tapes``: the parents are taken in ``order`` (by tape), and child ``s`` of
        the ``k``-th of them is at ``8 k + s``.

        Returns ``(order, state, flo, fhi, child_tapes, suspects, classified)``:
        states (int8; children past the grid are EMPTY), enclosures, tapes (int32),
        the recheck's suspects (with ``recheck > 0``: the children
        :func:`implicitvox.octree.octants.suspect_voxels` picks; all False
        otherwise) and the number of children inside the grid.
        """
        pool = self.pool
        m = len(parents)
        state = np.empty(8 * m, dtype=np.int8)
        flo, fhi = np.empty(8 * m), np.empty(8 * m)
        child_tapes = np.empty(8 * m, dtype=np.int32)
        suspects = np.zeros(8 * m, dtype=np.bool_)
        order = np.arange(m)
        if pool.undefined:
            state[:], flo[:], fhi[:] = EMPTY, np.inf, -np.inf
            child_tapes[:] = np.repeat(tapes, 8)
            return order, state, flo, fhi, child_tapes, suspects, 8 * m
        mean_rows = int(pool.lengths(tapes[:64]).mean()) if m else 0
        derives = prune and pool.branches > 0
        if derives:
            pool.grow(*self._reserve(m, mean_rows))
        before = (pool.rows_used, len(pool))
        used = len(pool)
        registers = int(pool.tapes[:used, REGISTERS].max())
        rows = int(pool.tapes[:used, ROWS].max())
        # (writable contiguous arrays, as Numba compiled _classify for)
        tapes = np.require(tapes, np.int32, ("C", "W"))
        parents = np.require(parents, np.uint64, ("C", "W"))
        order = np.argsort(tapes, kind="stable")
        lanes = 8 * BLOCK_PARENTS
        width = max(rows, 1)
        buffers = (np.zeros((registers, lanes)), np.zeros((registers, lanes)),
                   np.zeros(lanes, dtype=np.bool_), np.zeros(lanes, dtype=np.bool_),
                   np.zeros((width, lanes), dtype=np.int8), np.zeros(width, dtype=np.int32),
                   np.zeros(width, dtype=np.int64), np.zeros(width, dtype=np.int64),
                   np.zeros((3, BLOCK_PARENTS), dtype=np.int64))
        classified = _classify(*self._edges(level), parents, tapes, bool(prune),
                               _subtree_boxes(self.grid.depth - level - 2), DERIVE_COST,
                               float(recheck),
                               pool.params, pool.constant_lo, pool.constant_hi,
                               pool.is_constant, pool.inputs, *pool.arrays(),
                               order, state, flo, fhi, child_tapes, suspects, *buffers)
        self.added = (pool.rows_used - before[0], len(pool) - before[1])
        self.filled |= pool.ran_out
        return order, state, flo, fhi, child_tapes, suspects, int(classified)


def _subtree_boxes(levels: int) -> int:
    """Boxes an octant's subtree evaluates over ``levels`` levels below it: 8 children
    each of the about 4 octants per level a surface crosses (Stolte §4.1.3)."""
    return 0 if levels <= 0 else 8 * (4 ** levels - 1) // 3


@njit(**COMPILE)
def _classify(xlo, xhi, ylo, yhi, zlo, zhi, limits, parents, tapes, prune,
              subtree, derive_cost, recheck, params, constant_lo, constant_hi, is_constant, inputs,
              rows, tapes_, derivations, contents, keys, used, masks, domain, fixed, scratch, kept,
              order, state, flo, fhi, child_tapes, suspects, rlo, rhi, empty, outside, choices,
              key, branch_rows, branch_masks, coords):
    """:meth:`Descent.children` (``order``: the parents by tape, given; the buffers
    from the caller: allocations and slice assignments are slow to compile)."""
    m = parents.size
    ci, cj, ck = coords[0], coords[1], coords[2]
    classified = 0
    k = 0
    while k < m:
        t = np.int64(tapes[order[k]])
        e = k + 1
        while e < m and e - k < BLOCK_PARENTS and tapes[order[e]] == t:
            e += 1
        n = e - k
        for q in range(n):
            code = parents[order[k + q]]
            ci[q] = compact(code)
            cj[q] = compact(code >> np.uint64(1))
            ck[q] = compact(code >> np.uint64(2))
        # the fixed registers: constants, then the children's boxes
        for f in range(fixed):
            if is_constant[f]:
                for j in range(8 * n):
                    rlo[f, j] = constant_lo[f]
                    rhi[f, j] = constant_hi[f]
        for s in range(8):
            for q in range(n):
                lane = s * n + q
                if inputs[0] >= 0:
                    rlo[inputs[0], lane] = xlo[s & 1, ci[q]]
                    rhi[inputs[0], lane] = xhi[s & 1, ci[q]]
                if inputs[1] >= 0:
                    rlo[inputs[1], lane] = ylo[(s >> 1) & 1, cj[q]]
                    rhi[inputs[1], lane] = yhi[(s >> 1) & 1, cj[q]]
                if inputs[2] >= 0:
                    rlo[inputs[2], lane] = zlo[(s >> 2) & 1, ck[q]]
                    rhi[inputs[2], lane] = zhi[(s >> 2) & 1, ck[q]]
        for j in range(8 * n):
            empty[j] = False
        start = tapes_[t, START]
        count = tapes_[t, ROWS]
        n_branches = 0
        for r in range(count):
            row = rows[start + r]
            op = row[OP]
            if op == MIN or op == MAX or op == ABS:
                branch_rows[n_branches] = r
                branch_masks[n_branches] = row[MASK]
                n_branches += 1
            v = row[VALUE]
            # (int64 arguments, as evaluate_boxes passes them: one compiled run_row)
            run_row(np.int64(op), np.int64(row[OUT]), np.int64(row[ARG_A]),
                    np.int64(row[ARG_B]), np.int64(row[ARG_C]), np.int64(row[MASK]),
                    np.int64(row[MASK_A]), np.int64(row[MASK_B]), np.int64(row[MASK_C]),
                    np.int64(r), params[v, 0], params[v, 1], params[v, 2], np.int64(n),
                    rlo, rhi, outside, choices)
            if is_domain(op):      # the flags of the slots it computed, to every child
                mo = row[MASK]
                for s in range(8):
                    for q in range(n):
                        empty[s * n + q] |= outside[(s & mo) * n + q]
        # the children's states and tapes
        root = tapes_[t, ROOT]
        out = tapes_[t, OUTPUT]
        out_mask = masks[root]
        for q in range(n):
            for s in range(8):
                lane = s * n + q
                index = 8 * (k + q) + s
                inside = 2 * ci[q] + (s & 1) < limits[0] and \
                    2 * cj[q] + ((s >> 1) & 1) < limits[1] and \
                    2 * ck[q] + ((s >> 2) & 1) < limits[2]
                child_tapes[index] = t
                if empty[lane]:
                    flo[index], fhi[index] = np.inf, -np.inf
                    state[index] = EMPTY
                    continue
                a = (s & out_mask) * n + q
                lo, hi = rlo[out, a], rhi[out, a]
                flo[index], fhi[index] = lo, hi
                if not inside or lo > 0.0:
                    state[index] = EMPTY
                elif hi < 0.0:
                    state[index] = AMBIGUOUS - 1            # FULL
                else:
                    state[index] = AMBIGUOUS
                    if prune and n_branches * subtree >= derive_cost * count:
                        n_key = 0
                        for b in range(n_branches):     # (computed at the slot of its mask)
                            c = choices[branch_rows[b], (s & branch_masks[b]) * n + q]
                            if c != 0:
                                key[n_key] = branch_rows[b] * 4 + c
                                n_key += 1
                        if n_key * subtree >= derive_cost * count:
                            child_tapes[index] = prune_tape(
                                t, key, np.int64(n_key), rows, tapes_, derivations, contents,
                                keys, used,
                                masks, domain, fixed, scratch, kept)
                if inside:
                    classified += 1
            if recheck > 0.0:
                _pick_suspects(flo, fhi, 8 * (k + q), ci[q], cj[q], ck[q], limits, recheck,
                               suspects)
        k = e
    return classified


@njit(**COMPILE)
def _pick_suspects(flo, fhi, first, i, j, k, limits, recheck, suspects):
    """:func:`implicitvox.octree.octants.suspect_voxels` on the 8 children of one
    octant (at ``first`` .. ``first + 7``; coordinates ``i, j, k``): the spread of
    their midpoints over the children inside the grid estimates the range of
    ``f`` over one, and a child whose enclosure reaches 0 by less than
    ``recheck`` times its width less that spread is a suspect."""
    top, bottom = -np.inf, np.inf
    for s in range(8):
        inside = 2 * i + (s & 1) < limits[0] and 2 * j + ((s >> 1) & 1) < limits[1] and \
            2 * k + ((s >> 2) & 1) < limits[2]
        twice_mid = flo[first + s] + fhi[first + s]
        if inside and twice_mid == twice_mid:     # (NaN: an empty child, ignored)
            top = max(top, twice_mid)
            bottom = min(bottom, twice_mid)
    if top < bottom:
        return                          # no child to measure (NaN spread: no suspect)
    spread = (top - bottom) * 0.5
    for s in range(8):
        lo, hi = flo[first + s], fhi[first + s]
        margin = ((hi - lo) - spread) * recheck
        suspects[first + s] = min(-lo, hi) <= margin
