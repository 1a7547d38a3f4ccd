"""Shapes to ``Voxels``: one module per kind of input.

* :mod:`.implicit` - ``voxelize``: expressions and shapes (interval octree, exact tests);
* :mod:`.mesh` - ``voxelize_mesh``: triangle meshes, exactly;
* :mod:`.bezier` - ``voxelize_bezier``: Bézier patches;
* :mod:`.memory` - the memory budget and estimates every voxelizer checks first.
"""
from .implicit import voxelize
from .mesh import voxelize_mesh
from .bezier import voxelize_bezier

__all__ = ["voxelize", "voxelize_mesh", "voxelize_bezier"]
