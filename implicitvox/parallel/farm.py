"""Hand a job's pieces to workers and yield their results as they complete.

Four backends behind one generator, :func:`farm`:

* ``workers=n`` (no executor): a ``ProcessPoolExecutor`` of ``n`` processes,
  forked (or, when this process runs other threads, started by a
  ``forkserver`` with ``implicitvox`` preloaded: see :func:`pool_context`),
  kept for the next run (starting workers costs more than a small run); the
  job is pickled once into a file (in ``/dev/shm`` where there is one) that
  each worker reads on its first piece: it travels once per worker.
* ``workers=n, threads=True``: ``n`` threads of this process, for a job whose
  pieces run in compiled code that releases the GIL (the compiled
  subdivision, :mod:`implicitvox.octree.descend`): nothing is pickled, the
  pieces share the job as it is.
* ``executor=`` a ``dask.distributed.Client``: a job larger than
  :data:`SCATTER_BYTES` pickled (a mesh's triangles) is ``scatter``-ed to
  every worker (``broadcast=True``) and each piece is a task reading it
  there; a smaller one (an expression's tape: a few KiB) goes with each task,
  which saves the broadcast's round trip to every worker; Dask retries a
  piece whose worker died and then reports it (``KilledWorker``).
* ``executor=`` any other ``concurrent.futures.Executor`` (a thread pool, a
  process pool of your own, an MPI pool): the job goes with every piece and is
  prepared once per worker process (:func:`implicitvox.parallel.jobs.run_piece`).

Pieces are submitted all at once; the executors hand them to workers as
they free up (a queue: uneven pieces balance). A piece that fails re-raises
its error here; a worker that dies raises :class:`WorkerError` at once
(never a hang); an interrupt (Ctrl-C) or any error cancels the pieces not
started and stops the workers of an own pool.

Examples
--------
>>> from concurrent.futures import ThreadPoolExecutor
>>> from implicitvox.parallel.jobs import Job
>>> class Square(Job):
...     def run(self, piece):
...         return piece * piece
>>> with ThreadPoolExecutor(2) as pool:
...     sorted(farm(Square(), [1, 2, 3], executor=pool))
[(0, 1), (1, 4), (2, 9)]
"""
from __future__ import annotations

import multiprocessing
import os
import pickle
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, ThreadPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable, Iterator, Optional, Sequence

from .jobs import Job, run_piece, run_stored_piece, store_job
from .plan import is_dask_client

__all__ = ["farm", "WorkerError", "pool_context", "shutdown_pools", "SCATTER_BYTES",
           "OWNER_CHECK_SECONDS"]

#: a job pickled larger than this is scattered to Dask's workers once; a smaller one
#: travels with each task (Dask warns of task graphs past 10 MB: 16 pieces stay far below)
SCATTER_BYTES = 1 << 18


class WorkerError(RuntimeError):
    """A worker process died (killed, out of memory, crashed) while running a piece."""


def farm(job: Job, pieces: Sequence[Any], *, workers: int = 2, executor: Any = None,
         weights: Optional[Sequence[float]] = None,
         progress: Optional[Callable[[float], Any]] = None,
         what: str = "a parallel run", threads: bool = False) -> Iterator[tuple[int, Any]]:
    """Run ``job.run(piece)`` for every piece on workers; yield ``(index, result)``
    as each completes (in no fixed order).

    Parameters
    ----------
    job : Job
        What the pieces share, sent once per worker.
    pieces : sequence
        Small, picklable descriptions of independent work (subtrees).
    workers : int, default: 2
        Processes of an own pool, or threads with ``threads`` (ignored with
        ``executor``).
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Where to run instead of an own pool.
    weights : sequence of float, optional
        Each piece's share of the work, for ``progress`` (default: equal).
    progress : callable, optional
        Called with the share of the weight completed, after each piece.
    what : str
        The run, for error messages ("voxelizing at (512, 512, 512)").
    threads : bool, default: False
        Run the pieces on ``workers`` threads of this process instead of
        processes (without ``executor``).

    Raises
    ------
    WorkerError
        A worker died; the message names the run and how far it got.
    """
    if not len(pieces):
        return
    weights = [1.0] * len(pieces) if weights is None else [float(w) for w in weights]
    total = sum(weights) or 1.0
    if executor is None and threads:
        backend = _Threads(job, workers)
    elif executor is None:
        backend = _OwnPool(job, workers)
    elif is_dask_client(executor):
        backend = _Dask(job, executor)
    else:
        backend = _Futures(job, executor)
    done = 0.0
    ok = False
    try:
        pending = {backend.submit(piece): i for i, piece in enumerate(pieces)}
        finished = 0
        for future, index in backend.completed(pending):
            result = backend.result(future, finished, len(pieces), what)
            finished += 1
            done += weights[index]
            if progress is not None:
                progress(min(done / total, 1.0))
            yield index, result
        backend.finish()
        ok = True
    finally:
        if not ok:
            backend.close()


