"""The per-pair arithmetic of the certified distance search, in compiled code.

:mod:`implicitvox.fields.certified` brackets the distance from each sample to
the zeros of ``f`` by branch and bound over (sample, box) pairs, millions of
them on a band at 128³. For each pair it needs a lower bound of the distance
from the sample to the box's zeros, and for each sample a candidate zero near
the plane of its most promising box. :func:`pair_bounds` computes both, pair by
pair, from the boxes' enclosures (value, gradient, centre value); the distances
from a point to a box cut by a slab are exact in both norms:

* Euclidean (:func:`euclidean_box_slab`): the projection onto a box and a
  hyperplane, as in the continuous quadratic knapsack;
* weighted max-norm (:func:`linf_box_slab`): the smallest cube about the point
  whose intersection with the box reaches the slab, from the first zeros of
  two concave piecewise linear functions (:func:`first_reach`).

Examples
--------
>>> import numpy as np
>>> p, lo, hi = np.zeros(3), np.array([1.0, -1.0, -1.0]), np.array([2.0, 1.0, 1.0])
>>> g = np.array([1.0, 0.0, 0.0])                  # the slab 1.5 <= x <= 1.75
>>> room = np.empty(9)
>>> float(euclidean_box_slab(p, lo, hi, g, 1.5, 1.75, room))
1.5
>>> float(linf_box_slab(p, np.ones(3), lo, hi, g, 1.5, 1.75, room))
1.5
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np
from numba import njit

from ..interval.rules import COMPILE

__all__ = ["box_slabs", "pair_bounds", "settle_pairs", "shell_pairs", "euclidean_box_slab",
           "linf_box_slab", "first_reach", "CentreGrid", "ball_pairs", "number_boxes",
           "gather_boxes", "split_boxes"]

_EPS = float(np.finfo(np.float64).eps)
_INF = math.inf


@njit(**COMPILE)
def _clip(v, lo, hi):
    return lo if v < lo else (hi if v > hi else v)


@njit(**COMPILE)
def euclidean_box_slab(p, lo, hi, g, s_lo, s_hi, lam):
    """The Euclidean distance from ``p`` to box ∩ slab ``{s_lo <= g·q <= s_hi}``,
    exactly (``inf`` where it is empty). If the box's nearest point to ``p`` is in
    the slab it is the answer; else the nearest point of box ∩ {g·q = s} (the
    slab's near face) is ``clip(p + λ g, lo, hi)`` for the ``λ`` where
    ``φ(λ) = g·clip(p + λ g, lo, hi)``, non-decreasing and piecewise linear with a
    break where each coordinate meets a face of the box, reaches ``s``: the breaks
    are sorted and ``φ`` is interpolated between the two around ``s`` (``lam``: room
    for 7 floats)."""
    v0 = 0.0
    d0 = 0.0
    for j in range(3):
        q = _clip(p[j], lo[j], hi[j])
        v0 += g[j] * q
        d0 += (q - p[j]) * (q - p[j])
    above = v0 > s_hi
    if not (v0 < s_lo or above):
        return math.sqrt(d0)
    sign = -1.0 if above else 1.0                  # the direction: towards the slab
    target = -s_hi if above else s_lo
    lam[0] = 0.0
    count = 1
    for j in range(3):
        dj = sign * g[j]
        if dj != 0.0:
            for face in (lo[j], hi[j]):
                t = (face - p[j]) / dj
                if t > 0.0 and t < _INF:
                    lam[count] = t
                    count += 1
    for i in range(1, count):                      # insertion sort: at most 7
        v = lam[i]
        m = i - 1
        while m >= 0 and lam[m] > v:
            lam[m + 1] = lam[m]
            m -= 1
        lam[m + 1] = v
    f_prev, l_prev = -_INF, 0.0
    for k in range(count):
        phi = 0.0
        for j in range(3):
            dj = sign * g[j]
            phi += _clip(p[j] + lam[k] * dj, lo[j], hi[j]) * dj
        if phi >= target:
            l1, f1 = lam[k], phi
            if k == 0:
                step = l1
            else:
                step = l_prev + (target - f_prev) / (f1 - f_prev) * (l1 - l_prev) \
                    if f1 > f_prev else l1
            d = 0.0
            for j in range(3):
                q = _clip(p[j] + step * sign * g[j], lo[j], hi[j])
                d += (q - p[j]) * (q - p[j])
            return math.sqrt(d)
        f_prev, l_prev = phi, lam[k]
    return _INF


@njit(**COMPILE)
def first_reach(start, slope, stop, target):
    """The least ``t >= 0`` with ``start + Σ_i slope_i min(t, stop_i) >= target``
    (a concave, non-decreasing piecewise linear function; ``inf`` if never);
    ``slope``, ``stop``: 3 values each."""
    o0, o1, o2 = 0, 1, 2                          # the stops' order
    if stop[o1] < stop[o0]:
        o0, o1 = o1, o0
    if stop[o2] < stop[o1]:
        o1, o2 = o2, o1
        if stop[o1] < stop[o0]:
            o0, o1 = o1, o0
    value = start
    for i in range(3):
        value += slope[i] * min(0.0, stop[i])
    if value >= target:
        return 0.0
    left = 0.0
    for j in range(4):
        if j < 3:
            right = stop[o0] if j == 0 else (stop[o1] if j == 1 else stop[o2])
        else:
            right = _INF
        right = max(right, left)
        rate = 0.0
        for i in range(3):
            if (stop[i] >= right) if j < 3 else (stop[i] == _INF):
                rate += slope[i]
        t = left + (target - value) / rate
        if rate > 0.0 and t >= left and t <= right:
            return t
        if right < _INF:
            value += rate * (right - left)
        left = right
    return _INF


@njit(**COMPILE)
def linf_box_slab(p, w, lo, hi, g, s_lo, s_hi, scratch):
    """The weighted max-norm distance from ``p`` to box ∩ slab, exactly: the cube
    ``C(p, t)`` meets it iff ``C(p, t) ∩ box`` (a box, non-empty from ``t`` = the
    distance to the box) reaches the slab, and the largest and smallest ``g·q``
    over that box are concave and convex piecewise linear in ``t``, with a break
    per axis where the cube passes the box's face (``scratch``: room for 9
    floats)."""
    a, up_stop, down_stop = scratch[0:3], scratch[3:6], scratch[6:9]
    gp = 0.0
    for j in range(3):
        a[j] = abs(g[j]) * w[j]
        if g[j] >= 0.0:
            up_stop[j] = (hi[j] - p[j]) / w[j]
            down_stop[j] = (p[j] - lo[j]) / w[j]
        else:
            up_stop[j] = (p[j] - lo[j]) / w[j]
            down_stop[j] = (hi[j] - p[j]) / w[j]
        gp += g[j] * p[j]
    return max(first_reach(gp, a, up_stop, s_lo), first_reach(-gp, a, down_stop, -s_hi))


@njit(**COMPILE)
def _inside(lo, hi, b, interior_lo, interior_hi):
    for j in range(3):
        if not (lo[j, b] > interior_lo[j] and hi[j, b] < interior_hi[j]):
            return False
    return True


@njit(**COMPILE)
def _excludes_normals(p, lo, hi, glo, ghi, b):
    """Is ``q - p`` parallel to no ``ξ ∈ [∇f](box)`` for any ``q`` in box ``b``? (Some
    component of the cross product ``(q - p) × ξ``, enclosed with outward rounding,
    excludes 0.)"""
    return _excludes_normals_of(p, lo, hi, b, glo, ghi, b)


@njit(**COMPILE)
def _product_range(al, ah, bl, bh):
    """The least and greatest of the four products of ``[al, ah] × [bl, bh]`` as
    computed, and their largest magnitude."""
    p0, p1, p2, p3 = al * bl, al * bh, ah * bl, ah * bh
    least = min(min(p0, p1), min(p2, p3))
    most = max(max(p0, p1), max(p2, p3))
    return least, most, max(abs(least), abs(most))


@njit(**COMPILE)
def _excludes_normals_of(p, lo, hi, b, glo, ghi, a):
    """:func:`_excludes_normals` for box ``b`` with the gradient enclosure ``a`` (of a
    box holding ``b``). In floating point, each component's range widened by 4 ulps
    of its terms' magnitudes (above the few roundings of the offsets, products and
    difference)."""
    for j in range(3):
        k, m = (j + 1) % 3, (j + 2) % 3
        l0, h0, m0 = _product_range(lo[k, b] - p[k], hi[k, b] - p[k], glo[m, a], ghi[m, a])
        l1, h1, m1 = _product_range(lo[m, b] - p[m], hi[m, b] - p[m], glo[k, a], ghi[k, a])
        slack = 4.0 * _EPS * (m0 + m1)
        if l0 - h1 - slack > 0.0 or h0 - l1 + slack < 0.0:
            return True
    return False


@njit(**COMPILE)
def box_slabs(lo, hi, vlo, vhi, glo, ghi, valid, clo, chi, g, s_lo, s_hi, slab):
    """Per box ``b``: may it hold a zero (its enclosure holds 0; else ``slab[b]`` is
    False and ``s_lo[b] = inf``), and the slab of the mean value form that holds its
    zeros, ``s_lo[b] <= g[:, b]·q <= s_hi[b]``: ``f(q) ∈ [f(c)] + [∇f]·(q - c)``, so a
    zero has ``g·(q - c) ∈ -[f(c)] ∓ Σ_i rad([∇f]_i) h_i`` (``g`` the gradient
    enclosure's midpoint, ``h`` the half-sizes), widened by the roundings of these
    few operations; ``slab[b]`` is False where the slab is not proved (the mean value
    theorem fails, a zero gradient midpoint, an overflow)."""
    for b in range(lo.shape[1]):
        slab[b] = False
        if not (vlo[b] <= 0.0 and vhi[b] >= 0.0):
            s_lo[b], s_hi[b] = _INF, -_INF
            continue
        gc = spread = norm = 0.0
        for j in range(3):
            g[j, b] = 0.5 * (glo[j, b] + ghi[j, b])
            spread += 0.5 * (ghi[j, b] - glo[j, b]) * (0.5 * (hi[j, b] - lo[j, b]))
            gc += g[j, b] * (0.5 * (lo[j, b] + hi[j, b]))
            norm += g[j, b] * g[j, b]
        c_lo, c_hi = clo[b], chi[b]
        slack = 8.0 * _EPS * (abs(gc) + max(abs(c_lo), abs(c_hi)) + spread)
        s_lo[b] = gc - c_hi - spread - slack
        s_hi[b] = gc - c_lo + spread + slack
        slab[b] = valid[b] and c_lo <= c_hi and norm > 0.0 and math.isfinite(norm) \
            and math.isfinite(s_lo[b]) and math.isfinite(s_hi[b])


@njit(**COMPILE)
def _to_box_and_slab(euclidean, p, s, w, lo, hi, b, s_lo, s_hi, q, ww, blo, bhi, gb, scratch):
    """The distances from sample ``p[s]`` to box ``b`` of ``lo, hi`` and to the box's
    part in the slab ``s_lo <= gb·q <= s_hi`` (``inf`` where it is empty; ``q, ww,
    blo, bhi`` are room for 3 floats each, ``scratch`` for 9)."""
    gap2 = gapm = 0.0
    for j in range(3):
        q[j], ww[j] = p[s, j], w[s, j]
        blo[j], bhi[j] = lo[j, b], hi[j, b]
        gap = max(max(blo[j] - q[j], q[j] - bhi[j]), 0.0)
        gap2 += gap * gap
        gapm = max(gapm, gap / ww[j])
    to_box = math.sqrt(gap2) if euclidean else gapm
    if euclidean:
        to_both = euclidean_box_slab(q, blo, bhi, gb, s_lo, s_hi, scratch)
    else:
        to_both = linf_box_slab(q, ww, blo, bhi, gb, s_lo, s_hi, scratch)
    return to_box, to_both


@njit(**COMPILE)
def pair_bounds(euclidean, p, w, pt, box, lo, hi, g, s_lo, s_hi, slab, glo, ghi, valid,
                interior_lo, interior_hi, lb, lead, lead_q, lead_unit, lead_delta):
    """Per pair ``(pt[k], box[k])``: ``lb[k]``, a lower bound of the distance from
    sample ``p[pt[k]]`` to the zeros of ``f`` in box ``box[k]``: the distance to box ∩
    slab (:func:`box_slabs`), or to the box where the slab is not proved; ``inf``
    where the box holds no zero.

    Euclidean pairs whose box lies strictly inside ``(interior_lo, interior_hi)``
    and holds no point ``q`` where ``q - p`` is parallel to a gradient (Clarke's
    generalized gradient where ``f`` has kinks) get ``inf`` too: the nearest zero
    ``q*`` within the domain, if it is not on the domain's boundary, satisfies the
    Fritz John condition ``q* - p ∥ ξ``, ``ξ ∈ ∂f(q*)``, wherever ``f`` is
    Lipschitz (the box is valid: its gradient enclosure ``glo, ghi`` holds the
    gradients on the closed box), so such a box does not hold it; every other box's
    bound stays, and the least of them is still a lower bound of the distance.

    Per sample, ``lead[s]`` is its pair of least bound if that pair's slab holds
    (else -1), and ``lead_q[s]`` a start for a candidate zero: the sample's nearest
    point on the slab's middle plane, clipped to the box; ``lead_unit[s]`` the
    unit gradient and ``lead_delta[s]`` a segment half-length for certifying it.
    ``lead`` must hold -1 on entry; boxes' arrays are per box (``(3, m)`` for the
    vectors), the rest per pair."""
    best = np.full(lead.size, _INF)
    q, ww, blo, bhi, gb = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    scratch = np.empty(9)
    slab_ok = np.zeros(pt.size, dtype=np.bool_)
    for k in range(pt.size):
        s, b = pt[k], box[k]
        if not s_lo[b] <= s_hi[b]:                   # no zero in the box
            lb[k] = _INF
            continue
        if euclidean and valid[b] and _inside(lo, hi, b, interior_lo, interior_hi) \
                and _excludes_normals(p[s], lo, hi, glo, ghi, b):
            lb[k] = _INF
            continue
        for j in range(3):
            gb[j] = g[j, b]
        to_box, to_both = _to_box_and_slab(euclidean, p, s, w, lo, hi, b, s_lo[b], s_hi[b], q,
                                           ww, blo, bhi, gb, scratch)
        ok = slab[b] and not math.isnan(to_both)
        lb[k] = max(to_box, to_both) if ok else to_box
        slab_ok[k] = ok
        if lb[k] < best[s]:
            best[s] = lb[k]
            lead[s] = k
    for s in range(lead.size):
        k = lead[s]
        if k < 0:
            continue
        if not slab_ok[k]:
            lead[s] = -1
            continue
        b = box[k]
        norm = gp = dual1 = 0.0
        for j in range(3):
            norm += g[j, b] * g[j, b]
            gp += g[j, b] * p[s, j]
            dual1 += abs(g[j, b]) * w[s, j]
        norm = math.sqrt(norm)
        dual = norm if euclidean else dual1
        mid = ((s_lo[b] + s_hi[b]) / 2 - gp) / dual
        size = centre = 0.0
        for j in range(3):
            step = g[j, b] / norm if euclidean else \
                math.copysign(w[s, j], g[j, b]) * (g[j, b] != 0.0)
            c = 0.5 * (lo[j, b] + hi[j, b])
            v = p[s, j] + mid * step
            v = v if math.isfinite(v) else c
            lead_q[s, j] = _clip(v, lo[j, b], hi[j, b])
            u = g[j, b] / norm
            lead_unit[s, j] = u if math.isfinite(u) else 0.0
            size = max(size, 0.5 * (hi[j, b] - lo[j, b]))
            centre = max(centre, abs(c))
        lead_delta[s] = max(size * 1e-4, 1e-12 * (1.0 + centre))


@njit(**COMPILE)
def settle_pairs(pt, lb, reach, best, keep):
    """``keep[k]``: pair ``k`` may still hold its sample's nearest zero (a finite
    bound within the sample's reach); ``best[s]``: the least bound over the
    sample's kept pairs (``inf`` where none; ``best`` must hold ``inf`` on
    entry)."""
    for k in range(pt.size):
        s = pt[k]
        keep[k] = math.isfinite(lb[k]) and lb[k] <= reach[s]
        if keep[k] and lb[k] < best[s]:
            best[s] = lb[k]


@njit(**COMPILE)
def shell_pairs(euclidean, p, w, pt, lo, hi, box, lower, reach, parents, g, s_lo, s_hi, slab,
                glo, ghi, valid, interior_lo, interior_hi, keep, alive):
    """``keep[k]``: box ``box[k]`` may hold the nearest zero of its sample ``s =
    pt[k]``, by what is known before evaluating it: it meets the shell ``lower[s]
    <= |q - p[s]| <= reach[s]`` (a box wholly nearer than the proved lower bound
    holds no zero; one wholly past the reach need not be searched), and, when
    ``parents`` (box ``b``'s parent is box ``b >> 3`` of the per-box arrays, from
    :func:`box_slabs` and the gradient enclosures), it meets the parent's slab, the
    slab is within the reach, and the parent's gradients pass the Fritz John test
    of :func:`pair_bounds` on it (the parent's enclosures hold the child's). (Cheap
    tests only: the exact distance to box ∩ slab costs about what evaluating the
    box does.) ``alive[s]`` is set True for each sample with a pair kept."""
    for k in range(pt.size):
        s, b = pt[k], box[k]
        near2 = far2 = near = far = 0.0
        for j in range(3):
            dlo, dhi = lo[j, b] - p[s, j], hi[j, b] - p[s, j]
            gap = max(max(dlo, -dhi), 0.0)
            span = max(abs(dlo), abs(dhi))
            near2 += gap * gap
            far2 += span * span
            near = max(near, gap / w[s, j])
            far = max(far, span / w[s, j])
        if euclidean:
            near, far = math.sqrt(near2), math.sqrt(far2)
        limit = reach[s] * (1.0 + 4.0 * _EPS)
        keep[k] = near <= limit and far >= lower[s] * (1.0 - 4.0 * _EPS)
        if not keep[k] or not parents:
            continue
        a = b >> 3
        if slab[a]:
            # the child's part in the parent's slab: empty, or beyond the reach?
            # (the sums' rounding errors: below 4 eps times the sums of magnitudes)
            least = most = gp = dual2 = dual1 = size = at = 0.0
            for j in range(3):
                gj = g[j, a]
                least += gj * (lo[j, b] if gj >= 0.0 else hi[j, b])
                most += gj * (hi[j, b] if gj >= 0.0 else lo[j, b])
                gp += gj * p[s, j]
                dual2 += gj * gj
                dual1 += abs(gj) * w[s, j]
                size += abs(gj) * max(abs(lo[j, b]), abs(hi[j, b]))
                at += abs(gj * p[s, j])
            dual = math.sqrt(dual2) if euclidean else dual1
            slack, off = 4.0 * _EPS * size, 4.0 * _EPS * at
            to_slab = max(max(s_lo[a] - gp - off, gp - s_hi[a] - off), 0.0) / dual
            if most + slack < s_lo[a] or least - slack > s_hi[a] or to_slab > limit:
                keep[k] = False
                continue
        if euclidean and valid[a] and _inside(lo, hi, b, interior_lo, interior_hi) \
                and _excludes_normals_of(p[s], lo, hi, b, glo, ghi, a):
            keep[k] = False
    for k in range(pt.size):
        if keep[k]:
            alive[pt[k]] = True


class CentreGrid:
    """Box centres bucketed in a uniform grid of cells (``cell`` at least the boxes'
    largest side), sorted by cell, for :func:`ball_pairs`: the boxes whose centre
    lies within a ball, found by scanning the cells the ball's bounding cube meets
    (a binary search per column of cells), in compiled code."""

    def __init__(self, centres: np.ndarray, cell: float):
        self.centres = np.ascontiguousarray(centres, dtype=np.float64)      # (m, 3)
        self.origin = self.centres.min(axis=0) if len(centres) else np.zeros(3)
        self.cell = float(cell) if cell > 0 else 1.0
        index = np.floor((self.centres - self.origin) / self.cell).astype(np.int64)
        self.dims = index.max(axis=0) + 1 if len(centres) else np.ones(3, dtype=np.int64)
        key = (index[:, 0] * self.dims[1] + index[:, 1]) * self.dims[2] + index[:, 2]
        self.order = np.argsort(key, kind="stable")
        self.keys = key[self.order]

    def pairs(self, p: np.ndarray, radius: np.ndarray, counts: Optional[np.ndarray] = None):
        """``counts`` (n,) of boxes whose centre is within ``radius`` of each point ``p``
        (n, 3) (squared distances compared with a relative slack of 1e-12, so rounding
        only adds boxes); with ``counts`` given, the pairs ``(point, box)``, point by
        point."""
        n = len(p)
        fill = counts is not None
        total = int(counts.sum()) if fill else 0
        out_counts = np.zeros(n, dtype=np.int64)
        pt = np.empty(total, dtype=np.int64)
        box = np.empty(total, dtype=np.int64)
        ball_pairs(self.keys, self.order, self.centres, self.origin, self.cell, self.dims,
                   np.ascontiguousarray(p, dtype=np.float64),
                   np.ascontiguousarray(radius, dtype=np.float64), fill, out_counts, pt, box)
        return (pt, box) if fill else out_counts


@njit(**COMPILE)
def ball_pairs(keys, order, centres, origin, cell, dims, p, radius, fill, counts, pt, box):
    """:meth:`CentreGrid.pairs` in compiled code: per point, ``counts[i]`` boxes, and
    where ``fill``, their pairs written in order of the points."""
    k = 0
    lo_c = np.empty(3, dtype=np.int64)
    hi_c = np.empty(3, dtype=np.int64)
    for i in range(p.shape[0]):
        r = radius[i]
        r2 = r * r * (1.0 + 1e-12)
        empty = not (r >= 0.0)
        for j in range(3):
            a = math.floor((p[i, j] - r - origin[j]) / cell)
            b = math.floor((p[i, j] + r - origin[j]) / cell)
            if not (a <= b) or b < 0 or a > dims[j] - 1:
                empty = True
                break
            lo_c[j] = max(int(a), 0)
            hi_c[j] = min(int(b), dims[j] - 1)
        if empty:
            continue
        found = 0
        for ix in range(lo_c[0], hi_c[0] + 1):
            for iy in range(lo_c[1], hi_c[1] + 1):
                column = (ix * dims[1] + iy) * dims[2]
                first = np.searchsorted(keys, column + lo_c[2])
                last = np.searchsorted(keys, column + hi_c[2], side="right")
                for m in range(first, last):
                    b = order[m]
                    d2 = 0.0
                    for j in range(3):
                        d = centres[b, j] - p[i, j]
                        d2 += d * d
                    if d2 <= r2:
                        found += 1
                        if fill:
                            pt[k] = i
                            box[k] = b
                            k += 1
        counts[i] = found


@njit(**COMPILE)
def number_boxes(box, index):
    """``index[b]``: box ``b``'s number among the boxes ``box`` names, in order of
    ``b`` (-1 for the others; ``index`` must hold -1 on entry); returns their count."""
    for k in range(box.size):
        index[box[k]] = 0
    count = 0
    for b in range(index.size):
        if index[b] == 0:
            index[b] = count
            count += 1
    return count


@njit(**COMPILE)
def gather_boxes(box, index, lo, hi, new_box, new_lo, new_hi):
    """The pairs' boxes renumbered by ``index`` (:func:`number_boxes`) into
    ``new_box``, and the numbered boxes' corners into ``new_lo, new_hi`` (3, count)."""
    for b in range(index.size):
        j = index[b]
        if j >= 0:
            for a in range(3):
                new_lo[a, j] = lo[a, b]
                new_hi[a, j] = hi[a, b]
    for k in range(box.size):
        new_box[k] = index[box[k]]


@njit(**COMPILE)
def split_boxes(pt, box, lo, hi, child_pt, child_box, child_lo, child_hi):
    """Each box ``j`` of ``lo, hi`` (3, m) into its 8 children ``8j .. 8j + 7`` (child
    ``c`` takes the upper half along axis ``a`` where bit ``2 - a`` of ``c`` is set),
    and each pair ``(pt[k], box[k])`` into the 8 pairs of its box's children."""
    for j in range(lo.shape[1]):
        for a in range(3):
            mid = 0.5 * (lo[a, j] + hi[a, j])
            for c in range(8):
                upper = (c >> (2 - a)) & 1
                child_lo[a, 8 * j + c] = mid if upper else lo[a, j]
                child_hi[a, 8 * j + c] = hi[a, j] if upper else mid
    for k in range(pt.size):
        for c in range(8):
            child_pt[8 * k + c] = pt[k]
            child_box[8 * k + c] = 8 * box[k] + c
