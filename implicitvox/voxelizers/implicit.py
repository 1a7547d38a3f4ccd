"""``voxelize``: a shape to the voxels its surface passes through, none missed.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z, sqrt
>>> vox = iv.voxelize(sqrt(x**2 + y**2 + z**2) - 1, bounds=((-1.5,) * 3, (1.5,) * 3),
...                   resolution=32, normals=True)
>>> vox.count > 1000, vox.normals.shape[1]
(True, 3)
"""
from __future__ import annotations

import time
import warnings
from typing import Any, Callable, Optional, Union

import numpy as np

from .. import batches
from ..version import __version__
from ..eval.function import Function
from ..expr.shape import as_shape, exact_classifier, surface_normals, voxel_classifier
from ..expr.nodes import source_preview
from ..meshing.mesher import REFINE, mesh, mesh_grid
from ..octree.morton import MAX_BITS
from ..octree.grid import Grid, grid_of
from ..octree.pilot import Estimate, estimate_surface
from ..octree.run import Run
from ..octree.store import Octree
from ..octree.subdivide import RECHECK
from ..octree.surface import (SurfaceOptions, subdivide_voxels, surface_payload, unit_vectors,
                              voxel_normals)
from ..octree.subtrees import parallel_bytes, subdivide_in_parallel
from ..octree.voxels import Voxels
from .. import validate

__all__ = ["voxelize", "estimate_memory", "bytes_per_voxel", "grid_of", "ImplicitSource",
           "voxel_normals"]

#: bytes per surface voxel while collecting and building (coords, codes, sort, tree)
_BYTES_PER_VOXEL = 48
_BYTES_PER_NORMAL = 24
#: bytes of working interval arrays per box in a chunk (a few dozen float64 registers)
_BYTES_PER_BOX = 512
#: a run whose surface voxels are at least this share of a grid of at least
#: USELESS_MIN_CELLS voxels is flagged with a warning
USELESS_SHARE = 0.5
USELESS_MIN_CELLS = 4096


def estimate_memory(func: Function, grid: Grid, normals: bool = False, prune: bool = True
                    ) -> tuple[Estimate, int]:
    """The pilot's estimate of the surface voxels
    (:func:`implicitvox.octree.pilot.estimate_surface`) and the peak bytes of a
    serial voxelization: the kept voxels and the subdivision's working arrays."""
    estimate = estimate_surface(func, grid, prune=prune)
    return estimate, int(estimate.voxels * bytes_per_voxel(normals) + working_bytes(grid))


def working_bytes(grid: Grid) -> int:
    """The subdivision's working arrays: one chunk of boxes in flight (a small grid
    has small chunks, so a small job is never refused under a small budget)."""
    cells = int(np.prod(grid.shape, dtype=np.float64))
    return min(batches.FRONTIER, cells) * _BYTES_PER_BOX


def bytes_per_voxel(normals: bool) -> int:
    """Peak bytes per kept surface voxel: collecting, sorting and building the tree,
    and the normals when stored."""
    return _BYTES_PER_VOXEL + (_BYTES_PER_NORMAL if normals else 0)


class ImplicitSource:
    """The shape and options a :class:`Voxels` came from (its
    :class:`~implicitvox.octree.voxels.VoxelSource`)."""

    def __init__(self, shape: Any, func: Function, options: SurfaceOptions, run: Run):
        self.shape = shape
        self.func = func
        self.options = options
        #: the run it came from: :meth:`refine` uses its workers and executor again
        self.run = run

    def refine(self, voxels: Voxels, levels: int, progress: Any = None,
               max_memory: Optional[int] = None) -> Voxels:
        """Continue from the stored surface voxels (the AMBIGUOUS octants at the
        old depth) on ``voxels.grid.finer(levels)``, under the memory budget."""
        grid = voxels.grid.finer(levels)
        coords = voxels.coords().astype(np.int32)
        return _run(self, grid, self.run.again(max_memory=max_memory, progress=progress),
                    start=(voxels.grid.depth, coords), interior_before=voxels.interior)

    def to_mesh(self, voxels: Voxels, tolerance: Optional[float] = None, *,
                refine: Optional[int] = None, progress: Any = None,
                max_memory: Optional[int] = None) -> Any:
        """:func:`implicitvox.mesh` of the shape over the voxels' bounds: on their
        grid, or on the grid ``tolerance`` picks."""
        levels = REFINE if refine is None else validate.int_in(refine, "refine", 0, 12)
        if tolerance is not None:
            return mesh(self.shape, tolerance, bounds=voxels.grid.bounds, refine=levels,
                        progress=progress, max_memory=max_memory, prune=self.options.prune)
        if voxels.grid.depth + levels > MAX_BITS:
            raise ValueError(f"to_mesh with refine={levels} on a depth-{voxels.grid.depth} "
                             f"grid needs more than the octree's {MAX_BITS} levels; lower refine")
        return mesh_grid(self.shape, voxels.grid, Run.of(max_memory=max_memory,
                                                         progress=progress),
                         refine=levels, prune=self.options.prune)

    def normals_at(self, points: np.ndarray) -> np.ndarray:
        """Unit normals at ``points`` (n, 3): the shape's own where its function only
        bounds it (:func:`implicitvox.expr.shape.surface_normals`), else the unit
        gradients of its function."""
        own = surface_normals(self.shape)
        if own is not None and len(points):
            return np.asarray(own(points), dtype=np.float32)
        _, g = self.func.gradient(points[:, 0], points[:, 1], points[:, 2])
        return unit_vectors(g)

    def __repr__(self) -> str:
        return f"<ImplicitSource {self.shape!r:.60}>"


