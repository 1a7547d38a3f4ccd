"""``voxelize`` on several threads, processes or a Dask cluster (Stolte §5.2, Fig. 10).

Stolte's master subdivides the top of the octree and hands the ambiguous
subtrees to workers, which subdivide them to the voxels; the master merges
what they found. Here:

1. The master runs the subdivision down to a split level where the
   AMBIGUOUS octants number at least :data:`OCTANTS_PER_PIECE` per piece
   (:data:`OCTANTS_PER_THREAD_PIECE` on threads), or :data:`MIN_LEVELS_BELOW`
   levels above the voxels (``until_level``,
   :class:`~implicitvox.octree.subdivide.Subdivision` ``.pending``), keeping
   the FULL octants it met on the way. On the compiled kernel the pending
   octants keep their pruned tapes (``.pending_tapes``: a pool of tapes and
   each octant's), and the workers continue on them.
2. Those octants, in Morton order, are cut into contiguous runs
   (:func:`implicitvox.parallel.pieces_for`: from 2 to ``PIECES_PER_WORKER``
   per worker, by the estimated voxels; neighbouring subtrees share pruned
   tapes, and the queue balances uneven runs) and farmed out
   (:func:`implicitvox.parallel.farm`): to threads of this process for a
   model on the compiled kernel (whose subdivision releases the GIL), else
   to processes. The shape, its compiled tape, the grid, the options and the
   head's pool of tapes (without its spare room) travel once per worker (a
   :class:`SubtreeJob`); each piece continues in its own copy of the pool.
3. Each worker continues the subdivision from its octants
   (:func:`~implicitvox.octree.surface.subdivide_voxels` with ``start``),
   maps sub-voxels back, computes the normals of its voxels, sorts them, and
   returns its part of the octree (the child masks of its subtrees' levels,
   :func:`~implicitvox.octree.store.subtree_masks`: about 1.3 bytes per voxel,
   not an 8-byte code), their normals and its FULL octants.
4. The master keeps each result as it arrives (the workers' working arrays
   never reach it) and joins the parts in Morton order
   (:meth:`~implicitvox.octree.store.Octree.from_subtrees`: the levels above
   the split from the parts' roots, the levels below end to end; nothing is
   sorted again): the octree, the interior octants (Morton order per level)
   and the normals are **bit-identical** to the serial run's
   whatever the number of workers and the order pieces finish in, since a
   box's state depends on the box alone, a pruned tape's enclosures and
   gradients equal the full tape's bit for bit, and a voxel lies in exactly
   one subtree.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from ..eval.function import Function
from ..expr.shape import exact_classifier, voxel_classifier
from . import morton
from .grid import Grid
from .guard import MemoryGuard
from .octants import PrunedTapes, runs_compiled
from .store import Octree, subtree_masks
from .run import Run
from .subdivide import Subdivision
from ..parallel import PIECES_PER_WORKER, Job, farm, pieces_for, split_evenly
from .surface import SurfaceOptions, subdivide_voxels, surface_payload

__all__ = ["SubtreeJob", "SubtreeResult", "ParallelSubdivision", "subdivide_in_parallel",
           "parallel_bytes",
           "OCTANTS_PER_PIECE", "OCTANTS_PER_THREAD_PIECE", "MIN_LEVELS_BELOW"]

#: the split level is the first with at least this many AMBIGUOUS octants per piece:
#: a piece starts with full-sized batches (measured in bench_parallel.py: 4 octants
#: per piece made the workers' first levels a string of small numpy calls)
OCTANTS_PER_PIECE = 512
#: ...or this many on threads (compiled kernel): a piece is not pickled, and starts on
#: the head's pruned tapes (bench_parallel.py: 128 against 512 on three CSG models)
OCTANTS_PER_THREAD_PIECE = 128
#: ...and leaves at least this many levels to the workers (else the run is serial)
MIN_LEVELS_BELOW = 3


@dataclass
class SubtreeResult:
    """What a worker found in its subtrees."""

    #: Morton codes of the surface voxels (uint64; with ``tapes``, in the order of the
    #: tape runs; else sorted)
    codes: np.ndarray
    #: per-voxel arrays in the order of ``codes`` (the normals)
    payload: dict = field(default_factory=dict)
    #: FULL octants per level, as Morton codes
    interior: dict = field(default_factory=dict)
    evaluated: int = 0
    tapes_built: int = 0
    #: runs ``(count, tape)`` of the pruned tapes over ``codes`` (when asked for)
    tapes: list = field(default_factory=list)
    #: without ``tapes``: the subtrees' part of the octree
    #: (:func:`~implicitvox.octree.store.subtree_masks`
    #: of the sorted codes at the job's level); ``codes`` are then not sent back
    octree: Optional[tuple] = None
    #: surface voxels found
    count: int = 0


class SubtreeJob(Job):
    """The subdivision of subtrees at ``level``, shared by every piece of one run."""

    def __init__(self, shape: Any, func: Function, grid: Grid, options: SurfaceOptions,
                 level: int, budget: int, per_voxel: int, what: str, tapes: bool = False,
                 pool: Any = None):
        super().__init__()
        self.tapes = tapes
        #: the head's pool of pruned tapes (compiled kernel), which the pieces' tapes index
        self.pool = pool
        self.shape, self.func, self.grid, self.options = shape, func, grid, options
        self.level, self.budget, self.per_voxel, self.what = level, int(budget), per_voxel, what

    @functools.cached_property
    def prepared_exact(self) -> tuple:
        """The shape's exact box and voxel tests (closures: built in the worker)."""
        return exact_classifier(self.shape), voxel_classifier(self.shape)

    def run(self, piece: tuple) -> SubtreeResult:
        """Subdivide the subtrees rooted at octants ``piece = (codes, tapes)``
        (Morton codes at :attr:`level`; their pool tapes, or None) to the voxels."""
        codes, tapes = piece
        coords = morton.decode(codes).astype(np.int32)
        guard = MemoryGuard(self.budget, f"{self.what} (a worker)", self.per_voxel)
        result = subdivide_voxels(self.func, self.grid, self.options, self.prepared_exact,
                                  start=(self.level, coords), guard=guard,
                                  start_tapes=None if tapes is None else
                                  PrunedTapes(self.pool, tapes))
        payload = surface_payload(self.func, self.grid, result, self.options.normals)
        interior = {lvl: morton.encode(c) for lvl, c in result.interior.items()}
        count = len(result.codes)
        if self.tapes:
            return SubtreeResult(result.codes, payload, interior, result.evaluated,
                                 result.tapes_built, result.tapes, count=count)
        # sorted here, and sent as octree levels (about 1.3 bytes per voxel, not 8)
        codes = result.codes
        if payload:
            order = np.argsort(codes, kind="stable")
            codes = codes[order]
            payload = {key: values[order] for key, values in payload.items()}
        else:
            codes.sort()
        part = subtree_masks(codes, self.grid.depth, min(self.level, self.grid.depth))
        return SubtreeResult(np.zeros(0, dtype=np.uint64), payload, interior, result.evaluated,
                             result.tapes_built, octree=part, count=count)


