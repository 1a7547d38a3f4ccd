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

All of it is array code over every edge at once: the cells around an edge
are found by locating four probe points (beside the edge's midpoint, one in
each quadrant around it) among the sorted Morton codes of each level.

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
from .adaptive import AdaptiveGrid, per_tape
from .edges import crossings
from .qef import solve

__all__ = ["Contour", "dual_contour", "EDGES"]

#: the 12 cell edges as (start corner, end corner, axis), the start the lower end
EDGES = np.array([(c, c | (1 << a), a) for a in range(3) for c in range(8) if not (c >> a) & 1],
                 dtype=np.int64)


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
    it, whatever its level."""

    def __init__(self, agrid: AdaptiveGrid):
        self.depth = agrid.grid.depth
        self.shape = np.asarray(agrid.grid.shape)
        shift = (3 * (self.depth - agrid.levels.astype(np.int64))).astype(np.uint64)
        starts = morton.encode(agrid.coords) << shift
        order = np.argsort(starts, kind="stable")
        self.starts = starts[order]
        self.ends = self.starts + (np.uint64(1) << shift[order])
        self.index = order
        self.levels = agrid.levels.astype(np.int64)[order]

    def _codes(self, fine: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        inside = ((fine >= 0) & (fine < self.shape)).all(1)
        return morton.encode(np.where(inside[:, None], fine, 0)), inside

    def split(self, fine: np.ndarray, level: np.ndarray) -> np.ndarray:
        """Whether the cell at ``level`` holding finest-level cell ``fine`` has
        leaves below it (it was split): a leaf deeper than ``level`` starts in
        its run of finest codes."""
        shift = (3 * (self.depth - np.asarray(level, dtype=np.int64))).astype(np.uint64)
        codes = morton.encode(np.maximum(fine, 0))        # past the grid: no leaf there
        first = (codes >> shift) << shift
        lo = np.searchsorted(self.starts, first, side="left")
        hi = np.searchsorted(self.starts, first + (np.uint64(1) << shift), side="left")
        count = hi - lo
        deeper = np.zeros(len(fine), dtype=bool)
        one = count == 1
        deeper[one] = self.levels[lo[one]] > np.asarray(level)[one]
        return (count >= 2) | deeper

    def find(self, fine: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Leaf index and level (-1 where none) of finest-level cells ``fine`` (n, 3)."""
        codes, inside = self._codes(fine)
        at = np.searchsorted(self.starts, codes, side="right") - 1
        hit = inside & (at >= 0)
        hit[hit] = codes[hit] < self.ends[at[hit]]
        found = np.full(len(fine), -1, dtype=np.int64)
        level_of = np.full(len(fine), -1, dtype=np.int64)
        found[hit] = self.index[at[hit]]
        level_of[hit] = self.levels[at[hit]]
        return found, level_of


