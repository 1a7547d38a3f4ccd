"""
CAD solids of tori, ellipsoids and polyhedra (Varadhan et al. Fig. 10)
=====================================================================

Varadhan et al.'s adaptive-grid figure meshes CAD benchmarks made of a few boolean
operations on tori, ellipsoids and polyhedra. Three such solids, 3 to 5 booleans
each, built with ``csg``: every leaf has an exact max-norm voxel test (§5.1), so the
voxelization is exactly the voxels the surface meets, and ``implicitvox.mesh``
triangulates them within a guaranteed Hausdorff distance (sharp edges kept by the
quadric vertices of dual contouring).

* a bracket: an ellipsoidal boss on a plate, a torus groove cut around it, a wedge
  (a convex polyhedron) added as a rib, a bore through all;
* linked rings: two tori through each other, an ellipsoid hub, cut flat by a
  half-space;
* a knob: an ellipsoid cut by a box, with a torus grip and an octahedral key hole.
"""
# %%
import numpy as np

from implicitvox.gallery import RESOLUTION, out

import implicitvox as iv
from csg import Box, ConvexPolyhedron, Cylinder, Ellipsoid, HalfSpace, Torus
from implicitvox.io.rendering import render_mesh

# %%
plate = Box((2.0, 1.4, 0.3), center=True)
boss = Ellipsoid((0.55, 0.45, 0.5)).translate((0.0, 0.0, 0.15))
groove = Torus(R=0.62, r=0.08).translate((0.0, 0.0, 0.15))
wedge = ConvexPolyhedron(points=[(0.6, -0.1, 0.15), (0.95, -0.1, 0.15), (0.6, -0.1, 0.55),
                                 (0.6, 0.1, 0.15), (0.95, 0.1, 0.15), (0.6, 0.1, 0.55)])
bore = Cylinder(h=2.0, r=0.18, center=True)
bracket = ((plate | boss) - groove | wedge) - bore

rings = (Torus(R=0.5, r=0.12) | Torus(R=0.5, r=0.12).rotate("x", 90).translate((0.5, 0, 0))
         | Ellipsoid((0.25, 0.25, 0.35)).translate((0.25, 0, 0))) & HalfSpace((0, 0, 1), 0.45)

octahedron = ConvexPolyhedron(points=[(s * a, 0, 0) for s in (-1, 1) for a in (0.2,)]
                              + [(0, s * 0.2, 0) for s in (-1, 1)]
                              + [(0, 0, s * 0.6) for s in (-1, 1)])
knob = ((Ellipsoid((0.7, 0.7, 0.55)) & Box((2.0, 2.0, 0.8), center=True))
        | Torus(R=0.68, r=0.1)) - octahedron.translate((0, 0, 0.2))

scene = bracket.translate((-1.4, 0, 0)) | rings.translate((0.9, 0.0, 0.0)) \
    | knob.translate((0.0, 1.9, 0.0))

# %%
vox = iv.voxelize(scene, RESOLUTION, normals=True)
print(vox.render(out("cad-benchmarks.png"), title=f"three CAD solids: {vox.count:,} voxels, "
                 f"exact (§5.1) at {RESOLUTION}"), vox.count)
m = iv.mesh(scene, resolution=max(32, RESOLUTION // 3))
bound = float(m.field_data["hausdorff_bound"][0])
print(render_mesh(m, out("cad-benchmarks-mesh.png"), title=f"meshed: {m.n_cells:,} triangles "
                  f"within {bound:.3g}"), m.n_cells, np.round(bound, 4))
