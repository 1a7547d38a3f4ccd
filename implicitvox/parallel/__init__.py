"""Pieces of one run farmed out to worker processes or a Dask cluster (Stolte §5.2).

A parallel run is a :class:`Job` (what every piece shares: the shape, its
tape, the grid, the options), sent **once per worker** and prepared there
once, and a list of pieces (independent subtrees of the octree), handed out
one at a time as workers free up (a queue, as in Stolte's Fig. 10, so uneven
subtrees balance). :func:`farm` yields each piece's result as it completes;
the caller merges them into one octree in an order-independent way, so the
result is bit-identical to the serial run for any number of workers and any
schedule.

The same code path serves one machine and a cluster: ``workers=n`` starts a
pool of ``n`` processes of this machine (forked, or from a ``forkserver``: see
:func:`~implicitvox.parallel.farm.pool_context`); ``executor=`` takes
any ``concurrent.futures.Executor`` or a ``dask.distributed.Client`` (Dask is
the distributed engine; nothing here schedules or talks over a network).
This layer knows nothing of octrees: each algorithm defines its job next to
itself (:mod:`implicitvox.octree.subtrees`, :mod:`implicitvox.triangles.pairs`,
...).
"""
from .farm import SCATTER_BYTES, WorkerError, farm
from .jobs import Job, run_piece
from .plan import (DASK_WORK_PER_PIECE, MIN_PARALLEL_WORK, PIECES_PER_WORKER, WORK_PER_PIECE,
                   WORKERS_VARIABLE, available_cores, executor_workers, is_dask_client,
                   pieces_for, plan_workers, split_evenly)

__all__ = ["farm", "WorkerError", "Job", "run_piece", "available_cores", "executor_workers",
           "plan_workers", "pieces_for", "split_evenly", "MIN_PARALLEL_WORK", "PIECES_PER_WORKER",
           "WORK_PER_PIECE", "WORKERS_VARIABLE", "SCATTER_BYTES", "DASK_WORK_PER_PIECE",
           "is_dask_client"]
