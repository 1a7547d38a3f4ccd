"""Exact EMPTY / FULL / AMBIGUOUS of boxes against a closed triangle mesh.

A box is AMBIGUOUS iff a triangle meets the closed box (the exact test of
:class:`implicitvox.triangles.tribox.Triangles`), else FULL or EMPTY by the
winding number at a corner (:class:`implicitvox.triangles.crossings.RayWinding`).
Asked about boxes cold, the leaf tests each box against the triangles bucketed
near it in a uniform grid.

Asked by the octree (with the boxes' :class:`~implicitvox.expr.shape.Octants`),
it remembers, for each box it found AMBIGUOUS and the octree will subdivide,
the triangles that meet it (:class:`BoxMemory`, kept in the run's scratch
space and dropped as the children are asked); the children are tested against
those only - a superset of the triangles that meet a child, so the answer is
the same. A box met by one triangle ``T`` alone of a closed mesh needs less:

* ``T``'s edges are shared with other triangles (the mesh is closed), and none
  of those meets the box, so no edge of ``T`` does: ``T`` crosses the box
  whole, and within the box ``T`` is its plane;
* so a sub-box meets the surface iff it meets ``T``'s plane - two ``orient3d``
  signs at the sub-box's corners least and greatest along the normal
  (:meth:`implicitvox.triangles.tribox.Triangles.plane_sides`), exactly what the full
  test would answer;
* and a sub-box off the plane lies in one of the two halves of the box the
  plane leaves, each connected and off the surface, so its winding number is
  that half's: asked once, at a corner of the box strictly on that side, and
  inherited by every box below.

So once a region of the surface is one triangle per box - the deep levels,
nearly everywhere - a box costs two signs and no winding query. A box no
triangle meets keeps its winding number for its children (in a CSG tree the
octree subdivides it where another leaf's surface passes), so they need no
test at all; a box the whole tree decided is forgotten at once
(:func:`forget_decided`), so the memory holds only octants still to be
subdivided.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from ..expr.shape import AMBIGUOUS, EMPTY, FULL, Octants
from .crossings import RayWinding
from .pairs import sorted_unique
from .ranges import buckets, expand_boxes, gather, grid_cells
from .tribox import Triangles
from .weld import weld

__all__ = ["MeshClassifier", "BoxMemory", "edges_shared", "edges_balanced", "forget_decided",
           "LISTED", "OFF"]

#: a remembered box's ``single`` when it holds no one triangle: its triangles are
#: listed (LISTED), or none meets it and ``above`` holds its winding number (OFF)
LISTED, OFF = -1, -2


def edges_shared(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Whether every edge of the mesh (between two distinct points, vertices merged
    by their coordinates) lies on two face slots at least: no boundary edge, so
    each point of a triangle's edge lies on another triangle too."""
    a, b, n = _edges(vertices, faces)
    _, count = np.unique(np.minimum(a, b) * n + np.maximum(a, b), return_counts=True)
    return bool(np.all(count >= 2))


def _edges(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """The faces' edges ``a -> b`` between two distinct points (vertices merged by their
    coordinates, int64 numbers), and the number of points."""
    v = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)].reshape(-1, 3) + 0.0
    _, point = weld(v)
    point = point.reshape(-1, 3).astype(np.int64)
    a = point.ravel()
    b = np.roll(point, -1, axis=1).ravel()
    real = a != b
    return a[real], b[real], int(point.max(initial=0)) + 1