def _died(done: int, count: int, what: str, cause: BaseException) -> WorkerError:
    return WorkerError(f"a worker died while {what} ({done} of {count} pieces done; "
                       f"{type(cause).__name__}: {str(cause).rstrip('.')}); the run was "
                       "stopped. Out of memory? Lower the resolution or the workers.")


class _Executor:
    """A ``concurrent.futures`` executor's futures: completion and results."""

    def completed(self, pending: dict) -> Iterator:
        return _as_completed(pending)

    def result(self, future, done: int, count: int, what: str):
        try:
            return future.result()
        except BrokenProcessPool as err:
            raise _died(done, count, what, err) from None


class _OwnPool(_Executor):
    """A process pool of this machine, kept between runs; the job is pickled once
    into a file that each worker reads on its first piece (:func:`run_stored_piece`)."""

    def __init__(self, job: Job, workers: int):
        self.job = job
        self.pool, self.key = _shared_pool(workers)
        self.path = store_job(job)

    def submit(self, piece):
        return self.pool.submit(run_stored_piece, self.job.token, self.path, piece)

    def finish(self) -> None:
        """The run is over and every piece came back: the pool stays for the next."""
        _remove(self.path)

    def close(self) -> None:
        """Stop the pool: an error, an interrupt, a worker lost. A piece still
        running is stopped, not waited for (Python 3.14 names this
        ``terminate_workers``; before, the processes are reached through the pool)."""
        _remove(self.path)
        _POOLS.pop(self.key, None)
        self.pool.shutdown(wait=False, cancel_futures=True)
        terminate = getattr(self.pool, "terminate_workers", None)
        if terminate is not None:
            terminate()
            return
        for process in list((getattr(self.pool, "_processes", None) or {}).values()):
            if process.is_alive():
                process.terminate()


def _remove(path: str) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


#: the pools kept between runs, by their number of workers (this process's own: a
#: forked child forgets its parent's, :func:`_forget_inherited_pools`)
_POOLS: dict = {}
#: a forked child's copies of its parent's pools: never used, never shut down (their
#: processes and threads are the parent's), only kept from the garbage collector, whose
#: clean-up would write to the parent's wake-up pipe
_INHERITED: list = []
#: seconds between a worker's checks that the process that started it is alive
OWNER_CHECK_SECONDS = 0.2


def _shared_pool(workers: int):
    """The pool of ``workers`` processes kept for this process's runs (started on
    first use, by :func:`pool_context`'s method), and its key. Its workers exit on
    their own when this process ends, however it ends (:func:`_exit_with_owner`)."""
    if workers not in _POOLS:
        _POOLS[workers] = ProcessPoolExecutor(max_workers=workers, mp_context=pool_context(),
                                              initializer=_exit_with_owner)
    return _POOLS[workers], workers


def _forget_inherited_pools() -> None:
    """In a forked child: the pools copied from the parent are the parent's; the
    child starts its own on its first parallel run."""
    _INHERITED.extend(_POOLS.values())
    _POOLS.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_inherited_pools)


def _exit_with_owner() -> None:
    """A pool worker's initializer: a daemon thread that ends the worker as soon as
    the process that started it is gone (its parent changes: the owner died, or the
    forkserver that started it did, which ends with the owner). ``atexit`` is not
    enough: an owner that leaves by ``os._exit`` (a forked child of a test runner or
    of ``multiprocessing``) or by a signal runs none, and its workers would keep the
    pipes they inherited open."""
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(OWNER_CHECK_SECONDS)
        os._exit(0)

    threading.Thread(target=watch, name="implicitvox-owner-watch", daemon=True).start()


