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
from typing import Any, Callable, Optional, Union

import numpy as np

from . import morton
from .function import Function
from .grid import Grid
from .octree import Octree
from .shape import as_shape, exact_classifier, voxel_classifier
from .subdivide import RECHECK, subdivide
from .voxels import Voxels

__all__ = ["voxelize", "estimate_memory", "memory_budget", "refine_voxels"]

#: bytes per surface voxel while collecting and building (coords, codes, sort, tree)
_BYTES_PER_VOXEL = 48
_BYTES_PER_NORMAL = 24
_PILOT_DEPTH = 6


def _default_budget() -> int:
    """Half the memory available now (Linux), else 8 GiB."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024 // 2
    except OSError:
        pass
    return 8 << 30


def memory_budget(max_memory: Any) -> int:
    """The byte budget of a run: ``max_memory`` (checked), or half the available memory."""
    if max_memory is None:
        return _default_budget()
    if isinstance(max_memory, bool) or not isinstance(max_memory, (int, np.integer)) \
            or max_memory <= 0:
        raise ValueError(f"max_memory must be a positive number of bytes, got {max_memory!r}")
    return int(max_memory)


def estimate_memory(func: Function, grid: Grid, normals: bool = False) -> tuple[int, int]:
    """Estimated surface voxels and peak bytes of a voxelization.

    A pilot subdivision to depth ``min(depth, 6)`` counts the AMBIGUOUS
    octants there and extrapolates with Stolte's growth factor of 4 per level
    (§4.1.3); the working set of the subdivision itself is bounded.
    """
    depth = grid.depth
    pilot_depth = min(depth, _PILOT_DEPTH)
    scale = 1 << (depth - pilot_depth)
    pilot = Grid(grid.origin, tuple(h * scale for h in grid.voxel_size),
                 tuple(-(-n // scale) for n in grid.shape))
    # The pilot's voxels are unions of grid voxels; crop effects are ignored.
    # No recheck: the pilot is cheaper and its count an upper estimate.
    found = len(subdivide(func, pilot, recheck=0.0).codes)
    voxels = found * 4 ** (depth - pilot_depth)
    per_voxel = _BYTES_PER_VOXEL + (_BYTES_PER_NORMAL if normals else 0)
    working = 8 * (1 << 17) * max(depth, 1) * 64  # chunks on the stack, interval arrays
    return int(voxels), int(voxels * per_voxel + working)


def _compute_normals(func: Function, grid: Grid, coords: np.ndarray,
                     chunk: int = 1 << 18) -> np.ndarray:
    """Unit gradients at voxel centres (Stolte §2), float32; zero where undefined."""
    out = np.zeros((len(coords), 3), dtype=np.float32)
    for s in range(0, len(coords), chunk):
        c = grid.centers(coords[s:s + chunk])
        _, g = func.gradient(c[:, 0], c[:, 1], c[:, 2])
        norm = np.linalg.norm(g, axis=1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = np.where((norm > 0) & np.isfinite(norm), g / norm, 0.0)
        out[s:s + chunk] = unit
    return out


def voxelize(shape: Any, bounds: Any = None, resolution: Union[int, tuple[int, int, int]] = 256,
             *, interior: bool = False, normals: bool = False,
             progress: Optional[Callable[[float], Any]] = None,
             max_memory: Optional[int] = None, mean_value: bool = False,
             subvoxel: int = 0, recheck: float = RECHECK) -> Voxels:
    """Voxelize a shape: every voxel whose closed box the surface meets is output.

    Interval arithmetic rejects octants the surface cannot meet and
    subdivides the rest (Stolte §2); if the shape has an exact box test
    (Varadhan §5.1) it settles what intervals leave open.

    Parameters
    ----------
    shape : Expr or Shape
        The implicit function ``f`` (solid ``f <= 0``) or a shape object.
    bounds : ((x0, y0, z0), (x1, y1, z1)), optional
        The grid's box; required when the shape has no ``bounds``.
    resolution : int or (int, int, int), default: 256
        Voxels along the longest side (others in proportion), or per axis.
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
        the mean value form (:mod:`implicitvox.mean_value`); about 3-4x the
        time, 10-15% fewer false voxels on curved surfaces.
    subvoxel : int, default: 0
        Sub-voxel refinement: keep a voxel only if one of its ``8**subvoxel``
        sub-voxels stays AMBIGUOUS. Tighter (never a miss), about
        ``4**subvoxel`` times the work.
    recheck : float, default: 0.25
        Sub-voxel refinement for the suspect voxels alone: those whose
        enclosure reaches 0 only by the amount it overestimates ``f``, as
        estimated from the voxel's siblings
        (:func:`implicitvox.subdivide.suspect_voxels`). 0.25 rechecks the
        voxels predicted to be settled (about 10% of them, adding about 30%
        to the time); larger values recheck more, up to nearly all at 4; 0
        turns it off. Ignored for shapes with an exact voxel test.

    Returns
    -------
    Voxels

    Raises
    ------
    ValueError
        For bad bounds or resolution.
    MemoryError
        When the estimate exceeds ``max_memory``.
    """
    shape = as_shape(shape)
    if bounds is None:
        bounds = getattr(shape, "bounds", None)
        if bounds is None:
            raise ValueError("bounds is required: the shape has no bounds of its own; pass "
                             "bounds=((x0, y0, z0), (x1, y1, z1))")
    budget = memory_budget(max_memory)
    if isinstance(subvoxel, bool) or not isinstance(subvoxel, (int, np.integer)) \
            or not 0 <= subvoxel <= 4:
        raise ValueError(f"subvoxel must be an int from 0 to 4, got {subvoxel!r}")
    if isinstance(recheck, bool) or not isinstance(recheck, (int, float, np.floating)) \
            or not 0.0 <= recheck <= 4.0:
        raise ValueError(f"recheck must be a number from 0 to 4, got {recheck!r}")
    grid = Grid.from_bounds(bounds, resolution)
    if grid.depth + subvoxel > 21:
        raise ValueError(f"resolution {grid.shape} with subvoxel={subvoxel} exceeds the octree's "
                         "21 levels")
    func = Function(shape.expr)
    estimated_voxels, estimated_bytes = estimate_memory(func, grid, normals)
    if estimated_bytes > budget:
        raise MemoryError(
            f"voxelizing at {grid.shape} needs an estimated {estimated_bytes / 2**30:.2f} GiB "
            f"(~{estimated_voxels:,} surface voxels), over the budget of {budget / 2**30:.2f} GiB; "
            "lower the resolution or raise max_memory")
    options = {"interior": interior, "normals": normals, "mean_value": bool(mean_value),
               "subvoxel": int(subvoxel), "recheck": float(recheck)}
    return _run(shape, func, grid, options, progress, start=None, interior_before=None,
                estimated_voxels=estimated_voxels)


def _run(shape, func, grid, options, progress, start, interior_before, estimated_voxels=None):
    t0 = time.perf_counter()
    result = _subdivide(func, grid, options, (exact_classifier(shape), voxel_classifier(shape)),
                        progress, start)
    t1 = time.perf_counter()
    payload = {}
    if options["normals"]:
        payload["normals"] = _compute_normals(func, grid, result.surface)
    tree = Octree.from_codes(result.codes, grid.depth, payload)
    interior = dict(interior_before or {})
    for level, coords in result.interior.items():
        interior[level] = np.concatenate([interior[level], coords]) if level in interior else coords
    metadata = {
        "model": repr(shape.expr)[:2000],
        "seconds_subdivide": t1 - t0,
        "seconds_total": time.perf_counter() - t0,
        "boxes_evaluated": result.evaluated,
        "estimated_voxels": estimated_voxels if estimated_voxels is not None else -1,
        "implicitvox": _version(),
    }
    return Voxels(grid, tree, interior, metadata, shape=shape, options=options)


def _subdivide(func, grid, options, exact, progress, start):
    """Subdivide on the grid, or on a finer one mapped back (``subvoxel``)."""
    s = options["subvoxel"]
    exact_boxes, exact_voxels = exact
    result = subdivide(func, grid.finer(s) if s else grid, start=start,
                       interior=options["interior"], exact=exact_boxes, progress=progress,
                       mean_value=options["mean_value"], exact_voxels=exact_voxels,
                       recheck=options.get("recheck", RECHECK))
    if not s:
        return result
    result.codes = np.unique(result.codes >> np.uint64(3 * s))   # the voxels holding them
    result.interior = _interior_from_subvoxels(result.interior, grid, s)
    return result


def _interior_from_subvoxels(interior, grid, s):
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
        whole = morton.decode(uniq[covered == 8 ** s]).astype(np.int32)
        if len(whole):
            kept[depth] = np.concatenate([kept[depth], whole]) if depth in kept else whole
    return kept


def _version() -> str:
    from . import __version__
    return __version__


def refine_voxels(vox: Voxels, levels: int, progress=None) -> Voxels:
    """``vox`` continued ``levels`` levels deeper (see :meth:`Voxels.refine`)."""
    if isinstance(levels, bool) or not isinstance(levels, (int, np.integer)) or levels < 1:
        raise ValueError(f"levels must be a positive int, got {levels!r}")
    if vox._shape is None:
        raise ValueError("refine needs the shape: these voxels were loaded from a file; "
                         "voxelize the shape again at the finer resolution")
    grid = vox.grid.finer(levels)
    coords = vox.coords().astype(np.int32)
    # The stored surface voxels are the AMBIGUOUS octants at the old depth: go on from there.
    func = Function(vox._shape.expr)
    return _run(vox._shape, func, grid, dict(vox._options), progress,
                start=(vox.grid.depth, coords), interior_before=vox.interior)
