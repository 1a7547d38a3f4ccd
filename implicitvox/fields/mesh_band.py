"""A mesh's distance band, triangle by triangle over the bricks (Varadhan §4.2).

Varadhan §4.2 computes a max-norm distance field by rendering, slice by slice,
each triangle's distance function over its region of influence, the depth
test keeping the least value: at each sample, the minimum over the triangles
that reach it. :func:`mesh_band` takes the same minimum on the CPU, exactly,
over the band's bricks (OpenVDB's 8³ leaves), in the max-norm or the
Euclidean norm.

**Which triangles reach a sample.** A band sample lies within ``band`` voxels
(per axis) of a surface voxel, and the surface meets that voxel (the
voxelizer misses none), so the sample lies within ``(band + 1/2) h_a`` of a
surface point along each axis ``a``. Its max-norm distance is then at most
``band + 1/2`` longest voxel edges, and its nearest triangle's nearest point
lies within ``(band + 1/2) h_a`` of it along each axis; its Euclidean distance
is at most the length ``R`` of that offset, and the nearest point lies within
``R`` along each axis. Either way the nearest point is inside the triangle's
bounding box grown by that much. Each triangle goes to the samples of its
grown box, and each sample keeps the least of their exact distances
(:func:`implicitvox.linf.triangle_axes.linf_below` and
:func:`implicitvox.linf.mesh_walk.triangle_euclidean`, the same floats as
everywhere else). The argument leans on the voxelization; the result does
not: a sample whose least value exceeds the bound (none, where the argument
holds) is computed again by the hierarchy walk
(:meth:`implicitvox.linf.TriangleMesh.distance`), so every value is the exact
minimum over all triangles either way.

**Culling** (§4.1's lower and upper bounds). A brick lists the triangles whose
grown box meets it, nearest to its centre first: a sample's least value falls
after its first few triangles, and then most of the rest are dropped by their
bounding box's distance, a lower bound, before any other axis is projected.

**Threads.** Bricks are independent: threads take ranges of them (the
compiled loop releases the GIL), and the values are the same for any number.

Examples
--------
>>> import numpy as np, pyvista as pv
>>> from implicitvox.linf import TriangleMesh
>>> from implicitvox.triangles.inputs import as_triangles
>>> from implicitvox.octree.grid import Grid
>>> mesh = TriangleMesh(*as_triangles(pv.Cube()))
>>> grid = Grid((-1.0, -1.0, -1.0), (0.25, 0.25, 0.25), (8, 8, 8))
>>> keys = np.zeros(1, dtype=np.uint64)
>>> active = np.ones((1, 8, 8, 8), dtype=bool)
>>> values = mesh_band(mesh, grid, keys, active, 4)
>>> bool(np.array_equal(values, np.abs(mesh.distance(grid.centers(np.argwhere(active[0]))))))
True
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from ..linf.triangle_mesh import TriangleMesh
from ..octree import morton
from ..octree.grid import Grid
from ..parallel import Job, farm
from .bricks import BRICK, masked_coords

__all__ = ["mesh_band", "brick_triangles", "PIECE_PAIRS"]

#: brick-triangle pairs per piece handed to a thread (progress steps, balance)
PIECE_PAIRS = 1 << 16
#: the reach's allowance for rounding, relative and in voxels (far above the rounding of
#: coordinates of at most 21 bits)
_SLACK = 1e-6


def _kernels():
    from . import mesh_band_kernels     # (loads Numba: not at import)
    return mesh_band_kernels


def brick_triangles(rows: np.ndarray, keys: np.ndarray, grid: Grid, margin: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Per brick of ``keys``, the triangles (rows of
    :func:`~implicitvox.linf.triangle_axes.axis_rows`) whose bounding box grown by
    ``margin`` (per axis, world units) holds a sample of the brick, nearest to the
    brick's middle first: ``(start, triangles)``, brick ``b``'s in
    ``triangles[start[b]:start[b + 1]]``."""
    origins, centres = _layout(keys, grid)
    return _kernels().brick_triangles(rows, keys, origins, centres,
                                      np.asarray(margin, dtype=float))


def _layout(keys: np.ndarray, grid: Grid) -> tuple[np.ndarray, tuple]:
    """Each brick's first voxel index (k, 3), and the samples' coordinates per axis
    (the grid's one centre formula)."""
    origins = morton.decode(keys).astype(np.int64) * BRICK
    centres = tuple(0.5 * (grid.edge(a, np.arange(grid.shape[a]))
                           + grid.edge(a, np.arange(grid.shape[a]) + 1)) for a in range(3))
    return origins, centres


