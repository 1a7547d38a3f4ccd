"""The memory budget of a run: checked once, before anything big is allocated.

Every voxelizer estimates its peak bytes first and refuses (``MemoryError``)
a run whose estimate exceeds the budget: ``max_memory`` if given, else half
the memory available now.

Examples
--------
>>> from implicitvox.octree.budget import memory_budget
>>> memory_budget(2**30)
1073741824
>>> memory_budget(None) > 0
True
"""
from __future__ import annotations

from typing import Any, Optional

from .. import validate

__all__ = ["memory_budget", "available_memory", "refuse_over_budget", "size_text"]


def available_memory() -> int:
    """Bytes this process may still use now: the least of the machine's available
    memory (Linux ``MemAvailable``), what its cgroup allows beyond its current use
    (``memory.max``, v2 or v1), and its address-space limit (``RLIMIT_AS``) beyond
    its current size; 16 GiB where none of them can be read."""
    limits = [v for v in (_meminfo_available(), _cgroup_room(), _rlimit_room()) if v is not None]
    return max(0, min(limits)) if limits else 16 << 30


def _read_int(path: str) -> Optional[int]:
    try:
        with open(path) as fh:
            text = fh.read().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def _meminfo_available() -> Optional[int]:
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _cgroup_room() -> Optional[int]:
    for limit, usage in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                         ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                          "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        cap = _read_int(limit)             # "max" (no limit) reads as None
        if cap is not None and cap < 1 << 60:
            return cap - (_read_int(usage) or 0)
    return None


def _rlimit_room() -> Optional[int]:
    try:
        import resource
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    except (ImportError, ValueError, OSError):
        return None
    if soft == resource.RLIM_INFINITY or soft < 0:
        return None
    size = 0
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    size = int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return soft - size


def memory_budget(max_memory: Any) -> int:
    """The byte budget of a run: ``max_memory`` (checked), or half the available memory."""
    checked = validate.max_memory(max_memory)
    return available_memory() // 2 if checked is None else checked


def refuse_over_budget(need: int, budget: int, what: str) -> None:
    """Raise ``MemoryError`` saying ``what`` needs ``need`` bytes, if over ``budget``."""
    if need > budget:
        raise MemoryError(f"{what} needs an estimated {size_text(need)}, over the budget "
                          f"of {size_text(budget)}; lower the resolution or raise max_memory")


def size_text(nbytes: float) -> str:
    """Bytes in GiB, or in MiB below a GiB (so a small budget does not read as 0.00 GiB).

    >>> size_text(3 * 2**30), size_text(5 * 2**20)
    ('3.00 GiB', '5.0 MiB')
    """
    if nbytes >= 2**30:
        return f"{nbytes / 2**30:.2f} GiB"
    return f"{nbytes / 2**20:.1f} MiB"
