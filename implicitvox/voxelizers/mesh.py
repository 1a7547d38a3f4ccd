"""``voxelize_mesh``: exactly the voxels a triangle mesh meets (Stolte §6, Varadhan §3.3).

A voxel is output iff its closed box meets a closed triangle of the mesh,
decided by the exact box-triangle test of :mod:`implicitvox.triangles.tribox`
during an octree subdivision with per-node triangle lists
(:mod:`implicitvox.triangles.pairs`). ``interior=True`` adds the interior of
closed meshes (:mod:`implicitvox.triangles.fill`).

Examples
--------
>>> import pyvista as pv
>>> import implicitvox as iv
>>> vox = iv.voxelize_mesh(pv.Cube(), resolution=8)
>>> vox.resolution, vox.count          # the faces of the cube, half a voxel inside the grid
((8, 8, 8), 296)
>>> solid = iv.voxelize_mesh(pv.Cube(), resolution=8, interior=True)
>>> solid.interior_count               # the 6 x 6 x 6 voxels inside
216
"""
from __future__ import annotations

import os
import time
from typing import Any, Callable, Optional, Union

import numpy as np

from .. import validate
from ..triangles.fill import BYTES_PER_VOXEL, interior_octants
from ..triangles.inputs import as_triangles
from ..triangles.pairs import surface_codes
from ..triangles.tribox import Triangles
from ..octree.grid import Grid, grid_of
from ..octree.run import Run
from ..octree.store import Octree
from ..octree.voxels import Voxels

__all__ = ["voxelize_mesh", "mesh_bounds", "MeshSource", "nearest_triangle_normals",
           "triangle_surface", "estimate_triangle_voxels", "estimate_triangle_memory"]

#: bytes per surface voxel (codes, sort, octree) and per (node, triangle) pair
_BYTES_PER_VOXEL = 40


class MeshSource:
    """The triangles a :class:`Voxels` came from (so it can be refined)."""

    def __init__(self, triangles: Triangles, name: str, interior: bool, run: Run):
        self.triangles = triangles
        self.name = name
        self.interior = interior
        #: the run it came from: :meth:`refine` uses its workers and executor again
        self.run = run

    def refine(self, voxels: Voxels, levels: int, progress: Any = None,
               max_memory: Optional[int] = None) -> Voxels:
        """The mesh voxelized on ``voxels.grid.finer(levels)`` (the same edges)."""
        return _voxelize_on(self, voxels.grid.finer(levels),
                            self.run.again(max_memory=max_memory, progress=progress),
                            dict(voxels.metadata))

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


