"""The narrow band, stored in bricks of 8³ samples (OpenVDB's leaf nodes).

A distance field is sampled at voxel centres (Bærentzen §2: "a voxel is a
point sample"). Only the samples near the surface are kept: the *band* of
width ``b`` holds every voxel whose index lies within ``b`` (per axis) of a
surface voxel. Since every point of the surface lies in a surface voxel
(the voxelizer misses none), a sample whose distance to the surface is at
most ``(b + 1/2)`` voxels, in either norm, is in the band.

The band is stored as the bricks that hold a band voxel: sorted Morton
codes of the bricks' indices, and per brick a ``(8, 8, 8)`` block of
samples. Finding the band is compiled (:func:`implicitvox.fields.brick_kernels.band_samples`):
the bricks near a brick holding surface voxels are the candidates; each
marks the surface voxels in its apron (the brick grown by ``b``) and takes
each sample's max-norm distance to the marks, in index steps, one axis at a
time (:func:`band_steps`; the band's samples are those at most ``b`` steps
away); those left with a sample are the band's.

Examples
--------
>>> import numpy as np
>>> keys, active = band_bricks(np.array([[8, 8, 8]]), 1, (32, 32, 32))
>>> len(keys), int(active.sum())           # 27 band voxels over 8 bricks
(8, 27)
"""
from __future__ import annotations

import numpy as np

from ..octree import morton

__all__ = ["BRICK", "band_bricks", "band_steps", "all_bricks", "brick_coords", "masked_coords",
           "in_grid", "BrickIndex", "MAX_BAND"]

#: samples per brick edge
BRICK = 8
_BITS = 3
#: the widest band, in voxels
MAX_BAND = 64


def band_bricks(surface: np.ndarray, band: int, shape: tuple[int, int, int]
                ) -> tuple[np.ndarray, np.ndarray]:
    """The bricks of the band around ``surface`` voxels (n, 3) on a grid of ``shape``.

    Returns
    -------
    keys : ndarray of uint64, shape (k,)
        Morton codes of the brick indices, sorted.
    active : ndarray of bool, shape (k, 8, 8, 8)
        The band's samples in each brick (inside the grid, within ``band`` of a
        surface voxel per axis); every brick holds one.
    """
    keys, steps = band_steps(surface, band, shape)
    return keys, steps <= band


def band_steps(surface: np.ndarray, band: int, shape: tuple[int, int, int]
               ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`band_bricks` with, per sample, its distance in voxels to the surface voxels.

    Returns
    -------
    keys : ndarray of uint64, shape (k,)
        As for :func:`band_bricks`.
    steps : ndarray of uint8, shape (k, 8, 8, 8)
        The Chebyshev distance (index steps, the largest over the axes) from each
        sample to the nearest surface voxel: 0 on the surface voxels, at most
        ``band`` on the band's samples, ``band + 1`` elsewhere. A surface point
        lies in that voxel, so it lies within ``steps + 1/2`` voxels of the
        sample along each axis: an upper bound of the sample's distance.
    """
    from .brick_kernels import band_samples        # (loads Numba: not at import)
    surface = np.asarray(surface, dtype=np.int64).reshape(-1, 3)
    if not len(surface):
        return np.zeros(0, dtype=np.uint64), np.zeros((0, BRICK, BRICK, BRICK), dtype=np.uint8)
    codes = morton.encode(surface >> _BITS)
    if np.any(codes[1:] < codes[:-1]):
        order = np.argsort(codes, kind="stable")
        codes, surface = codes[order], surface[order]
    bricks, first = np.unique(codes, return_index=True)
    start = np.append(first, len(codes)).astype(np.int64)
    # the candidates: every brick within the band's reach of a surface brick
    reach = -(-band // BRICK)
    span = np.arange(-reach, reach + 1)
    offsets = np.stack(np.meshgrid(span, span, span, indexing="ij"), -1).reshape(-1, 3)
    near = (morton.decode(bricks)[:, None, :] + offsets[None]).reshape(-1, 3)
    near = near[np.all((near >= 0) & (near < -(-np.asarray(shape) // BRICK)), axis=1)]
    keys = np.unique(morton.encode(near))
    steps = np.empty((len(keys), BRICK, BRICK, BRICK), dtype=np.uint8)
    band_samples(bricks, morton.decode(keys), start, surface, band,
                 np.asarray(shape, dtype=np.int64), steps)
    held = (steps <= band).any(axis=(1, 2, 3))
    return keys[held], steps[held]


def all_bricks(shape: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Every brick of a grid of ``shape``, every sample in the grid active (a field
    everywhere)."""
    counts = -(-np.asarray(shape) // BRICK)
    idx = np.stack(np.meshgrid(*[np.arange(n) for n in counts], indexing="ij"), -1).reshape(-1, 3)
    keys = np.sort(morton.encode(idx))
    return keys, in_grid(keys, shape)


def brick_coords(keys: np.ndarray) -> np.ndarray:
    """Voxel indices of every sample of the bricks ``keys``: ``(k, 8, 8, 8, 3)``."""
    origins = morton.decode(np.asarray(keys, dtype=np.uint64)).astype(np.int64) * BRICK
    local = np.stack(np.meshgrid(*[np.arange(BRICK)] * 3, indexing="ij"), axis=-1)
    return origins[:, None, None, None, :] + local[None]


def masked_coords(keys: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Voxel indices (n, 3) of the samples ``mask`` (k, 8, 8, 8) of the bricks ``keys``,
    brick by brick: ``brick_coords(keys)[mask]`` without the whole of it."""
    brick, i, j, k = np.nonzero(mask)
    origins = morton.decode(np.asarray(keys, dtype=np.uint64)).astype(np.int64) * BRICK
    out = origins[brick]
    out[:, 0] += i
    out[:, 1] += j
    out[:, 2] += k
    return out


def in_grid(keys: np.ndarray, shape: tuple[int, int, int]) -> np.ndarray:
    """Which samples of the bricks ``keys`` lie in a grid of ``shape``: (k, 8, 8, 8)."""
    origins = morton.decode(np.asarray(keys, dtype=np.uint64)).astype(np.int64) * BRICK
    step = np.arange(BRICK)
    inside = [origins[:, a, None] + step[None] < shape[a] for a in range(3)]
    return inside[0][:, :, None, None] & inside[1][:, None, :, None] & \
        inside[2][:, None, None, :]


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
