"""OpenSCAD's ``text``: the glyph outlines OpenSCAD 2021.01 draws, as one polygon.

The steps are OpenSCAD's (``FreetypeRenderer``, ``DrawingCallback``):

* The font is found by fontconfig (its ``fc-match``) from OpenSCAD's font name
  (``"Liberation Sans:style=Bold"``); an empty name is OpenSCAD's default,
  ``Liberation Sans:style=Regular`` (Debian: ``fonts-liberation``).
* The text is shaped by HarfBuzz (``uharfbuzz``: kerning, ligatures, direction,
  script and language as given) and its glyphs are loaded by FreeType
  (``freetype-py``), hinted, at a character size of 100,000 (26.6 points) at
  100 dpi, as OpenSCAD loads them.
* Each quadratic or cubic curve of an outline becomes ``segments`` straight
  pieces, ``segments = max(floor(fragments(size) / 8) + 1, 2)`` with OpenSCAD's
  ``get_fragments_from_r`` of ``$fn, $fa, $fs`` at r = ``size``.
* A point is scaled by ``size / 100`` after adding the glyph's offset and
  advance (HarfBuzz's 26.6 positions divided by 64 · 16, as OpenSCAD divides
  them); ``halign`` and ``valign`` shift the whole text by its advance width
  and by the glyphs' grid-fitted ascent and descent.

Every contour of every glyph goes into one polygon, filled even-odd
(:class:`csg.planar.Polygon`), as OpenSCAD tessellates it. The result is
OpenSCAD's polygon in both facet modes: its curves are sampled by OpenSCAD's
rule, not by the font's true curves.

Examples
--------
The letter "l" of OpenSCAD's default font is one rectangle:

>>> contours = text_contours("l", size=10)
>>> len(contours), contours[0].round(4).tolist()
(1, [[0.9358, 0.0], [0.9358, 10.0634], [2.1564, 10.0634], [2.1564, 0.0]])
"""
from __future__ import annotations

import functools
import math
import shutil
import subprocess
import warnings
from typing import Optional

import numpy as np

from .facets import fragments

__all__ = ["text_contours", "text_polygon", "find_font", "FontFallbackWarning", "DEFAULT_FONT",
           "MAX_GLYPHS"]

#: the font OpenSCAD 2021.01 uses when ``font`` is empty
DEFAULT_FONT = "Liberation Sans:style=Regular"
#: characters a text may hold (a page of text is a few thousand)
MAX_GLYPHS = 100_000
_CHAR_SIZE = 100_000          # OpenSCAD's FT_Set_Char_Size (26.6 points), at 100 dpi
_POINT_SCALE = 1000.0         # FreetypeRenderer::scale: outline points / 1000
_POSITION_SCALE = 64.0 * 16.0  # GlyphData: HarfBuzz positions / 64 / 16


class FontFallbackWarning(UserWarning):
    """The font a text asks for is not installed: fontconfig gave another family.

    OpenSCAD takes fontconfig's fallback too, so the text is still drawn, but its
    outlines (and voxels) are those of the fallback font. The test suite turns this
    warning into an error, so a machine without ``fonts-liberation`` fails the text
    tests with a message that names the missing font.
    """


@functools.lru_cache(maxsize=64)
def find_font(font: str = "") -> tuple[str, int]:
    """``(file, face index)`` of the font fontconfig matches to an OpenSCAD font
    name, as OpenSCAD finds it (an empty name is :data:`DEFAULT_FONT`).

    Raises
    ------
    ValueError
        fontconfig's ``fc-match`` is not installed, or matches no font file.

    Warns
    -----
    FontFallbackWarning
        fontconfig has no font of the family asked for and gives its fallback
        (once per font name and process).
    """
    name = font.strip() or DEFAULT_FONT
    if shutil.which("fc-match") is None:
        raise ValueError("text needs fontconfig's fc-match to find its font "
                         "(Debian: apt-get install fontconfig fonts-liberation)")
    found = subprocess.run(["fc-match", "--format=%{file}\n%{index}\n%{family}", name],
                           capture_output=True, text=True, timeout=30)
    lines = found.stdout.splitlines()
    if found.returncode != 0 or not lines or not lines[0]:
        raise ValueError(f"text: fontconfig finds no font for {name!r}")
    index = int(lines[1]) if len(lines) > 1 and lines[1].isdigit() else 0
    asked = name.split(":")[0].strip()
    families = [f.strip().lower() for f in (lines[2] if len(lines) > 2 else "").split(",")]
    if asked and asked.lower() not in families:
        hint = " (Debian: apt-get install fonts-liberation)" if "liberation" in asked.lower() \
            else ""
        warnings.warn(f"text: font {asked!r} is not installed; fontconfig gives {lines[0]} "
                      f"instead{hint}", FontFallbackWarning, stacklevel=3)
    return lines[0], index