def voxelize(shape: Any, resolution: Union[int, tuple[int, int, int], None] = None, *,
             bounds: Any = None, voxel_size: Union[float, tuple[float, float, float], None] = None,
             interior: bool = False, normals: bool = False,
             progress: Optional[Callable[[float], Any]] = None,
             max_memory: Optional[int] = None, mean_value: bool = False,
             subvoxel: int = 0, recheck: float = RECHECK, prune: bool = True,
             workers: Optional[int] = None, executor: Any = None) -> Voxels:
    """Voxelize a shape: every voxel whose closed box the surface meets is output.

    Interval arithmetic rejects octants the surface cannot meet and
    subdivides the rest (Stolte §2); if the shape has an exact box test
    (Varadhan §5.1) it settles what intervals leave open.

    Parameters
    ----------
    shape : Expr or Shape
        The implicit function ``f`` (solid ``f <= 0``) or a shape object.
    resolution : int or (int, int, int), default: 256
        Voxels along the longest side of the bounds (cubic voxels), or per
        axis (non-cubic, only when asked for). Give this or ``voxel_size``.
    bounds : ((x0, y0, z0), (x1, y1, z1)), optional
        The grid's box; by default the shape's own bounds grown by half a
        voxel on every side (:func:`implicitvox.octree.grid.padded_bounds`,
        the rule every entry point uses). Required when the shape has none.
    voxel_size : float or (float, float, float), optional
        The voxels' edge length instead of ``resolution``.
    interior : bool, default: False
        Also record the octants inside the solid (``f < 0`` over the box).
    normals : bool, default: False
        Store unit gradients at the surface voxel centres.
    progress : callable, optional
        Called with the estimated share of work done (0 to 1).
    max_memory : int, optional
        Refuse (``MemoryError``) before starting when the estimated peak
        exceeds this many bytes; default half the available memory.
    mean_value : bool, default: False
        Tighten octants the natural interval extension leaves AMBIGUOUS with
        the mean value form (:mod:`implicitvox.eval.mean_value`); about 3-4x
        the time, 10-15% fewer false voxels on curved surfaces.
    subvoxel : int, default: 0
        Sub-voxel refinement: keep a voxel only if one of its ``8**subvoxel``
        sub-voxels stays AMBIGUOUS. Tighter (never a miss), about
        ``4**subvoxel`` times the work.
    recheck : float, default: 0.25
        Sub-voxel refinement for the suspect voxels alone: those whose
        enclosure reaches 0 only by the amount it overestimates ``f``, as
        estimated from the voxel's siblings
        (:func:`implicitvox.octree.subdivide.suspect_voxels`). 0.25 rechecks
        the voxels predicted to be settled (about 10% of them, adding about
        30% to the time); larger values recheck more, up to nearly all at 4;
        0 turns it off. Ignored for shapes with an exact voxel test.
    prune : bool, default: True
        Evaluate each region with the expression pruned to the branches of
        ``min``, ``max`` and ``abs`` that can still matter there
        (:mod:`implicitvox.eval.pruning`): a union of many parts costs, near
        each voxel, about what the parts near it cost. The voxels, interior
        and normals are bit-identical with ``prune=False``.
    workers : int, optional
        Threads or processes to subdivide on (Stolte §5.2,
        :mod:`implicitvox.octree.subtrees`): threads of this process for a
        model on the compiled kernel (:mod:`implicitvox.octree.descend`, which
        releases the GIL), processes for the others. Default: every core this
        process may use, or one (serial) for a run estimated below
        :data:`implicitvox.parallel.MIN_PARALLEL_WORK` surface voxels.
        The voxels, interior and normals are bit-identical for any number.
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Run the pieces there instead (a Dask client: on its cluster;
        ``workers`` then only sets how finely the work is cut, default the
        cluster's threads).

    Returns
    -------
    Voxels
        Its ``metadata`` records the run: ``seconds_subdivide``,
        ``seconds_total``, ``boxes_evaluated``, ``tapes_built`` (pruned tapes),
        ``estimated_voxels``, ``workers`` and ``parallel`` (where they ran:
        ``"serial"``, ``"threads"``, ``"processes"`` or ``"executor"``).

    Raises
    ------
    ValueError
        For bad bounds, resolution or options (the message names the parameter).
    MemoryError
        When the estimate exceeds ``max_memory``.
    """
    shape = as_shape(shape)
    run = Run.of(max_memory=max_memory, progress=progress, workers=workers, executor=executor)
    options = SurfaceOptions.of(interior=interior, normals=normals, mean_value=mean_value,
                                subvoxel=subvoxel, recheck=recheck, prune=prune)
    grid = grid_of(getattr(shape, "bounds", None), bounds, resolution, voxel_size)
    options.check_depth(grid)
    func = Function(shape.expr)
    return _run(ImplicitSource(shape, func, options, run), grid, run, start=None,
                interior_before=None)


