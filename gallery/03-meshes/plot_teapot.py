"""
The Utah teapot from its 32 Bézier patches
==========================================

Newell's bicubic patches, voxelized by De Casteljau subdivision with a
flatness stop (Stolte §4.2): every voxel a patch meets is output.
"""
# %%
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import RESOLUTION, out  # noqa: E402

import implicitvox as iv  # noqa: E402

# %%
vox = iv.voxelize_bezier(iv.utah_teapot(), RESOLUTION)
print(vox.render(out("teapot.png"), title=f"Utah teapot, {vox.count:,} voxels"), vox.count)
