"""``voxelize_bezier``: every voxel a Bézier patch meets (Stolte §4.2).

The patches are cut into flat pieces with a certified distance
(:func:`implicitvox.triangles.patches.bezier_triangles`), and the pieces, grown by
that distance, voxelized exactly (:mod:`implicitvox.triangles.pairs`).

Examples
--------
>>> import implicitvox as iv
>>> vox = iv.voxelize_bezier(iv.utah_teapot(), 32)
>>> vox.count > 500
True
"""
from __future__ import annotations

import time
from typing import Any, Callable, Iterable, Optional, Union

import numpy as np

from .. import validate
from ..triangles.patches import BezierPatch, bezier_triangles
from ..triangles.tribox import Triangles
from ..octree.grid import Grid, grid_of
from ..octree.run import Run
from ..octree.store import Octree
from ..octree.voxels import Voxels
from .mesh import nearest_triangle_normals, triangle_surface

__all__ = ["voxelize_bezier", "BezierSource"]


class BezierSource:
    """The patches a :class:`Voxels` came from (its
    :class:`~implicitvox.octree.voxels.VoxelSource`)."""

    def __init__(self, patches: list[BezierPatch], flatness: float, run: Run):
        self.patches = patches
        self.flatness = flatness
        #: the run it came from: :meth:`refine` uses its workers and executor again
        self.run = run

    def refine(self, voxels: Voxels, levels: int, progress: Any = None,
               max_memory: Optional[int] = None) -> Voxels:
        """The patches voxelized on ``voxels.grid.finer(levels)`` (the same edges)."""
        return _voxelize_on(self, voxels.grid.finer(levels),
                            self.run.again(max_memory=max_memory, progress=progress),
                            dict(voxels.metadata))

    def normals_at(self, points: np.ndarray) -> np.ndarray:
        """Unit normals at ``points`` of the nearest flat piece of the patches (for shading)."""
        span = np.ptp(np.concatenate([p.control_points.reshape(-1, 3) for p in self.patches]), 0)
        tri, _ = bezier_triangles(self.patches, np.full(3, 1e-3 * span.max()))
        return nearest_triangle_normals(tri, points)

    def __repr__(self) -> str:
        return f"<{len(self.patches)} Bezier patches>"


def voxelize_bezier(patches: Union[BezierPatch, Iterable[BezierPatch]],
                    resolution: Union[int, tuple[int, int, int], None] = None, *,
                    bounds: Any = None,
                    voxel_size: Union[float, tuple[float, float, float], None] = None,
                    flatness: float = 0.125,
                    progress: Optional[Callable[[float], Any]] = None,
                    max_memory: Optional[int] = None, workers: Optional[int] = None,
                    executor: Any = None) -> Voxels:
    """Voxelize Bézier patches: every voxel a patch meets is output (Stolte §4.2).

    Parameters
    ----------
    patches : BezierPatch or iterable of BezierPatch
    resolution : int or (int, int, int), default: 256
        Voxels along the longest side of the bounds (cubic voxels), or per axis.
    bounds : ((x0, y0, z0), (x1, y1, z1)), optional
        Default: the control nets' box grown by half a voxel on every side
        (the rule of :func:`implicitvox.voxelize`).
    voxel_size : float or (float, float, float), optional
        The voxels' edge length instead of ``resolution``.
    flatness : float, default: 0.125
        Sub-patches are split until they lie within this many voxels of two
        flat triangles; the voxels within that distance of the patch may be
        output too (smaller: tighter, more splitting).
    progress : callable, optional
        Called with the share of the work done (0 to 1).
    max_memory : int, optional
        Refuse (``MemoryError``) before voxelizing when the estimated peak
        (from the flat pieces' area) exceeds this many bytes; default half the
        available memory.
    workers : int, optional
        Processes to voxelize the flat pieces on (as :func:`implicitvox.voxelize_mesh`);
        default every core this process may use, one for a small run.
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Run the pieces there instead.

    Returns
    -------
    Voxels
    """
    run = Run.of(max_memory=max_memory, progress=progress, workers=workers, executor=executor)
    if isinstance(patches, BezierPatch):
        patches = [patches]
    patches = list(patches)
    for i, p in enumerate(patches):
        if not isinstance(p, BezierPatch):
            raise TypeError(f"patches[{i}] must be a BezierPatch, got {type(p).__name__}")
    flatness = validate.number_in(flatness, "flatness", 0, 4, open_low=True)
    own = None
    if bounds is None:
        if not patches:
            raise ValueError("no patches: pass bounds to get an empty voxelization")
        nets = np.concatenate([p.control_points.reshape(-1, 3) for p in patches])
        own = (tuple(nets.min(0).tolist()), tuple(nets.max(0).tolist()))
    grid = grid_of(own, bounds, resolution, voxel_size, "the patches")
    metadata = {"model": f"{len(patches)} Bezier patches", "flatness": flatness}
    source = BezierSource(patches, flatness, run)
    return _voxelize_on(source, grid, run, metadata)


def _voxelize_on(source: BezierSource, grid: Grid, run: Run, metadata: dict) -> Voxels:
    t0 = time.perf_counter()
    tri, dil = bezier_triangles(source.patches, source.flatness * np.asarray(grid.voxel_size))
    codes = triangle_surface(Triangles(tri, dil), grid, run, "the patches")
    tree = Octree.from_codes(codes, grid.depth, {}, presorted=True)
    metadata = dict(metadata, seconds_total=time.perf_counter() - t0)
    return Voxels(grid, tree, {}, metadata, source=source)
