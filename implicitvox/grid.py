"""The voxel grid: bounds, voxel size, resolution, and octant boxes.

Voxel ``m`` on axis ``a`` spans ``[edge(a, m), edge(a, m + 1)]`` with
``edge(a, m) = origin[a] + m * voxel_size[a]``, computed by this one formula
everywhere. Rounding is monotone in ``m``, so neighbouring voxels share their
edge exactly (no gaps) and every octant box holds its children's boxes. The
octree spans the next power of two (``2**depth`` voxels per axis) and crops:
octants past the grid are never evaluated.

Examples
--------
>>> g = Grid.from_bounds(((0, 0, 0), (2, 1, 1)), 4)
>>> g.shape, g.depth
((4, 2, 2), 2)
>>> g.voxel_size
(0.5, 0.5, 0.5)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .morton import MAX_BITS

__all__ = ["Grid", "parse_bounds", "parse_resolution", "MAX_RESOLUTION"]

#: voxels per axis at most (octree depth 21)
MAX_RESOLUTION = 1 << MAX_BITS


def parse_bounds(bounds: Any) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Check ``((x0, y0, z0), (x1, y1, z1))``; raise ``ValueError`` naming the problem."""
    try:
        b = np.asarray(bounds, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"bounds must be ((x0, y0, z0), (x1, y1, z1)), got {bounds!r:.80}") from None
    if b.shape != (2, 3):
        raise ValueError(f"bounds must be ((x0, y0, z0), (x1, y1, z1)), got shape {b.shape}")
    if not np.all(np.isfinite(b)):
        raise ValueError(f"bounds must be finite numbers, got {b.tolist()}")
    for a in range(3):
        if not b[1, a] > b[0, a]:
            raise ValueError(f"bounds have zero or negative extent on axis {'xyz'[a]}: "
                             f"{b[0, a]!r} .. {b[1, a]!r}")
    return tuple(b[0].tolist()), tuple(b[1].tolist())


def parse_resolution(resolution: Any, extent: np.ndarray) -> tuple[int, int, int]:
    """Voxels per axis from an int (along the longest side) or a 3-tuple."""
    def as_count(v: Any, name: str) -> int:
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
            raise ValueError(f"{name} must be a positive int, got {type(v).__name__} {v!r:.40}")
        if not 1 <= v <= MAX_RESOLUTION:
            raise ValueError(f"{name} must be between 1 and {MAX_RESOLUTION}, got {v}")
        return int(v)
    if isinstance(resolution, (tuple, list, np.ndarray)):
        if len(resolution) != 3:
            raise ValueError(f"resolution must be an int or 3 ints, got {resolution!r:.60}")
        return tuple(as_count(v, f"resolution[{i}]") for i, v in enumerate(resolution))
    n = as_count(resolution, "resolution")
    longest = float(extent.max())
    return tuple(max(1, min(MAX_RESOLUTION, int(round(n * e / longest)))) for e in extent)


@dataclass(frozen=True)
class Grid:
    """A box of ``shape`` voxels from ``origin``, each ``voxel_size`` wide."""

    origin: tuple[float, float, float]
    voxel_size: tuple[float, float, float]
    shape: tuple[int, int, int]

    @classmethod
    def from_bounds(cls, bounds: Any, resolution: Any) -> "Grid":
        lo, hi = parse_bounds(bounds)
        extent = np.subtract(hi, lo)
        shape = parse_resolution(resolution, extent)
        size = tuple(float(e / n) for e, n in zip(extent, shape))
        return cls(lo, size, shape)

    @property
    def depth(self) -> int:
        """Octree levels below the root: ``2**depth >= max(shape)``."""
        return max(0, math.ceil(math.log2(max(self.shape))))

    @property
    def bounds(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        hi = tuple(float(self.edge(a, self.shape[a])) for a in range(3))
        return self.origin, hi

    def finer(self, levels: int) -> "Grid":
        """The grid with each voxel split ``2**levels`` times per axis (same edges)."""
        f = 1 << levels
        return Grid(self.origin, tuple(h / f for h in self.voxel_size),
                    tuple(n * f for n in self.shape))

    def edge(self, axis: int, m: Any) -> Any:
        """World coordinate of voxel boundary ``m`` along ``axis`` (the one formula)."""
        return self.origin[axis] + np.asarray(m, dtype=np.float64) * self.voxel_size[axis]

    def octant_boxes(self, level: int, coords: np.ndarray
                     ) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
        """Per-axis ``(lo, hi)`` columns of octants at ``level``, cropped to the grid."""
        scale = 1 << (self.depth - level)
        lo, hi = [], []
        for a in range(3):
            first = coords[:, a].astype(np.float64) * scale
            last = np.minimum(first + scale, self.shape[a])
            lo.append(self.edge(a, first))
            hi.append(self.edge(a, last))
        return tuple(lo), tuple(hi)

    def centers(self, coords: np.ndarray) -> np.ndarray:
        """Centres of voxels ``coords`` (n, 3)."""
        out = np.empty(coords.shape, dtype=np.float64)
        for a in range(3):
            out[:, a] = 0.5 * (self.edge(a, coords[:, a]) + self.edge(a, coords[:, a] + 1))
        return out

    def voxels_holding(self, points: np.ndarray) -> list[np.ndarray]:
        """For points (n, 3): the voxel(s) whose closed box holds each point.

        Returns the candidate index arrays (n, 3): the voxel found by division
        and, for points on a shared edge, the neighbour below on each axis.
        Points outside the grid get -1.
        """
        idx = np.empty(points.shape, dtype=np.int64)
        below = np.empty(points.shape, dtype=np.int64)
        for a in range(3):
            m = np.floor((points[:, a] - self.origin[a]) / self.voxel_size[a]).astype(np.int64)
            m = np.clip(m, 0, self.shape[a] - 1)
            for _ in range(2):  # correct the division's rounding against the edge formula
                m = np.where(self.edge(a, m) > points[:, a], m - 1, m)
                m = np.where(self.edge(a, m + 1) < points[:, a], m + 1, m)
            m = np.clip(m, 0, self.shape[a] - 1)
            on_lower_edge = self.edge(a, m) == points[:, a]
            inside = (points[:, a] >= self.edge(a, 0)) & (points[:, a] <= self.edge(a, self.shape[a]))
            idx[:, a] = np.where(inside, m, -1)
            below[:, a] = np.where(inside & on_lower_edge & (m > 0), m - 1, idx[:, a])
        return [idx, below]
