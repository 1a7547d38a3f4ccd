"""A memory budget watched during a run, not only guessed before it.

Estimates extrapolate (Stolte's growth of 4 per level); a surface that grows
faster, such as ``sin(1000x) sin(1000y) sin(1000z)``, beats them. The
subdivision therefore counts what it keeps and asks the guard after every
step; past the budget the run stops with a ``MemoryError`` that says what it
had found and what the estimate said, and nothing partial is returned.

Examples
--------
>>> guard = MemoryGuard(1000, "voxelizing a test", bytes_per_voxel=48)
>>> guard.check(voxels=10, octants=0)
>>> guard.check(voxels=100, octants=0)
Traceback (most recent call last):
...
MemoryError: voxelizing a test stopped after 100 surface voxels: it would need 4.47e-06 GiB, over the budget of 9.31e-07 GiB (max_memory); lower the resolution or raise max_memory
"""
from __future__ import annotations

from typing import Optional

__all__ = ["MemoryGuard"]


class MemoryGuard:
    """Raises ``MemoryError`` once the kept voxels and pending octants would exceed ``budget``.

    Parameters
    ----------
    budget : int
        Bytes the run may use.
    what : str
        The run, for the message ("voxelizing at (512, 512, 512)").
    bytes_per_voxel : int
        Peak bytes per kept surface voxel (collecting, sorting, building the tree).
    bytes_per_octant : int, default: 8
        Bytes per pending octant or interior octant (a packed key).
    estimated_voxels : int, optional
        What the estimate said, quoted in the message.
    working : int, default: 0
        Bytes the run needs whatever it keeps (its working arrays).
    """

    def __init__(self, budget: int, what: str, bytes_per_voxel: int,
                 bytes_per_octant: int = 8, estimated_voxels: Optional[int] = None,
                 working: int = 0):
        self.budget = int(budget)
        self.working = int(working)
        self.what = what
        self.bytes_per_voxel = int(bytes_per_voxel)
        self.bytes_per_octant = int(bytes_per_octant)
        self.estimated_voxels = estimated_voxels

    def need(self, voxels: int, octants: int, extra: int = 0) -> int:
        """Bytes for ``voxels`` kept surface voxels and ``octants`` other keys, and
        ``extra`` bytes more (what else the run holds: its tapes)."""
        return (self.working + voxels * self.bytes_per_voxel + octants * self.bytes_per_octant
                + extra)

    def check(self, voxels: int, octants: int, extra: int = 0) -> None:
        """Raise ``MemoryError`` if the run's holdings would pass the budget."""
        need = self.need(voxels, octants, extra)
        if need <= self.budget:
            return
        said = "" if self.estimated_voxels is None else \
            f" (the estimate said ~{self.estimated_voxels:,})"
        raise MemoryError(f"{self.what} stopped after {voxels:,} surface voxels{said}: it would "
                          f"need {need / 2**30:.3g} GiB, over the budget of "
                          f"{self.budget / 2**30:.3g} GiB (max_memory); lower the resolution "
                          "or raise max_memory")
