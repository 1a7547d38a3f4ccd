"""DXF drawings as OpenSCAD 2021.01 imports them (``import("part.dxf", layer, origin, scale)``).

`ezdxf <https://ezdxf.mozman.at>`_ reads the file (ASCII or binary, any
version); what OpenSCAD makes of its entities is reproduced here, after its
``dxfdata.cc``, so that the outline is OpenSCAD's to the last bit:

* ``LINE``, ``LWPOLYLINE`` (straight segments: bulges are ignored, as
  OpenSCAD ignores them), ``CIRCLE``, ``ARC`` and ``ELLIPSE`` become line
  segments, arcs in OpenSCAD's fragments (``$fn, $fa, $fs`` of the import;
  an arc takes ``ceil(n · sweep / 360°)`` of a full circle's ``n``), and
  ``INSERT`` places a block's segments (scaled by its x and y scale, turned by
  its rotation, then the import's ``scale``, at its insertion point; the
  block's base point is ignored, as OpenSCAD ignores it). Points are moved by
  ``-origin`` and multiplied by ``scale`` (block contents are not). Other
  entities are skipped with an :class:`~csg.openscad_parser.OpenSCADWarning`
  counting them, as OpenSCAD warns.
* Every segment end is snapped to OpenSCAD's grid of 2⁻¹⁰ units (``Grid2d``
  with ``GRID_COARSE``: to an existing point in a neighbouring cell if there
  is one), and the segments are chained into paths exactly as OpenSCAD chains
  them: open paths first (from the first segment with a free end), then
  closed ones. Open paths are closed, as OpenSCAD closes them.
* The outlines are filled even-odd (OpenSCAD sanitizes an imported polygon
  with Clipper's even-odd union): a :class:`~csg.planar.Polygon` with one
  path per outline; outlines with fewer than three distinct points or no
  area are dropped, as Clipper drops them.

Examples
--------
>>> import ezdxf, tempfile, os
>>> doc = ezdxf.new()
>>> _ = doc.modelspace().add_lwpolyline([(0, 0), (4, 0), (4, 3), (0, 3)], close=True)
>>> _ = doc.modelspace().add_circle((2, 1.5), 1, dxfattribs={"layer": "hole"})
>>> path = os.path.join(tempfile.mkdtemp(), "plate.dxf")
>>> doc.saveas(path)
>>> plate = read_dxf(path)                      # every layer: the rectangle minus the hole
>>> len(plate.paths), plate.bounds
(2, ((0.0, 0.0, 0.0), (4.0, 3.0, 0.0)))
>>> len(read_dxf(path, layer="hole").paths)
1
"""
from __future__ import annotations

import heapq
import math
import os
import warnings
from collections import Counter
from typing import Any, Optional

import numpy as np

from . import facets as fx
from .openscad_parser import OpenSCADWarning
from .planar import Polygon

__all__ = ["read_dxf", "GRID", "MAX_SEGMENTS"]

#: OpenSCAD's ``GRID_COARSE``: segment ends are snapped to multiples of it
GRID = 2.0 ** -10
#: segments a drawing may make (circles and arcs in their fragments included)
MAX_SEGMENTS = 2_000_000


def read_dxf(path: Any, layer: Optional[str] = None, origin: Any = (0.0, 0.0),
             scale: float = 1.0, fn: float = 0.0, fs: float = 2.0, fa: float = 12.0
             ) -> Optional[Polygon]:
    """The 2D region OpenSCAD 2021.01 imports from a DXF file, or None when the
    (layer of the) drawing holds no closed area.

    Parameters
    ----------
    path : str or path-like
        The ``.dxf`` file.
    layer : str, optional
        Only this layer's entities (``None`` or ``""``: all layers).
    origin : (float, float)
        Subtracted from every point of the drawing.
    scale : float
        Multiplies every point (after ``origin``).
    fn, fs, fa : float
        OpenSCAD's ``$fn, $fs, $fa`` for circles, arcs and ellipses.

    Raises
    ------
    ValueError
        The file cannot be read as DXF (naming it and ezdxf's reason), or the
        drawing makes more than :data:`MAX_SEGMENTS` segments.
    """
    import ezdxf
    from ezdxf.lldxf.const import DXFError
    name = os.fspath(path)
    try:
        doc = ezdxf.readfile(name)
    except (OSError, DXFError, UnicodeDecodeError, ValueError) as err:
        raise ValueError(f"{name}: not a readable DXF file ({type(err).__name__}: "
                         f"{str(err).splitlines()[0] if str(err) else ''})") from None
    drawing = _Drawing(name, layer or "", (float(origin[0]), float(origin[1])), float(scale),
                       (float(fn), float(fs), float(fa)))
    for block in doc.blocks:
        if not block.is_any_layout:                 # the model and paper spaces are not blocks
            drawing.read_block(block)
    drawing.read_entities(doc.modelspace())
    drawing.warn_unsupported()
    outlines = drawing.outlines()
    return _polygon(outlines)


