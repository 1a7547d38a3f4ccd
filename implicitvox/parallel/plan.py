"""How many workers a run uses and how its work is cut into pieces.

Examples
--------
>>> split_evenly(10, 3)
[(0, 4), (4, 7), (7, 10)]
>>> plan_workers(None, None, work=10, cores=8)        # too small to pay: serial
1
>>> plan_workers(None, None, work=10**7, cores=8)
8
>>> plan_workers(3, None, work=10, cores=8)           # asked for: always
3
"""
from __future__ import annotations

import os
from typing import Any, Optional

__all__ = ["available_cores", "executor_workers", "plan_workers", "pieces_for", "split_evenly",
           "is_dask_client", "MIN_PARALLEL_WORK", "PIECES_PER_WORKER", "WORK_PER_PIECE",
           "DASK_WORK_PER_PIECE", "WORKERS_VARIABLE"]

#: below this much work (estimated surface voxels, or triangle pairs) a run with the
#: default ``workers=None`` stays serial: starting processes and shipping results
#: costs more than it saves (tests/benchmarks/bench_parallel.py measures it)
MIN_PARALLEL_WORK = 1 << 18
#: pieces per worker, at most: enough that uneven subtrees balance on the queue, few
#: enough that each piece keeps full-sized batches
PIECES_PER_WORKER = 8
#: estimated voxels per piece on a Dask cluster (:func:`pieces_for`): about 0.1 s of
#: work, against a round trip of about 15 ms per task (tests/benchmarks/bench_parallel.py)
DASK_WORK_PER_PIECE = 1 << 21
#: work per piece (surface voxels) below which a run is cut into fewer pieces, down to
#: two per worker (each piece costs a few milliseconds of setting up, sorting and
#: sending: measured in bench_parallel.py on the gear and the sponge)
WORK_PER_PIECE = 1 << 19


#: the environment variable that sets the default number of workers (as
#: ``OMP_NUM_THREADS`` does for OpenMP): ``1`` keeps every run serial, for
#: instance under pytest-xdist, which runs one test per core already
WORKERS_VARIABLE = "IMPLICITVOX_WORKERS"


def available_cores() -> int:
    """The workers a run may use by default: ``$IMPLICITVOX_WORKERS`` if set, else
    the cores this process may run on (its CPU affinity); 1 inside a daemonic
    process (a worker of someone's pool), which may not start processes."""
    import multiprocessing
    if multiprocessing.current_process().daemon:
        return 1
    setting = os.environ.get(WORKERS_VARIABLE, "").strip()
    if setting:
        if not setting.isdigit() or int(setting) < 1:
            raise ValueError(f"{WORKERS_VARIABLE} must be a positive int, got {setting!r}")
        return int(setting)
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def executor_workers(executor: Any) -> Optional[int]:
    """Workers behind a ``dask.distributed.Client`` (its threads in all), or None
    for an executor that does not say."""
    info = getattr(executor, "scheduler_info", None)
    if callable(info) and callable(getattr(executor, "scatter", None)):
        workers = info().get("workers", {})
        return max(1, sum(int(w.get("nthreads", 1)) for w in workers.values()))
    return None


def plan_workers(workers: Optional[int], executor: Any, work: float,
                 cores: Optional[int] = None) -> int:
    """Workers for a run of ``work`` units: ``workers`` if given; with an
    executor, its workers; else every core, or 1 when ``work`` is below
    :data:`MIN_PARALLEL_WORK` (:func:`available_cores`: ``$IMPLICITVOX_WORKERS``
    sets the default). 1 means serial, in this process."""
    if workers is not None:
        return workers
    if executor is not None:
        return executor_workers(executor) or available_cores()
    if work < MIN_PARALLEL_WORK:
        return 1
    return available_cores() if cores is None else cores


def is_dask_client(executor: Any) -> bool:
    """Whether ``executor`` is a ``dask.distributed.Client`` (without importing Dask)."""
    return type(executor).__module__.split(".")[0] == "distributed" and \
        callable(getattr(executor, "scatter", None))


def pieces_for(workers: int, work: float, executor: Any = None) -> int:
    """How many pieces a run of ``work`` units on ``workers`` is cut into: one per
    :data:`WORK_PER_PIECE`, from 2 to :data:`PIECES_PER_WORKER` per worker, rounded
    up to a multiple of ``workers`` (the last round then keeps every worker busy:
    7 pieces on 2 workers left one idle for a seventh of the run).

    On a Dask ``executor`` each task costs a round trip through the scheduler
    (measured: about 15 ms on this 2-core machine, where the scheduler's event
    loop competes with the workers), so pieces are larger
    (:data:`DASK_WORK_PER_PIECE`) and one per worker is allowed.

    >>> pieces_for(2, 2e6), pieces_for(2, 1e9), pieces_for(2, 10), pieces_for(2, 3.4e6)
    (4, 16, 4, 8)
    """
    per_piece, least = WORK_PER_PIECE, 2
    if executor is not None and is_dask_client(executor):
        per_piece, least = DASK_WORK_PER_PIECE, 1
    wanted = int(-(-work // per_piece))
    pieces = max(least * workers, min(PIECES_PER_WORKER * workers, wanted))
    return -(-pieces // workers) * workers


def split_evenly(n: int, parts: int) -> list[tuple[int, int]]:
    """``[start, stop)`` ranges cutting ``range(n)`` into at most ``parts``
    contiguous runs whose lengths differ by at most one (none empty)."""
    parts = max(1, min(parts, n))
    base, extra = divmod(n, parts)
    out, start = [], 0
    for i in range(parts):
        stop = start + base + (i < extra)
        out.append((start, stop))
        start = stop
    return out if n else []
