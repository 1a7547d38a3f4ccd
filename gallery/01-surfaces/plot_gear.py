"""
A gear in cylindrical coordinates
=================================

Stolte's Fig. 11-c: teeth ``rho - (0.8 + 0.05 sin(32 theta))`` cut to a slab,
with a hub and a bore (CSG by min/max).
"""
# %%
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import RESOLUTION, out  # noqa: E402

import implicitvox as iv  # noqa: E402
from implicitvox.expr.examples import gear

# %%
vox = iv.voxelize(gear(), resolution=RESOLUTION, normals=True, interior=True)
print(vox.render(out("gear.png"), title=f"gear, {vox.count:,} surface voxels"), vox.count)
