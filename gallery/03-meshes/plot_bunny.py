"""
The Stanford bunny, voxelized exactly
=====================================

Every voxel whose box meets one of the bunny's 69,451 triangles, and no
other (exact box-triangle test in an octree of (node, triangle) pairs).
The bunny is read from the workspace's shared data (it is not
redistributed); without it, PyVista's bundled nut stands in.
"""
# %%
import os
from pathlib import Path

from implicitvox.gallery import RESOLUTION, out

import implicitvox as iv

# %%
bunny = Path(os.environ.get("IMPLICITVOX_BUNNY", Path(__file__).resolve().parents[3] /
                            "shared" / "data" / "meshes" / "stanford-bunny.obj"))
if bunny.exists():
    mesh, name = str(bunny), "Stanford bunny"
else:
    import pyvista as pv
    mesh, name = pv.examples.load_nut(), "nut (bunny not found)"
vox = iv.voxelize_mesh(mesh, RESOLUTION)
print(vox.render(out("bunny.png"), title=f"{name}, {vox.count:,} voxels"), vox.count)
