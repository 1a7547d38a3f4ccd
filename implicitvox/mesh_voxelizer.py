"""``voxelize_mesh``: exactly the voxels a triangle mesh meets (Stolte §6, Varadhan §3.3).

A voxel is output iff its closed box meets a closed triangle of the mesh,
decided by the exact box-triangle test of :mod:`implicitvox.tribox` during
an octree subdivision with per-node triangle lists
(:mod:`implicitvox.mesh_subdivide`). ``solid=True`` adds the interior of
closed meshes (:mod:`implicitvox.mesh_solid`).

Examples
--------
>>> import pyvista as pv
>>> import implicitvox as iv
>>> vox = iv.voxelize_mesh(pv.Cube(), resolution=8)
>>> vox.resolution, vox.count          # the faces of the cube, half a voxel inside the grid
((8, 8, 8), 296)
>>> solid = iv.voxelize_mesh(pv.Cube(), resolution=8, solid=True)
>>> solid.interior_count               # the 6 x 6 x 6 voxels inside
216
"""
from __future__ import annotations

import os
import time
from typing import Any, Callable, Optional, Union

import numpy as np

from .grid import Grid
from .mesh_input import as_triangles
from .mesh_solid import BYTES_PER_VOXEL, interior_octants
from .mesh_subdivide import surface_codes
from .octree import Octree
from .tribox import Triangles
from .voxelizer import memory_budget
from .voxels import Voxels

__all__ = ["voxelize_mesh", "default_mesh_bounds", "MeshSource"]

#: bytes per surface voxel (codes, sort, octree) and per (node, triangle) pair
_BYTES_PER_VOXEL = 40


class MeshSource:
    """The triangles a :class:`Voxels` came from (so it can be refined)."""

    def __init__(self, triangles: Triangles, name: str):
        self.triangles = triangles
        self.name = name

    def normals_at(self, points: np.ndarray) -> np.ndarray:
        """Unit normals ``(n, 3)`` of the triangles nearest to ``points`` (for shading)."""
        return nearest_triangle_normals(self.triangles.v, points)

    def __repr__(self) -> str:
        return f"<mesh {self.name}: {len(self.triangles)} triangles>"


