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
def _window_any(src, n, width, dst):
    """``dst[i] = any(src[i:i + width])`` for ``i < n`` (a running count)."""
    count = 0
    for x in range(width - 1):
        count += src[x]
    for i in range(n):
        count += src[i + width - 1]
        dst[i] = count > 0
        count -= src[i]


@njit(**COMPILE)
def band_samples(bricks, candidates, start, voxels, band, shape, active):
    """The band's samples of each candidate brick into ``active`` (c, 8, 8, 8): those
    inside the grid ``shape`` within ``band`` (per axis) of a surface voxel.

    ``bricks`` (sorted codes) are the bricks holding surface voxels, brick
    ``u``'s voxels are ``voxels[start[u]:start[u + 1]]``; ``candidates`` (c, 3)
    are brick indices. Each candidate marks the surface voxels in its apron (the
    brick grown by ``band``) and dilates the marks by ``2 band + 1`` along each
    axis in turn (the window's running count along each line)."""
    side = BRICK + 2 * band
    reach = (band + BRICK - 1) // BRICK
    marks = np.zeros((side, side, side), dtype=np.int64)
    line = np.zeros(side, dtype=np.int64)
    out = np.zeros(BRICK, dtype=np.bool_)
    along_x = np.zeros((BRICK, side, side), dtype=np.int64)
    along_y = np.zeros((BRICK, BRICK, side), dtype=np.int64)
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
                            marks[x, y, z] = 1
                            lit[y, z] = True
                            any_mark = True
        if not any_mark:
            continue
        along_x[:] = 0
        for y in range(side):                 # along x, on the lines that hold a mark
            for z in range(side):
                if not lit[y, z]:
                    continue
                for x in range(side):
                    line[x] = marks[x, y, z]
                    marks[x, y, z] = 0
                _window_any(line, BRICK, 2 * band + 1, out)
                for i in range(BRICK):
                    along_x[i, y, z] = out[i]
                lit[y, z] = False
        for i in range(BRICK):                # along y
            for z in range(side):
                _window_any(along_x[i, :, z], BRICK, 2 * band + 1, out)
                for j in range(BRICK):
                    along_y[i, j, z] = out[j]
        for i in range(BRICK):                # along z, inside the grid
            for j in range(BRICK):
                _window_any(along_y[i, j], BRICK, 2 * band + 1, out)
                for k in range(BRICK):
                    active[c, i, j, k] = out[k] and ci * BRICK + i < shape[0] and \
                        cj * BRICK + j < shape[1] and ck * BRICK + k < shape[2]
