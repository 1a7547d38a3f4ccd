"""
The Utah teapot from its 32 Bézier patches
==========================================

Newell's bicubic patches, voxelized by De Casteljau subdivision with a
flatness stop (Stolte §4.2): every voxel a patch meets is output.
"""
# %%
from implicitvox.gallery import RESOLUTION, out

import implicitvox as iv

# %%
vox = iv.voxelize_bezier(iv.utah_teapot(), RESOLUTION)
print(vox.render(out("teapot.png"), title=f"Utah teapot, {vox.count:,} voxels"), vox.count)
