"""
A bracket and a knob from OpenSCAD
==================================

``openscad bracket.scad -o bracket.csg`` writes the evaluated CSG tree;
:func:`csg.read_openscad` turns it into solids with true curves (or, with
``facets="openscad"``, OpenSCAD's own facets) and the kernel voxelizes them.
"""
# %%
from pathlib import Path

from implicitvox.gallery import RESOLUTION, out

from csg import read_openscad

HERE = Path(__file__).resolve().parent

# %%
for name in ("bracket", "knob"):
    solid = read_openscad(HERE / f"{name}.csg", facets="true")
    vox = solid.voxelize(RESOLUTION, interior=True)
    print(vox.render(out(f"{name}.png"), title=f"{name}.scad, {vox.count:,} surface voxels"),
          vox.count)