@dataclass
class ParallelSubdivision:
    """What :func:`subdivide_in_parallel` found."""

    #: interior octants and boxes evaluated (with ``tapes``: also the codes and tapes)
    result: Subdivision
    #: per-voxel arrays, in Morton order (with ``tapes``: in the order of the codes)
    payload: dict
    #: the octree of the surface voxels (None with ``tapes``)
    tree: Optional[Octree]
    #: surface voxels
    count: int
    #: where the pieces ran: "threads", "processes" or "executor"
    on: str = "processes"


def parallel_bytes(voxels: int, per_voxel: int, working: int, workers: int) -> int:
    """Peak bytes of a parallel run on one machine: the master holds every voxel
    (collecting, sorting, building the octree), each worker one chunk of boxes in
    flight and the voxels of its pieces (about ``1 / PIECES_PER_WORKER`` of its
    share at once, counted twice: its arrays and the result sent)."""
    share = 2 * voxels * per_voxel / (PIECES_PER_WORKER * workers)
    return int(voxels * per_voxel + workers * (working + share))


def subdivide_in_parallel(shape: Any, func: Function, grid: Grid, options: SurfaceOptions,
                          run: Run, *, workers: int,
                          start: Optional[tuple[int, np.ndarray]] = None,
                          per_voxel: int, guard: Optional[MemoryGuard] = None,
                          what: str = "voxelizing", tapes: bool = False,
                          estimated: Optional[float] = None
                          ) -> Optional["ParallelSubdivision"]:
    """The serial run's octree, interior and boxes evaluated, computed by
    ``workers`` processes or the ``run``'s executor, under its budget and
    reporting to its progress hook.

    Returns None when the octree is too shallow to split (fewer than
    :data:`MIN_LEVELS_BELOW` levels below level 1): the caller runs serially.
    ``start``: continue from these octants (``Voxels.refine``), which are then
    the pieces. ``guard`` watches the master's holdings as the results arrive;
    each worker has its own, of ``budget / (workers + 1)`` at ``per_voxel``
    bytes per voxel kept. ``tapes``: return the voxels' codes and the workers'
    pruned tapes (:attr:`Subdivision.tapes`, in the order of the codes as they
    arrived; the mesher evaluates with them) instead of the octree.
    ``estimated``: the surface voxels expected, which set the number of pieces
    (:func:`implicitvox.parallel.pieces_for`; default the most).
    """
    executor, budget = run.executor, run.budget
    s = options.subvoxel
    depth = grid.depth + s                     # levels of the grid subdivided
    exact = (exact_classifier(shape), voxel_classifier(shape))
    pieces_wanted = PIECES_PER_WORKER * workers if estimated is None else \
        pieces_for(workers, estimated, executor)
    threads = executor is None and runs_compiled(func.tape, grid.finer(s) if s else grid)
    per_piece = OCTANTS_PER_THREAD_PIECE if threads else OCTANTS_PER_PIECE
    heads: list[Subdivision] = []
    seeds = None                    # the pruned tapes of the pending octants (compiled kernel)
    if start is not None:
        level, pending = start[0], morton.encode(start[1])
    else:
        level, pending = 0, None
        deepest = min(grid.depth, depth - MIN_LEVELS_BELOW)
        if deepest < 1:
            return None
        while True:
            level += 1
            head = subdivide_voxels(func, grid, options, exact, guard=guard, until_level=level,
                                    start=None if pending is None else
                                    (level - 1, morton.decode(pending).astype(np.int32)),
                                    start_tapes=seeds)
            heads.append(head)
            pending, seeds = head.pending, head.pending_tapes
            if len(pending) >= per_piece * pieces_wanted or not len(pending) \
                    or level == deepest:
                break
    ranges = split_evenly(len(pending), pieces_wanted)
    job = SubtreeJob(shape, func, grid, options, level, budget // (workers + 1), per_voxel, what,
                     tapes, pool=None if seeds is None else seeds.pool)
    pieces = [(pending[a:b], None if seeds is None else seeds.tapes[a:b]) for a, b in ranges]
    runs: list = []
    codes: list[np.ndarray] = []
    payload: dict[str, list] = {}
    interior: dict[int, list] = {}
    evaluated = sum(h.evaluated for h in heads)
    built = sum(h.tapes_built for h in heads)
    for head in heads:
        for lvl, c in head.interior.items():
            interior.setdefault(lvl, []).append(morton.encode(c))
    kept = 0
    parts: dict[int, SubtreeResult] = {}          # by piece: merged in Morton order
    for index, part in farm(job, pieces, workers=workers, executor=executor,
                            weights=[b - a for a, b in ranges], progress=run.progress,
                            what=what, threads=threads):
        parts[index] = part
        if tapes:                                  # else the codes stay in the workers
            codes.append(part.codes)
            runs.extend(part.tapes)
        for lvl, c in part.interior.items():
            interior.setdefault(lvl, []).append(c)
        evaluated += part.evaluated
        built += part.tapes_built
        kept += part.count
        if guard is not None:
            guard.check(kept, sum(len(c) for group in interior.values() for c in group))
    ordered = [parts[i] for i in sorted(parts)] if not tapes else list(parts.values())
    for part in ordered:
        for key, values in part.payload.items():
            payload.setdefault(key, []).append(values)
    result = Subdivision(
        codes=np.concatenate(codes) if codes else np.zeros(0, dtype=np.uint64),
        interior={lvl: morton.decode(np.sort(np.concatenate(group))).astype(np.int32)
                  for lvl, group in sorted(interior.items())},
        evaluated=evaluated, tapes_built=built, tapes=runs)
    merged = {key: np.concatenate(values) for key, values in payload.items()}
    tree = None
    if not tapes:
        tree = Octree.from_subtrees(grid.depth, min(level, grid.depth),
                                    [p.octree for p in ordered], merged)
    on = "executor" if executor is not None else "threads" if threads else "processes"
    return ParallelSubdivision(result, merged, tree, kept, on)
