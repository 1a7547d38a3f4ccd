"""Compiled loops over bricks: Morton codes of brick indices, the band's samples.

Examples
--------
>>> int(brick_code(1, 0, 0)), int(brick_code(0, 1, 0)), int(brick_code(3, 5, 7))
(1, 2, 431)
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from ..octree.morton_kernels import encode_one

__all__ = ["brick_code", "brick_row", "band_samples", "BRICK"]

#: samples per brick edge (as :data:`implicitvox.fields.bricks.BRICK`)
BRICK = 8
#: :func:`implicitvox.octree.morton.encode` of one index ``(i, j, k)``
brick_code = encode_one


@njit(**COMPILE)
def brick_row(keys, i, j, k):
    """The row of brick ``(i, j, k)`` in the sorted codes ``keys``, or -1."""
    if i < 0 or j < 0 or k < 0:
        return -1
    code = brick_code(i, j, k)
    at = np.searchsorted(keys, code)
    return at if at < keys.size and keys[at] == code else -1


@njit(**COMPILE)
def band_samples(bricks, candidates, start, voxels, band, shape, steps):
    """The band's samples of each candidate brick into ``steps`` (c, 8, 8, 8): each
    sample's Chebyshev distance, in voxels, to the nearest surface voxel where it is
    at most ``band`` and the sample lies inside the grid ``shape``, else ``band + 1``.

    ``bricks`` (sorted codes) are the bricks holding surface voxels, brick
    ``u``'s voxels are ``voxels[start[u]:start[u + 1]]``; ``candidates`` (c, 3)
    are brick indices. Each candidate marks the surface voxels in its apron (the
    brick grown by ``band``), then takes the distance along x to the nearest mark,
    and along y and z in turn the least ``max(|offset|, distance so far)`` within
    ``band`` (the max-norm distance transform, separable)."""
    side = BRICK + 2 * band
    far = band + 1
    reach = (band + BRICK - 1) // BRICK
    marks = np.zeros((side, side, side), dtype=np.bool_)
    along_x = np.empty((BRICK, side, side), dtype=np.int64)        # (x, z, y)
    plane = np.zeros(side, dtype=np.bool_)                            # z with a mark
    along_y = np.empty((BRICK, BRICK, side), dtype=np.int64)
    lit = np.zeros((side, side), dtype=np.bool_)
    for c in range(candidates.shape[0]):
        ci, cj, ck = candidates[c, 0], candidates[c, 1], candidates[c, 2]
        base = np.array([ci * BRICK - band, cj * BRICK - band, ck * BRICK - band])
        any_mark = False
        for di in range(-reach, reach + 1):
            for dj in range(-reach, reach + 1):
                for dk in range(-reach, reach + 1):
                    u = brick_row(bricks, ci + di, cj + dj, ck + dk)
                    if u < 0:
                        continue
                    for v in range(start[u], start[u + 1]):
                        x = voxels[v, 0] - base[0]
                        y = voxels[v, 1] - base[1]
                        z = voxels[v, 2] - base[2]
                        if 0 <= x < side and 0 <= y < side and 0 <= z < side:
                            marks[x, y, z] = True
                            lit[y, z] = True
                            any_mark = True
        steps[c] = far
        if not any_mark:
            continue
        # along x, on the lines that hold a mark: the distance to the nearest mark (two
        # sweeps), capped at far
        along_x[:] = far
        plane[:] = False
        for y in range(side):
            for z in range(side):
                if not lit[y, z]:
                    continue
                lit[y, z] = False
                plane[z] = True
                last = -side
                for x in range(BRICK + band):
                    if marks[x, y, z]:
                        last = x
                    if x >= band:
                        along_x[x - band, z, y] = min(far, x - last)
                last = 2 * side
                for x in range(side - 1, band - 1, -1):
                    if marks[x, y, z]:
                        last = x
                        marks[x, y, z] = False
                    if x < band + BRICK:
                        along_x[x - band, z, y] = min(along_x[x - band, z, y], last - x)
                for x in range(band):
                    marks[x, y, z] = False
        # along y, then z: min(far, max(|d|, line[at + d])) over |d| <= band
        for i in range(BRICK):
            for z in range(side):
                for j in range(BRICK):
                    least = far
                    if plane[z]:
                        for d in range(2 * band + 1):
                            least = min(least, max(abs(d - band), along_x[i, z, j + d]))
                    along_y[i, j, z] = least
        for i in range(BRICK):                # along z, inside the grid
            for j in range(BRICK):
                inside = ci * BRICK + i < shape[0] and cj * BRICK + j < shape[1]
                for k in range(BRICK):
                    if not (inside and ck * BRICK + k < shape[2]):
                        continue
                    least = far
                    for d in range(2 * band + 1):
                        least = min(least, max(abs(d - band), along_y[i, j, k + d]))
                    steps[c, i, j, k] = least
