"""``mesh``: a shape to triangles within a guaranteed Hausdorff distance.

The adaptive grid without complex cells (Varadhan et al. §5.2,
:mod:`implicitvox.meshing.adaptive`) contoured by dual contouring
(:mod:`implicitvox.meshing.contour`). The two-sided Hausdorff distance
between the mesh and the true surface is at most the tolerance (Euclidean),
except in the uncertified cells, which the result counts and a warning names.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z, sqrt
>>> m = iv.mesh(sqrt(x**2 + y**2 + z**2) - 1, tolerance=0.05, bounds=((-1.2,) * 3, (1.2,) * 3))
>>> m.n_cells > 1000, float(m.field_data["hausdorff_bound"][0]) <= 0.05
(True, True)
"""
from __future__ import annotations

import math
import time
import warnings
from typing import Any, Callable, Optional, Union

import numpy as np

from .. import validate
from ..eval.function import Function
from ..expr.shape import (as_shape, boundary_mesh, exact_classifier, expression_is_exact,
                          voxel_classifier)
from ..octree.grid import Grid, grid_of
from ..octree.morton import MAX_BITS
from ..octree.pilot import Estimate, estimate_surface
from ..octree.run import Run
from ..octree.octants import runs_compiled
from ..octree.subtrees import subdivide_in_parallel
from ..octree.surface import SurfaceOptions
from ..version import __version__
from .adaptive import BYTES_PER_CELL, adaptive_grid
from .contour import dual_contour
from .manifold import edge_counts, split_nonmanifold

__all__ = ["mesh", "mesh_grid", "estimate_meshing_memory", "REFINE", "LEAVES_PER_VOXEL"]

#: levels below the tolerance's cells that complex cells may be split to
REFINE = 4
#: leaves per surface voxel of the tolerance level the pilot estimates, for the estimate
#: (``bench_mesh_memory.py``: 0.71-1.02 on six of the seven models at 256 and 512; the
#: refined complex cells of sin(9θ)sin(18φ) - r make 1.30-2.23, which the guard watches)
LEAVES_PER_VOXEL = 1.0


