"""
Replication sweeps
==================

A torus repeated without end along z (Stolte §3, Fig. 2) and a flange whose
bolt circle is one hole repeated about z; the stack also as a mesh within a
guaranteed Hausdorff distance (the sweep evaluates only the instances near each cell).
"""
# %%
from implicitvox.gallery import RESOLUTION, out

import implicitvox as iv
from implicitvox.io.rendering import render_mesh
from implicitvox.expr.examples import flange, replicated_torus

# %%
# The endless stack: only the grid's bounds end it.
vox = iv.voxelize(replicated_torus(), resolution=RESOLUTION, normals=True)
print(vox.render(out("torus-sweep.png"), title=f"repeat(torus), {vox.count:,} voxels"))
m = iv.mesh(replicated_torus(), resolution=max(24, RESOLUTION // 4))
print(render_mesh(m, out("torus-sweep-mesh.png"), title=f"repeat(torus): {m.n_cells:,} triangles "
                  f"within {float(m.field_data['hausdorff_bound'][0]):.3g}"))

# %%
# The flange: disc minus bore minus repeat_polar(hole, 8).
vox = iv.voxelize(flange(), resolution=RESOLUTION, normals=True)
print(vox.render(out("flange.png"), title=f"flange, {vox.count:,} voxels"))