def dual_contour(func: Function, agrid: AdaptiveGrid, bound: float = np.inf,
                 progress: Optional[Callable[[float], Any]] = None) -> Contour:
    """The triangles of the surface over the adaptive grid (module docstring);
    ``bound`` (Euclidean) is the distance a complex leaf's points may be from
    the nearest vertex of a leaf around it (:attr:`Contour.uncovered`);
    ``progress`` is called with the share done after each stage."""
    share = progress if progress is not None else (lambda s: None)
    grid, depth = agrid.grid, agrid.grid.depth
    n = agrid.count
    inside = agrid.corners < 0
    scale = np.left_shift(1, depth - agrid.levels.astype(np.int64))       # cell size, fine units
    # every (leaf, edge) with a sign change
    change = inside[:, EDGES[:, 0]] != inside[:, EDGES[:, 1]]               # (n, 12)
    leaf, which = np.nonzero(change)
    start_corner, end_corner, axis = EDGES[which].T
    origin = agrid.coords[leaf] * scale[leaf, None]                        # fine units
    a_idx = origin + CORNERS[start_corner] * scale[leaf, None]
    b_idx = origin + CORNERS[end_corner] * scale[leaf, None]
    # each edge bisected once, though up to four cells list it
    code = morton.encode(a_idx)
    length = scale[leaf]
    points = np.empty((len(leaf), 3))
    normals = np.empty((len(leaf), 3))
    for a in range(3):
        for size in np.unique(length):
            rows = np.flatnonzero((axis == a) & (length == size))
            _, first, back = np.unique(code[rows], return_index=True, return_inverse=True)
            one = rows[first]
            a_pos = np.stack([grid.edge(k, a_idx[one, k]) for k in range(3)], 1)
            b_pos = np.stack([grid.edge(k, b_idx[one, k]) for k in range(3)], 1)
            p, nrm = per_tape(agrid.tapes, agrid.tape_index[leaf[one]],
                              lambda tape, a, b: crossings(tape, a, b), a_pos, b_pos)
            points[rows], normals[rows] = p[back.ravel()], nrm[back.ravel()]
    lo = np.stack([grid.edge(k, agrid.coords[:, k] * scale) for k in range(3)], 1)
    hi = np.stack([grid.edge(k, np.minimum((agrid.coords[:, k] + 1) * scale, grid.shape[k]))
                   for k in range(3)], 1)
    vertex = solve(leaf, points, normals, n, lo, hi)
    share(0.6)
    # the cells around each edge: probes beside its midpoint, one per quadrant
    locator = _Locator(agrid)
    u, v = (axis + 1) % 3, (axis + 2) % 3
    rows = np.arange(len(leaf))
    around = np.empty((len(leaf), 4), dtype=np.int64)
    around_level = np.empty((len(leaf), 4), dtype=np.int64)
    probes = []
    for q, (du, dv) in enumerate(((-1, -1), (0, -1), (0, 0), (-1, 0))):    # counter-clockwise
        fine = a_idx.copy()
        fine[rows, axis] += scale[leaf] // 2
        fine[rows, u] += du
        fine[rows, v] += dv
        around[:, q], around_level[:, q] = locator.find(fine)
        probes.append(fine)
    level = agrid.levels[leaf].astype(np.int64)
    complete = (around >= 0).all(1)
    minimal = complete & (around_level <= level[:, None]).all(1)
    # an edge with a cell around it missing, not because a finer neighbour split it
    unmatched_edges = ~complete & (around_level <= level[:, None]).all(1)
    for q in range(4):
        rows = np.flatnonzero(unmatched_edges & (around[:, q] < 0))
        unmatched_edges[rows[locator.split(probes[q][rows], level[rows])]] = False
    # one polygon per minimal edge, though every cell around it lists it
    chosen = np.concatenate([_first_of_each(code, minimal & (axis == a)) for a in range(3)])
    n_unmatched = sum(len(_first_of_each(code, unmatched_edges & (axis == a))) for a in range(3))
    share(0.85)
    quads = around[chosen]
    flip = ~inside[leaf[chosen], start_corner[chosen]]      # f >= 0 at the lower end: normal -axis
    quads[flip] = quads[flip][:, ::-1]
    faces = _triangles(quads, vertex)
    used, faces = np.unique(faces.ravel(), return_inverse=True)
    has_vertex = np.zeros(n, dtype=bool)
    has_vertex[used] = True
    uncovered = _uncovered(agrid, locator, vertex, has_vertex, lo, hi, bound)
    return Contour(vertex[used], faces.reshape(-1, 3).astype(np.int64), used, uncovered,
                   int(n_unmatched))


def _first_of_each(code: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Indices (into ``code``) of the first row of each distinct code among ``mask``."""
    rows = np.flatnonzero(mask)
    _, first = np.unique(code[rows], return_index=True)
    return rows[first]




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


def _triangles(quads: np.ndarray, vertex: np.ndarray) -> np.ndarray:
    """Quads (cyclic cell indices) to triangles: split along the shorter diagonal;
    a quad with a cell twice (a coarse cell beside two finer ones) is one triangle."""
    same = quads == np.roll(quads, -1, axis=1)             # position i equals i + 1
    degenerate = same.any(1)
    full = quads[~degenerate]
    d02 = np.linalg.norm(vertex[full[:, 0]] - vertex[full[:, 2]], axis=1)
    d13 = np.linalg.norm(vertex[full[:, 1]] - vertex[full[:, 3]], axis=1)
    split02 = d02 <= d13
    t1 = np.where(split02[:, None], full[:, [0, 1, 2]], full[:, [1, 2, 3]])
    t2 = np.where(split02[:, None], full[:, [0, 2, 3]], full[:, [1, 3, 0]])
    tri = []
    one_repeat = degenerate & (same.sum(1) == 1)           # three distinct cells
    if one_repeat.any():
        tri.append(quads[one_repeat][~same[one_repeat]].reshape(-1, 3))
    return np.concatenate([t1, t2] + tri) if len(full) or tri else np.zeros((0, 3), np.int64)
