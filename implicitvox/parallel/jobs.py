"""The worker's side: jobs installed once per process, pieces run against them.

Examples
--------
A job doubles numbers; here it runs in this process, as a worker runs it:

>>> class Double(Job):
...     def run(self, piece):
...         return 2 * piece
>>> job = Double()
>>> run_piece(job, 21)
42
>>> install(job); run_piece(job.token, 4)      # installed: pieces name it by token
8
"""
from __future__ import annotations

import ctypes
import ctypes.util
import os
import pickle
import sys
import tempfile
import uuid
from collections import OrderedDict
from typing import Any, Union

__all__ = ["Job", "install", "store_job", "run_stored_piece", "run_piece",
           "tune_allocator", "INSTALLED_LIMIT",
           "MMAP_THRESHOLD", "TRIM_THRESHOLD"]

#: jobs a worker process keeps installed (a long-lived Dask worker serves many runs)
INSTALLED_LIMIT = 2
_INSTALLED: "OrderedDict[str, Job]" = OrderedDict()
#: glibc's thresholds in a worker (:func:`tune_allocator`): arrays up to this size come
#: from the heap, and the heap's top is returned to the system past the other
MMAP_THRESHOLD = 32 << 20
TRIM_THRESHOLD = 64 << 20
_TUNED = False


def tune_allocator() -> bool:
    """Let glibc reuse freed memory for numpy's temporaries in this process (once).

    Dask starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536`` (to give memory
    back to the system; it sets it in the parent's environment too, so a pool
    started later inherits it). Setting it fixes glibc's mmap threshold at
    128 KiB: every temporary of a chunk of boxes is then mapped, faulted in and
    unmapped afresh, and the subdivision runs 6 times slower
    (``MALLOC_TRIM_THRESHOLD_=65536 python ...``: 7.7 s against 1.2 s for
    sin(9θ)sin(18φ) − r at 1024³). A worker running a job therefore sets the
    thresholds near glibc's own adaptive ones (``mallopt``: arrays up to
    :data:`MMAP_THRESHOLD` from the heap, trimmed past :data:`TRIM_THRESHOLD`):
    freed memory still goes back, in larger steps. Does nothing off glibc.
    Returns whether it was applied.
    """
    global _TUNED
    if _TUNED or not sys.platform.startswith("linux"):
        return _TUNED
    _TUNED = True
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    m_trim_threshold, m_mmap_threshold = -1, -3          # glibc's malloc.h
    return bool(mallopt(m_mmap_threshold, MMAP_THRESHOLD)) and \
        bool(mallopt(m_trim_threshold, TRIM_THRESHOLD))


class Job:
    """What every piece of one run shares; subclasses define :meth:`run`.

    A job is pickled once per worker (the pool's initializer, or Dask's
    broadcast ``scatter``) and kept there by its :attr:`token`, so what it
    prepares on first use (a compiled tape, the exact classifiers) is prepared
    once per worker, not per piece. Keep prepared state in attributes that
    are not pickled (``functools.cached_property`` computed in the worker).
    """

    def __init__(self) -> None:
        #: names this job in the workers' caches
        self.token = uuid.uuid4().hex

    def run(self, piece: Any) -> Any:
        """The result of one piece (called in a worker)."""
        raise NotImplementedError

    def __getstate__(self) -> dict:
        # cached, prepared state (functools.cached_property) stays behind
        return {k: v for k, v in self.__dict__.items() if not k.startswith("prepared_")}


def install(job: Job) -> None:
    """Keep ``job`` in this process (a pool's initializer), the oldest beyond
    :data:`INSTALLED_LIMIT` dropped."""
    _INSTALLED[job.token] = job
    _INSTALLED.move_to_end(job.token)
    while len(_INSTALLED) > INSTALLED_LIMIT:
        _INSTALLED.popitem(last=False)


def store_job(job: Job) -> str:
    """Pickle ``job`` once into a file for :func:`run_stored_piece` (in ``/dev/shm``,
    memory, where there is one); the caller removes it after the run."""
    folder = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) \
        else None
    handle, path = tempfile.mkstemp(prefix="implicitvox-job-", suffix=".pickle", dir=folder)
    with os.fdopen(handle, "wb") as out:
        pickle.dump(job, out, protocol=pickle.HIGHEST_PROTOCOL)
    return path


def run_stored_piece(token: str, path: str, piece: Any) -> Any:
    """Run one piece of the job stored at ``path`` (read once per worker process)."""
    if token not in _INSTALLED:
        with open(path, "rb") as stored:
            install(pickle.load(stored))
    return run_piece(token, piece)


def run_piece(job: Union[Job, str], piece: Any) -> Any:
    """Run one piece: ``job`` is the job or the token of one installed here.

    A job that arrives with the piece (any ``Executor``) is installed on first
    sight, so a worker that runs several of its pieces prepares it once."""
    tune_allocator()
    if isinstance(job, str):
        try:
            job = _INSTALLED[job]
        except KeyError:
            raise RuntimeError(f"job {job} is not installed in this worker process") from None
    elif job.token in _INSTALLED:
        job = _INSTALLED[job.token]
    else:
        install(job)
    return job.run(piece)
