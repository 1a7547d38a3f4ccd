"""Which float type the subdivision's interval evaluation runs in, per octree level.

A tape that can run in float32 (:func:`implicitvox.eval.float32_tapes.supports_float32`)
does so at a level only where the boxes themselves lose little: rounding a
corner to float32 moves it by at most ``2**-24 |x|``, which must stay below
1/1024 of the box. The choice depends on the boxes' size, not on the grid's
resolution, so a box gets the same state in every run (``Voxels.refine``
equals a direct run).

Examples
--------
>>> from implicitvox import compile
>>> from implicitvox.expr.examples import sinsin
>>> from implicitvox.octree.grid import Grid
>>> shape = sinsin(3, 4)
>>> tape = compile(shape.expr).tape
>>> interval_dtype(tape, Grid.from_bounds(shape.bounds, 1024)).name
'float32'
>>> interval_dtype(tape, Grid.from_bounds(((1e4, 0, 0), (1e4 + 1, 1, 1)), 1024)).name
'float64'
"""
from __future__ import annotations

import numpy as np

from ..eval.float32_tapes import supports_float32
from ..eval.tape import Tape
from .grid import Grid

__all__ = ["interval_dtype", "level_dtype", "VOXEL_IN_ULPS"]

#: a voxel must be at least this many float32 spacings of the largest coordinate
VOXEL_IN_ULPS = 1024


def interval_dtype(tape: Tape, grid: Grid, level: int | None = None) -> np.dtype:
    """float32 where it is safe and loses nothing visible (see the module), else float64.

    ``level``: the octree level of the boxes (default: the voxels). The choice
    depends on the boxes' size, not on the grid's resolution, so a box gets
    the same state in every run (``Voxels.refine`` equals a direct run).
    """
    if not supports_float32(tape):
        return np.dtype(np.float64)
    return level_dtype(grid, grid.depth if level is None else level)


def level_dtype(grid: Grid, level: int) -> np.dtype:
    """float32 for octants at ``level`` if rounding their corners to float32
    moves them by at most 1/1024 of their size (for a tape that
    :func:`supports_float32`)."""
    lo, hi = grid.bounds
    largest = max(max(abs(v) for v in lo), max(abs(v) for v in hi))
    size = min(grid.voxel_size) * 2.0 ** (grid.depth - level)
    if largest > 1e30 or largest * 2.0 ** -23 * VOXEL_IN_ULPS > size:
        return np.dtype(np.float64)
    return np.dtype(np.float32)
