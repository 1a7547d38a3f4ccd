"""Is a solid suitable for voxelization at a resolution? Bærentzen et al. §4-§5.

The criterion: the solid ``X`` is S_r-open and S_r-closed (a ball of radius
``r`` rolls everywhere inside and everywhere outside it) with ``r > √6``
voxels. Then its curvature is bounded (Property 1: ``κ <= 1 / (r - |σ|)``)
and the medial surfaces keep at least ``r`` from the boundary (Property 2),
so trilinear reconstruction and central-difference gradients never mix
samples from both sides of a medial surface (Condition 2: the 28 samples
of a gradient lie within ``√6`` of the point), and the error is at most
:func:`~implicitvox.fields.errors.analytic_error_bound` of ``r``.

Estimating ``r``: the solid is voxelized on a grid ``oversample`` times finer
(interior octants, plus the surface voxels whose centre is inside), and
Euclidean distance transforms (:func:`scipy.ndimage.distance_transform_edt`)
give the morphological opening with a ball of radius ``ρ`` as the set of
points within ``ρ`` of a centre where the ball fits (its distance to the
outside is at least ``ρ``). ``X`` is S_ρ-open when the opening is all of
``X``; bisection on ``ρ`` finds the largest such radius. Closing is the
opening of the complement. Samples are voxel centres, so a ball's centre
is a voxel centre (up to ``√3/2`` from the ideal one) and a voxel counts as
covered when its centre is within ``ρ + 1`` of one: the answer is good to
about one fine voxel (a cube, ``r = 0``, comes out below one target voxel
at ``oversample=4``), and the bisection stops at a quarter of one.

The fine grid is by default the finest of 4, 2 and 1 fine voxels per target
voxel whose padded grid has at most :data:`SUITABILITY_FINE_CELLS` voxels (the
time goes with them: a dozen or so distance transforms); at 256³ that is the
target grid itself, and the answer is good to about one target voxel
(``Suitability.oversample`` says which ran).

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import linf
>>> s = iv.suitability(linf.Sphere((0, 0, 0), 1.0), 13, oversample=2, max_radius=8)
>>> 5 < s.r <= 6.5, s.suitable                 # radius 6 voxels
(True, True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from .. import validate
from ..eval.function import Function
from ..expr.shape import as_shape
from ..octree.budget import memory_budget, refuse_over_budget
from ..octree.grid import grid_of
from ..voxelizers.implicit import voxelize
from .bounds import analytic_error_bound

__all__ = ["Suitability", "suitability", "CRITICAL_RADIUS", "solid_voxels", "is_suitable_at",
           "SUITABILITY_CHECK_LIMIT", "SUITABILITY_FINE_CELLS"]

#: Condition 2: no medial surface within √6 voxels of the boundary
CRITICAL_RADIUS = math.sqrt(6)
#: voxels of the largest grid :func:`implicitvox.distance_field` checks the criterion on
SUITABILITY_CHECK_LIMIT = 1 << 25
#: padded fine-grid voxels :func:`suitability` takes at most by default, choosing its
#: ``oversample`` (about a second per distance transform here)
SUITABILITY_FINE_CELLS = 1 << 23


@dataclass(frozen=True)
class Suitability:
    """The answer of :func:`suitability` (radii in voxels of the target grid)."""

    r_open: float           #: the largest ball radius for which the solid is open
    r_closed: float         #: ... and for which it is closed (``max_radius`` = no limit found)
    max_radius: float       #: the largest radius tried
    oversample: int = 4     #: fine voxels per target voxel of the estimate (its precision)

    @property
    def r(self) -> float:
        """The radius of the criterion: ``min(r_open, r_closed)``."""
        return min(self.r_open, self.r_closed)

    @property
    def suitable(self) -> bool:
        """Bærentzen's criterion: ``r > √6``."""
        return self.r > CRITICAL_RADIUS

    @property
    def predicted_error(self) -> float:
        """The analytic bound of the trilinear error at ``r`` (voxels; ``inf`` for
        ``r <= √3``)."""
        return analytic_error_bound(self.r)

    def __str__(self) -> str:
        verdict = "suitable" if self.suitable else "not suitable"
        def shown(r: float) -> str:
            return f"{r:.2f}{'+' if r >= self.max_radius else ''}"
        if self.r > math.sqrt(3):
            error = f"predicted trilinear error at most {self.predicted_error:.3g} voxels"
        else:
            error = (f"no bound on the trilinear error: r <= √3 (a sharp edge or corner, or "
                     f"a part or gap about {2 * self.r:.1f} voxels thin; Bærentzen eq. 22 "
                     f"needs r > √3)")
        return (f"S_r-open up to r = {shown(self.r_open)}, S_r-closed up to r = "
                f"{shown(self.r_closed)} voxels (to about {1 / self.oversample:g} voxel): "
                f"{verdict} (r {'>' if self.suitable else '<='} √6 = {CRITICAL_RADIUS:.3f}); "
                f"{error}")


