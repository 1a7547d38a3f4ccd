"""Morton (Z-order) codes of integer voxel coordinates, vectorized.

Bit ``3l`` of a code is bit ``l`` of ``i`` (x), bit ``3l+1`` of ``j`` (y) and
bit ``3l+2`` of ``k`` (z): the child slot of an octant is
``x + 2y + 4z``, as in Stolte's octree (§5.1, Fig. 9). Coordinates have at
most :data:`MAX_BITS` bits, so octrees are at most 21 levels deep.

Examples
--------
>>> import numpy as np
>>> from implicitvox.octree.morton import encode, decode
>>> codes = encode(np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [3, 5, 7]]))
>>> codes.tolist()
[1, 2, 4, 431]
>>> decode(codes).tolist()[-1]
[3, 5, 7]
"""
from __future__ import annotations

import numpy as np
from .. import batches

__all__ = ["encode", "decode", "MAX_BITS", "CORNERS", "NEIGHBOURS"]

MAX_BITS = 21
#: the 8 corners (or child octants) of a box in child-slot order: row ``c`` is
#: ``(c & 1, (c >> 1) & 1, (c >> 2) & 1)``, 1 meaning the high end on that axis
CORNERS = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=np.int64)
#: offsets to the 26 cells that share a face, an edge or a corner with a cell
NEIGHBOURS = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)
                       if (i, j, k) != (0, 0, 0)], dtype=np.int64)
CORNERS.flags.writeable = False
_U = np.uint64
_SPREAD = [(32, 0x1F00000000FFFF), (16, 0x1F0000FF0000FF), (8, 0x100F00F00F00F00F),
           (4, 0x10C30C30C30C30C3), (2, 0x1249249249249249)]


def _spread(v: np.ndarray) -> np.ndarray:
    v = v.astype(_U) & _U(0x1FFFFF)
    for shift, mask in _SPREAD:
        v = (v | (v << _U(shift))) & _U(mask)
    return v


def _compact(v: np.ndarray) -> np.ndarray:
    v = v & _U(0x1249249249249249)
    for (shift, _), (_, mask) in zip(reversed(_SPREAD), reversed([(0, 0x1FFFFF)] + _SPREAD[:-1])):
        v = (v ^ (v >> _U(shift))) & _U(mask)
    return v


_BLOCK = batches.MORTON


def encode(coords: np.ndarray) -> np.ndarray:
    """Morton codes (uint64) of non-negative integer coordinates, shape (n, 3)."""
    coords = np.asarray(coords)
    out = np.empty(coords.shape[0], dtype=_U)
    for s in range(0, coords.shape[0], _BLOCK):
        c = coords[s:s + _BLOCK]
        out[s:s + _BLOCK] = (_spread(c[:, 0]) | (_spread(c[:, 1]) << _U(1))
                             | (_spread(c[:, 2]) << _U(2)))
    return out


def decode(codes: np.ndarray) -> np.ndarray:
    """Integer coordinates (int64, shape (n, 3)) of Morton codes."""
    codes = np.asarray(codes, dtype=_U)
    out = np.empty((codes.shape[0], 3), dtype=np.int64)
    for s in range(0, codes.shape[0], _BLOCK):
        block = codes[s:s + _BLOCK]
        for axis in range(3):
            out[s:s + _BLOCK, axis] = _compact(block >> _U(axis)).astype(np.int64)
    return out
