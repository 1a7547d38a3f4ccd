"""The memory budget of a run: checked once, before anything big is allocated.

Every voxelizer estimates its peak bytes first and refuses (``MemoryError``)
a run whose estimate exceeds the budget: ``max_memory`` if given, else half
the memory available now.

Examples
--------
>>> from implicitvox.voxelizers.memory import memory_budget
>>> memory_budget(2**30)
1073741824
>>> memory_budget(None) > 0
True
"""
from __future__ import annotations

from typing import Any

from .. import _validate

__all__ = ["memory_budget", "available_memory", "refuse_over_budget"]


def available_memory() -> int:
    """Bytes available now (Linux ``MemAvailable``), else 16 GiB."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 16 << 30


def memory_budget(max_memory: Any) -> int:
    """The byte budget of a run: ``max_memory`` (checked), or half the available memory."""
    checked = _validate.max_memory(max_memory)
    return available_memory() // 2 if checked is None else checked


def refuse_over_budget(need: int, budget: int, what: str) -> None:
    """Raise ``MemoryError`` saying ``what`` needs ``need`` bytes, if over ``budget``."""
    if need > budget:
        raise MemoryError(f"{what} needs an estimated {need / 2**30:.2f} GiB, over the budget "
                          f"of {budget / 2**30:.2f} GiB; lower the resolution or raise "
                          "max_memory")
