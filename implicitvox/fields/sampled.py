"""``distance_field``: a shape's signed distance sampled in a narrow band (Varadhan §4.2,
Bærentzen §3.2).

The surface voxels come from the voxelizer (none missed, so the band holds
every sample near the surface); the band's samples get the most exact
distance the shape allows (:mod:`.kernels`), with a bound on its error.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z
>>> field = iv.distance_field(x * x + y * y + z * z - 1, 24, band=1,
...                           bounds=((-1.5,) * 3, (1.5,) * 3))
>>> field.kind, field.max_error <= 1e-3 * field.grid.voxel_size[0]
('certified', True)
"""
from __future__ import annotations

import math
import time
import warnings
from typing import Any, Callable, Optional, Union

import numpy as np

from .. import validate
from ..expr.nodes import Expr
from ..expr.shape import as_shape
from ..linf.triangle_mesh import TriangleMesh
from ..octree.grid import padded_bounds
from ..octree.run import Run
from ..triangles.inputs import as_triangles
from ..triangles.weld import weld
from ..voxelizers.implicit import voxelize
from ..voxelizers.mesh import voxelize_mesh
from .bricks import BRICK, MAX_BAND, all_bricks, band_steps, in_grid, masked_coords
from .band_chunks import DistanceKernel, band_distances, mesh_band_distances
from .field import DTYPES, NORMS, DistanceField, stored
from .suitability import CRITICAL_RADIUS, SUITABILITY_CHECK_LIMIT, is_suitable_at, solid_voxels

__all__ = ["distance_field", "TOLERANCE", "estimate_bytes"]

#: default error target of certified samples, in voxels
TOLERANCE = 1e-3
#: bytes per brick sample beside its value and error: the band flag, and the working
#: copies (float64)
_BYTES_PER_SAMPLE = 1 + 48
#: voxels the certified search first looks within, for a field everywhere
_FIRST_REACH = 5


def estimate_bytes(bricks: int, dtype: str = "float64") -> int:
    """Peak bytes of a field of ``bricks`` bricks stored in ``dtype``."""
    return bricks * BRICK ** 3 * (_BYTES_PER_SAMPLE + 2 * np.dtype(dtype).itemsize)


def _as_mesh(shape: Any) -> Optional[TriangleMesh]:
    """A triangle mesh input (``TriangleMesh``, ``(vertices, faces)``, PyVista, trimesh,
    or a mesh file) as a :class:`~implicitvox.linf.TriangleMesh`; None for shapes."""
    if isinstance(shape, TriangleMesh):
        return shape
    if isinstance(shape, Expr) or isinstance(getattr(shape, "expr", None), Expr):
        return None
    return TriangleMesh(*as_triangles(shape))


