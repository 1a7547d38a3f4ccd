"""The narrow band, stored in bricks of 8³ samples (OpenVDB's leaf nodes).

A distance field is sampled at voxel centres (Bærentzen §2: "a voxel is a
point sample"). Only the samples near the surface are kept: the *band* of
width ``b`` holds every voxel whose index lies within ``b`` (per axis) of a
surface voxel. Since every point of the surface lies in a surface voxel
(the voxelizer misses none), a sample whose distance to the surface is at
most ``(b + 1/2)`` voxels, in either norm, is in the band.

The band is stored as the bricks that hold a band voxel: sorted Morton
codes of the bricks' indices, and per brick a ``(8, 8, 8)`` block of
samples. Finding the band is array work: each surface voxel is paired with
the bricks whose apron (the brick grown by ``b``) holds it, marked in a
stack of apron blocks, and the marks are dilated by a cube of ``2b + 1``
(three 1D maximum filters on the whole stack in one call each).

Examples
--------
>>> import numpy as np
>>> keys, active = band_bricks(np.array([[8, 8, 8]]), 1, (32, 32, 32))
>>> len(keys), int(active.sum())           # 27 band voxels over 8 bricks
(8, 27)
"""
from __future__ import annotations

import itertools

import numpy as np

from ..octree import morton

__all__ = ["BRICK", "band_bricks", "all_bricks", "brick_coords", "BrickIndex", "MAX_BAND"]

#: samples per brick edge
BRICK = 8
_BITS = 3
#: the widest band, in voxels
MAX_BAND = 64


def _pairs(surface: np.ndarray, band: int) -> tuple[np.ndarray, np.ndarray]:
    """(surface voxel row, brick index (n, 3)) for every brick whose apron holds the voxel."""
    first = (surface - band) >> _BITS
    last = (surface + band) >> _BITS
    span = int((last - first).max()) + 1 if len(surface) else 1
    rows, bricks = [], []
    for offset in itertools.product(range(span), repeat=3):
        b = first + np.asarray(offset)
        ok = np.all(b <= last, axis=1)
        rows.append(np.flatnonzero(ok))
        bricks.append(b[ok])
    return np.concatenate(rows), np.concatenate(bricks)


def band_bricks(surface: np.ndarray, band: int, shape: tuple[int, int, int]
                ) -> tuple[np.ndarray, np.ndarray]:
    """The bricks of the band around ``surface`` voxels (n, 3) on a grid of ``shape``.

    Returns
    -------
    keys : ndarray of uint64, shape (k,)
        Morton codes of the brick indices, sorted.
    active : ndarray of bool, shape (k, 8, 8, 8)
        The band's samples in each brick (inside the grid, within ``band`` of a
        surface voxel per axis).
    """
    from scipy.ndimage import maximum_filter1d
    surface = np.asarray(surface, dtype=np.int64).reshape(-1, 3)
    if not len(surface):
        return np.zeros(0, dtype=np.uint64), np.zeros((0, BRICK, BRICK, BRICK), dtype=bool)
    rows, bricks = _pairs(surface, band)
    n_bricks = -(-np.asarray(shape) // BRICK)
    ok = np.all((bricks >= 0) & (bricks < n_bricks), axis=1)
    rows, bricks = rows[ok], bricks[ok]
    codes = morton.encode(bricks)
    keys, which = np.unique(codes, return_inverse=True)
    side = BRICK + 2 * band
    marks = np.zeros((len(keys), side, side, side), dtype=np.uint8)
    local = surface[rows] - bricks * BRICK + band
    marks[which, local[:, 0], local[:, 1], local[:, 2]] = 1
    for axis in (1, 2, 3):
        marks = maximum_filter1d(marks, 2 * band + 1, axis=axis, mode="constant")
    inner = slice(band, band + BRICK)
    active = marks[:, inner, inner, inner].astype(bool)
    coords = brick_coords(keys)
    inside = coords < np.asarray(shape)[None, None, None, None, :]
    return keys, active & np.all(inside, axis=-1)


def all_bricks(shape: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Every brick of a grid of ``shape``, every sample in the grid active (a field
    everywhere)."""
    counts = -(-np.asarray(shape) // BRICK)
    idx = np.stack(np.meshgrid(*[np.arange(n) for n in counts], indexing="ij"), -1).reshape(-1, 3)
    keys = np.sort(morton.encode(idx))
    active = np.all(brick_coords(keys) < np.asarray(shape), axis=-1)
    return keys, active


def brick_coords(keys: np.ndarray) -> np.ndarray:
    """Voxel indices of every sample of the bricks ``keys``: ``(k, 8, 8, 8, 3)``."""
    origins = morton.decode(np.asarray(keys, dtype=np.uint64)).astype(np.int64) * BRICK
    local = np.stack(np.meshgrid(*[np.arange(BRICK)] * 3, indexing="ij"), axis=-1)
    return origins[:, None, None, None, :] + local[None]


class BrickIndex:
    """Finds samples in sorted bricks: voxel indices to ``(brick, i, j, k)``."""

    def __init__(self, keys: np.ndarray):
        self.keys = np.asarray(keys, dtype=np.uint64)

    def locate(self, coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For voxel indices (n, 3): the brick of each (``-1`` where no brick holds
        it) and the offsets (n, 3) within it."""
        coords = np.asarray(coords, dtype=np.int64)
        outside = np.any(coords < 0, axis=1)
        brick = np.where(outside[:, None], 0, coords >> _BITS)
        codes = morton.encode(brick)
        at = np.searchsorted(self.keys, codes)
        at = np.minimum(at, max(len(self.keys) - 1, 0))
        found = ~outside & (len(self.keys) > 0)
        if len(self.keys):
            found &= self.keys[at] == codes
        return np.where(found, at, -1), coords & (BRICK - 1)