def mesh(shape: Any, tolerance: Optional[float] = None,
         resolution: Union[int, tuple[int, int, int], None] = None, *, bounds: Any = None,
         refine: int = REFINE, progress: Optional[Callable[[float], Any]] = None,
         max_memory: Optional[int] = None, prune: bool = True,
         workers: Optional[int] = None, executor: Any = None) -> Any:
    """Triangulate a shape's surface within a guaranteed Hausdorff distance.

    Parameters
    ----------
    shape : Expr or Shape
        The implicit function ``f`` (solid ``f <= 0``) or a shape object (csg
        solids and OpenSCAD models included: their exact box tests are used). A
        polyhedral solid (every part a polytope: boxes, OpenSCAD's facets, imported
        meshes, extruded outlines) is meshed as its own closed boundary
        (``shape.boundary_mesh``: its faces, the booleans computed by Manifold), whole
        and exactly, whatever the tolerance: ``hausdorff_bound`` 0, up to the
        rounding of the vertices the booleans create; a cube is 12 triangles.
    tolerance : float, optional
        The bound (world units, Euclidean) on the two-sided Hausdorff distance
        between the mesh and the surface. The largest cells are cubes of edge
        ``tolerance / √3``. Give this or ``resolution``.
    resolution : int, optional
        Cells along the longest side of the bounds at the coarsest leaf level
        instead; the bound is then ``√3`` times the cell size.
    bounds : ((x0, y0, z0), (x1, y1, z1)), optional
        The grid's box; by default the shape's own bounds padded by half a
        cell. The mesh is open where the surface leaves the bounds.
    refine : int, default: 4
        Levels below the largest cells that complex cells (the surface meets
        them but no edge shows it: thin sheets, near contacts) are split to.
    progress : callable, optional
        Called with the share of work done (0 to 1).
    max_memory : int, optional
        Refuse (``MemoryError``) when the estimate exceeds this many bytes,
        and stop when the run does; default half the available memory.
    prune : bool, default: True
        Prune the tapes while voxelizing (:func:`implicitvox.voxelize`).
    workers : int, optional
        Processes for the subdivision down to the largest cells
        (:func:`implicitvox.octree.subtrees.subdivide_in_parallel`); the
        refinement and the contouring run here. The mesh is the same, bit for
        bit, for any number. Default: every core this process may use, one for
        a small run and, for now, for a model on the compiled kernel (its
        subdivision is a small share of the run:
        :meth:`implicitvox.octree.run.Run.workers_for`).
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Run the subdivision there instead.

    Returns
    -------
    pyvista.PolyData
        Triangles oriented outward (their normals point to ``f > 0``). Its
        ``field_data`` holds ``hausdorff_bound`` (Euclidean, world units),
        ``linf_bound`` (max norm), ``complex_cells`` (finest cells the surface
        may meet that no edge shows), ``uncertified_cells`` (those of them with
        a point farther than the bound from every vertex around them: the bound
        does not cover them; 0 means it holds everywhere), ``open_edges``
        (sign-change edges at the bounds, where the mesh is open),
        ``non_manifold_edges`` (edges still in more than two triangles after
        the vertex splitting of :mod:`implicitvox.meshing.manifold`), ``leaves``
        and ``seconds``.

    Raises
    ------
    ValueError
        For bad options (the message names the parameter); for a solid whose
        expression only bounds it and that has no closed mesh of its own (a
        polyhedron beside a curved part, an open mesh); for bounds that cut a
        polyhedral solid.
    MemoryError
        When the estimate, or the run, exceeds ``max_memory``.
    """
    shape = as_shape(shape)
    if (tolerance is None) == (resolution is None):
        raise ValueError("give one of tolerance (the Hausdorff bound, world units) or "
                         "resolution (cells along the longest side)")
    voxel_size = None
    if tolerance is not None:
        tol = validate.positive_number(tolerance, "tolerance")
        voxel_size = tol / math.sqrt(3) * (1 - 2.0 ** -40)
    refine = validate.int_in(refine, "refine", 0, 12)
    run = Run.of(max_memory=max_memory, progress=progress, workers=workers, executor=executor)
    prune = validate.boolean(prune, "prune")
    grid = grid_of(getattr(shape, "bounds", None), bounds, resolution, voxel_size)
    if grid.depth + refine > MAX_BITS:
        raise ValueError(f"the grid {grid.shape} with refine={refine} needs "
                         f"{grid.depth + refine} octree levels, over the {MAX_BITS} there are; "
                         "raise tolerance or lower refine")
    return mesh_grid(shape, grid, run, refine=refine, prune=prune)


def mesh_grid(shape: Any, grid: Grid, run: Run, *, refine: int = REFINE,
              prune: bool = True) -> Any:
    """:func:`mesh` on a given grid (its voxels are the largest cells), under the
    ``run``'s budget, progress and workers; :meth:`implicitvox.Voxels.to_mesh` uses it."""
    import pyvista as pv

    shape = as_shape(shape)
    found = boundary_mesh(shape)
    if found is not None or not expression_is_exact(shape):
        return _boundary(found, grid)
    func = Function(shape.expr)
    exact, exact_voxels = exact_classifier(shape), voxel_classifier(shape)
    estimate, estimated, need = estimate_meshing_memory(shape, grid, prune)
    what = f"meshing at {grid.shape}"
    run.refuse(need, f"{what} (~{estimated:,} cells; {estimate.explained()})")
    guard = run.guard(what, BYTES_PER_CELL, estimated=estimated)
    t0 = time.perf_counter()
    workers = run.workers_for(estimate.voxels, default_serial=runs_compiled(func.tape, grid))
    split = None
    if workers > 1 or run.executor is not None:
        split = subdivide_in_parallel(shape, func, grid, SurfaceOptions(prune=prune),
                                      run.part(0.0, 0.3), workers=workers,
                                      per_voxel=BYTES_PER_CELL, guard=guard, what=what,
                                      tapes=True)
    agrid = adaptive_grid(func, grid, refine, exact=exact, exact_voxels=exact_voxels,
                          progress=run.part(0.0, 0.6).progress, guard=guard, prune=prune,
                          voxels=None if split is None else split.result)
    h = max(grid.voxel_size)
    contour = dual_contour(func, agrid, bound=h * math.sqrt(3),
                           progress=run.part(0.6, 0.95).progress)
    run.report(1.0)
    points, triangles, non_manifold = split_nonmanifold(contour.points, contour.faces)
    faces = np.hstack([np.full((len(triangles), 1), 3, dtype=np.int64), triangles])
    out = pv.PolyData(points, faces=faces.ravel()) if len(triangles) else pv.PolyData()
    out.field_data["hausdorff_bound"] = [h * math.sqrt(3)]
    out.field_data["linf_bound"] = [h]
    out.field_data["uncertified_cells"] = [contour.uncovered]
    out.field_data["complex_cells"] = [int(agrid.complex.sum())]
    out.field_data["open_edges"] = [contour.unmatched]
    out.field_data["non_manifold_edges"] = [non_manifold]
    out.field_data["leaves"] = [agrid.count]
    out.field_data["seconds"] = [time.perf_counter() - t0]
    out.field_data["workers"] = [workers if split is not None else 1]
    out.field_data["implicitvox"] = [__version__]
    if contour.uncovered:
        warnings.warn(f"{contour.uncovered:,} cells of size {h / 2 ** refine:.3g} may hold "
                      "surface that no cell edge shows (detail below the finest cell, or a "
                      "tangency): the Hausdorff bound does not cover them; raise refine or "
                      "lower tolerance", UserWarning, stacklevel=3)
    return out


