"""The band's samples computed in chunks, here or on workers (Stolte §5.2's farm).

A mesh's distances run in compiled code that releases the GIL
(:mod:`implicitvox.linf.mesh_walk`): their chunks go to threads of this
process; the other kernels' to processes.

A :class:`DistanceKernel` names everything a kernel needs (the shape, the norm,
the certified search's boxes and limits) and builds it where it runs, once;
:func:`band_distances` runs it over the samples in chunks of :data:`CHUNK`
points (by the kernel's cost), serially or farmed out (:func:`implicitvox.parallel.farm`), the
chunks the same either way, so the values and errors are bit-identical for
any number of workers.
"""
from __future__ import annotations

import functools
from typing import Any, Optional

import numpy as np

from ..eval.function import Function
from ..linf.triangle_mesh import TriangleMesh
from ..octree.grid import Grid
from ..octree.run import Run
from ..parallel import Job, farm
from .bricks import masked_coords
from .certified import SurfaceBoxes, certified_distances
from .distance_kernels import Kernel, choose_kernel
from .mesh_band import mesh_band

__all__ = ["DistanceKernel", "SamplesJob", "band_distances", "mesh_band_distances", "CHUNK",
           "COST"]

#: samples computed per call, by the kernel's cost (:attr:`DistanceKernel.cost`):
#: bounded temporaries, progress steps, one farmed piece (a certified search takes
#: a few tenths of a millisecond per sample, so its pieces are small enough for the
#: queue to balance)
CHUNK = {"analytic": 1 << 16, "mesh": 1 << 14, "box test": 1 << 14, "certified": 1 << 11}
#: cost of one sample, in surface voxels of the voxelizer (for ``workers=None``'s
#: "does it pay"): analytic distances, a hierarchy walk, a box-test bisection,
#: a certified search
COST = {"analytic": 4, "mesh": 32, "box test": 32, "certified": 512}


class DistanceKernel:
    """The distance kernel of a field, rebuilt wherever it runs (picklable)."""

    def __init__(self, target: Any, norm: str, limit: float, tolerance: float,
                 boxes: Optional[tuple[np.ndarray, np.ndarray]]):
        self.target, self.norm, self.limit, self.tolerance = target, norm, limit, tolerance
        #: the surface voxels' boxes (lo, hi), for the certified search
        self.boxes = boxes

    @property
    def cost(self) -> str:
        """The kernel's cost class: a key of :data:`COST` and :data:`CHUNK`."""
        kind = self.kernel.kind
        if kind == "exact":
            return "mesh" if isinstance(self.target, TriangleMesh) else "analytic"
        return kind

    @functools.cached_property
    def kernel(self) -> Kernel:
        """:func:`~implicitvox.fields.distance_kernels.choose_kernel`'s kernel for the target."""
        return choose_kernel(self.target, self.norm, self._certify)

    @functools.cached_property
    def surface(self) -> SurfaceBoxes:
        """:attr:`boxes` indexed for the certified search, once where the kernel runs."""
        return SurfaceBoxes(*self.boxes)

    def _certify(self, points: np.ndarray, weights: Any):
        func = _compiled(self)
        return certified_distances(func, points, self.norm, weights, self.surface,
                                   limit=self.limit, tolerance=self.tolerance)

    def __getstate__(self) -> dict:
        return {k: v for k, v in self.__dict__.items()
                if k not in ("kernel", "function", "surface")}


def _compiled(spec: DistanceKernel) -> Function:
    if "function" not in spec.__dict__:
        spec.__dict__["function"] = Function(spec.target.expr)
    return spec.__dict__["function"]


class SamplesJob(Job):
    """A field's kernel and grid, shared by every chunk of samples."""

    def __init__(self, spec: DistanceKernel, grid: Grid, weights: np.ndarray):
        super().__init__()
        self.spec, self.grid, self.weights = spec, grid, weights

    def run(self, coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values and errors at the centres of voxels ``coords`` (n, 3)."""
        return self.spec.kernel(self.grid.centers(coords), self.weights)


def band_distances(spec: DistanceKernel, grid: Grid, weights: np.ndarray, coords: np.ndarray,
                   run: Run) -> tuple[np.ndarray, np.ndarray, int]:
    """Values and errors at the centres of voxels ``coords`` (n, 3), on the
    ``run``'s workers, and the workers used (1: serial, here)."""
    values = np.empty(len(coords))
    errors = np.empty(len(coords))
    chunk = CHUNK[spec.cost]
    starts = range(0, len(coords), chunk)
    n = run.workers_for(len(coords) * COST[spec.cost])
    if (n > 1 or run.executor is not None) and len(starts) > 1:
        job = SamplesJob(spec, grid, weights)
        for i, (v, e) in farm(job, [coords[s:s + chunk] for s in starts], workers=n,
                              executor=run.executor, progress=run.progress,
                              weights=[min(chunk, len(coords) - s) for s in starts],
                              what=f"computing distances at {grid.shape}",
                              threads=spec.cost == "mesh"):
            values[starts[i]:starts[i] + chunk], errors[starts[i]:starts[i] + chunk] = v, e
        return values, errors, n
    for s in starts:
        part = slice(s, s + chunk)
        values[part], errors[part] = spec.kernel(grid.centers(coords[part]), weights)
        run.report(min(1.0, (s + chunk) / max(len(coords), 1)))
    return values, errors, 1


def mesh_band_distances(mesh: TriangleMesh, grid: Grid, norm: str, weights: np.ndarray,
                        keys: np.ndarray, steps: np.ndarray, band: int, run: Run
                        ) -> tuple[np.ndarray, int]:
    """A mesh's values at the band's samples (``brick_coords(keys)[active]``, ``active``
    where ``steps <= band``: :func:`implicitvox.fields.bricks.band_steps`), signed
    where it is closed, by its triangles scattered over the bricks
    (:func:`implicitvox.fields.mesh_band.mesh_band`, threads over ranges of
    bricks), and the workers used."""
    active = steps <= band
    count = int(active.sum())
    n = run.workers_for(count * COST["mesh"])
    values = mesh_band(mesh, grid, keys, active, band, norm, weights, steps=steps, workers=n,
                       executor=run.executor, progress=run.progress)
    if mesh.closed:
        values = mesh.with_sign(grid.centers(masked_coords(keys, active)), values)
    return values, n
