"""Triangle meshes and Bézier patches in: exact predicates, the box-triangle test,
(node, triangle) pairs, solid fill and winding numbers (Stolte §6, §4.2; Varadhan §3.3.1).

* :mod:`.predicates` - signs of 2x2 and 3x3 determinants, filtered, exact fallback;
* :mod:`.tribox` - the exact box-triangle test;
* :mod:`.inputs` - meshes from arrays, PyVista, trimesh or files, checked;
* :mod:`.ranges` - bucketed index ranges for pair expansion;
* :mod:`.pairs` - the octree of (node, triangle) pairs: the surface voxels;
* :mod:`.crossings`, :mod:`.winding` - exact ray crossings, generalized winding numbers;
* :mod:`.fill` - the interior of closed meshes;
* :mod:`.bezier` - Bézier patches, De Casteljau subdivision, the Utah teapot.
"""
from .patches import BezierPatch, bezier_triangles, utah_teapot
from .inputs import MESH_SUFFIXES, as_triangles
from .tribox import Triangles
from .winding import winding_numbers

__all__ = ["BezierPatch", "bezier_triangles", "utah_teapot", "MESH_SUFFIXES", "as_triangles",
           "Triangles", "winding_numbers"]