def curve_segments(size: float, fn: float = 0.0, fs: float = 2.0, fa: float = 12.0) -> int:
    """The straight pieces OpenSCAD 2021.01 draws a glyph's curve with."""
    return max(fragments(size, fn, fs, fa) // 8 + 1, 2)


def text_contours(text: str, size: float = 10.0, font: str = "", halign: str = "left",
                  valign: str = "baseline", spacing: float = 1.0, direction: str = "",
                  language: str = "en", script: str = "", fn: float = 0.0, fs: float = 2.0,
                  fa: float = 12.0) -> list[np.ndarray]:
    """The closed contours (each (k, 2), not repeating its first point) of the text
    as OpenSCAD 2021.01 draws it (module docstring).

    Raises
    ------
    ValueError
        A parameter out of range (naming it), over :data:`MAX_GLYPHS`
        characters, or no font found.
    """
    import freetype
    import uharfbuzz as hb

    if not isinstance(text, str):
        raise ValueError(f"text must be a string, got {text!r:.40}")
    if len(text) > MAX_GLYPHS:
        raise ValueError(f"text of {len(text):,} characters, over {MAX_GLYPHS:,} "
                         "(csg.text.MAX_GLYPHS)")
    if not (math.isfinite(size) and size > 0):
        raise ValueError(f"size must be a positive number, got {size!r}")
    if not math.isfinite(spacing):
        raise ValueError(f"spacing must be a finite number, got {spacing!r}")
    segments = curve_segments(size, fn, fs, fa)
    path, index = find_font(font)
    face = freetype.Face(path, index)
    face.set_char_size(0, _CHAR_SIZE, 100, 100)
    upem = face.units_per_EM
    hb_font = hb.Font(hb.Face(hb.Blob.from_file_path(path), index))
    scale = (face.size.x_scale * upem + (1 << 15)) >> 16     # as hb_ft_font_create sets it
    hb_font.scale = (scale, (face.size.y_scale * upem + (1 << 15)) >> 16)
    buf = hb.Buffer()
    buf.add_str(text)
    buf.guess_segment_properties()
    for attr, value in (("direction", direction), ("script", script),
                        ("language", language)):
        if value:
            try:
                setattr(buf, attr, value)
            except (ValueError, TypeError):
                raise ValueError(f"text: {attr} {value!r} is not one HarfBuzz knows") from None
    hb.shape(hb_font, buf, {})
    glyphs = list(zip(buf.glyph_infos, buf.glyph_positions))
    horizontal = buf.direction in ("ltr", "rtl")
    loaded = []
    width = ascend = descend = 0.0
    for info, pos in glyphs:
        face.load_glyph(info.codepoint, freetype.FT_LOAD_DEFAULT)
        outline = face.glyph.outline
        points = np.array(outline.points, dtype=np.float64).reshape(-1, 2) / _POINT_SCALE
        loaded.append((points, list(outline.tags), list(outline.contours), pos))
        box = _grid_fitted_box(points * _POINT_SCALE)
        if horizontal:
            width += pos.x_advance / _POSITION_SCALE * spacing
            ascend = max(ascend, box[3] / 64.0 / 16.0)
            descend = max(descend, -box[1] / 64.0 / 16.0)
        else:
            width = max(width, (box[2] - box[0]) / 64.0 / 16.0)
            ascend += pos.y_advance / _POSITION_SCALE * spacing
    x_offset = {"left": 0.0, "right": -width, "center": -width / 2.0}.get(halign)
    y_offset = {"baseline": 0.0, "top": -ascend, "bottom": descend,
                "center": descend / 2.0 - ascend / 2.0}.get(valign)
    if x_offset is None:
        raise ValueError(f"halign must be 'left', 'right' or 'center', got {halign!r}")
    if y_offset is None:
        raise ValueError(f"valign must be 'baseline', 'top', 'bottom' or 'center', "
                         f"got {valign!r}")
    contours = []
    advance = np.zeros(2)
    for points, tags, ends, pos in loaded:
        offset = np.array([x_offset + pos.x_offset / _POSITION_SCALE,
                           y_offset + pos.y_offset / _POSITION_SCALE])
        start = 0
        for end in ends:
            ring = _decompose(points[start:end + 1], tags[start:end + 1], segments)
            start = end + 1
            if len(ring) >= 3:
                contours.append(size / 100.0 * (ring + offset + advance))
        advance += np.array([pos.x_advance, pos.y_advance]) / _POSITION_SCALE * spacing
    return contours


def text_polygon(text: str, size: float = 10.0, **options) -> Optional["Polygon"]:
    """The text as one :class:`csg.planar.Polygon` (all contours, even-odd), or
    None when it draws nothing (spaces, an empty string)."""
    from .planar import Polygon
    contours = text_contours(text, size, **options)
    if not contours:
        return None
    paths, first = [], 0
    for ring in contours:
        paths.append(list(range(first, first + len(ring))))
        first += len(ring)
    return Polygon(np.concatenate(contours), paths)


def _grid_fitted_box(points: np.ndarray) -> tuple[float, float, float, float]:
    """FT_Glyph_Get_CBox(FT_GLYPH_BBOX_GRIDFIT) of 26.6 points: the control box
    rounded outward to whole pixels (64)."""
    if len(points) == 0:
        return 0.0, 0.0, 0.0, 0.0
    lo, hi = points.min(axis=0), points.max(axis=0)
    return (math.floor(lo[0] / 64) * 64, math.floor(lo[1] / 64) * 64,
            math.ceil(hi[0] / 64) * 64, math.ceil(hi[1] / 64) * 64)


def _decompose(points: np.ndarray, tags: list[int], segments: int) -> np.ndarray:
    """One contour as FT_Outline_Decompose walks it (on-curve points, conic and
    cubic control points), each curve drawn as OpenSCAD's ``segments`` pieces."""
    n = len(points)
    if n == 0:
        return points
    kind = [t & 3 for t in tags]             # 1 on, 0 conic control, 2 cubic control
    if kind[0] == 1:
        first, order = points[0], list(range(1, n))
    elif kind[-1] == 1:
        first, order = points[-1], list(range(0, n - 1))
    else:                                    # both conic: start between them
        first, order = (points[0] + points[-1]) / 2, list(range(0, n))
    a = np.arange(1, segments + 1) / segments
    out = [first[None, :]]
    pen, pending = first, []
    for i in order:
        p, k = points[i], kind[i]
        if k == 1:
            pen = _curve(out, pen, pending, p, a)
            pending = []
        elif k == 0 and pending and kind[pending[-1][1]] == 0:
            mid = (pending[-1][0] + p) / 2   # two conic controls: an implied on point
            pen = _curve(out, pen, pending, mid, a)
            pending = [(p, i)]
        else:
            pending.append((p, i))
    _curve(out, pen, pending, first, a)
    ring = np.concatenate(out)
    if len(ring) > 1 and np.array_equal(ring[0], ring[-1]):
        ring = ring[:-1]
    return ring


def _curve(out: list, pen: np.ndarray, controls: list, to: np.ndarray,
           a: np.ndarray) -> np.ndarray:
    """Append a line, conic or cubic from ``pen`` to ``to`` (sampled at ``a``)."""
    b = 1 - a[:, None]
    t = a[:, None]
    if not controls:
        out.append(to[None, :])
    elif len(controls) == 1:
        c = controls[0][0]
        out.append(pen * b ** 2 + c * 2 * b * t + to * t ** 2)
    else:
        c1, c2 = controls[0][0], controls[1][0]
        out.append(pen * b ** 3 + c1 * 3 * b ** 2 * t + c2 * 3 * b * t ** 2 + to * t ** 3)
    return to
