"""Numba's on-disk caches of the package's kernels, kept in step with all of its sources.

Numba keys a cached function by the timestamp and size of the file that
defines it. A kernel that inlines functions from another file (every kernel
inlines :mod:`implicitvox.interval.rules`) keeps its old machine code when
only that other file changes: in a working tree, a ``git pull`` that changes
``rules.py`` would leave every kernel running the old rules, silently. (A
fresh install writes every file, so every cache goes stale together there.)

:func:`refresh` fingerprints every source file of the package and keeps the
fingerprint beside the caches; where it differs, it deletes the package's
cached kernels, which Numba then compiles again on first use. It runs once,
when :mod:`implicitvox.interval.rules` is imported, before any kernel is
compiled.

Examples
--------
>>> import pathlib, tempfile
>>> root = pathlib.Path(tempfile.mkdtemp())
>>> (root / "kernel.py").write_text("x = 1")
5
>>> (root / "__pycache__").mkdir()
>>> _ = (root / "__pycache__" / "kernel.f-1.py311.nbi").write_bytes(b"old")
>>> refresh(root)                       # no fingerprint yet: the caches may be stale
1
>>> refresh(root)                       # the same sources: nothing to do
0
"""
from __future__ import annotations

import hashlib
from pathlib import Path

__all__ = ["refresh", "fingerprint", "STAMP"]

#: the file, in the package's top ``__pycache__``, that holds the fingerprint
STAMP = "numba-sources.sha256"


def fingerprint(package: Path) -> str:
    """SHA-256 of the package's ``.py`` files: their paths and contents, in order."""
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        digest.update(path.relative_to(package).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


def refresh(package: Path) -> int:
    """Delete the cached kernels (``__pycache__/*.nbi``, ``*.nbc``) under ``package``
    unless they were compiled from the sources there now; returns how many files
    were deleted. Where the package cannot be written (a read-only install, whose
    caches Numba keeps elsewhere and whose sources do not change), nothing is done."""
    package = Path(package)
    stamp = package / "__pycache__" / STAMP
    now = fingerprint(package)
    try:
        if stamp.read_text() == now:
            return 0
    except OSError:
        pass
    deleted = 0
    for cached in [*package.rglob("__pycache__/*.nbi"), *package.rglob("__pycache__/*.nbc")]:
        try:
            cached.unlink()
            deleted += 1
        except OSError:               # another process deleted it, or read-only
            pass
    try:
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(now)
    except OSError:
        pass
    return deleted