def _run(source: ImplicitSource, grid: Grid, run: Run, start, interior_before) -> Voxels:
    """Estimate, refuse over the budget, then subdivide under a guard of the same budget."""
    shape, func, options = source.shape, source.func, source.options
    estimate, estimated_bytes = estimate_memory(func, grid, options.normals, options.prune)
    workers = run.workers_for(estimate.voxels)
    per_voxel = bytes_per_voxel(options.normals)
    if workers > 1:
        estimated_bytes = parallel_bytes(estimate.voxels, per_voxel, working_bytes(grid),
                                         workers)
    what = f"voxelizing at {grid.shape}"
    run.refuse(estimated_bytes, f"{what} ({estimate.explained()}"
               + (f"; {workers} workers)" if workers > 1 else ")"))
    guard = run.guard(what, per_voxel, estimated=estimate.voxels, working=working_bytes(grid))
    t0 = time.perf_counter()
    split = None
    if workers > 1 or run.executor is not None:
        split = subdivide_in_parallel(shape, func, grid, options, run, workers=workers,
                                      start=start, per_voxel=per_voxel, guard=guard,
                                      what=what, estimated=estimate.voxels)
    if split is None:
        result = subdivide_voxels(func, grid, options,
                                  (exact_classifier(shape), voxel_classifier(shape)),
                                  run.progress, start, guard)
        payload = surface_payload(func, grid, result, options.normals)
        count = len(result.codes)
    else:
        result, count = split.result, split.count
    t1 = time.perf_counter()
    _warn_if_useless(count, grid)
    tree = Octree.from_codes(result.codes, grid.depth, payload) if split is None else split.tree
    if options.normals and surface_normals(shape) is not None and count:
        # the function only bounds the solid: its gradient says nothing of the surface
        tree.payload["normals"] = source.normals_at(grid.centers(tree.coords()))
    interior = dict(interior_before or {})
    for level, coords in result.interior.items():
        interior[level] = np.concatenate([interior[level], coords]) if level in interior else coords
    metadata = {
        "model": source_preview(func.expr, 2000),
        "seconds_subdivide": t1 - t0,
        "seconds_total": time.perf_counter() - t0,
        "boxes_evaluated": result.evaluated,
        "tapes_built": result.tapes_built,
        "estimated_voxels": estimate.voxels,
        "workers": workers if split is not None else 1,
        "parallel": split.on if split is not None else "serial",
        "implicitvox": __version__,
    }
    return Voxels(grid, tree, interior, metadata, source=source)


def _warn_if_useless(count: int, grid: Grid) -> None:
    """Warn when the surface voxels are most of the grid: the intervals could not
    tell inside from outside, and the voxels say little about the shape."""
    cells = int(np.prod(grid.shape, dtype=np.float64))
    if cells >= USELESS_MIN_CELLS and count >= USELESS_SHARE * cells:
        warnings.warn(f"{count:,} of the grid's {cells:,} voxels ({count / cells:.0%}) are "
                      "surface voxels: interval arithmetic could not separate inside from "
                      "outside (detail finer than a voxel, catastrophic cancellation, or a "
                      "scale below the float resolution); check the model's scale or the "
                      "resolution", UserWarning, stacklevel=4)