def distance_field(shape: Any, resolution: Union[int, tuple[int, int, int], None] = None, *,
                   bounds: Any = None,
                   voxel_size: Union[float, tuple[float, float, float], None] = None,
                   norm: str = "euclidean", band: Optional[int] = 4,
                   tolerance: Optional[float] = None,
                   check_suitability: bool = True, dtype: str = "float64",
                   progress: Optional[Callable[[float], Any]] = None,
                   max_memory: Optional[int] = None, workers: Optional[int] = None,
                   executor: Any = None) -> DistanceField:
    """Signed distances at the voxel centres within ``band`` voxels of the surface.

    Parameters
    ----------
    shape : Expr, Shape, or a triangle mesh
        An expression or shape (as :func:`implicitvox.voxelize` takes), or a mesh
        (``(vertices, faces)``, PyVista, trimesh, a file, or a
        :class:`implicitvox.linf.TriangleMesh`; signed where it is closed).
    resolution : int or (int, int, int), default: 256
        Voxels along the longest side (cubic voxels), or per axis.
    bounds, voxel_size
        As for :func:`implicitvox.voxelize`, except that the default bounds reach
        ``band`` voxels (1 with ``band=None``) past the shape's own on every side
        (:func:`implicitvox.octree.grid.padded_bounds` with a margin), of the
        ``resolution`` voxels along the longest side: the samples then enclose
        the surface, and its isosurface is closed.
    norm : {"euclidean", "linf"}
        The Euclidean distance, or the max-norm of Varadhan et al. (weighted by
        the voxel size over its longest edge when voxels are not cubes, so that
        the surface meets a voxel iff ``|d(centre)| <= longest edge / 2``).
    band : int or None, default: 4
        Samples within this many voxels (per axis) of a surface voxel are
        computed (1 to 64); the rest hold ``±(band + 1)`` voxels. None: every
        sample of the grid.
    tolerance : float, optional
        The error target of certified distances, in world units; default
        ``1e-3`` of the shortest voxel edge. Exact kinds ignore it.
    check_suitability : bool, default: True
        Test Bærentzen's criterion (S_r-open and S_r-closed with ``r = √6``
        voxels, :func:`implicitvox.fields.suitability.is_suitable_at`) on the
        grid itself, and warn when it fails; grids over
        :data:`~implicitvox.fields.suitability.SUITABILITY_CHECK_LIMIT` voxels and
        meshes are not tested (``metadata["suitable"]`` is then None).
    dtype : {"float64", "float32"}, default: "float64"
        The float type the field stores (half the memory and file size in
        float32). Each error bound then includes the value's rounding to
        float32 (at most 2⁻²⁴ of it; :func:`implicitvox.fields.field.stored`), so
        ``|value - true| <= error`` still holds and ``max_error`` says so.
    progress : callable, optional
        Called with the share of the work done (0 to 1).
    max_memory : int, optional
        Refuse (``MemoryError``) before allocating the bricks when they would
        exceed this many bytes; default half the available memory.
    workers : int, optional
        Processes for the voxelization and the band's samples (chunks of
        :data:`implicitvox.fields.band_chunks.CHUNK` points farmed out; the same
        values and errors, bit for bit, for any number). Default: every core
        this process may use, one for a small run.
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Run them there instead (as :func:`implicitvox.voxelize`).

    Returns
    -------
    DistanceField

    Warns
    -----
    UserWarning
        When a certified sample's error stays above the tolerance (detail the
        refinement could not resolve), and when the solid is not suitable for
        voxelization at the resolution (sharp edges, parts or gaps thinner than
        about 5 voxels, curvature above 1/√6 per voxel): values and gradients
        reconstructed near those places are off (Bærentzen §4-§6).
    """
    norm = validate.choice(norm, "norm", NORMS)
    dtype = validate.float_type(dtype, "dtype", DTYPES)
    run = Run.of(max_memory=max_memory, progress=progress, workers=workers, executor=executor)
    band = None if band is None else validate.int_in(band, "band", 1, MAX_BAND)
    mesh = _as_mesh(shape)
    target = mesh if mesh is not None else as_shape(shape)
    own = getattr(target, "bounds", None)
    if bounds is None and own is not None:
        # the samples reach past the surface by the band on every side (else the faces
        # on the shape's extremes have no sample beyond them, and the isosurface is open)
        bounds = padded_bounds(own, resolution, voxel_size, margin=band or 1)
    t0 = time.perf_counter()
    first = run.part(0.0, 0.2)
    if mesh is not None:
        # a closed mesh's triangles with their shared vertices again (the fill needs the
        # connectivity); an open one's as they are (the surface voxels are the same)
        vertices, corners = weld(mesh.tri.reshape(-1, 3)) if mesh.closed else \
            (mesh.tri.reshape(-1, 3), np.arange(3 * len(mesh.tri)))
        vox = voxelize_mesh((vertices, corners.reshape(-1, 3)),
                            resolution, bounds=bounds, voxel_size=voxel_size,
                            interior=mesh.closed, max_memory=first.budget,
                            progress=first.progress, workers=first.workers,
                            executor=first.executor)
    else:
        vox = voxelize(target, resolution, bounds=bounds, voxel_size=voxel_size, interior=True,
                       max_memory=first.budget, progress=first.progress,
                       workers=first.workers, executor=first.executor)
    grid = vox.grid
    h = np.asarray(grid.voxel_size)
    tol = float(h.min()) * TOLERANCE if tolerance is None else \
        validate.positive_number(tolerance, "tolerance")
    weights = h / h.max()
    surface = vox.coords()
    if band is None:
        keys, active = all_bricks(grid.shape)
    else:
        keys, steps = band_steps(surface, band, grid.shape)
        active = steps <= band
    run.refuse(estimate_bytes(len(keys), dtype),
               f"a distance field of {len(keys):,} bricks at {grid.shape}")
    # where the certified search looks first (it widens where no zero is proved)
    reach = _FIRST_REACH if band is None else band + 1
    limit = reach * float(h.max()) * (math.sqrt(3) if norm == "euclidean" else 1.0)

    spec = DistanceKernel(target, norm, limit, tol, None)
    if spec.kernel.kind == "certified":
        spec.boxes = _surface_boxes(vox)
    kernel = spec.kernel
    if mesh is not None and band is not None:
        values_band, used = mesh_band_distances(mesh, grid, norm, weights, keys, steps, band,
                                                run.part(0.2, 1.0))
        errors_band = np.zeros(len(values_band))
    else:
        values_band, errors_band, used = band_distances(spec, grid, weights,
                                                        masked_coords(keys, active),
                                                        run.part(0.2, 1.0))
    field = _assemble(grid, norm, band, keys, active, values_band, errors_band, kernel.kind, vox,
                      dtype)
    field.signed = mesh is None or mesh.closed
    field.metadata["suitable"] = _check_suitability(target, vox) if check_suitability and \
        mesh is None else None
    if kernel.kind == "certified" and field.count and field.max_error > tol:
        worst = int(np.sum(errors_band > tol))
        warnings.warn(f"{worst:,} of {field.count:,} certified samples keep an error above the "
                      f"tolerance {tol:.3g} (largest {field.max_error:.3g}): detail finer than "
                      "the refinement resolves", UserWarning, stacklevel=2)
    field.metadata.update({"seconds": time.perf_counter() - t0, "surface_voxels": vox.count,
                           "tolerance": tol, "bricks": len(keys), "workers": used})
    run.report(1.0)
    return field


