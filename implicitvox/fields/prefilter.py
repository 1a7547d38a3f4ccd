"""Prefiltering, for comparison: Bærentzen et al. §3.1 (Wang and Kaufman's method).

The inside-outside function ``B_X`` (1 inside, 0 outside) is convolved with
a Bartlett filter (the hypercone: ``1 - |x| / R`` on a ball of radius ``R``,
0 beyond) and sampled at the voxel centres; the surface is the isosurface
``σ = 1/2``, the value on a plane. Bærentzen's point (Fig. 1): only a
plane splits the filter's support in two equal halves, so on a curved
surface the convolution at a true surface point is not 1/2 and the
isosurface moves, by an amount set by the curvature and independent of
the sampling; the distance field's 0-isosurface does not
(:func:`isosurface_offsets` measures both).

The convolution is a quadrature: the filter's ball is covered by a lattice
of ``quadrature`` points per radius, each weighted by the cone, and
``B_X`` is the sign of ``f`` there.

Examples
--------
>>> from implicitvox import x, y, z, sqrt
>>> ball = sqrt(x * x + y * y + z * z) - 4.0          # radius 4 voxels of size 1
>>> grid, values = prefiltered_samples(ball, bounds=((-7.0,) * 3, (7.0,) * 3), voxel_size=1.0)
>>> offsets = isosurface_offsets(trilinear(grid, values), 0.5, (0, 0, 0), 4.0, rays=50)
>>> bool(offsets.mean() < -0.1)              # the isosurface moved inward
True
>>> exact = isosurface_offsets(prefiltered(ball, 2.0), 0.5, (0, 0, 0), 4.0, rays=50)
>>> bool(exact.mean() < -0.1)                # before any sampling: intrinsic
True
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .. import validate
from ..eval.function import Function
from ..expr.shape import as_shape
from ..octree.grid import Grid, grid_of
from ..octree.voxels import DEFAULT_DENSE_LIMIT
from ..meshing.hausdorff import sphere_directions

__all__ = ["bartlett_kernel", "prefiltered", "prefiltered_samples", "trilinear",
           "prefilter_comparison", "isosurface_offsets", "QUADRATURE"]

#: quadrature points per filter radius, per axis
QUADRATURE = 8
_BISECT = 48


def bartlett_kernel(radius: float, quadrature: int = QUADRATURE) -> tuple[np.ndarray, np.ndarray]:
    """Offsets (m, 3) and weights (m,) (summing to 1) of the Bartlett filter of
    ``radius``: the cone ``1 - |x| / radius`` on a lattice of midpoints."""
    step = radius / quadrature
    axis = (np.arange(-quadrature, quadrature) + 0.5) * step
    offsets = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
    weights = 1.0 - np.linalg.norm(offsets, axis=1) / radius
    keep = weights > 0
    return offsets[keep], weights[keep] / weights[keep].sum()


def prefiltered(shape: Any, radius: float, quadrature: int = QUADRATURE
                ) -> Callable[[np.ndarray], np.ndarray]:
    """The continuous prefiltered function: ``points (n, 3) -> (B_X * Ba)(points)``
    for a Bartlett filter of ``radius`` (world units), by quadrature."""
    radius = validate.positive_number(radius, "radius")
    quadrature = validate.int_in(quadrature, "quadrature", 1, 32)
    offsets, weights = bartlett_kernel(radius, quadrature)
    func = Function(as_shape(shape).expr)
    block = max(1, (64 << 20) // (24 * len(offsets)))

    def convolve(points: np.ndarray) -> np.ndarray:
        points = np.asarray(points, dtype=np.float64)
        out = np.empty(len(points))
        for s in range(0, len(points), block):
            p = (points[s:s + block, None, :] + offsets[None]).reshape(-1, 3)
            with np.errstate(all="ignore"):
                inside = func(p[:, 0], p[:, 1], p[:, 2]).reshape(-1, len(offsets)) <= 0
            out[s:s + block] = inside @ weights
        return out

    return convolve


def prefiltered_samples(shape: Any, resolution: Any = None, *, bounds: Any = None,
                        voxel_size: Any = None, radius: float = 2.0,
                        quadrature: int = QUADRATURE,
                        max_memory: int = DEFAULT_DENSE_LIMIT) -> tuple[Grid, np.ndarray]:
    """``(grid, values)``: ``B_X`` convolved with a Bartlett filter of ``radius``
    voxels, at every voxel centre of the grid (dense; for comparisons on small grids).
    Values are 1 deep inside, 0 far outside, 1/2 on a plane's surface."""
    radius = validate.number_in(radius, "radius", 0.25, 16.0)
    shape = as_shape(shape)
    grid = grid_of(getattr(shape, "bounds", None), bounds, resolution, voxel_size)
    cells = int(np.prod(grid.shape, dtype=np.float64))
    if 8 * cells > max_memory:
        raise MemoryError(f"prefiltered samples on {grid.shape} need {8 * cells / 2**30:.2f} GiB, "
                          f"over max_memory={max_memory / 2**30:.2f} GiB")
    convolve = prefiltered(shape, radius * max(grid.voxel_size), quadrature)
    ijk = np.stack(np.meshgrid(*[np.arange(n) for n in grid.shape], indexing="ij"),
                   -1).reshape(-1, 3)
    return grid, convolve(grid.centers(ijk)).reshape(grid.shape)


