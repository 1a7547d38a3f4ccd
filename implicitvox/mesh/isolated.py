"""Native readers run in a child process, so a crash on a hostile file cannot take ours down.

VTK's readers are C++: on a corrupted file some of them dereference garbage
(the fuzz suite found binary PLY mutants that end the process with SIGSEGV or
SIGABRT). :func:`run_isolated` forks, runs the reader in the child and sends
its result back through a pipe; a child that dies by a signal becomes a
``ValueError`` naming the file, and the reader's own errors come back as
they were raised (``ValueError``, ``FileNotFoundError``, ``MemoryError``;
anything else as a ``ValueError``). Where ``fork`` does not exist the reader
runs in this process.

Examples
--------
>>> run_isolated(sum, [1, 2, 3], where="a list")
6
"""
from __future__ import annotations

import os
import pickle
import signal
from typing import Any, Callable

__all__ = ["run_isolated"]

_PASSED = (ValueError, FileNotFoundError, MemoryError)


def run_isolated(fn: Callable[..., Any], *args: Any, where: str) -> Any:
    """``fn(*args)`` in a forked child; its result (picklable) or its error."""
    if not hasattr(os, "fork"):
        return fn(*args)
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:                                   # the child: never returns
        os.close(read_end)
        try:
            try:
                payload = pickle.dumps(("ok", fn(*args)), protocol=pickle.HIGHEST_PROTOCOL)
            except BaseException as err:  # noqa: BLE001 - everything goes back to the parent
                kind = type(err) if isinstance(err, _PASSED) else ValueError
                message = str(err) if isinstance(err, _PASSED) else \
                    f"{where}: {type(err).__name__}: {err}"
                payload = pickle.dumps(("error", kind, message))
            with os.fdopen(write_end, "wb") as out:
                out.write(payload)
        finally:
            os._exit(0)
    os.close(write_end)
    with os.fdopen(read_end, "rb") as inp:
        data = inp.read()
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        name = signal.Signals(os.WTERMSIG(status)).name
        raise ValueError(f"{where}: the reader crashed on it ({name}); the file is corrupt")
    if not data:
        raise ValueError(f"{where}: the reader ended without an answer (exit status "
                         f"{os.WEXITSTATUS(status)})")
    result = pickle.loads(data)
    if result[0] == "ok":
        return result[1]
    raise result[1](result[2])
