"""The pilot run: a subdivision's surface voxels estimated before it starts.

A coarse subdivision of the same function (at :func:`pilot_depth_for`, 64³
by default) counts its AMBIGUOUS octants and extrapolates to the grid's depth.
A surface meets about 4 times as many octants at each finer level (Stolte
§4.1.3, Fig. 6); a function whose detail is finer than the pilot's octants
(``sin(1000x) sin(1000y) sin(1000z)``) fills them, and its count grows by up
to 8 per level. The pilot therefore measures the growth ``g`` between its last
two levels (its AMBIGUOUS octants per AMBIGUOUS parent, clamped to Stolte's 4
below and to 8, every child, above). Where the pilot's octants are nearly all
full (``g`` of at least :data:`FILLING`) it extrapolates with ``g``; else the
excess over 4 comes from what the coarse octants blur (thin strokes resolving,
the second-order overestimate of the intervals), which fades as the octants
shrink: it is halved at each finer level, ``4 + (g - 4) / 2^(k+1)`` at the
k-th (measured on the benchmarks' models, ``tests/benchmarks/bench_estimate.py``:
a constant ``g`` overestimated thin lettering 2.8×, the halving 1.2×). Every
producer that subdivides an expression (``voxelize``, ``mesh``,
``distance_field``) estimates with this one function, and its refusal quotes
how (:meth:`Estimate.explained`).

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z, sin
>>> from implicitvox.octree.grid import Grid
>>> from implicitvox.octree.pilot import estimate_surface
>>> sphere = estimate_surface(iv.compile(x**2 + y**2 + z**2 - 1),
...                           Grid.from_bounds(((-1.1,) * 3, (1.1,) * 3), 256))
>>> sphere.pilot_depth, sphere.growth
(6, 4.0)
>>> dense = estimate_surface(iv.compile(sin(1000 * x) * sin(1000 * y) * sin(1000 * z)),
...                          Grid.from_bounds(((-1,) * 3, (1,) * 3), 256))
>>> dense.growth, dense.voxels == 256 ** 3
(8.0, True)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from ..eval.function import Function
from .grid import Grid
from .subdivide import subdivide

__all__ = ["Estimate", "estimate_surface", "pilot_depth_for", "extrapolate", "PILOT_DEPTH",
           "PILOT_BELOW", "LEAST_GROWTH", "MOST_GROWTH", "FILLING"]

#: the pilot's depth (64³), at most
PILOT_DEPTH = 6
#: ...and at least this many levels coarser than the grid (a sixteenth of its voxels)
PILOT_BELOW = 2
#: octants per level a surface grows by (Stolte §4.1.3): the least growth extrapolated
LEAST_GROWTH = 4.0
#: every child of every octant: the most
MOST_GROWTH = 8.0
#: a measured growth from which the pilot's octants count as filled (no fading excess)
FILLING = 7.5


@dataclass(frozen=True)
class Estimate:
    """A pilot's estimate of the surface voxels on a grid."""

    #: surface voxels expected on the grid (at most its voxels)
    voxels: int
    #: the pilot's depth and the AMBIGUOUS octants it found there
    pilot_depth: int
    found: int
    #: the growth per level the pilot measured (module docstring: how it is extrapolated)
    growth: float

    def explained(self) -> str:
        """How the estimate was made, for a refusal's message."""
        side = 1 << self.pilot_depth
        return (f"~{self.voxels:,} surface voxels, estimated from {self.found:,} at a "
                f"{side}³ pilot growing {self.growth:.1f}× per level")


def extrapolate(found: int, growth: float, levels: int) -> float:
    """The count ``levels`` levels below a pilot that found ``found`` octants growing
    ``growth`` per level (module docstring).

    >>> extrapolate(100, 4.0, 2), extrapolate(100, 8.0, 2), extrapolate(100, 6.0, 2)
    (1600.0, 6400.0, 2250.0)
    """
    count = float(found)
    for k in range(levels):
        count *= growth if growth >= FILLING else \
            LEAST_GROWTH + (growth - LEAST_GROWTH) / 2.0 ** (k + 1)
    return count


def pilot_depth_for(depth: int) -> int:
    """The depth of the pilot of a grid of ``depth`` levels: :data:`PILOT_DEPTH`
    (64³), and at least :data:`PILOT_BELOW` levels coarser than the grid, so that
    the estimate costs little beside the run even on small grids; the whole grid
    only when it has 2 levels or fewer."""
    return max(min(depth, 2), min(PILOT_DEPTH, depth - PILOT_BELOW))


def estimate_surface(func: Function, grid: Grid, *, prune: bool = True,
                     exact: Optional[Any] = None) -> Estimate:
    """The surface voxels of ``func`` on ``grid``, from a pilot subdivision
    (module docstring). ``exact``: the shape's exact box test, if it has one (a
    tighter pilot). No sub-voxel recheck: the pilot is cheaper, and its count
    an upper estimate."""
    depth = grid.depth
    pilot_depth = pilot_depth_for(depth)
    codes = subdivide(func, grid.coarser(depth - pilot_depth), recheck=0.0, prune=prune,
                      exact=exact).codes
    found = len(codes)
    levels = depth - pilot_depth
    growth = LEAST_GROWTH
    if levels and pilot_depth >= 1 and found:
        parents = len(np.unique(np.asarray(codes, dtype=np.uint64) >> np.uint64(3)))
        growth = min(MOST_GROWTH, max(LEAST_GROWTH, found / parents))
    cells = float(np.prod(grid.shape, dtype=np.float64))
    voxels = int(min(extrapolate(found, growth, levels), cells))
    return Estimate(voxels, pilot_depth, found, float(growth))
