"""One run of a producer: what every voxelizer, mesher and field takes besides its model.

A producer (``voxelize``, ``voxelize_mesh``, ``voxelize_bezier``, ``mesh``,
``distance_field``) is its algorithm plus one :class:`Run`: the memory budget
(checked against the estimate before anything big is allocated, and watched
during the run by a :class:`~implicitvox.octree.guard.MemoryGuard`), the
progress hook, and the workers or executor. The run's arguments are checked
here, once, under their public names (``max_memory``, ``progress``,
``workers``, ``executor``), and nothing downstream checks them again.

Examples
--------
>>> from implicitvox.octree.run import Run
>>> seen = []
>>> run = Run.of(max_memory=2**30, progress=seen.append, workers=1)
>>> run.budget, run.workers_for(10**9)
(1073741824, 1)
>>> run.refuse(2**31, "meshing at (8, 8, 8)")
Traceback (most recent call last):
...
MemoryError: meshing at (8, 8, 8) needs an estimated 2.00 GiB, over the budget of 1.00 GiB; lower the resolution or raise max_memory
>>> half = run.part(0.5, 1.0)           # the second half of the work
>>> half.report(0.5); seen
[0.75]
"""
from __future__ import annotations

import os
from dataclasses import dataclass, replace
from typing import Any, Callable, Optional

from .. import validate
from ..parallel import WORKERS_VARIABLE, plan_workers
from .budget import memory_budget, refuse_over_budget
from .guard import MemoryGuard

__all__ = ["Run"]


def _ignore(share: float) -> None:
    return None


@dataclass(frozen=True)
class Run:
    """The budget, progress hook and workers of one producer's run.

    Build it with :meth:`of` (which checks the public arguments); a producer
    hands it down whole, and its steps take their share of the progress with
    :meth:`part`.
    """

    #: bytes the run may use (``max_memory``, or half the available memory)
    budget: int
    #: called with the share of the run done, from 0 to 1 (a no-op when not asked for)
    progress: Callable[[float], Any] = _ignore
    #: processes asked for (None: every core, or one for a small run)
    workers: Optional[int] = None
    #: a ``concurrent.futures.Executor`` or ``dask.distributed.Client``, or None
    executor: Any = None

    @classmethod
    def of(cls, *, max_memory: Any = None, progress: Any = None, workers: Any = None,
           executor: Any = None) -> "Run":
        """The run of these public arguments, each checked (``ValueError`` or
        ``TypeError`` naming it)."""
        hook = validate.progress(progress)
        return cls(memory_budget(max_memory), _ignore if hook is None else hook,
                   validate.workers(workers), validate.executor(executor))

    def again(self, *, max_memory: Any = None, progress: Any = None) -> "Run":
        """The same workers and executor under a new budget and progress hook (a
        refinement of an earlier run)."""
        return Run.of(max_memory=max_memory, progress=progress, workers=self.workers,
                      executor=self.executor)

    def workers_for(self, work: float, default_serial: bool = False) -> int:
        """The workers for ``work`` units (estimated surface voxels or pairs):
        :func:`implicitvox.parallel.plan_workers`; 1 means serial, here.

        ``default_serial``: the caller's parallel path does not pay yet, so its
        default (no ``workers``, no executor, no ``$IMPLICITVOX_WORKERS``) is one
        worker (meshing a model on the compiled kernel: its subdivision is a
        small share of the run, and the pieces' pruned tapes are rebuilt in Python)."""
        if default_serial and self.workers is None and self.executor is None \
                and not os.environ.get(WORKERS_VARIABLE, "").strip():
            return 1
        return plan_workers(self.workers, self.executor, work)

    def refuse(self, need: float, what: str) -> None:
        """``MemoryError`` before starting when the estimated ``need`` bytes pass the budget."""
        refuse_over_budget(int(need), self.budget, what)

    def guard(self, what: str, bytes_per_voxel: int, *, estimated: Optional[int] = None,
              working: int = 0) -> MemoryGuard:
        """The guard that watches the run's holdings against its budget."""
        return MemoryGuard(self.budget, what, bytes_per_voxel, estimated_voxels=estimated,
                           working=working)

    def report(self, share: float) -> None:
        """Say that ``share`` of the run is done."""
        self.progress(share)

    def part(self, start: float, stop: float) -> "Run":
        """The run of one step that covers ``start`` to ``stop`` of the progress:
        its own shares 0 to 1 are reported as ``start`` to ``stop``."""
        outer, span = self.progress, stop - start
        if outer is _ignore:
            return self
        return replace(self, progress=lambda share: outer(start + span * share))
