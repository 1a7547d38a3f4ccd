"""OpenSCAD's ``text`` (csg.text) against OpenSCAD 2021.01's own outlines and voxels.

``tests/openscad/glyphs.svg`` is OpenSCAD's SVG export of ``glyphs.scad``
(6 significant digits); the voxels of ``lettering.scad`` against OpenSCAD's
STL are checked with the other fixtures (tests/csg/test_openscad.py).
"""
import re
import warnings

import numpy as np
import pytest
from scipy.spatial import cKDTree

from csg import read_openscad
from csg.openscad_parser import OpenSCADError, OpenSCADWarning, parse
from csg.text import curve_segments, text_contours, text_polygon, MAX_GLYPHS
from tests.csg.test_openscad import FIXTURES


def _svg_points():
    text = (FIXTURES / "glyphs.svg").read_text()
    pts = re.findall(r"(-?[\d.]+(?:e-?\d+)?),(-?[\d.]+(?:e-?\d+)?)", text)
    return np.array([[float(a), -float(b)] for a, b in pts])


def test_outlines_are_openscads_to_its_svg_rounding():
    ours = np.concatenate(
        text_contours("AVg&", size=7, halign="center", valign="top")
        + [c + [0, -30] for c in text_contours("Qe8", size=12,
                                               font="Liberation Serif:style=Italic",
                                               spacing=1.2, halign="right",
                                               valign="bottom", fn=40)])
    svg = _svg_points()
    tol = 2e-5 * np.abs(svg).max()                   # 6 significant digits
    # every vertex of OpenSCAD's is one of ours: the same sampling of every curve
    assert cKDTree(ours).query(svg)[0].max() <= tol
    # OpenSCAD's 2D union (Clipper) drops the few points it finds collinear
    assert len(svg) <= len(ours) <= 1.02 * len(svg)


def test_curve_segments_follow_openscads_fragments():
    assert curve_segments(10) == 4                   # 30 fragments: floor(30 / 8) + 1
    assert curve_segments(3) == 2                    # 10 fragments
    assert curve_segments(7, fn=40) == 6


def test_holes_and_islands_fill_even_odd():
    polygon = text_polygon("oi", size=10)
    assert [len(holes) for _, holes in polygon.pieces] == [1, 0, 0]   # o's hole; i, its dot


def test_bad_options_name_the_parameter():
    with pytest.raises(ValueError, match="halign"):
        text_contours("a", halign="middle")
    with pytest.raises(ValueError, match="valign"):
        text_contours("a", valign="middle")
    with pytest.raises(ValueError, match="size"):
        text_contours("a", size=0)
    with pytest.raises(ValueError, match="MAX_GLYPHS"):
        text_contours("a" * (MAX_GLYPHS + 1))
    with pytest.raises(OpenSCADError, match=r"<csg>:1:28: text: text must be a string"):
        read_openscad('linear_extrude(height = 1) text(text = 3, size = 10);', facets="true")


def test_blank_text_is_skipped_with_a_warning():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        solid = read_openscad('linear_extrude(height = 1) text(text = "  ", size = 10); '
                              'cube(size = [1, 1, 1]);', facets="true")
    assert solid.bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    assert any(issubclass(w.category, OpenSCADWarning) and ":1:28:" in str(w.message)
               for w in caught)


def test_strings_keep_non_ascii_and_decode_openscads_escapes():
    # OpenSCAD writes "☼" into its .csg as UTF-8: one glyph, not three Latin-1 ones
    node = parse('text(text = "☼ \\u263C\\x41\\"\\\\", size = 5);')[0]
    assert node.args["text"] == '☼ ☼A"\\'
    read = read_openscad('linear_extrude(height = 1) text(text = "☼", size = 50);', facets="true")
    direct = text_polygon("☼", size=50)
    lo, hi = np.asarray(read.bounds)
    assert np.allclose(lo, [*direct.points.min(0), 0]) and np.allclose(hi, [*direct.points.max(0), 1])


def test_a_missing_font_is_named_in_a_warning():
    from csg.text import FontFallbackWarning, find_font
    find_font.cache_clear()
    with pytest.warns(FontFallbackWarning, match="'No Such Font Family' is not installed"):
        path, _ = find_font("No Such Font Family:style=Bold")
    assert path                                      # fontconfig's fallback is still drawn
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        find_font("Liberation Sans:style=Bold")      # installed: no warning
