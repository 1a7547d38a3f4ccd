"""Native readers run in a child process, so a crash on a hostile file cannot take ours down.

VTK's readers are C++: on a corrupted file some of them dereference garbage
(the fuzz suite found binary PLY mutants that end the process with SIGSEGV or
SIGABRT). :func:`run_isolated` forks, runs the reader in the child and sends
its result back through a pipe; a child that dies by a signal becomes a
``ValueError`` naming the file, and the reader's own errors come back as
they were raised (``ValueError``, ``FileNotFoundError``, ``MemoryError``;
anything else as a ``ValueError``). The child's address space is limited to
its size at the fork plus what the caller allows (by default half the memory
available), so a reader that believes a corrupt size fails at once instead
of filling memory first.
Where ``fork`` does not exist the reader runs in this process.

Examples
--------
>>> run_isolated(sum, [1, 2, 3], where="a list")
6
"""
from __future__ import annotations

import os
import pickle
import signal
from typing import Any, Callable, Optional

__all__ = ["run_isolated"]

_PASSED = (ValueError, FileNotFoundError, MemoryError)


def run_isolated(fn: Callable[..., Any], *args: Any, where: str,
                 max_bytes: Optional[int] = None) -> Any:
    """``fn(*args)`` in a forked child; its result (picklable) or its error.

    ``max_bytes``: what the child may allocate beyond its size at the fork
    (default: half the memory available)."""
    if not hasattr(os, "fork"):
        return fn(*args)
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:                                   # the child: never returns
        os.close(read_end)
        _limit_address_space(max_bytes)
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


def _limit_address_space(max_bytes: Optional[int]) -> None:
    try:
        import resource
        size = available = 0
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    size = int(line.split()[1]) * 1024
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    available = int(line.split()[1]) * 1024
        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        limit = size + (available // 2 if max_bytes is None else min(max_bytes, available))
        if size and available and (soft == resource.RLIM_INFINITY or limit < soft):
            resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    except (ImportError, OSError, ValueError):
        pass                                       # no limit where it cannot be read
