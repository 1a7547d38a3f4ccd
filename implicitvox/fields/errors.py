"""How wrong a reconstructed distance field is: Bærentzen et al. §6.

* :func:`analytic_error_bound` - §6.1, eq. 22: a solid that is S_r-open and
  S_r-closed has curvature at most ``1 / (r - |σ|)`` on its σ-isosurfaces
  (Property 1), so within a trilinear cell meeting the surface (every point
  within ``√3`` of it) the interpolation error is at most
  ``3 / (8 (r - √3))`` voxels (three nested linear interpolations, eq. 21).
* :func:`sphere_reconstruction_errors` - §6.2, Fig. 8: spheres of radius
  ``r`` voxels at random sub-voxel offsets, sampled (the exact Euclidean
  distance), reconstructed trilinearly; along rays from the centre the
  point where the reconstruction crosses 0 is found by bisection, and its
  distance to the true sphere is the error. Max, mean and standard
  deviation over all rays and offsets.

Examples
--------
>>> round(float(analytic_error_bound(3.0)), 4)
0.2958
>>> stats = sphere_reconstruction_errors(4.0, offsets=2, rays=50)
>>> stats["max"] < analytic_error_bound(4.0)
True
"""
from __future__ import annotations

import numpy as np

from .. import validate
from ..linf.sphere import Sphere
from ..meshing.hausdorff import sphere_directions
from .bounds import analytic_error_bound
from .sampled import distance_field

__all__ = ["analytic_error_bound", "sphere_reconstruction_errors"]

_BISECT = 48


def sphere_reconstruction_errors(radius: float, *, offsets: int = 8, rays: int = 500,
                                 seed: int = 0) -> dict[str, float]:
    """Bærentzen §6.2: the geometric error of the trilinear 0-isosurface of a sampled
    sphere of ``radius`` voxels, over ``offsets`` random sub-voxel centres and
    ``rays`` rays each. Returns ``{"max", "mean", "std"}`` in voxels."""
    radius = validate.number_in(radius, "radius", 1.0, 64.0)
    offsets = validate.int_in(offsets, "offsets", 1, 1000)
    rays = validate.int_in(rays, "rays", 1, 100000)
    rng = np.random.default_rng(seed)
    directions = sphere_directions(rays)
    errors = []
    for centre in rng.random((offsets, 3)):
        reach = radius + 3.0
        bounds = (tuple((centre - reach).tolist()), tuple((centre + reach).tolist()))
        field = distance_field(Sphere(centre, radius), bounds=bounds, voxel_size=1.0, band=3,
                               check_suitability=False)
        lo = np.full(rays, max(radius - 1.5, 0.0))
        hi = np.full(rays, radius + 1.5)
        for _ in range(_BISECT):
            mid = 0.5 * (lo + hi)
            inside = field.sample(centre + mid[:, None] * directions) < 0
            lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
        errors.append(np.abs(0.5 * (lo + hi) - radius))
    e = np.concatenate(errors)
    return {"max": float(e.max()), "mean": float(e.mean()), "std": float(e.std())}