def suitability(shape: Any, resolution: Any = None, *, bounds: Any = None,
                voxel_size: Any = None, oversample: Optional[int] = None,
                max_radius: float = 12.0, max_memory: Optional[int] = None) -> Suitability:
    """Estimate the largest ``r`` (voxels) for which ``shape`` is S_r-open and S_r-closed.

    Parameters
    ----------
    shape : Expr or Shape
    resolution, bounds, voxel_size
        The target grid, as for :func:`implicitvox.voxelize`.
    oversample : {1, 2, 4, 8}, optional
        The fine grid's voxels per target voxel, per axis; by default the largest
        of 4, 2 and 1 whose padded fine grid has at most
        :data:`SUITABILITY_FINE_CELLS` voxels.
    max_radius : float, default: 12
        The largest radius tried (voxels); a solid open or closed beyond it
        reports ``max_radius``.
    max_memory : int, optional
        Refuse (``MemoryError``) when the fine grid's arrays would exceed it.

    Returns
    -------
    Suitability
    """
    from scipy.ndimage import distance_transform_edt
    if oversample is not None:
        oversample = validate.int_in(oversample, "oversample", 1, 8)
        if oversample & (oversample - 1):
            raise ValueError(f"oversample must be 1, 2, 4 or 8, got {oversample}")
    max_radius = validate.number_in(max_radius, "max_radius", 0.5, 256.0)
    shape = as_shape(shape)
    grid = grid_of(getattr(shape, "bounds", None), bounds, resolution, voxel_size)

    def padded_cells(k: int) -> tuple[int, int]:
        pad = int(math.ceil(max_radius * k)) + 2
        return int(np.prod(np.asarray(grid.shape) * k + 2 * pad, dtype=np.float64)), pad

    if oversample is None:
        oversample = next((k for k in (4, 2) if padded_cells(k)[0] <= SUITABILITY_FINE_CELLS),
                          1)
    fine = grid.finer(int(math.log2(oversample)))
    cells, pad = padded_cells(oversample)
    refuse_over_budget(cells * 24, memory_budget(max_memory),
                       f"the suitability test on a {fine.shape} grid")
    solid = _solid(shape, fine, max_memory)
    solid = np.pad(solid, pad, constant_values=False)
    limit = max_radius * oversample
    r_open = _largest_open(solid, limit, distance_transform_edt)
    r_closed = _largest_open(~solid, limit, distance_transform_edt)
    return Suitability(r_open / oversample, r_closed / oversample, max_radius, oversample)


def _solid(shape, grid, max_memory) -> np.ndarray:
    vox = voxelize(shape, bounds=grid.bounds, voxel_size=grid.voxel_size, interior=True,
                   max_memory=max_memory)
    return solid_voxels(vox, shape)


def solid_voxels(vox, shape) -> np.ndarray:
    """The solid as a dense boolean array on the voxels' grid: interior octants, and
    surface voxels whose centre is inside (``f <= 0``)."""
    grid = vox.grid
    dense = vox.to_dense(interior=True)
    c = vox.coords()
    centres = grid.centers(c)
    inside = Function(shape.expr)(centres[:, 0], centres[:, 1], centres[:, 2]) <= 0
    dense[c[:, 0], c[:, 1], c[:, 2]] = inside
    return dense


def is_suitable_at(solid: np.ndarray, rho: float = CRITICAL_RADIUS) -> bool:
    """Whether the dense ``solid`` (padded by the caller where it reaches the array's
    edge) is S_ρ-open and S_ρ-closed, ``ρ`` in its voxels (one test each, no bisection)."""
    from scipy.ndimage import distance_transform_edt
    return all(_opens(part, rho, distance_transform_edt) for part in (solid, ~solid))


def _opens(solid: np.ndarray, rho: float, edt, depth: Optional[np.ndarray] = None) -> bool:
    """Is ``solid`` unchanged by the opening with a ball of radius ``rho``?"""
    if not solid.any():
        return True
    depth = edt(solid) if depth is None else depth   # distance to the nearest outside centre
    centres = depth >= rho                            # a ball of radius rho fits
    if not centres.any():
        return False
    reach = edt(~centres)
    return not np.any(solid & (reach > rho + 1.0))


def _largest_open(solid: np.ndarray, limit: float, edt) -> float:
    """The largest ``ρ <= limit`` (voxels) with ``solid`` S_ρ-open, by bisection to a
    quarter of a voxel (the samples' own precision is about one)."""
    if not solid.any():
        return limit
    depth = edt(solid)

    def is_open(rho: float) -> bool:
        return _opens(solid, rho, edt, depth)

    if is_open(limit):
        return limit
    lo, hi = 0.0, limit
    for _ in range(max(1, math.ceil(math.log2(4 * limit)))):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if is_open(mid) else (lo, mid)
    return lo
