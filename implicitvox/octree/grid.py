"""The voxel grid: bounds, voxel size, resolution, and octant boxes.

Voxels are **cubes** unless asked otherwise: ``resolution`` counts voxels
along the longest side of the bounds, the pitch is that side over the count,
and the other axes get as many whole voxels as they need to cover the bounds
(the grid starts at the bounds' low corner and may reach past their high end
by less than a voxel); ``voxel_size`` gives the pitch instead, as Open3D and
trimesh take it. Per-axis resolutions or pitches (3-tuples) make non-cubic
voxels, only when asked for.

Voxel ``m`` on axis ``a`` spans ``[edge(a, m), edge(a, m + 1)]`` with
``edge(a, m) = origin[a] + m * voxel_size[a]``, computed by this one formula
everywhere. Rounding is monotone in ``m``, so neighbouring voxels share their
edge exactly (no gaps) and every octant box holds its children's boxes. The
octree spans the next power of two (``2**depth`` voxels per axis) and crops:
octants past the grid are never evaluated.

Examples
--------
>>> g = Grid.from_bounds(((0, 0, 0), (2, 1, 0.9)), 4)
>>> g.shape, g.depth, g.voxel_size
((4, 2, 2), 2, (0.5, 0.5, 0.5))
>>> Grid.from_bounds(((0, 0, 0), (2, 1, 1)), voxel_size=0.25).shape
(8, 4, 4)
>>> padded_bounds(((0, 0, 0), (2, 1, 1)), 5)
((-0.25, -0.25, -0.25), (2.25, 1.25, 1.25))
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from .. import validate
from .morton import MAX_BITS

__all__ = ["Grid", "padded_bounds", "grid_of", "MAX_RESOLUTION"]

#: voxels per axis at most (octree depth 21)
MAX_RESOLUTION = 1 << MAX_BITS


def _whole_voxels(extent: float, pitch: float, axis: str) -> int:
    """Voxels of ``pitch`` covering ``extent`` (an extent within rounding of a
    whole number of voxels is not given one more)."""
    with np.errstate(over="ignore", divide="ignore"):
        ratio = np.float64(extent) / np.float64(pitch) * (1.0 - 1e-12)
    n = max(1, math.ceil(ratio)) if ratio <= MAX_RESOLUTION else MAX_RESOLUTION + 1
    if n > MAX_RESOLUTION:
        raise ValueError(f"voxel_size {pitch!r} gives {ratio:.4g} voxels on axis {axis}, "
                         f"over the octree's {MAX_RESOLUTION}")
    return n


def padded_bounds(bounds: Any, resolution: Any = None, voxel_size: Any = None,
                  margin: int = 0) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The default grid box of a shape with ``bounds``: grown by half a voxel on every side
    (and ``margin`` whole voxels more).

    This is the one rule for default bounds, used by every voxelizer, the
    ``csg`` solids and the command line. With ``resolution`` ``n`` the voxel
    is ``longest side / (n - 1)`` (the whole side for ``n = 1``), so the grid
    has ``n`` voxels along the longest side and the centres of its first and
    last voxels lie on the shape's extremes; with ``voxel_size`` the pitch is
    given. A flat shape (zero extent on an axis) gets one voxel of depth there.
    ``margin`` (a distance field's band): the grid still has ``n`` voxels, of
    which ``margin`` on each side lie beyond the extremes (the voxel is
    ``longest side / (n - 1 - 2 margin)``; fewer on a grid too small for them).
    """
    lo = np.asarray(bounds[0], dtype=np.float64)
    hi = np.asarray(bounds[1], dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or not (np.all(np.isfinite(lo))
                                                  and np.all(np.isfinite(hi))) or np.any(hi < lo):
        raise ValueError(f"the shape's bounds must be finite ((x0, y0, z0), (x1, y1, z1)) with "
                         f"x0 <= x1, ..., got {bounds!r:.80}")
    extent = hi - lo
    if voxel_size is not None:
        pitch = np.broadcast_to(np.asarray(validate.voxel_size(voxel_size), float), (3,))
    else:
        res = validate.resolution(resolution, MAX_RESOLUTION)
        counts = np.broadcast_to(np.asarray(res, dtype=np.float64), (3,))
        margin = max(0, min(int(margin), (int(counts.min()) - 2) // 2))
        inner = counts - 2 * margin           # voxels from extreme to extreme, centre to centre
        if isinstance(res, tuple):
            pitch = np.where(inner > 1, extent / np.maximum(inner - 1, 1), extent)
        else:
            longest = float(extent.max())
            pitch = np.full(3, longest / (inner[0] - 1) if inner[0] > 1 else longest)
        if not np.all(pitch > 0):
            pitch = np.where(pitch > 0, pitch, float(extent.max()))
    if not np.all(pitch > 0):
        raise ValueError(f"the shape's bounds have no extent (a point at {lo.tolist()}): pass "
                         "bounds or voxel_size")
    reach = pitch * (margin + 0.5)
    return tuple((lo - reach).tolist()), tuple((hi + reach).tolist())


@dataclass(frozen=True)
class Grid:
    """A box of ``shape`` voxels from ``origin``, each ``voxel_size`` wide."""

    origin: tuple[float, float, float]
    voxel_size: tuple[float, float, float]
    shape: tuple[int, int, int]

    @classmethod
    def from_bounds(cls, bounds: Any, resolution: Any = None, voxel_size: Any = None) -> "Grid":
        """The grid over ``bounds``: ``resolution`` voxels along the longest side
        (cubes) or per axis, or cubes of ``voxel_size`` (one of the two)."""
        lo, hi = validate.bounds(bounds)
        extent = np.subtract(hi, lo)
        if (resolution is None) == (voxel_size is None):
            raise ValueError("give one of resolution (voxels along the longest side) or "
                             "voxel_size")
        if voxel_size is not None:
            size = validate.voxel_size(voxel_size)
            sizes = size if isinstance(size, tuple) else (size,) * 3
            shape = tuple(_whole_voxels(e, h, a) for e, h, a in zip(extent, sizes, "xyz"))
            return cls(lo, tuple(float(h) for h in sizes), shape)
        res = validate.resolution(resolution, MAX_RESOLUTION)
        if isinstance(res, tuple):
            return cls(lo, tuple(float(e / n) for e, n in zip(extent, res)), res)
        longest = int(np.argmax(extent))
        pitch = float(extent[longest] / res)
        shape = tuple(res if a == longest else _whole_voxels(e, pitch, "xyz"[a])
                      for a, e in enumerate(extent))
        return cls(lo, (pitch,) * 3, shape)

    @property
    def cubic(self) -> bool:
        """Are the voxels cubes?"""
        return len(set(self.voxel_size)) == 1

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

    def coarser(self, levels: int) -> "Grid":
        """The grid whose voxels are ``2**levels`` of this one's per axis (same origin;
        it covers this grid, reaching past it where a side is not a multiple)."""
        f = 1 << levels
        return Grid(self.origin, tuple(h * f for h in self.voxel_size),
                    tuple(-(-n // f) for n in self.shape))

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


def grid_of(shape_bounds: Any, bounds: Any, resolution: Any, voxel_size: Any,
            what: str = "the shape") -> Grid:
    """The grid of a run: over ``bounds``, or over the shape's own bounds padded
    by the one rule (:func:`implicitvox.octree.grid.padded_bounds`); cubic
    voxels unless ``resolution`` or ``voxel_size`` is given per axis.
    ``resolution`` defaults to 256 when neither is given."""
    if resolution is None and voxel_size is None:
        resolution = 256
    if resolution is not None and voxel_size is not None:
        raise ValueError("give resolution or voxel_size, not both")
    if bounds is None:
        if shape_bounds is None:
            raise ValueError(f"bounds is required: {what} has no bounds of its own; pass "
                             "bounds=((x0, y0, z0), (x1, y1, z1))")
        bounds = padded_bounds(shape_bounds, resolution, voxel_size)
    return Grid.from_bounds(bounds, resolution, voxel_size)