def mesh_bounds(vertices: np.ndarray, faces: np.ndarray
                ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The bounding box of the vertices the faces use."""
    mask = np.zeros(len(vertices), dtype=bool)
    mask[faces.ravel()] = True
    used = vertices[mask]
    lo, hi = used.min(axis=0), used.max(axis=0)
    if not float((hi - lo).max()) > 0:
        raise ValueError("the mesh has zero extent (all its vertices coincide); pass bounds")
    return tuple(lo.tolist()), tuple(hi.tolist())


def voxelize_mesh(mesh: Any, resolution: Union[int, tuple[int, int, int], None] = None, *,
                  bounds: Any = None,
                  voxel_size: Union[float, tuple[float, float, float], None] = None,
                  interior: bool = False, progress: Optional[Callable[[float], Any]] = None,
                  max_memory: Optional[int] = None, workers: Optional[int] = None,
                  executor: Any = None) -> Voxels:
    """Voxelize a triangle mesh: every voxel whose closed box meets a triangle, and no other.

    Parameters
    ----------
    mesh : (vertices, faces), pyvista.PolyData, trimesh.Trimesh or path
        ``vertices (v, 3)`` floats and ``faces (f, 3)`` vertex indices, any
        PyVista surface (polygons are triangulated), a trimesh mesh, or a
        ``.stl``, ``.ply``, ``.obj``, ``.vtk`` or ``.vtp`` file.
    resolution : int or (int, int, int), default: 256
        Voxels along the longest side of the bounds (cubic voxels), or per axis.
    bounds : ((x0, y0, z0), (x1, y1, z1)), optional
        The grid's box; by default the mesh's bounding box grown by half a
        voxel on every side (the rule of :func:`implicitvox.voxelize`).
        Triangles outside it are clipped away.
    voxel_size : float or (float, float, float), optional
        The voxels' edge length instead of ``resolution``.
    interior : bool, default: False
        Also store the voxels inside the mesh (as octants; see
        :mod:`implicitvox.triangles.fill`, which says what open meshes get).
    progress : callable, optional
        Called with the share of the work done (0 to 1).
    max_memory : int, optional
        Refuse (``MemoryError``) before starting when the estimated peak
        exceeds this many bytes; default half the available memory.
    workers : int, optional
        Processes to subdivide on (:func:`implicitvox.triangles.pairs.split_pairs`);
        default every core this process may use, one for a small run. The
        voxels are the same for any number; the interior is filled after, here.
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Run the pieces there instead (as :func:`implicitvox.voxelize`).

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
    vertices, faces = as_triangles(mesh)
    interior = validate.boolean(interior, "interior")
    run = Run.of(max_memory=max_memory, progress=progress, workers=workers, executor=executor)
    if not len(faces) and bounds is None:
        raise ValueError("the mesh has no triangles: pass bounds to get an empty voxelization")
    own = mesh_bounds(vertices, faces) if bounds is None else None
    grid = grid_of(own, bounds, resolution, voxel_size, "the mesh")
    name = os.fspath(mesh) if isinstance(mesh, (str, os.PathLike)) else type(mesh).__name__
    source = MeshSource(Triangles(vertices[faces]), name, interior, run)
    metadata = {"model": f"mesh {name}: {len(vertices)} vertices, {len(faces)} triangles"}
    return _voxelize_on(source, grid, run, metadata)


def triangle_surface(tris: Triangles, grid: Grid, run: Run, what: str,
                     interior: bool = False) -> np.ndarray:
    """Sorted Morton codes of the voxels the triangles meet
    (:func:`implicitvox.triangles.pairs.surface_codes`), after the estimate is
    refused over the ``run``'s budget (``interior``: counting the dense fill too),
    on the workers the estimate plans."""
    workers = run.workers_for(estimate_triangle_voxels(tris.v, grid))
    run.refuse(estimate_triangle_memory(tris.v, grid, interior, workers),
               f"voxelizing {what} at {grid.shape}")
    return surface_codes(tris, grid, progress=run.progress, workers=workers,
                         executor=run.executor)


def _voxelize_on(source: MeshSource, grid: Grid, run: Run, metadata: dict) -> Voxels:
    t0 = time.perf_counter()
    codes = triangle_surface(source.triangles, grid, run, "the mesh", source.interior)
    t1 = time.perf_counter()
    interior = interior_octants(grid, codes, source.triangles.v) if source.interior else {}
    tree = Octree.from_codes(codes, grid.depth, {}, presorted=True)
    metadata = dict(metadata, seconds_subdivide=t1 - t0,
                    seconds_total=time.perf_counter() - t0)
    return Voxels(grid, tree, interior, metadata, source=source)


def estimate_triangle_voxels(triangles: np.ndarray, grid: Grid) -> float:
    """Surface voxels, from the triangles' area (a plane meets at most
    ``sqrt(3) * area / h**2`` voxels), plus a few per triangle."""
    e1 = triangles[:, 1] - triangles[:, 0]
    e2 = triangles[:, 2] - triangles[:, 0]
    h = np.asarray(grid.voxel_size)
    # area in voxel units: scale each axis by its voxel size
    area = 0.5 * np.linalg.norm(np.cross(e1 / h, e2 / h), axis=1).sum() if len(triangles) else 0.0
    return min(1.8 * area + 8 * len(triangles), float(np.prod(grid.shape)))


def estimate_triangle_memory(triangles: np.ndarray, grid: Grid, interior: bool,
                         workers: int = 1) -> int:
    """Peak bytes: the surface voxels (:func:`estimate_triangle_voxels`), the dense
    fill when ``interior``, and with ``workers`` each worker's copy of the
    triangles and its share of the voxels."""
    voxels = estimate_triangle_voxels(triangles, grid)
    need = voxels * _BYTES_PER_VOXEL + len(triangles) * 200
    if workers > 1:
        need += workers * (len(triangles) * 200 + 2 * voxels * _BYTES_PER_VOXEL / workers)
    if interior:
        need += float(np.prod(grid.shape)) * BYTES_PER_VOXEL
    return int(need)
