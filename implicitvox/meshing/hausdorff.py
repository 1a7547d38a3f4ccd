"""Measured distances between a mesh and the true surface: the bound checked.

:func:`implicitvox.mesh` proves a Hausdorff bound; these measure it.

* :func:`distance_to_surface` bounds from above each point's Euclidean
  distance to the surface ``f = 0``: along a few directions (down the
  gradient towards the other sign; towards the 26 neighbours of a cube where
  that left more than half the distance to settle, as at sharp edges; 400
  directions spread over the sphere where more, as near corners) it finds the nearest step where ``f`` changes sign and isolates the
  zero on that segment by bisection. A sign change on a segment holds a
  zero (``f`` continuous), and a sample where ``f`` is 0 is one, so the
  bound is certified, not estimated.
* :func:`surface_points` finds points on the surface independently of the
  mesher: sign changes on the edges of a uniform lattice, bisected.
* :func:`distance_to_mesh` is the exact distance to the triangles (VTK's
  cell locator).
* :func:`hausdorff` puts them together, both ways.

Examples
--------
>>> import numpy as np, implicitvox as iv
>>> from implicitvox import x, y, z, sqrt
>>> f = iv.compile(sqrt(x**2 + y**2 + z**2) - 1)
>>> d = distance_to_surface(f, np.array([[0.0, 0, 1.5], [0.6, 0, 0]]), limit=1.0)
>>> np.round(d, 6).tolist()
[0.5, 0.4]
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ..eval.function import Function
from ..eval.gradient import evaluate_gradients
from ..eval.point import evaluate_points
from ..octree.morton import NEIGHBOURS
from .edges import crossings

__all__ = ["distance_to_surface", "surface_points", "distance_to_mesh", "mesh_samples",
           "hausdorff", "sphere_directions"]

#: steps of the ladder along each direction, and bisection steps after it
_LADDER = 32
_BISECT = 12
#: directions tried last, where the others left a bound above a quarter of the limit
_MORE = 400


def _values(func: Function, p: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.broadcast_to(evaluate_points(func.tape, *p.T), (len(p),))


def distance_to_surface(func: Function, points: np.ndarray, limit: float,
                        settle: Optional[float] = None) -> np.ndarray:
    """Upper bounds of the Euclidean distances from ``points`` (n, 3) to ``f = 0``;
    ``inf`` where no zero was found within ``limit`` of the point.

    The gradient's direction is tried for every point; the 26 directions to a
    cube's neighbours where that left more than half of ``settle`` (default a
    quarter of ``limit``), and 400 more where more than ``settle``: a bound at
    most ``settle`` is as tight as the gradient gives, a larger one as tight as
    427 directions give."""
    settle = limit / 4 if settle is None else float(settle)
    points = np.asarray(points, dtype=np.float64)
    n = len(points)
    f0 = _values(func, points)
    best = np.where(f0 == 0, 0.0, np.inf)
    with np.errstate(all="ignore"):
        _, g = evaluate_gradients(func.tape, *points.T)
    g = np.broadcast_to(np.asarray(g, dtype=np.float64).reshape(3, -1), (3, n)).T
    norm = np.linalg.norm(g, axis=1, keepdims=True)
    unit = np.where((norm > 0) & np.isfinite(norm), g / np.where(norm > 0, norm, 1), 0)
    downhill = np.where((f0 > 0)[:, None], -unit, unit)     # towards the other sign
    directions = [downhill] + [np.broadcast_to(np.array(c) / np.linalg.norm(c), (n, 3))
                                  for c in NEIGHBOURS] + \
        [np.broadcast_to(c, (n, 3)) for c in sphere_directions(_MORE)]
    inside0 = f0 < 0
    for i, d in enumerate(directions):
        # the 26 only where the gradient left more than an eighth of the limit, the
        # many more only where a quarter (near corners, where no few directions aim)
        floor = 0 if i < 1 else settle / 2 if i < 1 + len(NEIGHBOURS) else settle
        todo = (np.abs(d).sum(1) > 0) & (best > floor)
        if not todo.any():
            continue
        rows = np.flatnonzero(todo)
        found = np.full(len(rows), np.inf)
        for k in range(1, _LADDER + 1):      # the first step with a sign change
            t = limit * k / _LADDER
            open_ = np.flatnonzero(~np.isfinite(found))
            if not len(open_):
                break
            r = rows[open_]
            v = _values(func, points[r] + t * d[r])
            change = ((v < 0) != inside0[r]) | (v == 0)
            found[open_[change]] = t
        hit = np.isfinite(found)
        if hit.any():
            r = rows[hit]
            lo, hi = np.zeros(len(r)), found[hit]
            p, dd, inside = points[r], d[r], inside0[r]
            for _ in range(_BISECT):
                mid = 0.5 * (lo + hi)
                v = _values(func, p + mid[:, None] * dd)
                same = ((v < 0) == inside) & (v != 0)
                lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
            best[r] = np.minimum(best[r], hi)
    return best


def sphere_directions(count: int) -> np.ndarray:
    """``count`` unit vectors spread evenly over the sphere (a Fibonacci lattice)."""
    k = np.arange(count) + 0.5
    z = 1 - 2 * k / count
    angle = np.pi * (1 + 5 ** 0.5) * k
    rho = np.sqrt(1 - z * z)
    return np.stack([rho * np.cos(angle), rho * np.sin(angle), z], 1)


def surface_points(func: Function, bounds: Any, resolution: int) -> np.ndarray:
    """Points on ``f = 0``: the bisected sign changes on the edges of a uniform
    ``resolution``-point lattice over ``bounds`` (per axis)."""
    lo, hi = (np.asarray(b, dtype=np.float64) for b in bounds)
    axes = [np.linspace(lo[a], hi[a], resolution) for a in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    grid = np.stack([X, Y, Z], -1)
    inside = _values(func, grid.reshape(-1, 3)).reshape(X.shape) < 0
    out = []
    for a in range(3):
        head = [slice(None)] * 3
        tail = [slice(None)] * 3
        head[a], tail[a] = slice(0, -1), slice(1, None)
        change = inside[tuple(head)] != inside[tuple(tail)]
        p0 = grid[tuple(head)][change]
        p1 = grid[tuple(tail)][change]
        out.append(crossings(func, p0, p1)[0])
    return np.concatenate(out)


def mesh_samples(points: np.ndarray, faces: np.ndarray, per_triangle: int = 1,
                 seed: int = 0) -> np.ndarray:
    """The vertices, the edges' midpoints and ``per_triangle`` random points of
    each triangle (uniform over it)."""
    rng = np.random.default_rng(seed)
    a, b, c = (points[faces[:, i]] for i in range(3))
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]],
                                              faces[:, [2, 0]]]), axis=1), axis=0)
    r1 = np.sqrt(rng.random((len(faces), per_triangle, 1)))
    r2 = rng.random((len(faces), per_triangle, 1))
    inner = (1 - r1) * a[:, None] + r1 * (1 - r2) * b[:, None] + r1 * r2 * c[:, None]
    return np.concatenate([points, 0.5 * (points[edges[:, 0]] + points[edges[:, 1]]),
                           inner.reshape(-1, 3)])


def distance_to_mesh(mesh: Any, points: np.ndarray) -> np.ndarray:
    """Euclidean distance from ``points`` (n, 3) to a ``pyvista.PolyData`` of triangles."""
    _, closest = mesh.find_closest_cell(np.asarray(points, dtype=np.float64),
                                        return_closest_point=True)
    return np.linalg.norm(np.asarray(closest) - points, axis=1)


def hausdorff(mesh: Any, func: Function, surface: np.ndarray,
              limit: Optional[float] = None) -> tuple[float, float]:
    """``(mesh_to_surface, surface_to_mesh)``: the largest measured distance from
    the mesh's samples (:func:`mesh_samples`) to the surface (an upper bound per
    sample, :func:`distance_to_surface` within ``limit``, default 4 times the
    mesh's ``hausdorff_bound``; every direction is tried where more than the bound)
    and from the ``surface`` points to the mesh."""
    bound = float(mesh.field_data["hausdorff_bound"][0])
    if limit is None:
        limit = 4 * bound
    samples = mesh_samples(np.asarray(mesh.points), mesh.regular_faces)
    there = distance_to_surface(func, samples, limit, settle=bound)
    back = distance_to_mesh(mesh, surface) if len(surface) else np.zeros(1)
    return float(there.max()), float(back.max())
