"""Which float type the subdivision's interval evaluation runs in.

numpy's float32 loops do twice the work per instruction of its float64 ones,
and its float32 ``sin``, ``cos`` and ``arctan2`` are vectorized (float64
``sin`` and ``cos`` call scalar libm): a tape evaluates about 3 times faster
in float32. libfive and Fidget evaluate their intervals in single precision
for the same reason. Outward rounding makes it as safe as float64 (the same
kernels, widened by float32 ulps, :data:`rounding.LIMITS`); it only costs
tightness where float32's 2**-24 is not small against a voxel, so
:func:`interval_dtype` picks it only where

* every instruction of the tape is one whose kernel handles float32
  (:data:`FLOAT32_OPS`), with its parameters exact in float32 (a constant
  operand that is not, such as 0.1, becomes an interval of two float32s), and
* the boxes themselves lose little: rounding a corner to float32 moves it by
  at most ``2**-24 |x|``, which must stay below 1/1024 of the box (so the
  choice is made per octree level, by the size of its boxes).

Examples
--------
>>> from implicitvox import compile
>>> from implicitvox.examples import sinsin
>>> from implicitvox.grid import Grid
>>> shape = sinsin(3, 4)
>>> tape = compile(shape.expr).tape
>>> interval_dtype(tape, Grid.from_bounds(shape.bounds, 1024)).name
'float32'
>>> interval_dtype(tape, Grid.from_bounds(((1e4, 0, 0), (1e4 + 1, 1, 1)), 1024)).name
'float64'
"""
from __future__ import annotations

import numpy as np

from .grid import Grid
from .tape import Tape

__all__ = ["FLOAT32_OPS", "interval_dtype", "supports_float32", "level_dtype",
           "exact_in_float32", "float32_bounds", "outward_float32"]

#: opcodes whose interval kernels are float32-aware (their rounding and constants)
FLOAT32_OPS = frozenset({
    "add", "sub", "neg", "mul", "square", "sqrt", "abs", "min", "max", "sin", "cos",
    "exp", "atan2", "hypot", "radius", "elevation", "periodic_angle", "distance",
    "addc", "rsubc", "mulc",
})
#: operations whose scalar parameter becomes an interval when float32 cannot hold it
CONSTANT_OPERAND = frozenset({"addc", "rsubc", "mulc"})
#: a voxel must be at least this many float32 spacings of the largest coordinate
VOXEL_IN_ULPS = 1024


def exact_in_float32(value: float) -> bool:
    """Does float32 hold ``value`` exactly (finite)?"""
    v = float(value)
    return _in_range(v) and float(np.float32(v)) == v


def float32_bounds(value: float) -> tuple[np.float32, np.float32]:
    """The nearest float32s below and above ``value`` (equal when exact)."""
    v = float(value)
    near = np.float32(v)
    lo = near if float(near) <= v else np.nextafter(near, np.float32(-np.inf))
    hi = near if float(near) >= v else np.nextafter(near, np.float32(np.inf))
    return np.float32(lo), np.float32(hi)


#: constants beyond this magnitude keep a tape in float64 (float32 ends at 3.4e38)
LARGEST_CONSTANT = 1e30


def _in_range(value: float) -> bool:
    return bool(np.isfinite(value)) and abs(float(value)) <= LARGEST_CONSTANT


def _params_fit(op: str, param) -> bool:
    if op == "periodic_angle":
        _, k, c = param
        return exact_in_float32(k) and exact_in_float32(c)
    if op == "distance":
        return all(exact_in_float32(c) for c in param)
    if op in CONSTANT_OPERAND:
        return _in_range(param)
    return True


def supports_float32(tape: Tape) -> bool:
    """Can every instruction of ``tape`` run in float32 (see the module)?"""
    if tape.undefined or not all(_in_range(c.lo) and _in_range(c.hi) for c in tape.constants):
        return False
    return all(ins.op.name in FLOAT32_OPS and _params_fit(ins.op.name, ins.param)
               for ins in tape.instructions)


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


_MAX32 = float(np.finfo(np.float32).max)


def outward_float32(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """float32 arrays ``lo32 <= lo`` and ``hi32 >= hi``, at most 2 float32s outward.

    Each end moves out by ``2**-23 |v| + 2**-149`` in float64 first, more than
    the half float32 spacing that the nearest conversion can move it back.
    """
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    lo32 = (lo - (np.abs(lo) * 2.0 ** -23 + 2.0 ** -149)).astype(np.float32)
    hi32 = (hi + (np.abs(hi) * 2.0 ** -23 + 2.0 ** -149)).astype(np.float32)
    # beyond float32's range: +inf is no lower bound of a finite value (nor -inf an upper)
    return np.fmin(lo32, np.float32(_MAX32)), np.fmax(hi32, np.float32(-_MAX32))
