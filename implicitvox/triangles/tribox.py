"""Exact test: does a closed axis-aligned box meet a closed triangle?

The separating axis theorem for a box and a triangle (Akenine-Moller, 2001;
the test Varadhan §3.3.1 and Stolte §6 reduce mesh voxelization to) needs 13
axes: the 3 box normals, the triangle's normal, and the 9 cross products of
a box axis with a triangle edge. They are disjoint iff one axis separates
their projections. Each comparison is rewritten as the sign of a determinant
of the input floats - no axis vector, projection or translation is ever
rounded - and evaluated with the exact predicates of
:mod:`implicitvox.triangles.predicates`:

* box normals: ``tri_min > box_hi`` or ``tri_max < box_lo`` (float compares,
  exact);
* triangle normal ``n = (v1 - v0) x (v2 - v0)``: the box corner extreme
  along ``n`` (chosen by the exact signs of the components of ``n``) lies
  strictly beyond the plane: ``orient3d`` signs;
* edge ``a -> b`` with third vertex ``w``, projected along box axis ``i``:
  the projection of the triangle on the edge's normal is ``[0, s(w)]`` (with
  ``sign s(w) = sign n_i`` for every edge of a cyclic triangle), so the box is
  separated iff its extreme corner ``q`` has ``det(b - a, q - w) > 0`` on one
  side or ``det(b - a, q - a) < 0`` on the other: ``det2`` signs.

Degenerate triangles (segments, points) are handled by the same axes: a zero
normal or edge never separates, and the remaining axes are the complete set
for a segment or point against a box. The answer is exact for the given
floats: a box touching the triangle in a single boundary point meets it.

Examples
--------
>>> import numpy as np
>>> tri = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
>>> t = Triangles(tri)
>>> lo = np.array([[0.5, 0.5, -1.0], [0.51, 0.5, -1.0]])
>>> hi = lo + 1.0
>>> t.meet_boxes(np.array([0, 0]), lo, hi).tolist()   # touches at (0.5, 0.5, 0); misses
[True, False]
"""
from __future__ import annotations

import functools
from typing import Optional

import numpy as np

from .predicates import FixedPlanes, det2_sign
from ..interval.rounding import down, up

__all__ = ["Triangles", "vertex_in_box"]

_PLANES = ((1, 2), (2, 0), (0, 1))   # for box axis i: the projection plane (j, l)


