"""``voxelize`` on several processes or a Dask cluster (Stolte §5.2, Fig. 10).

Stolte's master subdivides the top of the octree and hands the ambiguous
subtrees to workers, which subdivide them to the voxels; the master merges
what they found. Here:

1. The master runs the subdivision down to a split level where the
   AMBIGUOUS octants number at least :data:`OCTANTS_PER_PIECE` per piece (or
   :data:`MIN_LEVELS_BELOW` levels above the voxels)
   (``until_level``, :class:`~implicitvox.octree.subdivide.Subdivision`
   ``.pending``), keeping the FULL octants it met on the way.
2. Those octants, in Morton order, are cut into contiguous runs
   (``PIECES_PER_WORKER`` per worker: neighbouring subtrees share pruned
   tapes, and the queue balances uneven runs) and farmed out
   (:func:`implicitvox.parallel.farm`). The shape, its compiled tape, the grid
   and the options travel once per worker (a :class:`SubtreeJob`).
3. Each worker continues the subdivision from its octants
   (:func:`~implicitvox.octree.surface.subdivide_voxels` with ``start``),
   maps sub-voxels back, computes the normals of its voxels, and returns its
   surface voxels (Morton codes), their normals and its FULL octants.
4. The master merges each result as it arrives (the workers' working arrays
   never reach it) and sorts: the octree, the interior octants (Morton order
   per level) and the normals are **bit-identical** to the serial run's
   whatever the number of workers and the order pieces finish in, since a
   box's state depends on the box alone, a pruned tape's enclosures and
   gradients equal the full tape's bit for bit, and a voxel lies in exactly
   one subtree.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from ..eval.function import Function
from ..expr.shape import exact_classifier, voxel_classifier
from . import morton
from .grid import Grid
from .guard import MemoryGuard
from .subdivide import Subdivision
from ..parallel import PIECES_PER_WORKER, Job, farm, split_evenly
from .surface import subdivide_voxels, surface_payload

__all__ = ["SubtreeJob", "SubtreeResult", "subdivide_in_parallel", "parallel_bytes",
           "OCTANTS_PER_PIECE", "MIN_LEVELS_BELOW"]

#: the split level is the first with at least this many AMBIGUOUS octants per piece
OCTANTS_PER_PIECE = 4
#: ...and leaves at least this many levels to the workers (else the run is serial)
MIN_LEVELS_BELOW = 3


@dataclass
class SubtreeResult:
    """What a worker found in its subtrees."""

    #: Morton codes of the surface voxels (uint64, unsorted)
    codes: np.ndarray
    #: per-voxel arrays in the order of ``codes`` (the normals)
    payload: dict = field(default_factory=dict)
    #: FULL octants per level, as Morton codes
    interior: dict = field(default_factory=dict)
    evaluated: int = 0
    tapes_built: int = 0
    #: runs ``(count, tape)`` of the pruned tapes over ``codes`` (when asked for)
    tapes: list = field(default_factory=list)


class SubtreeJob(Job):
    """The subdivision of subtrees at ``level``, shared by every piece of one run."""

    def __init__(self, shape: Any, func: Function, grid: Grid, options: dict, level: int,
                 budget: int, per_voxel: int, what: str, tapes: bool = False):
        super().__init__()
        self.tapes = tapes
        self.shape, self.func, self.grid, self.options = shape, func, grid, dict(options)
        self.level, self.budget, self.per_voxel, self.what = level, int(budget), per_voxel, what

    @functools.cached_property
    def prepared_exact(self) -> tuple:
        """The shape's exact box and voxel tests (closures: built in the worker)."""
        return exact_classifier(self.shape), voxel_classifier(self.shape)

    def run(self, piece: np.ndarray) -> SubtreeResult:
        """Subdivide the subtrees rooted at octants ``piece`` (Morton codes at
        :attr:`level`) to the voxels."""
        coords = morton.decode(piece).astype(np.int32)
        guard = MemoryGuard(self.budget, f"{self.what} (a worker)", self.per_voxel)
        result = subdivide_voxels(self.func, self.grid, self.options, self.prepared_exact,
                                  start=(self.level, coords), guard=guard)
        payload = surface_payload(self.func, self.grid, result, self.options["normals"])
        return SubtreeResult(result.codes, payload,
                             {lvl: morton.encode(c) for lvl, c in result.interior.items()},
                             result.evaluated, result.tapes_built,
                             result.tapes if self.tapes else [])