def trilinear(grid: Grid, values: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """The trilinear reconstruction of dense samples at the grid's voxel centres."""
    from scipy.ndimage import map_coordinates
    h = np.asarray(grid.voxel_size)
    origin = np.asarray(grid.origin)

    def sample(points: np.ndarray) -> np.ndarray:
        u = ((np.asarray(points, dtype=np.float64) - origin) / h - 0.5).T
        return map_coordinates(values, u, order=1, mode="nearest")

    return sample


def isosurface_offsets(sample: Callable[[np.ndarray], np.ndarray], level: float, centre: Any,
                       radius: float, *, rays: int = 200, axis: Any = None,
                       reach: float = 2.0) -> np.ndarray:
    """Signed distances from the true surface to where ``sample`` crosses ``level``,
    along ``rays`` rays from ``centre``: a sphere of ``radius``, or with ``axis`` a
    cylinder about it (rays perpendicular to it). The crossing is searched within
    ``reach`` of the surface, by bisection. Negative: the isosurface lies inside."""
    centre = np.asarray(centre, dtype=np.float64)
    directions = sphere_directions(rays)
    if axis is not None:
        a = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
        directions = directions - (directions @ a)[:, None] * a
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    inner = bool(sample(centre[None])[0] > level)      # the side the centre is on
    lo = np.full(rays, max(radius - reach, 0.0))
    hi = np.full(rays, radius + reach)
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        v = sample(centre + mid[:, None] * directions)
        inside = (v > level) if inner else (v < level)
        lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
    return 0.5 * (lo + hi) - radius


def prefilter_comparison(radii: Any = (2, 3, 4, 5, 6, 7, 8, 9), *, filter_radius: float = 2.0,
                         rays: int = 200, seed: int = 0) -> list[dict[str, Any]]:
    """Bærentzen §3.1 measured: for spheres and cylinders of each radius (voxels, at a
    random sub-voxel centre), the mean signed offset (voxels) of the surface found by

    * ``prefilter``: the continuous prefiltered function's ``1/2``-isosurface (no
      sampling: the offset is the method's own, and grows with curvature);
    * ``prefilter_sampled``: its samples, reconstructed trilinearly;
    * ``distance_sampled``: the sampled distance field's 0-isosurface, reconstructed
      trilinearly (the continuous distance field's is the surface itself: 0).
    """
    from ..expr import functions as fn
    from ..expr.nodes import x, y, z
    from ..linf.cylinder import Cylinder
    from ..linf.sphere import Sphere
    from .sampled import distance_field
    rng = np.random.default_rng(seed)
    rows = []
    for radius in radii:
        r = float(radius)
        c = rng.random(3)
        reach = r + filter_radius + 3
        for kind in ("sphere", "cylinder"):
            if kind == "sphere":
                expr = fn.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) - r
                exact = Sphere(c, r)
                bounds = (tuple((c - reach).tolist()), tuple((c + reach).tolist()))
                axis, centre = None, c
            else:
                expr = fn.hypot(x - c[0], y - c[1]) - r
                exact = Cylinder((c[0], c[1], -100.0), (0, 0, 1), 200.0, r)
                bounds = ((c[0] - reach, c[1] - reach, -3.0), (c[0] + reach, c[1] + reach, 3.0))
                axis, centre = (0, 0, 1), np.array([c[0], c[1], 0.0])
            grid, values = prefiltered_samples(expr, bounds=bounds, voxel_size=1.0,
                                               radius=filter_radius)
            field = distance_field(exact, bounds=bounds, voxel_size=1.0, band=3,
                                   check_suitability=False)
            level = 0.5

            def offset(sample, lvl):
                return float(isosurface_offsets(sample, lvl, centre, r, rays=rays,
                                                axis=axis).mean())
            rows.append({"shape": kind, "radius": r,
                         "prefilter": offset(prefiltered(expr, filter_radius), level),
                         "prefilter_sampled": offset(trilinear(grid, values), level),
                         "distance_sampled": offset(trilinear(field.grid, field.to_dense()), 0.0)})
    return rows
