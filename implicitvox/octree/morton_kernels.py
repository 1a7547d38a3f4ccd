"""Morton codes of one index at a time, for compiled loops (:mod:`.morton` does arrays).

The same bit layout as :func:`implicitvox.octree.morton.encode`: bit ``3l`` of a
code is bit ``l`` of ``i``, bit ``3l + 1`` of ``j``, bit ``3l + 2`` of ``k``.

Examples
--------
>>> int(encode_one(1, 0, 0)), int(encode_one(0, 1, 0)), int(encode_one(3, 5, 7))
(1, 2, 431)
>>> int(compact(encode_one(3, 5, 7) >> 1))
5
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE

__all__ = ["spread", "encode_one", "compact"]


@njit(**COMPILE)
def spread(v):
    """The bits of ``v`` (21 at most) two places apart: one axis of a Morton code."""
    v = np.uint64(v) & np.uint64(0x1FFFFF)
    v = (v | (v << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    return (v | (v << np.uint64(2))) & np.uint64(0x1249249249249249)


@njit(**COMPILE)
def encode_one(i, j, k):
    """The Morton code (uint64) of the non-negative index ``(i, j, k)``."""
    return spread(i) | (spread(j) << np.uint64(1)) | (spread(k) << np.uint64(2))


@njit(**COMPILE)
def compact(v):
    """Every third bit of ``v`` (from bit 0), packed: one axis of a Morton code (int64)."""
    v = np.uint64(v) & np.uint64(0x1249249249249249)
    v = (v ^ (v >> np.uint64(2))) & np.uint64(0x10C30C30C30C30C3)
    v = (v ^ (v >> np.uint64(4))) & np.uint64(0x100F00F00F00F00F)
    v = (v ^ (v >> np.uint64(8))) & np.uint64(0x1F0000FF0000FF)
    v = (v ^ (v >> np.uint64(16))) & np.uint64(0x1F00000000FFFF)
    v = (v ^ (v >> np.uint64(32))) & np.uint64(0x1FFFFF)
    return np.int64(v)
