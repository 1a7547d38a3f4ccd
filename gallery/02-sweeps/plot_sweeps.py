"""
Replication sweeps
==================

A torus repeated without end along z (Stolte §3, Fig. 2) and a flange whose
bolt circle is one hole repeated about z.
"""
# %%
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import RESOLUTION, out  # noqa: E402

import implicitvox as iv  # noqa: E402
from implicitvox.expr.examples import flange, replicated_torus

# %%
# The endless stack: only the grid's bounds end it.
vox = iv.voxelize(replicated_torus(), resolution=RESOLUTION, normals=True)
print(vox.render(out("torus-sweep.png"), title=f"repeat(torus), {vox.count:,} voxels"))

# %%
# The flange: disc minus bore minus repeat_polar(hole, 8).
vox = iv.voxelize(flange(), resolution=RESOLUTION, normals=True)
print(vox.render(out("flange.png"), title=f"flange, {vox.count:,} voxels"))
