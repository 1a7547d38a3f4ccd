"""The octree: the grid, Morton codes, the interval subdivision, the store and ``Voxels``.

* :mod:`.grid` - the voxel grid (cubic voxels by default) and octant boxes;
* :mod:`.morton` - Morton codes of voxel indices;
* :mod:`.subdivide` - EMPTY / FULL / AMBIGUOUS octants by interval arithmetic (Stolte §2);
* :mod:`.level_dtype` - which float type each level's intervals run in;
* :mod:`.store` - the pointer octree (Stolte §5.1): ``Octree``, ``PointerOctree``;
* :mod:`.voxels` - ``Voxels``, the result; it knows its producer only as a source object.
"""
from .grid import Grid
from .store import Octree, PointerOctree
from .voxels import Voxels

__all__ = ["Grid", "Octree", "PointerOctree", "Voxels"]
