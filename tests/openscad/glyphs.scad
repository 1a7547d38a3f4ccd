// OpenSCAD 2021.01's glyph outlines, exported as SVG for tests/csg/test_text.py:
// kerning, a cubic-free TrueType font, curves from $fa/$fs and from $fn, and alignment.
text("AVg&", size = 7, halign = "center", valign = "top");
translate([0, -30]) text("Qe8", size = 12, font = "Liberation Serif:style=Italic",
                         spacing = 1.2, halign = "right", valign = "bottom", $fn = 40);