def shutdown_pools() -> None:
    """Stop the pools kept between runs (their workers hold the last jobs)."""
    for pool in list(_POOLS.values()):
        pool.shutdown(wait=True, cancel_futures=True)
    _POOLS.clear()


_FORKSERVER = None


def _foreign_threads() -> bool:
    """Whether threads other than the main one and those of this module's own
    pools (their managers and queue feeders hold no lock a fork could copy
    held) run in this process."""
    own = ("concurrent.futures.process", "multiprocessing.queues")
    for thread in threading.enumerate():
        if thread is threading.main_thread():
            continue
        target = getattr(thread, "_target", None)
        module = getattr(target, "__module__", None) or type(thread).__module__
        if module not in own:
            return True
    return False


def pool_context():
    """How the pool's processes start: ``fork`` where the platform has it and this
    process runs no other Python thread (cheap, and a script needs no ``if
    __name__ == "__main__"`` guard); else ``forkserver`` with implicitvox
    preloaded (a fork while another thread may hold a lock can deadlock), or
    ``spawn`` where there is neither. The last two import the main script again
    in each worker, so a script then needs the guard."""
    global _FORKSERVER
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods and not _foreign_threads():
        return multiprocessing.get_context("fork")
    if _FORKSERVER is None:
        if "forkserver" in methods:
            ctx = multiprocessing.get_context("forkserver")
            ctx.set_forkserver_preload(["implicitvox"])
        else:
            ctx = multiprocessing.get_context("spawn")
        _FORKSERVER = ctx
    return _FORKSERVER


class _Futures(_Executor):
    """Any ``concurrent.futures.Executor``: the job goes with each piece."""

    def __init__(self, job: Job, executor: Any):
        self.job, self.executor, self.futures = job, executor, []

    def submit(self, piece):
        future = self.executor.submit(run_piece, self.job, piece)
        self.futures.append(future)
        return future

    def finish(self) -> None:
        pass

    def close(self) -> None:
        for future in self.futures:
            future.cancel()


class _Threads(_Futures):
    """Threads of this process, for the length of one run; the job runs as it is
    (not installed: nothing of it outlives the run)."""

    def __init__(self, job: Job, workers: int):
        super().__init__(job, ThreadPoolExecutor(max(1, int(workers)),
                                                 thread_name_prefix="implicitvox"))

    def submit(self, piece):
        future = self.executor.submit(self.job.run, piece)
        self.futures.append(future)
        return future

    def finish(self) -> None:
        self.executor.shutdown(wait=True)

    def close(self) -> None:
        """Cancel the pieces not started; those running finish in the background
        (a thread cannot be stopped), their results dropped."""
        super().close()
        self.executor.shutdown(wait=False, cancel_futures=True)


class _Dask:
    """A ``dask.distributed.Client``: the job scattered to every worker once, or
    sent with each task when it is small (:data:`SCATTER_BYTES`)."""

    def __init__(self, job: Job, client: Any):
        self.client = client
        small = len(pickle.dumps(job, protocol=pickle.HIGHEST_PROTOCOL)) <= SCATTER_BYTES
        self.shared = job if small else client.scatter(job, broadcast=True, hash=False)
        self.futures = []

    def submit(self, piece):
        future = self.client.submit(run_piece, self.shared, piece, pure=False)
        self.futures.append(future)
        return future

    def completed(self, pending: dict) -> Iterator:
        from distributed import as_completed
        for future in as_completed(list(pending)):
            yield future, pending[future]

    def result(self, future, done: int, count: int, what: str):
        from distributed import KilledWorker
        try:
            return future.result()
        except KilledWorker as err:
            raise _died(done, count, what, err) from None

    def finish(self) -> None:
        if not isinstance(self.shared, Job):    # the job leaves the workers' memory
            self.client.cancel([self.shared])

    def close(self) -> None:
        if self.futures:
            self.client.cancel(self.futures)
        self.finish()


def _as_completed(pending: dict) -> Iterator:
    """``(future, index)`` as the futures complete."""
    waiting = set(pending)
    while waiting:
        finished, waiting = wait(waiting, return_when=FIRST_COMPLETED)
        for future in finished:
            yield future, pending[future]
