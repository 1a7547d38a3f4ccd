"""Writes drawing.dxf, the DXF fixture of drawing.scad (run once; the file is committed).

Every entity OpenSCAD 2021.01 imports, on three layers: a plate of LINEs with a
closed LWPOLYLINE slot, a CIRCLE hole, an ARC-and-LINE rounded tab, an ELLIPSE,
a block of LINEs and an ARC placed twice by INSERT (scaled, turned), and an
open LWPOLYLINE (OpenSCAD closes it).
"""
from pathlib import Path

import ezdxf


def main() -> None:
    doc = ezdxf.new("R2000")
    msp = doc.modelspace()
    plate = {"layer": "plate"}
    outline = [(0, 0), (40, 0), (40, 25), (28, 25), (28, 15), (12, 15), (12, 25), (0, 25)]
    for a, b in zip(outline, outline[1:] + outline[:1]):
        msp.add_line(a, b, dxfattribs=plate)
    msp.add_lwpolyline([(4, 4), (16, 4), (16, 8), (4, 8)], close=True, dxfattribs=plate)
    msp.add_circle((32, 8), 3.5, dxfattribs=plate)
    msp.add_ellipse((22, 6), major_axis=(3, 1), ratio=0.5, dxfattribs=plate)
    tab = {"layer": "tab"}
    msp.add_line((0, 30), (10, 30), dxfattribs=tab)
    msp.add_arc((10, 35), 5, -90, 90, dxfattribs=tab)
    msp.add_line((10, 40), (0, 40), dxfattribs=tab)
    msp.add_line((0, 40), (0, 30), dxfattribs=tab)
    msp.add_lwpolyline([(20, 30), (30, 30), (25, 38)], close=False, dxfattribs=tab)
    block = doc.blocks.new(name="TOOTH")
    block.add_line((0, 0), (4, 0))
    block.add_arc((2, 0), 2, 0, 180)
    msp.add_blockref("TOOTH", (45, 5), dxfattribs={"layer": "teeth", "xscale": 1.5,
                                                   "yscale": 1.0, "rotation": 30})
    msp.add_blockref("TOOTH", (45, 20), dxfattribs={"layer": "teeth"})
    doc.saveas(Path(__file__).with_name("drawing.dxf"))


if __name__ == "__main__":
    main()