def parallel_bytes(voxels: int, per_voxel: int, working: int, workers: int) -> int:
    """Peak bytes of a parallel run on one machine: the master holds every voxel
    (collecting, sorting, building the octree), each worker one chunk of boxes in
    flight and the voxels of its pieces (about ``1 / PIECES_PER_WORKER`` of its
    share at once, counted twice: its arrays and the result sent)."""
    share = 2 * voxels * per_voxel / (PIECES_PER_WORKER * workers)
    return int(voxels * per_voxel + workers * (working + share))


def subdivide_in_parallel(shape: Any, func: Function, grid: Grid, options: dict, *,
                          workers: int, executor: Any = None,
                          progress: Optional[Callable[[float], Any]] = None,
                          start: Optional[tuple[int, np.ndarray]] = None,
                          budget: int, per_voxel: int, guard: Optional[MemoryGuard] = None,
                          what: str = "voxelizing", tapes: bool = False
                          ) -> Optional[tuple[Subdivision, dict]]:
    """The serial run's :class:`Subdivision` (codes, interior, boxes evaluated) and
    payload, computed by ``workers`` processes or ``executor``.

    Returns None when the octree is too shallow to split (fewer than
    :data:`MIN_LEVELS_BELOW` levels below level 1): the caller runs serially.
    ``start``: continue from these octants (``Voxels.refine``), which are then
    the pieces. ``guard`` watches the master's holdings as the results arrive;
    each worker has its own, of ``budget / (workers + 1)`` at ``per_voxel``
    bytes per voxel kept. ``tapes``: return the workers' pruned tapes too
    (:attr:`Subdivision.tapes`, in the order of the codes as they arrived; the
    mesher evaluates with them).
    """
    s = options["subvoxel"]
    depth = grid.depth + s                     # levels of the grid subdivided
    exact = (exact_classifier(shape), voxel_classifier(shape))
    pieces_wanted = PIECES_PER_WORKER * workers
    heads: list[Subdivision] = []
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
                                    (level - 1, morton.decode(pending).astype(np.int32)))
            heads.append(head)
            pending = head.pending
            if len(pending) >= OCTANTS_PER_PIECE * pieces_wanted or not len(pending) \
                    or level == deepest:
                break
    ranges = split_evenly(len(pending), pieces_wanted)
    job = SubtreeJob(shape, func, grid, options, level, budget // (workers + 1), per_voxel, what,
                     tapes)
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
    for _, part in farm(job, [pending[a:b] for a, b in ranges], workers=workers,
                        executor=executor, weights=[b - a for a, b in ranges],
                        progress=progress, what=what):
        codes.append(part.codes)
        runs.extend(part.tapes)
        for key, values in part.payload.items():
            payload.setdefault(key, []).append(values)
        for lvl, c in part.interior.items():
            interior.setdefault(lvl, []).append(c)
        evaluated += part.evaluated
        built += part.tapes_built
        kept += len(part.codes)
        if guard is not None:
            guard.check(kept, sum(len(c) for parts in interior.values() for c in parts))
    result = Subdivision(
        codes=np.concatenate(codes) if codes else np.zeros(0, dtype=np.uint64),
        interior={lvl: morton.decode(np.sort(np.concatenate(parts))).astype(np.int32)
                  for lvl, parts in sorted(interior.items())},
        evaluated=evaluated, tapes_built=built, tapes=runs)
    return result, {key: np.concatenate(values) for key, values in payload.items()}
