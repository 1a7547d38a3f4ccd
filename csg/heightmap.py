"""Heightmaps (OpenSCAD's ``surface``): a ``.dat`` table of numbers or a PNG image, as
the closed mesh OpenSCAD 2021.01 builds from it (``SurfaceNode::createGeometry``).

* A ``.dat`` file holds rows of numbers separated by spaces or tabs; blank lines
  and lines starting with ``#`` are skipped; row ``i``, column ``j`` is the
  height at ``(j, i)``. A missing entry of a short row is 0, as OpenSCAD's
  table gives it (and, as in OpenSCAD, it does not lower the bottom).
* A PNG image (read with imageio, which scikit-image brings) gives each pixel
  the height ``100 / 255 · (0.2126 R + 0.7152 G + 0.0722 B)`` of its 8-bit
  channels, or ``100 / 255 · (1 − that sum)`` with ``invert`` (as OpenSCAD
  2021.01 computes it: the inverted heights are negative); the image's top row
  is at the largest y.
* Each cell becomes four triangles meeting at its centre (at the mean of its
  corners' heights); the four sides go down to the bottom, at
  ``min(0, lowest height − 1)``, which closes the mesh. ``center`` puts the
  table's middle at the origin in x and y.

Examples
--------
>>> import os, tempfile
>>> path = os.path.join(tempfile.mkdtemp(), "hill.dat")
>>> with open(path, "w") as out:
...     _ = out.write("# a hill\\n1 2 1\\n2 4 2\\n1 2 1\\n")
>>> v, f = heightmap_mesh(path)
>>> v.min(axis=0).tolist(), v.max(axis=0).tolist(), len(f)
([0.0, 0.0, 0.0], [2.0, 2.0, 4.0], 40)
"""
from __future__ import annotations

import os
from typing import Any

import numpy as np

__all__ = ["read_heights", "heightmap_mesh", "MAX_SAMPLES"]

#: heights a table or image may hold (a 4,096 x 4,096 image: 32 million triangles)
MAX_SAMPLES = 1 << 24
_PNG = b"\x89PNG\r\n\x1a\n"


def read_heights(path: Any, invert: bool = False) -> np.ndarray:
    """The table of heights (rows by columns) of a ``.dat`` file or PNG image, as
    OpenSCAD 2021.01 reads it (``invert`` applies to images only, as in OpenSCAD).

    Raises
    ------
    ValueError
        The file holds a value that is not a number, or over :data:`MAX_SAMPLES`
        heights, or an image that cannot be decoded (naming the file).
    """
    return _heights_and_lowest(path, invert)[0]


