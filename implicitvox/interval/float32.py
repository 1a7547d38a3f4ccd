"""Float32 interval ends: conversions rounded outward, and what float32 holds exactly.

The subdivision evaluates intervals in float32 where that loses nothing
visible (:mod:`implicitvox.eval.float32_tapes`, :mod:`implicitvox.octree.level_dtype`);
these are the conversions it needs, each rounded in a stated direction.

Examples
--------
>>> from implicitvox.interval.float32 import exact_in_float32, float32_bounds
>>> exact_in_float32(0.5), exact_in_float32(0.1)
(True, False)
>>> [float(b) for b in float32_bounds(0.1)]
[0.09999999403953552, 0.10000000149011612]
"""
from __future__ import annotations

import numpy as np

__all__ = ["exact_in_float32", "float32_bounds", "outward_float32", "in_float32_range",
           "LARGEST_CONSTANT"]

#: constants beyond this magnitude keep a tape in float64 (float32 ends at 3.4e38)
LARGEST_CONSTANT = 1e30


def in_float32_range(value: float) -> bool:
    """Is ``value`` finite and at most :data:`LARGEST_CONSTANT` in magnitude?"""
    return bool(np.isfinite(value)) and abs(float(value)) <= LARGEST_CONSTANT


def exact_in_float32(value: float) -> bool:
    """Does float32 hold ``value`` exactly (finite)?"""
    v = float(value)
    return in_float32_range(v) and float(np.float32(v)) == v


def float32_bounds(value: float) -> tuple[np.float32, np.float32]:
    """The nearest float32s below and above ``value`` (equal when exact)."""
    v = float(value)
    near = np.float32(v)
    lo = near if float(near) <= v else np.nextafter(near, np.float32(-np.inf))
    hi = near if float(near) >= v else np.nextafter(near, np.float32(np.inf))
    return np.float32(lo), np.float32(hi)


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