def nearest_triangle_normals(triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Unit normals of the triangles ``(t, 3, 3)`` nearest to ``points`` (VTK's cell
    locator); zero for degenerate triangles."""
    import pyvista as pv
    if not len(triangles) or not len(points):
        return np.zeros((len(points), 3), dtype=np.float32)
    t = len(triangles)
    faces = np.hstack([np.full((t, 1), 3), np.arange(3 * t).reshape(t, 3)]).ravel()
    poly = pv.PolyData(triangles.reshape(-1, 3), faces)
    cell = poly.find_closest_cell(np.asarray(points, dtype=np.float64))
    n = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(norm > 0, n / norm, 0.0)
    return unit[cell].astype(np.float32)


def default_mesh_bounds(vertices: np.ndarray, faces: np.ndarray, resolution: Any
                        ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The mesh's bounding box grown by half a voxel on every side (as Open3D does).

    The voxel size ``h`` makes ``resolution`` voxels span the longest side
    plus ``h``; a flat mesh gets one voxel across its flat axis.
    """
    mask = np.zeros(len(vertices), dtype=bool)
    mask[faces.ravel()] = True
    used = vertices[mask]
    lo, hi = used.min(axis=0), used.max(axis=0)
    longest = float((hi - lo).max())
    if not longest > 0:
        raise ValueError("the mesh has zero extent (all its vertices coincide); pass bounds")
    n = resolution if isinstance(resolution, (int, np.integer)) else max(resolution)
    h = longest / max(int(n) - 1, 1)
    return tuple((lo - h / 2).tolist()), tuple((hi + h / 2).tolist())


def voxelize_mesh(mesh: Any, resolution: Union[int, tuple[int, int, int]] = 256,
                  bounds: Any = None, *, solid: bool = False,
                  progress: Optional[Callable[[float], Any]] = None,
                  max_memory: Optional[int] = None) -> Voxels:
    """Voxelize a triangle mesh: every voxel whose closed box meets a triangle, and no other.

    Parameters
    ----------
    mesh : (vertices, faces) or pyvista.PolyData or path
        ``vertices (v, 3)`` floats and ``faces (f, 3)`` vertex indices, any
        PyVista surface (polygons are triangulated), or a ``.stl``, ``.ply``,
        ``.obj``, ``.vtk`` or ``.vtp`` file.
    resolution : int or (int, int, int), default: 256
        Voxels along the longest side of ``bounds``, or per axis.
    bounds : ((x0, y0, z0), (x1, y1, z1)), optional
        The grid's box; by default the mesh's bounding box plus half a voxel
        on every side. Triangles outside it are clipped away.
    solid : bool, default: False
        Also store the voxels inside the mesh (as octants; see
        :mod:`implicitvox.mesh_solid`, which says what open meshes get).
    progress : callable, optional
        Called with the share of the work done (0 to 1).
    max_memory : int, optional
        Refuse (``MemoryError``) before starting when the estimated peak
        exceeds this many bytes; default half the available memory.

    Returns
    -------
    Voxels

    Raises
    ------
    ValueError
        Bad mesh (non-finite vertices, faces out of range, unreadable file),
        bad bounds or resolution, or an empty mesh without ``bounds``.
    MemoryError
        When the estimate exceeds ``max_memory``.
    """
    t0 = time.perf_counter()
    vertices, faces = as_triangles(mesh)
    if not len(faces) and bounds is None:
        raise ValueError("the mesh has no triangles: pass bounds to get an empty voxelization")
    if bounds is None:
        bounds = default_mesh_bounds(vertices, faces, resolution)
    grid = Grid.from_bounds(bounds, resolution)
    budget = memory_budget(max_memory)
    triangles = vertices[faces]
    need = estimate_mesh_memory(triangles, grid, solid)
    if need > budget:
        raise MemoryError(f"voxelizing the mesh at {grid.shape} needs an estimated "
                          f"{need / 2**30:.2f} GiB, over the budget of {budget / 2**30:.2f} GiB; "
                          "lower the resolution or raise max_memory")
    tris = Triangles(triangles)
    codes = surface_codes(tris, grid, progress=progress)
    t1 = time.perf_counter()
    interior = interior_octants(grid, codes, triangles) if solid else {}
    tree = Octree._from_sorted_codes(codes, grid.depth, {})
    name = os.fspath(mesh) if isinstance(mesh, (str, os.PathLike)) else type(mesh).__name__
    metadata = {"model": f"mesh {name}: {len(vertices)} vertices, {len(faces)} triangles",
                "seconds_subdivide": t1 - t0, "seconds_total": time.perf_counter() - t0}
    return Voxels(grid, tree, interior, metadata, shape=MeshSource(tris, name),
                  options={"solid": bool(solid)})


def estimate_mesh_memory(triangles: np.ndarray, grid: Grid, solid: bool) -> int:
    """Peak bytes: surface voxels from the triangles' area (a plane meets at most
    ``sqrt(3) * area / h**2`` voxels, plus a few per triangle), and the dense
    fill when ``solid``."""
    e1 = triangles[:, 1] - triangles[:, 0]
    e2 = triangles[:, 2] - triangles[:, 0]
    h = np.asarray(grid.voxel_size)
    # area in voxel units: scale each axis by its voxel size
    area = 0.5 * np.linalg.norm(np.cross(e1 / h, e2 / h), axis=1).sum() if len(triangles) else 0.0
    voxels = min(1.8 * area + 8 * len(triangles), float(np.prod(grid.shape)))
    need = voxels * _BYTES_PER_VOXEL + len(triangles) * 200
    if solid:
        need += float(np.prod(grid.shape)) * BYTES_PER_VOXEL
    return int(need)


def refine_mesh_voxels(vox: Voxels, levels: int, progress=None) -> Voxels:
    """Mesh voxels at ``2**levels`` times the resolution (same edges)."""
    source: MeshSource = vox._shape
    grid = vox.grid.finer(levels)
    codes = surface_codes(source.triangles, grid, progress=progress)
    solid = vox._options.get("solid", False)
    interior = interior_octants(grid, codes, source.triangles.v) if solid else {}
    tree = Octree._from_sorted_codes(codes, grid.depth, {})
    return Voxels(grid, tree, interior, dict(vox.metadata), shape=source,
                  options=dict(vox._options))