def _heights_and_lowest(path: Any, invert: bool) -> tuple[np.ndarray, float]:
    """:func:`read_heights`, and the lowest height the file gives (a short row's missing
    entries are 0 in the table, but OpenSCAD's bottom comes from the given ones)."""
    name = os.fspath(path)
    with open(name, "rb") as stream:
        head = stream.read(8)
    if head == _PNG:
        heights = _png_heights(name, invert)
        return heights, float(heights.min()) if heights.size else 0.0
    rows = []
    count = 0
    with open(name, encoding="utf-8", errors="replace") as stream:
        for number, line in enumerate(stream, start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            try:
                row = [float(token) for token in line.replace("\t", " ").split()]
            except ValueError:
                raise ValueError(f"{name}:{number}: not a number in {line[:40]!r}") from None
            count += len(row)
            if count > MAX_SAMPLES:
                raise ValueError(f"{name}: over {MAX_SAMPLES:,} heights "
                                 "(csg.heightmap.MAX_SAMPLES)")
            rows.append(row)
    columns = max((len(r) for r in rows), default=0)
    table = np.zeros((len(rows), columns))
    for i, row in enumerate(rows):
        table[i, :len(row)] = row
    return table, min((min(r) for r in rows if r), default=0.0)


def _png_heights(name: str, invert: bool) -> np.ndarray:
    import imageio.v3 as iio
    try:
        meta = iio.improps(name)
        if int(np.prod(meta.shape[:2])) > MAX_SAMPLES:
            raise ValueError(f"{name}: over {MAX_SAMPLES:,} pixels (csg.heightmap.MAX_SAMPLES)")
        image = np.asarray(iio.imread(name))
    except ValueError:
        raise
    except Exception as err:                      # imageio's decoders raise many kinds
        raise ValueError(f"{name}: cannot read the PNG image ({type(err).__name__}: "
                         f"{err})") from None
    if image.dtype == np.uint16:                  # lodepng keeps the high byte of 16 bits
        image = (image >> 8).astype(np.uint8)
    image = image.astype(np.float64)
    if image.ndim == 2:
        rgb = np.repeat(image[:, :, None], 3, axis=2)
    elif image.shape[2] in (1, 2):                # grey (and alpha)
        rgb = np.repeat(image[:, :, :1], 3, axis=2)
    else:
        rgb = image[:, :, :3]
    pixel = 0.2126 * rgb[:, :, 0] + 0.7152 * rgb[:, :, 1] + 0.0722 * rgb[:, :, 2]
    heights = 100.0 / 255 * (1 - pixel if invert else pixel)
    return heights[::-1]                          # the top row at the largest y


def heightmap_mesh(path: Any, center: bool = False, invert: bool = False
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The closed triangle mesh OpenSCAD 2021.01's ``surface`` makes of a file:
    vertices (n, 3) and outward-facing triangles (m, 3).

    Raises
    ------
    ValueError
        As :func:`read_heights`, or a table smaller than 2 x 2 (no area).
    """
    heights, lowest = _heights_and_lowest(path, invert)
    lines, columns = heights.shape if heights.size else (0, 0)
    if lines < 2 or columns < 2:
        raise ValueError(f"{os.fspath(path)}: {lines} x {columns} heights span no area "
                         "(at least 2 x 2)")
    bottom = min(0.0, lowest - 1)         # of the given heights, not a short row's zeros
    ox = -(columns - 1) / 2.0 if center else 0.0
    oy = -(lines - 1) / 2.0 if center else 0.0
    jj, ii = np.meshgrid(np.arange(columns, dtype=np.float64), np.arange(lines, dtype=np.float64))
    grid = np.stack([ox + jj, oy + ii, heights], axis=-1).reshape(-1, 3)
    centre_h = (heights[:-1, :-1] + heights[:-1, 1:] + heights[1:, :-1] + heights[1:, 1:]) / 4
    cj, ci = np.meshgrid(np.arange(columns - 1) + 0.5, np.arange(lines - 1) + 0.5)
    centres = np.stack([ox + cj, oy + ci, centre_h], axis=-1).reshape(-1, 3)
    base = len(grid)
    i, j = np.meshgrid(np.arange(1, lines), np.arange(1, columns), indexing="ij")
    i, j = i.ravel(), j.ravel()
    v1, v2 = (i - 1) * columns + (j - 1), (i - 1) * columns + j
    v3, v4 = i * columns + (j - 1), i * columns + j
    vx = base + (i - 1) * (columns - 1) + (j - 1)
    top = np.concatenate([np.stack(t, axis=1) for t in
                          ((v1, v2, vx), (v2, v4, vx), (v4, v3, vx), (v3, v1, vx))])
    # the rim, down to the bottom: the grid's border points and their feet
    ring = np.concatenate([np.arange(columns - 1), (columns - 1) + columns * np.arange(lines - 1),
                           (lines - 1) * columns + np.arange(columns - 1, 0, -1),
                           columns * np.arange(lines - 1, 0, -1)])
    feet_start = base + len(centres)
    feet = grid[ring].copy()
    feet[:, 2] = bottom
    k = np.arange(len(ring))
    nxt = (k + 1) % len(ring)
    sides = np.concatenate([np.stack([ring[k], ring[nxt], feet_start + nxt], axis=1),
                            np.stack([ring[k], feet_start + nxt, feet_start + k], axis=1)])
    middle = feet_start + len(ring)
    floor = np.stack([feet_start + k, feet_start + nxt, np.full(len(k), middle)], axis=1)
    centre_of_floor = np.array([[ox + (columns - 1) / 2, oy + (lines - 1) / 2, bottom]])
    vertices = np.concatenate([grid, centres, feet, centre_of_floor])
    faces = np.concatenate([top, sides, floor])
    return vertices, _outward(vertices, faces, ox, oy, columns, lines)


def _outward(v: np.ndarray, f: np.ndarray, ox: float, oy: float, columns: int, lines: int
             ) -> np.ndarray:
    """Drop triangles of no area and turn the rest outward: the top (a graph over
    x and y) up, the floor down, the sides away from the middle."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normal = np.cross(b - a, c - a)
    keep = np.linalg.norm(normal, axis=1) > 0
    f, normal, centroid = f[keep], normal[keep], ((a + b + c) / 3)[keep]
    middle = np.array([ox + (columns - 1) / 2, oy + (lines - 1) / 2])
    away = centroid[:, :2] - middle
    vertical = np.abs(normal[:, 2]) <= 1e-12 * np.linalg.norm(normal, axis=1)
    is_floor = (f == len(v) - 1).any(axis=1)           # the floor's fan meets in its middle
    want = np.where(vertical, np.einsum("ij,ij->i", normal[:, :2], away),
                    np.where(is_floor, -normal[:, 2], normal[:, 2]))
    flip = want < 0
    f = f.copy()
    f[flip] = f[flip][:, ::-1]
    return f
