"""Dual contouring on the adaptive grid (Ju, Losasso, Schaefer, Warren 2002).

Each leaf with a sign change gets one vertex (:mod:`implicitvox.meshing.qef`,
from the certified crossings of :mod:`implicitvox.meshing.edges`), and each
*minimal* edge with a sign change - an edge of the smallest cells around it,
not split by a finer neighbour - gets the polygon joining the vertices of the
(up to four) cells around it. Cells of different sizes need no crack
patching: a coarse cell beside finer ones appears twice around the fine
edges on their common face, and its quads become triangles (Varadhan §6.3
contours the same way). The polygon is oriented so that its normal points
from ``f < 0`` to ``f >= 0`` along the edge: outward.

The loops over edges are compiled (:mod:`.contour_kernels`): each distinct edge is
found once (a hash of its start, axis and length), and the cells around it by
locating four probe points (beside the edge's midpoint, one in each quadrant
around it) among the leaves' runs of finest-level Morton codes.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z
>>> from implicitvox.octree.grid import Grid
>>> from implicitvox.meshing.adaptive import adaptive_grid
>>> g = Grid.from_bounds(((-1.2,) * 3, (1.2,) * 3), 8)
>>> f = iv.compile(x * x + y * y + z * z - 1)
>>> c = dual_contour(f, adaptive_grid(f, g, refine=1))
>>> c.points.shape[1], c.faces.shape[1], c.unmatched
(3, 3, 0)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np

from ..eval.function import Function
from ..octree import morton
from ..octree.morton import CORNERS, NEIGHBOURS
from .adaptive import AdaptiveGrid
from .qef import solve

__all__ = ["Contour", "dual_contour"]

@dataclass
class Contour:
    """Dual contouring's output.

    Attributes
    ----------
    points : ndarray (m, 3)
        Vertices, one per leaf that has a sign change.
    faces : ndarray of int64 (k, 3)
        Triangles, oriented outward.
    cell_of_point : ndarray of int64 (m,)
        The leaf (index into the grid's leaves) each vertex lies in.
    uncovered : int
        Complex leaves (:attr:`AdaptiveGrid.complex`) with a point farther than
        ``bound`` from every vertex of the leaves around them: the Hausdorff
        bound does not cover the surface they may hold.
    unmatched : int
        Minimal sign-change edges where a cell around the edge was not among
        the leaves (the grid's boundary, where the mesh is open, or a sign
        decided differently by rounding); no polygon is made there.
    """

    points: np.ndarray
    faces: np.ndarray
    cell_of_point: np.ndarray
    uncovered: int
    unmatched: int


class _Locator:
    """The leaf that holds a finest-level cell: the leaves are disjoint runs of the
    finest level's Morton codes (a leaf at level ``l`` covers ``8**(depth - l)``
    of them from its first), so one binary search over the runs' starts finds
    it, whatever its level (compiled: :func:`.contour_kernels.find_leaf`)."""

    def __init__(self, agrid: AdaptiveGrid):
        self.depth = agrid.grid.depth
        self.shape = np.asarray(agrid.grid.shape, dtype=np.int64)
        shift = (3 * (self.depth - agrid.levels.astype(np.int64))).astype(np.uint64)
        starts = morton.encode(agrid.coords) << shift
        order = np.argsort(starts, kind="stable")
        self.starts = starts[order]
        self.ends = self.starts + (np.uint64(1) << shift[order])
        self.index = order
        self.levels = agrid.levels.astype(np.int64)[order]

    def find(self, fine: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Leaf index and level (-1 where none) of finest-level cells ``fine`` (n, 3)."""
        from .contour_kernels import find_leaves          # (loads Numba)
        at = find_leaves(self.starts, self.ends, self.shape,
                         np.ascontiguousarray(fine, dtype=np.int64))
        hit = at >= 0
        return (np.where(hit, self.index[at], -1), np.where(hit, self.levels[at], -1))

    def edge_cells(self, start: np.ndarray, axis: np.ndarray, length: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:func:`.contour_kernels.edge_cells` over these leaves."""
        from .contour_kernels import edge_cells           # (loads Numba)
        return edge_cells(start, axis, length, self.starts, self.ends, self.index,
                          self.levels, self.shape, self.depth)


def dual_contour(func: Function, agrid: AdaptiveGrid, bound: float = np.inf,
                 progress: Optional[Callable[[float], Any]] = None) -> Contour:
    """The triangles of the surface over the adaptive grid (module docstring);
    ``bound`` (Euclidean) is the distance a complex leaf's points may be from
    the nearest vertex of a leaf around it (:attr:`Contour.uncovered`);
    ``progress`` is called with the share done after each stage."""
    from .contour_kernels import changed_edges, quad_triangles, unique_edges   # (Numba)
    share = progress if progress is not None else (lambda s: None)
    grid, depth = agrid.grid, agrid.grid.depth
    n = agrid.count
    # every (leaf, edge) with a sign change, and each distinct edge once (up to four
    # leaves list it): its crossing is found once
    leaf, start, axis, length, low_inside = changed_edges(
        np.ascontiguousarray(agrid.corners, dtype=np.float64), agrid.levels,
        np.ascontiguousarray(agrid.coords, dtype=np.int64), depth)
    first, edge_of, code = unique_edges(start, axis, length)
    e_start, e_axis, e_length = start[first], axis[first], length[first]
    e_end = e_start.copy()
    e_end[np.arange(len(first)), e_axis] += e_length
    a_pos = np.stack([grid.edge(k, e_start[:, k]) for k in range(3)], 1)
    b_pos = np.stack([grid.edge(k, e_end[:, k]) for k in range(3)], 1)
    p, nrm = agrid.tapes.crossings(agrid.tape_index[leaf[first]], a_pos, b_pos)
    scale = np.left_shift(1, depth - agrid.levels.astype(np.int64))       # cell size, fine units
    lo = np.stack([grid.edge(k, agrid.coords[:, k] * scale) for k in range(3)], 1)
    hi = np.stack([grid.edge(k, np.minimum((agrid.coords[:, k] + 1) * scale, grid.shape[k]))
                   for k in range(3)], 1)
    vertex = solve(leaf, p, nrm, n, lo, hi, crossing=edge_of)
    share(0.6)
    # the cells around each edge: probes beside its midpoint, one per quadrant
    locator = _Locator(agrid)
    around, minimal, unmatched = locator.edge_cells(e_start, e_axis, e_length)
    # polygons in the order of their edges' axes, then Morton codes
    chosen = np.flatnonzero(minimal)
    chosen = chosen[np.lexsort((code[chosen], e_axis[chosen]))]
    loose = np.flatnonzero(unmatched)
    n_unmatched = len(np.unique(np.stack([code[loose], e_axis[loose].astype(np.uint64)]),
                                axis=1).T) if len(loose) else 0
    share(0.85)
    quads = around[chosen]
    flip = ~low_inside[first[chosen]]             # f >= 0 at the lower end: normal -axis
    quads[flip] = quads[flip][:, ::-1]
    faces = quad_triangles(np.ascontiguousarray(quads), vertex)
    has_vertex = np.zeros(n, dtype=bool)
    has_vertex[faces.ravel()] = True
    used = np.flatnonzero(has_vertex)
    renumber = np.cumsum(has_vertex) - 1
    uncovered = _uncovered(agrid, locator, vertex, has_vertex, lo, hi, bound)
    return Contour(vertex[used], renumber[faces].reshape(-1, 3).astype(np.int64), used,
                   uncovered, int(n_unmatched))


def _uncovered(agrid: AdaptiveGrid, locator: "_Locator", vertex: np.ndarray,
               has_vertex: np.ndarray, lo: np.ndarray, hi: np.ndarray, bound: float) -> int:
    """Complex leaves whose farthest point is more than ``bound`` from the vertex
    of every leaf touching them (one leaf probed per neighbour direction)."""
    cells = np.flatnonzero(agrid.complex)
    if not len(cells):
        return 0
    corners = np.stack([np.where(CORNERS[None, :, a] == 1, hi[cells, None, a], lo[cells, None, a])
                        for a in range(3)], -1)                       # (m, 8, 3)
    best = np.full(len(cells), np.inf)
    shift = (agrid.grid.depth - agrid.levels[cells].astype(np.int64))[:, None]
    for offset in NEIGHBOURS:
        # the neighbour's finest cell nearest to this leaf
        near = (agrid.coords[cells] + offset) << shift
        near += np.where(offset < 0, (1 << shift) - 1, 0)
        j, _ = locator.find(near)
        ok = j >= 0
        ok[ok] = has_vertex[j[ok]]
        if ok.any():
            far = np.linalg.norm(corners[ok] - vertex[j[ok]][:, None, :], axis=2).max(1)
            best[ok] = np.minimum(best[ok], far)
    return int((best > bound).sum())
