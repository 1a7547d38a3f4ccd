"""The package's Numba caches are deleted when any of its sources changes
(interval/numba_cache.py): Numba itself only notices a change to a kernel's own file."""
from __future__ import annotations

import os
from pathlib import Path

import implicitvox
from implicitvox.interval import numba_cache


def _package(tmp_path: Path) -> Path:
    (tmp_path / "rules.py").write_text("def rule(a):\n    return a + 1\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "kernel.py").write_text("from ..rules import rule\n")
    return tmp_path


def _cache(package: Path) -> list:
    made = []
    for folder in (package / "__pycache__", package / "sub" / "__pycache__"):
        folder.mkdir(exist_ok=True)
        for suffix in ("nbi", "nbc"):
            path = folder / f"kernel.f-1.py311.{suffix}"
            path.write_bytes(b"machine code")
            made.append(path)
    return made


def test_a_change_to_any_source_deletes_every_cached_kernel(tmp_path):
    package = _package(tmp_path)
    _cache(package)
    assert numba_cache.refresh(package) == 4               # no fingerprint yet
    cached = _cache(package)
    assert numba_cache.refresh(package) == 0               # the same sources
    assert all(p.exists() for p in cached)
    (package / "rules.py").write_text("def rule(a):\n    return a + 2\n")   # not the kernel's file
    assert numba_cache.refresh(package) == 4
    assert not any(p.exists() for p in cached)
    other = package / "__pycache__" / "rules.cpython-311.pyc"      # Python's own: kept
    other.write_bytes(b"bytecode")
    (package / "sub" / "new.py").write_text("")                    # a new source counts too
    assert numba_cache.refresh(package) == 0 and other.exists()
    assert (package / "__pycache__" / numba_cache.STAMP).read_text() == \
        numba_cache.fingerprint(package)


def test_the_package_import_keeps_its_fingerprint():
    package = Path(implicitvox.__file__).resolve().parent
    stamp = package / "__pycache__" / numba_cache.STAMP
    if os.access(package, os.W_OK):
        assert stamp.read_text() == numba_cache.fingerprint(package)
