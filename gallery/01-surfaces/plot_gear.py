"""
A gear in cylindrical coordinates
=================================

Stolte's Fig. 11-c: teeth ``rho - (0.8 + 0.05 sin(32 theta))`` cut to a slab,
with a hub and a bore (CSG by min/max).
"""
# %%
from implicitvox.gallery import RESOLUTION, out

import implicitvox as iv
from implicitvox.expr.examples import gear

# %%
vox = iv.voxelize(gear(), resolution=RESOLUTION, normals=True, interior=True)
print(vox.render(out("gear.png"), title=f"gear, {vox.count:,} surface voxels"), vox.count)