def _check_suitability(shape, vox) -> Optional[bool]:
    """Bærentzen's criterion at ``r = √6`` on the voxels' own grid (one opening and one
    closing); a warning when it fails; None for grids too large to test."""
    pad = int(math.ceil(CRITICAL_RADIUS)) + 2
    cells = int(np.prod(np.asarray(vox.grid.shape) + 2 * pad, dtype=np.float64))
    if cells > SUITABILITY_CHECK_LIMIT:
        return None
    solid = np.pad(solid_voxels(vox, shape), pad, constant_values=False)
    if is_suitable_at(solid):
        return True
    warnings.warn(f"the solid is not suitable for voxelization at {vox.grid.shape} (Bærentzen "
                  "§4-§5: not S_r-open and S_r-closed for r = √6 voxels): a sharp edge, a part "
                  "or gap thinner than about 5 voxels, or curvature above 1/√6 per voxel; "
                  "values and gradients reconstructed there are off. "
                  "implicitvox.suitability(shape, resolution) measures r", UserWarning,
                  stacklevel=3)
    return False


def _surface_boxes(vox) -> tuple[np.ndarray, np.ndarray]:
    """The surface voxels' boxes ``(lo, hi)`` (m, 3): their union holds the surface."""
    lo, hi = vox.grid.octant_boxes(vox.grid.depth, vox.coords())
    return np.stack(lo, axis=1), np.stack(hi, axis=1)


def _assemble(grid, norm, band, keys, active, values_band, errors_band, kind, vox, dtype
              ) -> DistanceField:
    """The bricks in ``dtype``: band samples from the kernel (:func:`stored`), the rest
    the signed background (NaN beyond the grid)."""
    field = DistanceField(grid, norm, band, keys, np.empty(active.shape, dtype=dtype),
                          np.zeros(active.shape, dtype=dtype), active, kind, voxels=vox)
    values = field.values
    values[active], field.errors[active] = stored(values_band, errors_band, dtype)
    inside = in_grid(keys, grid.shape)
    values[~inside] = np.nan
    rest = inside & ~active
    values[rest] = field.background
    if vox is not None and len(vox.interior):
        solid = field.in_solid(masked_coords(keys, rest))
        held = values[rest]
        held[solid] = -field.background
        values[rest] = held
    return field