class _BandJob(Job):
    """The triangles, bricks and grid every range of bricks shares (threads)."""

    def __init__(self, mesh: TriangleMesh, grid: Grid, keys: np.ndarray, active: np.ndarray,
                 weights: np.ndarray, margin: np.ndarray, euclidean: bool,
                 steps: Optional[np.ndarray], scale: float):
        super().__init__()
        self.mesh, self.grid, self.active, self.weights = mesh, grid, active, weights
        self.margin, self.euclidean = margin, euclidean
        # the starting bounds: steps + 1/2 voxels, with room for rounding
        self.steps = np.zeros((0, BRICK, BRICK, BRICK), dtype=np.uint8) if steps is None \
            else steps
        self.unit = np.array([scale * (1 + _SLACK), _SLACK * min(grid.voxel_size)])
        self.origins, self.centres = _layout(keys, grid)
        self.start, self.triangles = _kernels().brick_triangles(mesh.axes, keys, self.origins,
                                                                self.centres, margin)

    def run(self, piece: tuple[int, int]) -> np.ndarray:
        """The least values of bricks ``piece[0]`` to ``piece[1]``: (bricks, 8, 8, 8)."""
        b0, b1 = piece
        values = np.where(self.active[b0:b1], np.inf, -np.inf)
        _kernels().scatter_bricks(b0, b1, self.start, self.triangles, self.mesh.axes,
                                  self.mesh.tri, self.origins, self.centres, self.weights,
                                  self.margin, self.euclidean, self.steps, self.unit, values)
        return values


def mesh_band(mesh: TriangleMesh, grid: Grid, keys: np.ndarray, active: np.ndarray,
              band: int, norm: str = "linf", weights: Any = None, *,
              steps: Optional[np.ndarray] = None, workers: int = 1, executor: Any = None,
              progress: Optional[Callable[[float], Any]] = None) -> np.ndarray:
    """Unsigned distances from ``mesh`` at the band's samples.

    Parameters
    ----------
    mesh : TriangleMesh
    grid : Grid
        Sample ``(i, j, k)`` is the centre of voxel ``(i, j, k)``.
    keys, active
        The band's bricks (:func:`implicitvox.fields.bricks.band_bricks`).
    band : int
        Every active sample lies within ``band`` voxels (per axis) of a voxel
        the surface meets.
    norm : {"linf", "euclidean"}
        The weighted max-norm, or the Euclidean distance.
    weights : (3,) array, optional
        The max-norm's weights (voxel size over its longest edge); default 1.
    steps : ndarray of uint8, (k, 8, 8, 8), optional
        Each sample's distance in voxels to the nearest surface voxel
        (:func:`implicitvox.fields.bricks.band_steps`). A sample starts from the
        bound it gives, ``steps + 1/2`` voxels per axis, so that only the triangles
        nearer than that are measured (the values are the same: a sample no
        triangle comes below it on is walked).
    workers : int, default: 1
        Threads over ranges of bricks (the same values for any number).
    executor, progress
        As for :func:`implicitvox.parallel.farm`.

    Returns
    -------
    ndarray (n,)
        The distance at each active sample, in the order of
        ``brick_coords(keys)[active]``.
    """
    h = np.asarray(grid.voxel_size, dtype=float)
    euclidean = norm == "euclidean"
    w = np.ones(3) if weights is None or euclidean else \
        np.asarray(weights, dtype=float).reshape(3)
    # a band sample's distance is at most its offset from a point of a surface voxel:
    # (band + 1/2) voxels per axis; the nearest point lies that far per axis (max norm,
    # weighted) or that offset's length along any axis (Euclidean)
    scale = float(np.linalg.norm(h)) if euclidean else float(h.max())
    limit = (band + 0.5) * scale
    reach = np.full(3, limit) if euclidean else (band + 0.5) * h
    job = _BandJob(mesh, grid, keys, active, w, reach * (1 + _SLACK) + _SLACK * h, euclidean,
                   steps, scale)
    pieces = _pieces(job.start)
    values = np.empty(active.shape)
    if workers > 1 or executor is not None:
        results = farm(job, pieces, workers=workers, executor=executor, progress=progress,
                       weights=[job.start[b1] - job.start[b0] + 1 for b0, b1 in pieces],
                       what=f"scattering triangles over {len(keys):,} bricks", threads=True)
    else:
        results = ((i, job.run(piece)) for i, piece in enumerate(pieces))
    for i, part in results:
        b0, b1 = pieces[i]
        values[b0:b1] = part
        if progress is not None and workers <= 1 and executor is None:
            progress(b1 / max(len(keys), 1))
    # beyond every triangle's reach, or no triangle below its starting bound (left at inf;
    # none where the voxelization holds): the walk over all of them
    far = active & (values > limit)
    if far.any():
        points = grid.centers(masked_coords(keys, far))
        values[far] = np.abs(mesh.euclidean_distance(points) if euclidean else
                             mesh.distance(points, np.broadcast_to(w, points.shape)))
    return values[active]


def _pieces(start: np.ndarray) -> list[tuple[int, int]]:
    """Ranges of bricks of about :data:`PIECE_PAIRS` brick-triangle pairs each."""
    n = len(start) - 1
    cuts = np.searchsorted(start, np.arange(PIECE_PAIRS, start[-1], PIECE_PAIRS))
    bounds = np.unique(np.concatenate([[0], cuts, [n]]))
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
