"""
Three ``.scad`` programs, read directly
=======================================

Where OpenSCAD is installed, :func:`csg.read_openscad` takes a ``.scad`` file
itself: OpenSCAD evaluates the program (modules, loops, ``text()``) into a
temporary ``.csg`` and the kernel voxelizes that, with OpenSCAD's own facets. The
same from the command line: ``implicitvox voxelize nameplate.scad --render
nameplate.png``. A name plate (text on a hull of cylinders), a twisted and tapered
star vase (an extrusion OpenSCAD slices), and the Minkowski sum of a slotted frame
(a difference, not convex) with a small octahedron, which bevels every edge.
"""
# %%
import shutil
from pathlib import Path

from implicitvox.gallery import RESOLUTION, out

from csg import read_openscad

HERE = Path(__file__).resolve().parent

# %%
if shutil.which("openscad") is None:
    print("OpenSCAD is not installed (apt-get install openscad): nothing to read")
else:
    for name in ("nameplate", "twisted_vase", "rounded_frame"):
        vox = read_openscad(HERE / f"{name}.scad").voxelize(RESOLUTION)
        print(vox.render(out(f"{name}.png"), title=f"{name}.scad, {vox.count:,} surface "
                         "voxels"), vox.count)