class Triangles:
    """Triangles ``(t, 3, 3)`` with what the box test needs per triangle.

    A triangle with a ``dilation`` ``d`` (per axis) stands for the set of
    points within ``d`` of it in the weighted max-norm: a box meets it iff the
    box grown by ``d`` (rounded outward) meets the triangle. That is how
    :mod:`implicitvox.triangles.patches` covers a curved patch with two flat triangles.

    Attributes
    ----------
    v : ndarray, (t, 3, 3)
        Vertex coordinates.
    lo, hi : ndarray, (t, 3)
        Axis-aligned bounding boxes (exact; grown by the dilation, rounded outward).
    normal_sign : ndarray of int8, (t, 3)
        Exact signs of the components of ``(v1 - v0) x (v2 - v0)``.
    """

    def __init__(self, vertices: np.ndarray, dilation: Optional[np.ndarray] = None):
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        if v.ndim != 3 or v.shape[1:] != (3, 3):
            raise ValueError(f"triangles must have shape (t, 3, 3), got {v.shape}")
        self.v = v
        self.dilation = None
        self.lo = v.min(axis=1)
        self.hi = v.max(axis=1)
        if dilation is not None:
            d = np.broadcast_to(np.asarray(dilation, dtype=np.float64), self.lo.shape)
            if not np.all(d >= 0):
                raise ValueError("dilation must be >= 0")
            self.dilation = np.ascontiguousarray(d)
            self.lo = down(self.lo - d)
            self.hi = up(self.hi + d)
        self.normal_sign = np.empty((len(v), 3), dtype=np.int8)
        v0, v1, v2 = v[:, 0], v[:, 1], v[:, 2]
        for i, (j, l) in enumerate(_PLANES):
            self.normal_sign[:, i] = det2_sign((v0[:, j], v0[:, l]), (v1[:, j], v1[:, l]),
                                               (v0[:, j], v0[:, l]), (v2[:, j], v2[:, l]))
        # the axis to project along for the quick accept: a large normal component
        # (any nonzero one is correct; -1 for degenerate triangles)
        with np.errstate(all="ignore"):
            n = np.abs(np.cross(v1 - v0, v2 - v0))
        n[self.normal_sign == 0] = -1.0
        self.axis = np.where(n.max(axis=1) >= 0, np.argmax(n, axis=1), -1).astype(np.int8)

    def __len__(self) -> int:
        return len(self.v)

    def meet_boxes(self, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Whether triangle ``tri[k]`` meets the closed box ``[lo[k], hi[k]]``.

        The compiled kernel (:func:`implicitvox.triangles.tribox_kernels.meet_pairs`)
        answers every pair its floating-point filters certify; the few it cannot
        go to :meth:`meet_by_arrays`, whose predicates fall back to exact integers.

        Parameters
        ----------
        tri : ndarray of int, (m,)
            Triangle indices.
        lo, hi : ndarray, (m, 3)
            Box corners.

        Returns
        -------
        ndarray of bool, (m,)
        """
        from .tribox_kernels import meet_pairs, settled     # (loads Numba: not at import)
        return settled(meet_pairs(self, tri, lo, hi), self.meet_by_arrays, tri, lo, hi) == 1

    def meet_any(self, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 start: np.ndarray) -> np.ndarray:
        """Per group of pairs ``start[g]:start[g + 1]``, whether one of them meets
        (:meth:`meet_boxes` of any): a group's pairs are tested in order until one
        meets, so a voxel with many candidates costs one witness.

        Parameters
        ----------
        tri : ndarray of int, (m,)
        lo, hi : ndarray, (m, 3)
        start : ndarray of int, (g + 1,)
            Increasing, from 0 to ``m``.

        Returns
        -------
        ndarray of bool, (g,)
        """
        from .tribox_kernels import UNSURE, meet_any_pairs     # (loads Numba: not at import)
        groups, pairs = meet_any_pairs(self, tri, lo, hi, start)
        out = groups == 1
        open_ = np.flatnonzero(groups == UNSURE)
        if len(open_):
            owner = np.repeat(np.arange(len(groups)), np.diff(start))
            unsure = np.flatnonzero((pairs == UNSURE) & (groups[owner] == UNSURE))
            met = self.meet_by_arrays(tri[unsure], lo[unsure], hi[unsure])
            out[owner[unsure[met]]] = True
        return out

    def meet_by_arrays(self, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """:meth:`meet_boxes` stage by stage over whole arrays, every predicate exact
        (filtered, then exact integers): the path for the pairs the compiled
        kernel leaves unsure, and the oracle the tests hold the kernel to."""
        out = np.zeros(len(tri), dtype=bool)
        alive = np.flatnonzero(np.all((self.lo[tri] <= hi) & (self.hi[tri] >= lo), axis=1))
        if not len(alive):
            return out
        tri, lo, hi = tri[alive], *self.grown(tri[alive], lo[alive], hi[alive])
        meets, open_ = self.plane_stage(tri, lo, hi)
        undecided = np.flatnonzero(open_)
        meets[undecided] = self.edge_stage(tri[undecided], lo[undecided], hi[undecided])
        out[alive] = meets
        return out

    @functools.cached_property
    def planes(self) -> FixedPlanes:
        """The triangles' planes, for ``orient3d`` against many points (built once)."""
        return FixedPlanes(self.v[:, 0], self.v[:, 1], self.v[:, 2])

    def plane_sides(self, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Where each closed box ``[lo, hi]`` lies against the plane of triangle
        ``tri``: ``1`` strictly on the side its normal ``(v1 - v0) x (v2 - v0)``
        points to, ``-1`` strictly on the other, ``0`` where the box meets the
        plane (a degenerate triangle's "plane" is everywhere: 0). Exact: the
        ``orient3d`` signs of the box corners least and greatest along the normal,
        compiled (:func:`implicitvox.triangles.tribox_kernels.plane_side_pairs`),
        the pairs its filter leaves unsure on :meth:`plane_sides_by_arrays`.
        """
        from .tribox_kernels import plane_side_pairs, settled    # (loads Numba: not at import)
        return settled(plane_side_pairs(self, tri, lo, hi), self.plane_sides_by_arrays,
                       tri, lo, hi)

    def plane_sides_by_arrays(self, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray
                              ) -> np.ndarray:
        """:meth:`plane_sides` over whole arrays (:class:`FixedPlanes`, exact)."""
        positive = self.normal_sign[tri] >= 0
        cmin = np.where(positive, lo, hi)
        side = (self.planes.sign(tri, cmin) > 0).astype(np.int8)
        rest = np.flatnonzero(side == 0)
        cmax = np.where(positive[rest], hi[rest], lo[rest])
        below = self.planes.sign(tri[rest], cmax) < 0
        side[rest[below]] = -1
        return side

    def grown(self, tri, lo, hi):
        """Boxes ``[lo, hi]`` grown by the dilation of triangles ``tri`` (rounded
        outward): a box meets a grown triangle iff the grown box meets it."""
        if self.dilation is None:
            return lo, hi
        return down(lo - self.dilation[tri]), up(hi + self.dilation[tri])

    def plane_stage(self, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
        """First stage on bounding-box-overlapping pairs (boxes already grown by the
        dilation): ``(meets, undecided)`` masks. Pairs in neither are disjoint.

        A vertex in the box, or a box straddling the plane whose shadow lies in
        the triangle's, meets it; a box strictly on one side of the plane does
        not; the rest need :meth:`edge_stage`.
        """
        meets = vertex_in_box(self.v[tri], lo, hi)
        alive = np.flatnonzero(~meets)
        v, lo, hi = self.v[tri[alive]], lo[alive], hi[alive]
        sign = self.normal_sign[tri[alive]]
        keep = self.plane_sides_by_arrays(tri[alive], lo, hi) == 0
        axis = self.axis[tri[alive]]
        for i, (j, l) in enumerate(_PLANES):
            cand = np.flatnonzero(keep & (axis == i))
            if len(cand):
                sure = _shadow_inside(v[cand], sign[cand, i], lo[cand], hi[cand], j, l)
                meets[alive[cand[sure]]] = True
                keep[cand[sure]] = False
        undecided = np.zeros(len(tri), dtype=bool)
        undecided[alive[keep]] = True
        return meets, undecided

    def edge_stage(self, tri: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """The 9 edge-axis tests on pairs :meth:`plane_stage` left undecided."""
        alive = np.arange(len(tri))
        v, sign = self.v[tri], self.normal_sign[tri]
        keep = np.ones(len(tri), dtype=bool)
        for i, (j, l) in enumerate(_PLANES):
            alive, v, lo, hi, sign = alive[keep], v[keep], lo[keep], hi[keep], sign[keep]
            if not len(alive):
                break
            keep = np.ones(len(alive), dtype=bool)
            for k in range(3):
                keep &= ~_edge_separates(v, sign[:, i], lo, hi, j, l, k)
        out = np.zeros(len(tri), dtype=bool)
        if len(alive):
            out[alive[keep]] = True
        return out


def vertex_in_box(v: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Whether a vertex of each triangle ``v (m, 3, 3)`` lies in its closed box."""
    inside = np.zeros(len(v), dtype=bool)
    for k in range(3):
        vk = v[:, k]
        inside |= ((vk[:, 0] >= lo[:, 0]) & (vk[:, 0] <= hi[:, 0]) & (vk[:, 1] >= lo[:, 1])
                   & (vk[:, 1] <= hi[:, 1]) & (vk[:, 2] >= lo[:, 2]) & (vk[:, 2] <= hi[:, 2]))
    return inside




def _shadow_inside(v, n, lo, hi, j, l) -> np.ndarray:
    """The box's projection on the plane ``(j, l)`` lies in the (closed) projection of
    the triangle, whose orientation there is ``sign n`` (nonzero).

    With the box straddling the triangle's plane, a point of the plane in the
    box then projects into the triangle's shadow, so it is on the triangle.
    """
    inside = np.ones(len(v), dtype=bool)
    pos = n > 0
    for k in range(3):
        a, b = v[:, k], v[:, (k + 1) % 3]
        aj, al, bj, bl = a[:, j], a[:, l], b[:, j], b[:, l]
        up_l, up_j = bj - aj > 0, bl - al > 0
        # the corner where s(q) = fj q_l - fl q_j is least (n > 0) or greatest (n < 0)
        low_l = up_l == pos
        low_j = up_j != pos
        q_l = np.where(low_l, lo[:, l], hi[:, l])
        q_j = np.where(low_j, lo[:, j], hi[:, j])
        s = det2_sign((aj, al), (bj, bl), (aj, al), (q_j, q_l))
        inside &= np.where(pos, s >= 0, s <= 0)
    return inside


def _edge_separates(v, n, lo, hi, j, l, k) -> np.ndarray:
    """Edge ``k`` of the triangle, projected along the box axis normal to plane ``(j, l)``,
    separates the box from the triangle."""
    a, b, w = v[:, k], v[:, (k + 1) % 3], v[:, (k + 2) % 3]
    aj, al, bj, bl = a[:, j], a[:, l], b[:, j], b[:, l]
    fj = bj - aj                       # signs of float differences are exact
    fl = bl - al
    # extreme corners of the box's projection along s(q) = fj q_l - fl q_j
    up_l, up_j = fj > 0, fl > 0
    qmin_l = np.where(up_l, lo[:, l], hi[:, l])
    qmin_j = np.where(up_j, hi[:, j], lo[:, j])
    # the triangle's projection is [0, s(w)] or [s(w), 0] (sign s(w) = sign n)
    pmin_j = np.where(n > 0, w[:, j], aj)
    pmin_l = np.where(n > 0, w[:, l], al)
    sep = det2_sign((aj, al), (bj, bl), (pmin_j, pmin_l), (qmin_j, qmin_l)) > 0
    rest = np.flatnonzero(~sep)
    if len(rest):
        r_up_l, r_up_j, r_neg = up_l[rest], up_j[rest], n[rest] < 0
        qmax_l = np.where(r_up_l, hi[rest, l], lo[rest, l])
        qmax_j = np.where(r_up_j, lo[rest, j], hi[rest, j])
        pmax_j = np.where(r_neg, w[rest, j], aj[rest])
        pmax_l = np.where(r_neg, w[rest, l], al[rest])
        below = det2_sign((aj[rest], al[rest]), (bj[rest], bl[rest]), (pmax_j, pmax_l),
                          (qmax_j, qmax_l)) < 0
        sep[rest[below]] = True
    return sep
