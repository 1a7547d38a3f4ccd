"""
The rest of Stolte's Fig. 11: the lobed plate, sin(4θ) sin(8φ) − r, ten blobby spheres
===================================================================================

Fig. 11 (d) is the crank-shaft part's contour ``rho - (1.2 + 0.05 sin 3θ)`` cut to a
plate with a bore (§4.1.3), (e) is ``sin(4θ) sin(8φ) - r`` and (f) ten blended spheres
(Stolte's Scene 1: a sum of Gaussians). Each is drawn as voxels (shaded points, one per
voxel, as Stolte shows them) and as a mesh within a guaranteed Hausdorff distance
(``implicitvox.mesh``). (a) to (c) are in ``plot_sinsin.py`` and ``plot_gear.py``.
"""
# %%
from implicitvox.gallery import RESOLUTION, out

import numpy as np

import implicitvox as iv
from implicitvox import exp, x, y, z
from implicitvox.expr.examples import lobed_plate, sinsin
from implicitvox.expr.shape import ExprShape
from implicitvox.io.rendering import render_mesh

# %%
# Ten spheres blended as a sum of Gaussians (Scene 1), their centres along a helix so
# that each shows and each blends into the next.
angle = np.linspace(0, 1.6 * np.pi, 10)
centres = np.stack([0.55 * np.cos(angle), 0.55 * np.sin(angle), np.linspace(-0.6, 0.6, 10)], 1)
blobs = 0.5 - sum(exp(-40.0 * ((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2))
                  for cx, cy, cz in centres)
scenes = {"fig11d-lobed-plate": ("rho - (1.2 + 0.05 sin 3 theta), a plate", lobed_plate()),
          "fig11e-sinsin48": ("sin(4 theta) sin(8 phi) - r", sinsin(4, 8)),
          "fig11f-blobby10": ("ten blended spheres", ExprShape(blobs, ((-1.0,) * 3, (1.0,) * 3)))}
for name, (title, shape) in scenes.items():
    vox = iv.voxelize(shape, resolution=RESOLUTION, normals=True)
    print(vox.render(out(f"{name}.png"), title=f"{title}: {vox.count:,} voxels at "
                     f"{RESOLUTION}^3"), vox.count)
    m = iv.mesh(shape, resolution=max(24, RESOLUTION // 4))
    bound = float(m.field_data["hausdorff_bound"][0])
    print(render_mesh(m, out(f"{name}-mesh.png"), title=f"{title}: {m.n_cells:,} triangles "
                      f"within {bound:.3g}"), m.n_cells)
