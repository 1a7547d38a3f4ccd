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

import uuid
from collections import OrderedDict
from typing import Any, Union

__all__ = ["Job", "install", "run_piece", "INSTALLED_LIMIT"]

#: jobs a worker process keeps installed (a long-lived Dask worker serves many runs)
INSTALLED_LIMIT = 4
_INSTALLED: "OrderedDict[str, Job]" = OrderedDict()


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


def run_piece(job: Union[Job, str], piece: Any) -> Any:
    """Run one piece: ``job`` is the job or the token of one installed here.

    A job that arrives with the piece (any ``Executor``) is installed on first
    sight, so a worker that runs several of its pieces prepares it once."""
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