def _boundary(found: Optional[tuple], grid: Grid) -> Any:
    """A polyhedral solid's mesh: its own closed boundary (``found``, from
    ``boundary_mesh``; None: the solid has none), checked against the grid's box and
    its edges counted."""
    import pyvista as pv

    t0 = time.perf_counter()
    if found is None:
        raise ValueError("this solid holds polyhedra (OpenSCAD's faceted spheres, extruded "
                         "text and other long outlines, polyhedron(), imported meshes) whose "
                         "expressions only bound them, beside a curved part or an open mesh: "
                         "it has neither point values to contour nor a closed mesh of its "
                         "own. Read OpenSCAD models with facets='true' (the true curves) or "
                         "all in facets, or voxelize the solid")
    points, triangles = found
    lo, hi = (np.asarray(b, dtype=np.float64) for b in grid.bounds)
    if len(points) and ((points.min(0) < lo).any() or (points.max(0) > hi).any()):
        raise ValueError(f"bounds: a polyhedral solid is meshed whole, and its boundary "
                         f"reaches {points.min(0).tolist()} - {points.max(0).tolist()}, past "
                         f"the bounds {lo.tolist()} - {hi.tolist()}; give bounds that hold "
                         "it, or none")
    _, _, counts = edge_counts(triangles) if len(triangles) else (None, None, np.zeros(0))
    faces = np.hstack([np.full((len(triangles), 1), 3, dtype=np.int64), triangles])
    out = pv.PolyData(points, faces=faces.ravel()) if len(triangles) else pv.PolyData()
    for key, value in (("hausdorff_bound", 0.0), ("linf_bound", 0.0), ("uncertified_cells", 0),
                       ("complex_cells", 0), ("open_edges", int((counts == 1).sum())),
                       ("non_manifold_edges", int((counts > 2).sum())), ("leaves", 0),
                       ("seconds", time.perf_counter() - t0), ("workers", 1),
                       ("implicitvox", __version__)):
        out.field_data[key] = [value]
    return out


def estimate_meshing_memory(shape: Any, grid: Grid, prune: bool = True
                            ) -> tuple[Estimate, int, int]:
    """The pilot's estimate (:func:`implicitvox.octree.pilot.estimate_surface`, with
    the shape's exact box test), and the leaves and peak bytes of :func:`mesh_grid`
    on ``grid``: the surface voxels times the leaves per surface voxel and the bytes
    per leaf."""
    shape = as_shape(shape)
    estimate = estimate_surface(Function(shape.expr), grid, prune=prune,
                                exact=exact_classifier(shape))
    leaves = int(estimate.voxels * LEAVES_PER_VOXEL)
    return estimate, leaves, leaves * BYTES_PER_CELL
