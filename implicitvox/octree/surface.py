"""The voxelizer's subdivision: on the voxel grid or on sub-voxels, and the normals.

Shared by the serial run (:mod:`implicitvox.voxelizers.implicit`) and the
workers of a parallel one (:mod:`implicitvox.octree.subtrees`), so both
classify, map sub-voxels and compute normals with the same code.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from .. import batches
from .. import validate
from ..eval.function import Function
from ..eval.gradient import evaluate_gradients
from . import morton
from .grid import Grid
from .guard import MemoryGuard
from .morton import MAX_BITS
from .octants import PrunedTapes, TapeRuns, recount, run_counts
from .subdivide import RECHECK, Subdivision, subdivide

__all__ = ["SurfaceOptions", "subdivide_voxels", "interior_from_subvoxels", "voxel_normals",
           "unit_vectors", "surface_payload"]


@dataclass(frozen=True)
class SurfaceOptions:
    """The options of the voxelizer's subdivision, named as :func:`implicitvox.voxelize`'s
    parameters (its docstring says what each does); :meth:`of` checks them.

    >>> SurfaceOptions.of(subvoxel=2).subvoxel
    2
    """

    interior: bool = False
    normals: bool = False
    mean_value: bool = False
    subvoxel: int = 0
    recheck: float = RECHECK
    prune: bool = True

    @classmethod
    def of(cls, *, interior: Any = False, normals: Any = False, mean_value: Any = False,
           subvoxel: Any = 0, recheck: Any = RECHECK, prune: Any = True) -> "SurfaceOptions":
        """The options, each checked (``ValueError`` naming the parameter)."""
        return cls(interior=validate.boolean(interior, "interior"),
                   normals=validate.boolean(normals, "normals"),
                   mean_value=validate.boolean(mean_value, "mean_value"),
                   subvoxel=validate.int_in(subvoxel, "subvoxel", 0, 4),
                   recheck=validate.number_in(recheck, "recheck", 0.0, 4.0),
                   prune=validate.boolean(prune, "prune"))

    def check_depth(self, grid: Grid) -> None:
        """``ValueError`` when the grid's levels and the sub-voxel levels pass the octree's."""
        if grid.depth + self.subvoxel > MAX_BITS:
            raise ValueError(f"resolution {grid.shape} with subvoxel={self.subvoxel} exceeds "
                             f"the octree's {MAX_BITS} levels")

_NORMALS_CHUNK = batches.NORMALS


def voxel_normals(func: Function, grid: Grid, coords: np.ndarray,
                  tapes: Optional[list] = None) -> np.ndarray:
    """Unit gradients at voxel centres (Stolte §2), float32; zero where undefined.

    ``tapes``: runs ``(count, tape)`` over ``coords`` of tapes valid over the
    voxels (the pruned tapes :attr:`Subdivision.tapes`; the same gradients,
    bit for bit, in fewer operations); default the function's own tape."""
    out = np.zeros((len(coords), 3), dtype=np.float32)
    if isinstance(tapes, TapeRuns) and tapes.pool is not None:
        from ..eval.pool_gradients import pool_gradients, takes_pool   # (loads Numba)
        if takes_pool(tapes.pool):
            return _pool_normals(tapes, grid, coords, out, pool_gradients)
    runs = tapes if tapes is not None else [(len(coords), func.tape)]
    start = 0
    for count, tape in runs:
        for s in range(start, start + count, _NORMALS_CHUNK):
            e = min(s + _NORMALS_CHUNK, start + count)
            c = grid.centers(coords[s:e])
            _, g = evaluate_gradients(tape, c[:, 0], c[:, 1], c[:, 2])
            out[s:e] = unit_vectors(g.T)
        start += count
    return out


