"""Exact box classification against an axis-aligned prism: a polygon region extruded
along a world axis (OpenSCAD's straight extrusions, :class:`csg.prism.Prism`).

A closed box meets the prism's surface iff its span along the extrusion axis meets
the prism's and its rectangle across meets an outline edge (exact orientation signs,
:func:`implicitvox.triangles.predicates.det2_sign`), or its rectangle lies inside the
region and its span reaches past a cap; a box off every edge is inside or outside the
region by the crossing number at one of its corners (exact too).

Examples
--------
>>> import numpy as np
>>> from implicitvox.expr.shape import AMBIGUOUS, EMPTY, FULL
>>> square = [np.array([[0, 0], [4, 0], [4, 4], [0, 4.0]])]
>>> prism = PrismClassifier(square, axes=(0, 1, 2), zlo=0.0, zhi=2.0)
>>> lo = np.array([[1.0, 1.0, 0.5], [5.0, 5.0, 0.5], [3.75, 1.0, 0.5]])
>>> prism.classify(lo, lo + 0.5).tolist() == [FULL, EMPTY, AMBIGUOUS]
True
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from ..expr.shape import AMBIGUOUS, EMPTY, FULL
from .pairs import sorted_unique
from .predicates import det2_sign
from .ranges import buckets, expand, expand_boxes, gather

__all__ = ["PrismClassifier", "axis_permutation"]


def axis_permutation(m: np.ndarray) -> Optional[tuple[int, int, int]]:
    """The world axes ``(a, b, c)`` that local x, y, z go to under the 3x3 part ``m``
    when it is a signed, scaled axis permutation (one non-zero per row and column),
    else None."""
    nonzero = m != 0
    if not (np.all(nonzero.sum(axis=0) == 1) and np.all(nonzero.sum(axis=1) == 1)):
        return None
    rows = nonzero.argmax(axis=0)                 # the world axis of each local axis
    return int(rows[0]), int(rows[1]), int(rows[2])


class PrismClassifier:
    """Exact EMPTY / FULL / AMBIGUOUS of boxes against an axis-aligned prism: the
    region of closed outlines ``rings`` (each (k, 2), in world axes ``a, b``),
    between ``zlo`` and ``zhi`` along world axis ``c`` (module docstring).

    Edges are bucketed in a uniform grid over the region's rectangle (for the
    boxes' rectangles) and in its rows (for the crossing number), as
    :class:`implicitvox.triangles.mesh_classifier.MeshClassifier` buckets triangles.
    """

    def __init__(self, rings: list[np.ndarray], axes: tuple[int, int, int], zlo: float,
                 zhi: float):
        self.axes = axes
        self.zlo, self.zhi = float(zlo), float(zhi)
        self.p = np.concatenate([np.asarray(r, dtype=np.float64) for r in rings])
        self.q = np.concatenate([np.roll(np.asarray(r, dtype=np.float64), -1, axis=0)
                                 for r in rings])
        lo2, hi2 = self.p.min(axis=0), self.p.max(axis=0)
        a, b, c = axes
        self.lo, self.hi = np.zeros(3), np.zeros(3)
        self.lo[[a, b, c]] = [lo2[0], lo2[1], self.zlo]
        self.hi[[a, b, c]] = [hi2[0], hi2[1], self.zhi]
        self.lo2 = lo2
        m = len(self.p)
        self.cells = int(np.clip(round(2 * np.sqrt(m)), 1, 256))
        self.cell_size = np.where(hi2 > lo2, hi2 - lo2, 1.0) / self.cells
        elo, ehi = np.minimum(self.p, self.q), np.maximum(self.p, self.q)
        self.elo, self.ehi = elo, ehi
        first, last = self._cell(elo), self._cell(ehi)
        edge, cell = expand_boxes(first, last)
        self.cell_edges, self.cell_start = buckets(cell[:, 0] * self.cells + cell[:, 1], edge,
                                                   self.cells ** 2)
        rows = last[:, 1] - first[:, 1] + 1
        owner, offset = expand(rows)
        self.row_edges, self.row_start = buckets(first[owner, 1] + offset, owner, self.cells)

    def _cell(self, p: np.ndarray) -> np.ndarray:
        """Each 2D point's cell, ``floor((p - lo) / size)`` clipped: monotone in
        floating point, so an edge meeting a rectangle shares a cell with it."""
        c = np.floor((p - self.lo2) / self.cell_size).astype(np.int64)
        return np.clip(c, 0, self.cells - 1)

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        a, b, c = self.axes
        state = np.full(len(lo), EMPTY, dtype=np.int8)
        near = np.flatnonzero(np.all((lo <= self.hi) & (hi >= self.lo), axis=1))
        if not len(near):
            return state
        rlo, rhi = lo[near][:, [a, b]], hi[near][:, [a, b]]
        edge_met = self._edges_meet(rlo, rhi)
        state[near[edge_met]] = AMBIGUOUS
        rest = ~edge_met
        inside = self._inside(rlo[rest])
        k = near[rest]
        within = (lo[k, c] > self.zlo) & (hi[k, c] < self.zhi)    # clear of both caps
        state[k] = np.where(inside, np.where(within, FULL, AMBIGUOUS), EMPTY)
        return state

    def _edges_meet(self, rlo: np.ndarray, rhi: np.ndarray) -> np.ndarray:
        """Whether an edge meets each closed rectangle (separating axes: the
        rectangle's, by the edge's box, and the edge's normal, by exact signs)."""
        first, last = self._cell(rlo), self._cell(rhi)
        box, cell = expand_boxes(first, last)
        key = cell[:, 0] * self.cells + cell[:, 1]
        pair, index = gather(self.cell_start[key], self.cell_start[key + 1] - self.cell_start[key])
        pb, pe = box[pair], self.cell_edges[index]
        met = np.zeros(len(rlo), dtype=bool)
        if not len(pb):
            return met
        n = len(self.p)
        codes = sorted_unique(pb.astype(np.int64) * n + pe)        # an edge once per box
        pb, pe = codes // n, codes % n
        ok = np.all((self.elo[pe] <= rhi[pb]) & (self.ehi[pe] >= rlo[pb]), axis=1)
        pb, pe = pb[ok], pe[ok]
        p, q = self.p[pe], self.q[pe]
        signs = np.stack([det2_sign(p, q, p, np.column_stack([xs[:, 0], ys[:, 1]]))
                          for xs in (rlo[pb], rhi[pb]) for ys in (rlo[pb], rhi[pb])])
        apart = np.all(signs > 0, axis=0) | np.all(signs < 0, axis=0)
        met[pb[~apart]] = True
        return met

    def _inside(self, points: np.ndarray) -> np.ndarray:
        """Whether each 2D point (on no edge) is inside the region: the parity of
        the edges crossing the ray from it towards +a."""
        if not len(points):
            return np.zeros(0, dtype=bool)
        row = self._cell(points)[:, 1]
        owner, index = gather(self.row_start[row], self.row_start[row + 1] - self.row_start[row])
        e = self.row_edges[index]
        y = points[owner, 1]
        p, q = self.p[e], self.q[e]
        straddle = (p[:, 1] > y) != (q[:, 1] > y)
        owner, e, p, q = owner[straddle], e[straddle], p[straddle], q[straddle]
        side = det2_sign(p, q, p, points[owner])
        up = np.where(q[:, 1] > p[:, 1], 1, -1)
        crossing = side * up > 0                        # the edge passes right of the point
        return np.bincount(owner[crossing], minlength=len(points)) % 2 == 1
