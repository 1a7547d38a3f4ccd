"""
sin(n θ) sin(m φ) − r
=====================

Stolte's Fig. 6 surfaces, voxelized robustly and drawn as shaded points
(one per voxel, as Stolte displays them).
"""
# %%
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from common import RESOLUTION, out  # noqa: E402

import implicitvox as iv  # noqa: E402
from implicitvox.expr.examples import sinsin

# %%
# Two of the four surfaces of Fig. 6.
for n, m in [(3, 4), (9, 18)]:
    vox = iv.voxelize(sinsin(n, m), resolution=RESOLUTION, normals=True)
    path = vox.render(out(f"sinsin{n}{m}.png"), title=f"sin({n} theta) sin({m} phi) - r, "
                      f"{vox.count:,} voxels at {RESOLUTION}^3")
    print(path, vox.count)