def _pool_normals(runs: TapeRuns, grid: Grid, coords: np.ndarray, out: np.ndarray,
                  pool_gradients) -> np.ndarray:
    """:func:`voxel_normals` on the pool tapes of ``runs`` in compiled code
    (:mod:`implicitvox.eval.pool_gradients`), in chunks of voxels."""
    ends = np.cumsum(runs.counts)
    starts = ends - runs.counts
    for s in range(0, len(coords), _NORMALS_CHUNK):
        e = min(s + _NORMALS_CHUNK, len(coords))
        first, last = np.searchsorted(ends, s, side="right"), np.searchsorted(starts, e)
        counts = np.minimum(ends[first:last], e) - np.maximum(starts[first:last], s)
        c = grid.centers(coords[s:e])
        _, g = pool_gradients(runs.pool, runs.ids[first:last], counts, c[:, 0], c[:, 1],
                              c[:, 2])
        out[s:e] = unit_vectors(g.T)
    return out


def unit_vectors(g: np.ndarray) -> np.ndarray:
    """Rows of ``g`` (n, 3) scaled to unit length, float32; zero where the length is
    zero or not finite."""
    norm = np.linalg.norm(g, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where((norm > 0) & np.isfinite(norm), g / norm, 0.0).astype(np.float32)


def surface_payload(func: Function, grid: Grid, result: Subdivision, normals: bool) -> dict:
    """The per-voxel arrays stored with ``result``'s voxels (in the order of its codes)."""
    if not normals:
        return {}
    return {"normals": voxel_normals(func, grid, result.surface, result.tapes)}


def subdivide_voxels(func: Function, grid: Grid, options: SurfaceOptions, exact: tuple,
                     progress: Any = None, start: Any = None, guard: Optional[MemoryGuard] = None,
                     until_level: Optional[int] = None,
                     start_tapes: Optional[PrunedTapes] = None) -> Subdivision:
    """:func:`implicitvox.octree.subdivide.subdivide` with the voxelizer's
    ``options`` on ``grid``, or on ``grid.finer(subvoxel)`` mapped back to
    ``grid``'s voxels. ``exact``: the shape's box and voxel tests;
    ``until_level`` (at most ``grid.depth``) stops there and returns the
    pending subtrees (:attr:`Subdivision.pending`, levels of the grid
    subdivided; their tapes in ``pending_tapes``, which ``start_tapes`` takes
    back)."""
    s = options.subvoxel
    exact_boxes, exact_voxels = exact
    result = subdivide(func, grid.finer(s) if s else grid, start=start,
                       interior=options.interior, exact=exact_boxes, progress=progress,
                       mean_value=options.mean_value, exact_voxels=exact_voxels,
                       recheck=options.recheck, guard=guard, prune=options.prune,
                       leaf_level=grid.depth, until_level=until_level,
                       start_tapes=start_tapes)
    if not s:
        return result
    # the voxels holding them, each with the tape of one of its sub-voxels (all have the voxel's)
    run_of = np.repeat(np.arange(len(result.tapes)), run_counts(result.tapes))
    result.codes, first = np.unique(result.codes >> np.uint64(3 * s), return_index=True)
    order = np.argsort(run_of[first], kind="stable")
    result.codes = result.codes[order]
    counts = np.bincount(run_of[first], minlength=len(result.tapes))
    result.tapes = recount(result.tapes, counts)
    result.interior = interior_from_subvoxels(result.interior, grid, s)
    return result


def interior_from_subvoxels(interior: dict, grid: Grid, s: int) -> dict:
    """FULL octants above the voxel level stay; below it, a voxel is interior
    when FULL sub-octants cover all of it."""
    depth = grid.depth
    kept = {lvl: c for lvl, c in interior.items() if lvl <= depth}
    voxels, weights = [], []
    for lvl, c in interior.items():
        if lvl > depth:
            voxels.append(c >> (lvl - depth))
            weights.append(np.full(len(c), 8 ** (depth + s - lvl), dtype=np.int64))
    if voxels:
        codes = morton.encode(np.concatenate(voxels))
        uniq, inverse = np.unique(codes, return_inverse=True)
        covered = np.bincount(inverse, weights=np.concatenate(weights))
        whole = uniq[covered == 8 ** s]
        if len(whole):
            if depth in kept:   # the union, in Morton order
                whole = np.sort(np.concatenate([morton.encode(kept[depth]), whole]))
            kept[depth] = morton.decode(whole).astype(np.int32)
    return kept