class _Drawing:
    """OpenSCAD's ``DxfData`` under construction: points, segments, the grid."""

    def __init__(self, name: str, layer: str, origin: tuple, scale: float, resolution: tuple):
        self.name, self.layer, self.origin, self.scale = name, layer, origin, scale
        self.resolution = resolution
        self.points: list[tuple[float, float]] = []
        self.lines: list[tuple[int, int]] = []       # point indices of the entity segments
        self.blocks: dict[str, list[tuple[int, int]]] = {}
        self.grid: dict[tuple[int, int], list[int]] = {}
        self.unsupported: Counter = Counter()
        self.count = 0

    # -- the grid (OpenSCAD's Grid2d.align) ------------------------------------------------
    def align(self, x: float, y: float) -> tuple[int, int]:
        ix, iy = _round(x / GRID), _round(y / GRID)
        if (ix, iy) not in self.grid:
            best = 10
            cx, cy = ix, iy
            for jx in (ix - 1, ix, ix + 1):
                for jy in (iy - 1, iy, iy + 1):
                    if (jx, jy) in self.grid:
                        d = abs(ix - jx) + abs(iy - jy)
                        if d < best:
                            best, cx, cy = d, jx, jy
            ix, iy = cx, cy
        self.grid.setdefault((ix, iy), [])
        return ix, iy

    def add_line(self, x1: float, y1: float, x2: float, y2: float, block: Optional[str]) -> None:
        self.count += 1
        if self.count > MAX_SEGMENTS:
            raise ValueError(f"{self.name}: over {MAX_SEGMENTS:,} segments (csg.dxf.MAX_SEGMENTS)")
        cells = (self.align(x1, y1), self.align(x2, y2))
        for cell in cells:                # OpenSCAD records the next entity segment's index
            self.grid[cell].append(len(self.lines))
        first = len(self.points)
        self.points.extend((c[0] * GRID, c[1] * GRID) for c in cells)
        if block is None:
            self.lines.append((first, first + 1))
        else:
            self.blocks.setdefault(block, []).append((first, first + 1))

    # -- entities -------------------------------------------------------------------------------
    def place(self, x: float, y: float, block: Optional[str]) -> tuple[float, float]:
        """A point of an entity: moved and scaled, unless in a block."""
        if block is not None:
            return x, y
        return (x - self.origin[0]) * self.scale, (y - self.origin[1]) * self.scale

    def read_block(self, block) -> None:
        for entity in block:
            self.read(entity, block.name)

    def read_entities(self, space) -> None:
        for entity in space:
            if self.layer and entity.dxf.get("layer", "0") != self.layer:
                continue
            self.read(entity, None)

    def read(self, e, block: Optional[str]) -> None:
        kind = e.dxftype()
        fn, fs, fa = self.resolution
        if kind == "LINE":
            a = self.place(e.dxf.start.x, e.dxf.start.y, block)
            b = self.place(e.dxf.end.x, e.dxf.end.y, block)
            self.add_line(*a, *b, block)
        elif kind == "LWPOLYLINE":
            pts = [self.place(x, y, block) for x, y in e.get_points("xy")]
            for a, b in zip(pts, pts[1:]):
                self.add_line(*a, *b, block)
            if e.closed and pts:
                self.add_line(*pts[-1], *pts[0], block)
        elif kind in ("CIRCLE", "ARC"):
            cx, cy = self.place(e.dxf.center.x, e.dxf.center.y, block)
            r = e.dxf.radius * (1.0 if block is not None else self.scale)
            n = fx.fragments(r, fn, fs, fa)
            if kind == "CIRCLE":
                steps = [(2 * math.pi * i / n, 2 * math.pi * (i + 1) / n) for i in range(n)]
            else:
                start, stop = float(e.dxf.start_angle), float(e.dxf.end_angle)
                while start > stop:
                    stop += 360.0
                m = int(math.ceil(n * (stop - start) / 360))
                steps = [((start + (stop - start) * i / m) * math.pi / 180.0,
                          (start + (stop - start) * (i + 1) / m) * math.pi / 180.0)
                         for i in range(m)]
            for a1, a2 in steps:
                self.add_line(math.cos(a1) * r + cx, math.sin(a1) * r + cy,
                              math.cos(a2) * r + cx, math.sin(a2) * r + cy, block)
        elif kind == "ELLIPSE":
            self.read_ellipse(e, block)
        elif kind == "INSERT":
            self.read_insert(e, block)
        else:
            self.unsupported[kind] += 1

    def read_ellipse(self, e, block: Optional[str]) -> None:
        fn, fs, fa = self.resolution
        cx, cy = self.place(e.dxf.center.x, e.dxf.center.y, block)
        # OpenSCAD reads the major axis (a vector) as a point: moved and scaled
        ex, ey = self.place(e.dxf.major_axis.x, e.dxf.major_axis.y, block)
        start, stop = float(e.dxf.start_param), float(e.dxf.end_param)
        while start > stop:
            stop += 2 * math.pi
        r_major = math.sqrt(ex * ex + ey * ey)
        cosval = min(max(ex / r_major, -1.0), 1.0)
        rot = math.acos(cosval)
        if ey < 0.0:
            rot = 2 * math.pi - rot
        r_minor = r_major * float(e.dxf.ratio) * (1.0 if block is not None else self.scale)
        sweep = stop - start
        n = int(math.ceil(fx.fragments(r_major, fn, fs, fa) * sweep / (2 * math.pi)))
        previous = None
        for i in range(n + 1):
            a = start + sweep * i / n
            px, py = math.cos(a) * r_major, math.sin(a) * r_minor
            point = (math.cos(rot) * px - math.sin(rot) * py + cx,
                     math.sin(rot) * px + math.cos(rot) * py + cy)
            if previous is not None:
                self.add_line(*previous, *point, block)
            previous = point

    def read_insert(self, e, block: Optional[str]) -> None:
        x, y = self.place(e.dxf.insert.x, e.dxf.insert.y, block)
        sx, sy = float(e.dxf.get("xscale", 1.0)), float(e.dxf.get("yscale", 1.0))
        a = float(e.dxf.get("rotation", 0.0)) * math.pi / 180.0
        scale = self.scale           # OpenSCAD scales a block's segments by the import's scale
        for p, q in self.blocks.get(e.dxf.name, []):
            ends = []
            for k in (p, q):
                lx, ly = self.points[k][0] * sx, self.points[k][1] * sy
                ends.extend(((math.cos(a) * lx - math.sin(a) * ly) * scale + x,
                             (math.sin(a) * lx + math.cos(a) * ly) * scale + y))
            self.add_line(*ends, block)

    def warn_unsupported(self) -> None:
        for kind, count in sorted(self.unsupported.items()):
            where = f" in layer {self.layer!r}" if self.layer else ""
            warnings.warn(f"{self.name}: unsupported DXF entity {kind!r} ({count}x){where}; "
                          "skipped, as OpenSCAD does", OpenSCADWarning, stacklevel=4)

    # -- paths (OpenSCAD's chaining, open paths first) -----------------------------------------
    def cell(self, point: int) -> tuple[int, int]:
        x, y = self.points[point]
        return _round(x / GRID), _round(y / GRID)

    def outlines(self) -> list[np.ndarray]:
        lines, points = self.lines, self.points
        disabled = [False] * len(lines)
        enabled = len(lines)
        cells = [(self.cell(p), self.cell(q)) for p, q in lines]
        holders: dict[int, list[tuple[int, int]]] = {}     # line index -> cells listing it
        for key, entries in self.grid.items():
            for k in entries:
                holders.setdefault(k, []).append(key)

        def free_end(idx: int) -> Optional[int]:
            for j in (0, 1):
                if not any(k != idx and k < len(lines) and not disabled[k]
                           for k in self.grid[cells[idx][j]]):
                    return j
            return None

        def disable(idx: int) -> None:
            nonlocal enabled
            disabled[idx] = True
            enabled -= 1
            for key in holders.get(idx, ()):         # their lines may now have a free end
                for k in self.grid[key]:
                    if k < len(lines) and not disabled[k]:
                        heapq.heappush(candidates, k)

        def walk(line: int, end: int) -> list[int]:
            path = [lines[line][end]]
            while True:
                ref = lines[line][1 - end]
                path.append(ref)
                disable(line)
                key = cells[line][1 - end]
                for k in self.grid[key]:
                    if k >= len(lines) or disabled[k]:
                        continue
                    if cells[k][0] == key:
                        line, end = k, 0
                        break
                    if cells[k][1] == key:
                        line, end = k, 1
                        break
                else:
                    return path

        candidates = list(range(len(lines)))
        heapq.heapify(candidates)
        paths: list[tuple[list[int], bool]] = []
        while enabled:                                # open paths, the lowest line first
            start = None
            while candidates:
                idx = heapq.heappop(candidates)
                if not disabled[idx] and (end := free_end(idx)) is not None:
                    start = (idx, end)
                    break
            if start is None:
                break
            paths.append((walk(*start), False))
        for idx in range(len(lines)):                 # then closed ones
            if not disabled[idx]:
                paths.append((walk(idx, 0), True))
        out = []
        for path, closed in paths:
            stop = len(path) + (0 if closed else 1)
            out.append(np.array([points[path[len(path) - j]] for j in range(1, stop)]))
        return out


def _round(v: float) -> int:
    """C's ``round``: halves away from zero."""
    return int(math.floor(v + 0.5)) if v >= 0 else -int(math.floor(-v + 0.5))


def _polygon(outlines: list[np.ndarray]) -> Optional[Polygon]:
    """The outlines filled even-odd; degenerate ones (under 3 distinct points, no area)
    dropped."""
    kept = []
    for o in outlines:
        if len(o) and np.array_equal(o[0], o[-1]):
            o = o[:-1]
        if len(np.unique(o, axis=0)) < 3:
            continue
        area = 0.5 * np.sum(o[:, 0] * np.roll(o[:, 1], -1) - np.roll(o[:, 0], -1) * o[:, 1])
        if area != 0:
            kept.append(o)
    if not kept:
        return None
    points = np.concatenate(kept)
    starts = np.cumsum([0] + [len(o) for o in kept])
    return Polygon(points, [list(range(a, b)) for a, b in zip(starts[:-1], starts[1:])])