def edges_balanced(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Whether every edge (vertices merged by their coordinates) is run as often from
    one end to the other as back by the faces: the oriented surface has no boundary,
    so the count of the triangles a ray crosses, signed, is the same for every ray
    from a point (its winding number)."""
    a, b, n = _edges(vertices, faces)
    key = np.minimum(a, b) * n + np.maximum(a, b)
    keys, index = np.unique(key, return_inverse=True)
    balance = np.zeros(len(keys), dtype=np.int64)
    np.add.at(balance, index, np.where(a < b, 1, -1))
    return bool(np.all(balance == 0))


class BoxMemory:
    """What a mesh leaf found on the boxes it was asked about, for their children:
    per level, chunks of boxes (sorted Morton codes) each with its single
    triangle and the winding numbers of the two sides of its plane, or with the
    list of triangles that meet it (:data:`LISTED`), or with the winding number
    of a box no triangle meets (:data:`OFF`). A box's entry goes when its
    children are asked (all eight in one call), or when the tree decides the box
    (:func:`forget_decided`: it will not be subdivided)."""

    def __init__(self) -> None:
        self._levels: dict[int, list[dict]] = {}

    def put(self, level: int, codes: np.ndarray, single: np.ndarray, above: np.ndarray,
            below: np.ndarray, owner: np.ndarray, tris: np.ndarray) -> None:
        """Remember boxes ``codes`` at ``level``: ``single`` their one triangle (or
        :data:`LISTED`, :data:`OFF`), ``above``/``below`` the winding numbers of its
        plane's sides (an OFF box's own in ``above``), and the pairs ``(owner,
        tris)`` (box index, triangle) of the boxes with ``single`` :data:`LISTED`."""
        if not len(codes):
            return
        order = np.argsort(codes, kind="stable")
        rank = np.empty(len(codes), dtype=np.int64)
        rank[order] = np.arange(len(codes))
        pair_order = np.argsort(rank[owner], kind="stable")
        counts = np.bincount(rank[owner], minlength=len(codes))
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        self._levels.setdefault(level, []).append({
            "codes": codes[order], "single": single[order], "above": above[order],
            "below": below[order], "start": starts, "count": counts,
            "tris": tris[pair_order], "alive": np.ones(len(codes), dtype=bool)})

    def take(self, level: int, codes: np.ndarray):
        """The entries of boxes ``codes`` at ``level``, removed: ``(found, single,
        above, below, owner, tris)`` - per code whether it was remembered, its
        single triangle (or :data:`LISTED`, :data:`OFF`), the sides' winding numbers
        (an OFF box's in ``above``), and the pairs
        ``(owner, tris)`` of the listed triangles (owner: index into ``codes``)."""
        n = len(codes)
        found = np.zeros(n, dtype=bool)
        single = np.full(n, LISTED, dtype=np.int64)
        above = np.zeros(n, dtype=np.int64)
        below = np.zeros(n, dtype=np.int64)
        owners, tris = [], []
        chunks = self._levels.get(level, [])
        for chunk in chunks:
            keys = chunk["codes"]
            pos = np.minimum(np.searchsorted(keys, codes), len(keys) - 1)
            hit = np.flatnonzero((keys[pos] == codes) & chunk["alive"][pos] & ~found)
            if not len(hit):
                continue
            row = pos[hit]
            found[hit] = True
            single[hit], above[hit], below[hit] = (chunk["single"][row], chunk["above"][row],
                                                   chunk["below"][row])
            listed = single[hit] == LISTED
            owner, index = gather(chunk["start"][row[listed]], chunk["count"][row[listed]])
            owners.append(hit[listed][owner])
            tris.append(chunk["tris"][index])
            chunk["alive"][row] = False
        self._prune(level)
        empty = np.zeros(0, dtype=np.int64)
        return (found, single, above, below,
                np.concatenate(owners) if owners else empty,
                np.concatenate(tris) if tris else empty)

    def forget(self, level: int, codes: np.ndarray) -> None:
        """Drop the entries of boxes ``codes`` at ``level``, if any."""
        for chunk in self._levels.get(level, []):
            keys = chunk["codes"]
            pos = np.minimum(np.searchsorted(keys, codes), len(keys) - 1)
            chunk["alive"][pos[keys[pos] == codes]] = False
        self._prune(level)

    def _prune(self, level: int) -> None:
        if level in self._levels:
            self._levels[level] = [c for c in self._levels[level] if c["alive"].any()]
            if not self._levels[level]:
                del self._levels[level]

    def __len__(self) -> int:
        return sum(int(c["alive"].sum()) for chunks in self._levels.values() for c in chunks)


def forget_decided(run: dict, octants: Octants, decided: np.ndarray) -> None:
    """Tell every mesh leaf's memory in ``run`` that the tree decided the boxes
    ``decided`` (indices into ``octants``): no child of theirs will be asked."""
    if not len(decided):
        return
    codes = octants.codes[decided]
    for memory in run.values():
        if isinstance(memory, BoxMemory):
            memory.forget(octants.level, codes)


class MeshClassifier:
    """Exact EMPTY / FULL / AMBIGUOUS of boxes against a closed triangle mesh (see
    the module docstring).

    Triangles are bucketed in a uniform grid over the mesh's box, so each box
    asked cold is tested only against the triangles near it.
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, flip: bool = False):
        self.tris = Triangles(vertices[faces])
        self.flip = flip
        self.winding = RayWinding(self.tris)
        #: closed (every edge shared): a box met by one triangle is cut by its plane
        self.closed = edges_shared(vertices, faces)
        #: oriented and closed (a cycle): its ray counts are its winding numbers
        self.oriented = self.closed and edges_balanced(vertices, faces)
        self.lo = self.tris.lo.min(axis=0)
        self.hi = self.tris.hi.max(axis=0)
        n = len(self.tris)
        span = np.where(self.hi > self.lo, self.hi - self.lo, 1.0)
        self.cells = grid_cells(self.tris.lo, self.tris.hi, self.lo, span,
                                int(np.clip(round(2 * n ** (1 / 3)), 1, 64)))
        self.cell_size = span / self.cells
        first = self._cell(self.tris.lo)
        last = self._cell(self.tris.hi)
        tri, cell = expand_boxes(first, last)
        key = (cell[:, 0] * self.cells + cell[:, 1]) * self.cells + cell[:, 2]
        self.cell_tris, self.cell_start = buckets(key, tri, self.cells ** 3)

    def _cell(self, p: np.ndarray) -> np.ndarray:
        """The cell of each point: ``floor((p - lo) / size)``, clipped. Every step is
        monotone in floating point (a rounded subtraction, a rounded division by a
        positive number, floor, clip), so a box and a triangle whose coordinate
        ranges overlap get cell ranges that overlap: no slack is needed."""
        c = np.floor((p - self.lo) / self.cell_size).astype(np.int64)
        return np.clip(c, 0, self.cells - 1)

    def classify(self, lo: np.ndarray, hi: np.ndarray, octants: Optional[Octants] = None,
                 remember: bool = False) -> np.ndarray:
        """States (int8) of closed boxes ``[lo, hi]`` (n, 3).

        With ``octants`` (the boxes' place in the octree), the boxes whose parents
        this leaf remembered are tested against what it found there; with
        ``remember``, what it finds on these boxes is kept for their children.
        """
        state = np.full(len(lo), EMPTY, dtype=np.int8)
        near = np.flatnonzero(np.all((lo <= self.hi) & (hi >= self.lo), axis=1))
        if not len(near):
            return state
        blo, bhi = lo[near], hi[near]
        n = len(near)
        if octants is not None:
            memory = octants.run.setdefault(("mesh", id(self)), BoxMemory())
            codes = octants.codes[near]
            level = octants.level - 1
        else:                            # asked cold: an empty memory remembers nothing
            memory, codes, level = BoxMemory(), np.zeros(n, dtype=np.uint64), 0
        found, single, above, below, mb, mt = memory.take(level, codes >> 3)
        sub = np.zeros(n, dtype=np.int8)
        wind = np.zeros(n, dtype=np.int64)           # the winding number off the surface
        # boxes in a parent no triangle meets: its winding number
        off = np.flatnonzero(single == OFF)
        wind[off] = above[off]
        sub[off] = np.where(above[off] != 0, FULL, EMPTY)
        # boxes in a parent met by one triangle: its plane decides
        one = np.flatnonzero(single >= 0)
        if len(one):
            t = single[one]
            side = self.tris.plane_sides(t, blo[one], bhi[one])
            w = np.where(side > 0, above[one], below[one])
            wind[one] = w
            sub[one] = np.where(side == 0, AMBIGUOUS, np.where(w != 0, FULL, EMPTY))
        # the others: against their parents' triangles, or cold against the grid's
        cold = np.flatnonzero(~found)
        fb, ft = self._pairs(cold, blo, bhi)
        pb, pt = np.concatenate([mb, fb]), np.concatenate([mt, ft])
        ok = self.tris.meet_boxes(pt, blo[pb], bhi[pb]) if len(pb) else np.zeros(0, dtype=bool)
        met_by = np.bincount(pb[ok], minlength=n)
        tested = single == LISTED
        sub[tested & (met_by > 0)] = AMBIGUOUS
        off = np.flatnonzero(tested & (met_by == 0))
        if len(off):
            # off the surface: the whole box is on the side of its corner (exact, in the box)
            wind[off] = self.winding.of_boxes(blo[off], bhi[off])
            sub[off] = np.where(wind[off] != 0, FULL, EMPTY)
        state[near] = sub
        if octants is not None and remember:
            self._remember(memory, octants.level, codes, sub, single, above, below, wind,
                           blo, bhi, pb[ok], pt[ok], met_by)
        return state

    def _remember(self, memory: BoxMemory, level: int, codes: np.ndarray, sub: np.ndarray,
                  single: np.ndarray, above: np.ndarray, below: np.ndarray, wind: np.ndarray,
                  blo: np.ndarray, bhi: np.ndarray, pb: np.ndarray, pt: np.ndarray,
                  met_by: np.ndarray) -> None:
        """Keep what the boxes hold for their children: an AMBIGUOUS box in a
        one-triangle parent inherits its entry, one now met by one triangle of a
        closed mesh gets the winding numbers of its plane's two sides, the others
        their triangles; a box no triangle meets, its winding number ``wind``."""
        amb = sub == AMBIGUOUS
        single, above, below = single.copy(), above.copy(), below.copy()
        single[~amb], above[~amb], below[~amb] = OFF, wind[~amb], 0
        fresh = amb & (single == LISTED) & (met_by == 1) & self.closed
        if fresh.any():
            which = np.flatnonzero(fresh)
            first = np.full(len(sub), -1, dtype=np.int64)
            first[pb[::-1]] = pt[::-1]
            t = first[which]
            t_ok = np.any(self.tris.normal_sign[t] != 0, axis=1)
            which, t = which[t_ok], t[t_ok]
            above[which], below[which] = self._sides(t, blo[which], bhi[which])
            single[which] = t
        listed = single == LISTED
        keep_pair = listed[pb]
        memory.put(level, codes, single, above, below, pb[keep_pair], pt[keep_pair])

    def _sides(self, t: np.ndarray, lo: np.ndarray, hi: np.ndarray):
        """Winding numbers of the parts of boxes ``[lo, hi]`` strictly above and below
        the plane of their one triangle ``t``: one ray query per box, at the corner
        greatest along the normal where it is off the plane (else at the least, and
        then nothing lies above: that side is never read). The other side differs
        by one: a segment between the two sides inside the box crosses ``t`` alone,
        once, and the winding number gains 1 across a triangle against its normal
        (``+x`` rays cross a triangle facing ``+x`` from behind it; a triangle facing
        ``-x``, from in front of it, counts ``-1``). That needs the ray counts to be
        a winding number: a mesh whose every edge is crossed as often one way as the
        other (:func:`edges_balanced`); on others both sides are asked."""
        positive = self.tris.normal_sign[t] >= 0
        top = np.where(positive, hi, lo)
        bottom = np.where(positive, lo, hi)
        above = np.zeros(len(t), dtype=np.int64)
        below = np.zeros(len(t), dtype=np.int64)
        if not self.oriented:           # ray counts that are no winding number: ask both
            for corner, want, out in ((top, 1, above), (bottom, -1, below)):
                strict = np.flatnonzero(self.tris.planes.sign(t, corner) == want)
                if len(strict):
                    out[strict] = self.winding(corner[strict])
            return above, below
        up = self.tris.planes.sign(t, top) == 1
        ask = np.flatnonzero(up)
        if len(ask):
            above[ask] = self.winding(top[ask])
            below[ask] = above[ask] + 1
        rest = np.flatnonzero(~up)
        if len(rest):
            rest = rest[self.tris.planes.sign(t[rest], bottom[rest]) == -1]
            below[rest] = self.winding(bottom[rest])
            above[rest] = below[rest] - 1
        return above, below

    def _pairs(self, boxes: np.ndarray, lo: np.ndarray, hi: np.ndarray):
        """(box, triangle) candidate pairs from the cells each box covers (exactly those:
        :meth:`_cell` is monotone, so a triangle meeting the box shares a cell with it)."""
        if not len(boxes):
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        first = self._cell(lo[boxes])
        last = self._cell(hi[boxes])
        b, cell = expand_boxes(first, last)
        key = (cell[:, 0] * self.cells + cell[:, 1]) * self.cells + cell[:, 2]
        pair, index = gather(self.cell_start[key], self.cell_start[key + 1] - self.cell_start[key])
        pb, pt = b[pair], self.cell_tris[index]
        # a triangle spanning several cells appears once per cell: keep one pair
        if len(pb):
            pair = sorted_unique(pb.astype(np.int64) * len(self.tris) + pt)
            pb, pt = pair // len(self.tris), pair % len(self.tris)
        return boxes[pb].astype(np.int64), pt.astype(np.int64)
