"""
sin(n θ) sin(m φ) − r
=====================

Stolte's Fig. 6 surfaces (Fig. 11 a and b), voxelized robustly and drawn as shaded
points (one per voxel, as Stolte displays them), and meshed within a guaranteed
Hausdorff distance.
"""
# %%
from implicitvox.gallery import RESOLUTION, out

import implicitvox as iv
from implicitvox.expr.examples import sinsin
from implicitvox.io.rendering import render_mesh

# %%
# Two of the four surfaces of Fig. 6.
for n, m in [(3, 4), (9, 18)]:
    vox = iv.voxelize(sinsin(n, m), resolution=RESOLUTION, normals=True)
    path = vox.render(out(f"sinsin{n}{m}.png"), title=f"sin({n} theta) sin({m} phi) - r, "
                      f"{vox.count:,} voxels at {RESOLUTION}^3")
    print(path, vox.count)
    tri = iv.mesh(sinsin(n, m), resolution=max(24, RESOLUTION // 4))
    bound = float(tri.field_data["hausdorff_bound"][0])
    print(render_mesh(tri, out(f"sinsin{n}{m}-mesh.png"), title=f"sin({n} theta) sin({m} phi) - "
                      f"r: {tri.n_cells:,} triangles within {bound:.3g}"))
