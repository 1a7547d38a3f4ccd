"""Certified distances to the surface of any expression: a lower and an upper bound.

For a general implicit function no closed form gives the distance from a
point ``p`` to the surface ``f = 0``. This module brackets it, in the
Euclidean or the (weighted) max-norm, by branch and bound over boxes:

* **upper bound** ``U``: a certified surface point. Where ``f`` takes
  opposite signs at the two ends of a short segment (signs proved by
  interval evaluation at the points, rounded outward), the segment holds a
  zero, and ``p`` is no farther from the surface than from the segment's
  farther end. Candidates come from Newton projections of ``p`` and, at
  every level, from the plane that approximates ``f`` in each kept box.
* **lower bound** ``L``: every surface point lies in one of the boxes the
  voxelizer kept (it misses none). A (point, box) pair is dropped when the
  box's interval enclosure excludes 0, and bounded below by the distance to
  the part of the box inside the *slab* that holds the box's zeros: by the
  mean value theorem ``f(q) ∈ f(c) + [∇f](box)·(q - c)`` for ``q`` in the box,
  so a zero ``q`` satisfies ``g·(q - c) ∈ -[f(c)] ∓ Σ_i rad([∇f]_i) h_i`` with
  ``g`` the midpoint of the gradient enclosure and ``h`` the half-sizes. The
  distance to box ∩ slab is computed exactly in both norms (a projection onto
  a box and a hyperplane; a cube growing into it); the slab is thin to second
  order in the box size, so near the contact few boxes survive at each level,
  and they are split until ``U - L`` is below the tolerance (Varadhan §4.3
  refines a hardware estimate by local optimization; this refines by
  intervals, so the result is proved).

The field stores ``(U + L) / 2`` with the error bound ``(U - L) / 2``. Each
bound is computed in floating point and then moved outward by a relative
``2**-40`` (far above the few roundings it contains).

Examples
--------
>>> import numpy as np, implicitvox as iv
>>> from implicitvox import x, y, z, sqrt
>>> f = iv.compile(x * x + y * y + z * z - 1)        # not a distance: needs certifying
>>> lo, hi = np.array([[0.9, -0.1, -0.1]]), np.array([[1.1, 0.1, 0.1]])
>>> value, error = certified_distances(f, np.array([[1.2, 0.0, 0.0]]), "euclidean", None,
...                                    lo, hi, limit=1.0, tolerance=1e-9)
>>> bool(abs(value[0] - 0.2) <= error[0] <= 1e-9)
True
"""
from __future__ import annotations

import itertools
from typing import Any, Callable, Optional

import numpy as np

from ..eval.function import Function
from ..eval.gradient import evaluate_gradients
from ..eval.interval import evaluate_intervals
from ..eval.mean_value import evaluate_interval_gradients
from ..eval.point import evaluate_points

__all__ = ["certified_distances", "MAX_LEVELS", "MAX_PAIRS"]

#: box halvings below the voxels at most
MAX_LEVELS = 14
#: (point, box) pairs in flight at most; a block of points with more is split
MAX_PAIRS = 1 << 19
#: points per block
_BLOCK = 4096
_NEWTON = 8
_MARGIN = 2.0 ** -40


class _Norm:
    """The Euclidean norm, or the max-norm weighted by ``w`` (one row per point)."""

    def __init__(self, name: str):
        self.euclidean = name == "euclidean"

    def length(self, v: np.ndarray, w: np.ndarray) -> np.ndarray:
        if self.euclidean:
            return np.sqrt(np.einsum("ij,ij->i", v, v))
        return np.max(np.abs(v) / w, axis=1)

    def dual(self, g: np.ndarray, w: np.ndarray) -> np.ndarray:
        """How fast ``g·q`` can change per unit of distance: the dual norm."""
        if self.euclidean:
            return np.sqrt(np.einsum("ij,ij->i", g, g))
        return np.sum(np.abs(g) * w, axis=1)

    def step(self, g: np.ndarray, w: np.ndarray) -> np.ndarray:
        """The unit vector along which ``g·q`` grows fastest."""
        with np.errstate(invalid="ignore", divide="ignore"):
            if self.euclidean:
                return g / self.dual(g, w)[:, None]
            return np.sign(g) * w


def _signs(tape, q: np.ndarray) -> np.ndarray:
    """+1 / -1 where the sign of ``f(q)`` is proved (outward-rounded enclosure), else 0."""
    cols = tuple(q.T)
    with np.errstate(all="ignore"):
        lo, hi = evaluate_intervals(tape, cols, cols)
    lo = np.broadcast_to(lo, (len(q),))
    hi = np.broadcast_to(hi, (len(q),))
    return np.where(lo > 0, 1, np.where(hi < 0, -1, 0))


def _certified_upper(tape, norm: _Norm, p: np.ndarray, w: np.ndarray, q: np.ndarray,
                     direction: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Upper bounds from segments ``q ± delta·direction`` whose ends have proved
    opposite signs (``inf`` elsewhere)."""
    a = q - delta[:, None] * direction
    b = q + delta[:, None] * direction
    sa, sb = _signs(tape, a), _signs(tape, b)
    ok = (sa * sb < 0) & np.all(np.isfinite(a), axis=1) & np.all(np.isfinite(b), axis=1)
    far = np.maximum(norm.length(a - p, w), norm.length(b - p, w))
    return np.where(ok, far * (1 + _MARGIN), np.inf)


def _newton(tape, q: np.ndarray, steps: int) -> np.ndarray:
    """Newton steps ``q <- q - f(q) ∇f / |∇f|²`` towards the surface (lanes where a
    step is not finite stay)."""
    with np.errstate(all="ignore"):
        for _ in range(steps):
            v, g = evaluate_gradients(tape, *q.T)
            v = np.broadcast_to(v, (len(q),))
            g = np.broadcast_to(np.asarray(g).reshape(3, -1), (3, len(q))).T
            gg = np.einsum("ij,ij->i", g, g)
            move = np.where((gg > 0)[:, None], -(v / np.where(gg > 0, gg, 1))[:, None] * g, 0.0)
            q = np.where(np.all(np.isfinite(move), axis=1)[:, None], q + move, q)
    return q


def _newton_upper(tape, norm: _Norm, p: np.ndarray, w: np.ndarray, scale: float) -> np.ndarray:
    """Upper bounds from Newton projections ``q <- q - f(q) ∇f / |∇f|²`` of the points."""
    q = _newton(tape, p, _NEWTON)
    with np.errstate(all="ignore"):
        _, g = evaluate_gradients(tape, *q.T)
        g = np.broadcast_to(np.asarray(g).reshape(3, -1), (3, len(q))).T
        unit = g / np.linalg.norm(g, axis=1, keepdims=True)
    unit = np.where(np.all(np.isfinite(unit), axis=1)[:, None], unit, 0.0)
    best = np.full(len(p), np.inf)
    for rel in (1e-9, 1e-6, 1e-3):
        best = np.minimum(best, _certified_upper(tape, norm, p, w, q, unit,
                                                 np.full(len(p), rel * scale)))
    return best


def certified_distances(func: Function, points: np.ndarray, norm: str, weights: Optional[Any],
                        boxes_lo: np.ndarray, boxes_hi: np.ndarray, *, limit: float,
                        tolerance: float, max_levels: int = MAX_LEVELS,
                        progress: Optional[Callable[[float], Any]] = None,
                        stats: Optional[dict] = None) -> tuple[np.ndarray, np.ndarray]:
    """Distances (signed, negative inside) and their error bounds, for ``points`` (n, 3).

    Parameters
    ----------
    func : Function
        The implicit function.
    points : ndarray (n, 3)
    norm : {"euclidean", "linf"}
    weights : None or array (3,) or (n, 3)
        Per-axis weights of the max-norm (ignored for the Euclidean norm).
    boxes_lo, boxes_hi : ndarray (m, 3)
        Boxes whose union holds every surface point within ``limit`` of a point
        (the voxelizer's surface voxels).
    limit : float
        Where to look first: the pairs are the boxes within ``limit`` (or the
        point's Newton bound); a point with no zero proved within it is searched
        again 4 times farther, up to the boxes' whole extent. A point with no
        surface anywhere in the boxes gets ``inf``.
    tolerance : float
        Stop refining a point when ``U - L <= tolerance``.
    stats : dict, optional
        Receives counts: ``"pairs"`` (point-box pairs evaluated) and ``"capped"``
        (points left above the tolerance when their pairs outgrew :data:`MAX_PAIRS`).

    Returns
    -------
    value, error : ndarray (n,)
        ``|value - d| <= error`` for the true signed distance ``d`` to the surface
        held in the boxes.
    """
    from scipy.spatial import cKDTree
    nm = _Norm(norm)
    p = np.asarray(points, dtype=np.float64)
    n = len(p)
    w = np.ones((n, 3)) if weights is None or nm.euclidean else \
        np.broadcast_to(np.asarray(weights, dtype=np.float64), (n, 3))
    value = np.zeros(n)
    error = np.zeros(n)
    if n == 0:
        return value, error
    tape = func.tape
    boxes_lo = np.asarray(boxes_lo, dtype=np.float64)
    boxes_hi = np.asarray(boxes_hi, dtype=np.float64)
    half_diag = float(np.max(np.linalg.norm(boxes_hi - boxes_lo, axis=1))) / 2 if len(boxes_lo) \
        else 0.0
    tree = cKDTree(0.5 * (boxes_lo + boxes_hi)) if len(boxes_lo) else None
    scale = float(np.max(boxes_hi - boxes_lo)) if len(boxes_lo) else 1.0
    span = np.concatenate([boxes_hi, p]).max(axis=0) - np.concatenate([boxes_lo, p]).min(axis=0) \
        if len(boxes_lo) else np.zeros(3)
    max_reach = max(limit, float(np.max(span / (1.0 if nm.euclidean else np.min(w)))) * 2.0)
    sign = _point_signs(tape, p)
    stats = {} if stats is None else stats
    stats.setdefault("pairs", 0)
    stats.setdefault("capped", 0)
    for s in range(0, n, _BLOCK):
        rows = np.arange(s, min(s + _BLOCK, n))
        reach = limit
        while len(rows):
            lo_b, up_b = _bracket(tape, nm, p[rows], w[rows], tree, boxes_lo, boxes_hi,
                                  half_diag, scale, reach, tolerance, max_levels, stats)
            value[rows] = 0.5 * (lo_b + up_b)
            error[rows] = 0.5 * (up_b - lo_b)
            # no zero proved within reach: search farther (all the boxes at the end)
            rows = rows[~(up_b <= reach)]
            if reach >= max_reach:
                value[rows], error[rows] = np.inf, np.inf
                break
            reach = min(4 * reach, max_reach)
        if progress is not None:
            progress(min(1.0, (s + _BLOCK) / n))
    return sign * value, error


def _point_signs(tape, p: np.ndarray) -> np.ndarray:
    """Signs of ``f`` at the points: proved where the enclosure excludes 0; where it
    does not, the point is within rounding of the surface and the float value's
    sign is taken (the distance there is 0 within the error)."""
    proved = _signs(tape, p)
    with np.errstate(all="ignore"):
        v = np.broadcast_to(evaluate_points(tape, *p.T), (len(p),))
    return np.where(proved != 0, proved, np.where(v < 0, -1.0, 1.0)).astype(np.float64)


def _bracket(tape, nm: _Norm, p, w, tree, boxes_lo, boxes_hi, half_diag, scale, limit,
             tolerance, max_levels, stats):
    """``(L, U)`` for one block of points (see the module docstring)."""
    n = len(p)
    if tree is None:                    # no box may hold the surface: none within reach
        return np.full(n, limit), np.full(n, np.inf)
    upper = _newton_upper(tape, nm, p, w, scale)
    # the initial pairs: boxes whose centre is within reach (a superset, then exact),
    # gathered for groups of points with at most MAX_PAIRS pairs between them
    reach = np.minimum(upper, limit)
    euclid_reach = reach * (1.0 if nm.euclidean else np.sqrt(3) * float(np.max(w))) + half_diag
    counts = np.asarray(tree.query_ball_point(p, euclid_reach, return_length=True),
                        dtype=np.int64)
    lower = np.where(counts == 0, reach, 0.0)     # no box within reach: nothing nearer
    state = {"upper": upper, "lower": lower, "open": counts > 0}
    group = np.cumsum(counts) // MAX_PAIRS
    for g in np.unique(group[counts > 0]):
        rows = np.flatnonzero((group == g) & (counts > 0))
        found = tree.query_ball_point(p[rows], euclid_reach[rows])
        box = np.fromiter(itertools.chain.from_iterable(found), dtype=np.int64,
                          count=int(counts[rows].sum()))
        pt = np.repeat(rows, counts[rows])
        _refine(tape, nm, p, w, pt, boxes_lo[box], boxes_hi[box], box, 0, state, limit,
                tolerance, max_levels, stats)
    lower, upper = state["lower"], state["upper"]
    # outward: a relative margin, and one for the roundings of coordinates of this size
    slack = _MARGIN * (1.0 + float(np.max(np.abs(p))))
    return np.maximum(lower * (1 - _MARGIN) - slack, 0.0), upper


def _refine(tape, nm, p, w, pt, lo, hi, bid, level, state, limit, tolerance, max_levels,
            stats):
    """Bound, prune and split the pairs ``(pt, box)`` level by level (``bid`` names each
    box: its surface voxel, then ``8 * parent + child``); where the children
    would exceed :data:`MAX_PAIRS`, the points are halved and each half refined on its
    own (a point's pairs stay together, so its bounds come from all of them)."""
    upper, lower, open_ = state["upper"], state["lower"], state["open"]
    while len(pt):
        mine = np.unique(pt)
        lb, cand_pt, cand = _pair_bounds(tape, nm, p, w, pt, lo, hi, bid)
        np.minimum.at(upper, cand_pt, cand)
        reach = np.minimum(upper, limit)
        keep = np.isfinite(lb) & (lb <= reach[pt])
        pt, lo, hi, lb, bid = pt[keep], lo[keep], hi[keep], lb[keep], bid[keep]
        best = np.full(len(p), np.inf)
        np.minimum.at(best, pt, lb)
        lower[mine] = np.where(open_[mine], np.minimum(best[mine], reach[mine]), lower[mine])
        open_[mine] &= reach[mine] - lower[mine] > tolerance
        still = open_[pt]
        pt, lo, hi, bid = pt[still], lo[still], hi[still], bid[still]
        if level == max_levels or not len(pt):
            return
        pt, lo, hi, bid = _split(pt, lo, hi, bid)
        level += 1
        stats["pairs"] += len(pt)
        if len(pt) > MAX_PAIRS:
            points = np.unique(pt)
            if len(points) == 1:            # one point's pairs alone are too many: stop here
                stats["capped"] += 1
                return
            first = pt < points[len(points) // 2]
            _refine(tape, nm, p, w, pt[first], lo[first], hi[first], bid[first], level, state,
                    limit, tolerance, max_levels, stats)
            _refine(tape, nm, p, w, pt[~first], lo[~first], hi[~first], bid[~first], level,
                    state, limit, tolerance, max_levels, stats)
            return


def _split(pt, lo, hi, bid):
    """Each box into its 8 children (the pairs' point repeated), named ``8 * bid + k``."""
    mid = 0.5 * (lo + hi)
    corner = np.array(list(np.ndindex(2, 2, 2)), dtype=bool)          # (8, 3)
    clo = np.where(corner[None], mid[:, None], lo[:, None]).reshape(-1, 3)
    chi = np.where(corner[None], hi[:, None], mid[:, None]).reshape(-1, 3)
    children = (bid[:, None] * 8 + np.arange(8)[None]).reshape(-1)
    return np.repeat(pt, 8), clo, chi, children


def _pair_bounds(tape, nm: _Norm, p, w, pt, lo, hi, bid):
    """Per (point, box) pair: a lower bound of the distance from point ``pt`` to the
    zeros of ``f`` in the box (``inf`` if the box has none). Boxes shared by several
    points (same ``bid``) are evaluated once. Also ``(points, upper)``: for each point,
    an upper bound from a certified zero near the plane of its most promising box
    (``inf`` where none was proved)."""
    boxes, first, which = np.unique(bid, return_index=True, return_inverse=True)
    ulo, uhi = lo[first], hi[first]
    with np.errstate(all="ignore"):
        vlo, vhi, glo, ghi, valid = evaluate_interval_gradients(tape, tuple(ulo.T), tuple(uhi.T))
        uc = 0.5 * (ulo + uhi)
        clo, chi = evaluate_intervals(tape, tuple(uc.T), tuple(uc.T))
    k = len(boxes)
    vlo, vhi = np.broadcast_to(vlo, (k,))[which], np.broadcast_to(vhi, (k,))[which]
    clo, chi = np.broadcast_to(clo, (k,))[which], np.broadcast_to(chi, (k,))[which]
    glo = np.broadcast_to(glo, (3, k)).T[which]
    ghi = np.broadcast_to(ghi, (3, k)).T[which]
    valid = np.broadcast_to(valid, (k,))[which]
    c = uc[which]
    q_pt, q_w = p[pt], w[pt]
    has_zero = (vlo <= 0) & (vhi >= 0)
    gap = np.maximum(np.maximum(lo - q_pt, q_pt - hi), 0.0)
    to_box = nm.length(gap, q_w)
    # the slab of the box's zeros (mean value form)
    half = 0.5 * (hi - lo)
    with np.errstate(all="ignore"):
        g = 0.5 * (glo + ghi)
        spread = np.sum(0.5 * (ghi - glo) * half, axis=1)
        gc = np.einsum("ij,ij->i", g, c)
        # widened by the roundings of these few operations (each relative 2**-53)
        slack = 8 * np.finfo(np.float64).eps * (np.abs(gc) + np.maximum(np.abs(clo), np.abs(chi))
                                                + spread)
        s_lo = gc - chi - spread - slack
        s_hi = gc - clo + spread + slack
        gp = np.einsum("ij,ij->i", g, q_pt)
        dual = nm.dual(g, q_w)
        to_slab = np.maximum(np.maximum(s_lo - gp, gp - s_hi), 0.0) / dual
        if nm.euclidean:
            to_both = _euclidean_box_slab(q_pt, lo, hi, g, s_lo, s_hi)
        else:
            to_both = _linf_box_slab(q_pt, q_w, lo, hi, g, s_lo, s_hi)
    slab_ok = valid & (dual > 0) & np.isfinite(to_slab) & (clo <= chi) & ~np.isnan(to_both)
    lb = np.where(slab_ok, np.maximum(to_box, to_both), to_box)
    lb = np.where(has_zero, lb, np.inf)
    # a candidate zero for each point, from its box of least bound: the point's nearest
    # point on the slab's middle plane, clipped to the box, then two Newton steps
    order = np.lexsort((lb, pt))
    lead = order[np.r_[True, pt[order][1:] != pt[order][:-1]]] if len(order) else order
    lead = lead[has_zero[lead] & slab_ok[lead]]
    r = lead
    direction = nm.step(g[r], q_w[r])
    with np.errstate(all="ignore"):
        q = q_pt[r] + (((s_lo[r] + s_hi[r]) / 2 - gp[r]) / dual[r])[:, None] * direction
    q = _newton(tape, np.clip(np.where(np.isfinite(q), q, c[r]), lo[r], hi[r]), steps=2)
    with np.errstate(all="ignore"):
        unit = g[r] / np.linalg.norm(g[r], axis=1, keepdims=True)
    unit = np.where(np.isfinite(unit), unit, 0.0)
    delta = np.maximum(np.max(half[r], axis=1) * 1e-4, 1e-12 * (1 + np.max(np.abs(c[r]), axis=1)))
    upper = _certified_upper(tape, nm, q_pt[r], q_w[r], q, unit, delta)
    return lb, pt[r], upper


def _euclidean_box_slab(p, lo, hi, g, s_lo, s_hi):
    """The Euclidean distance from ``p`` to box ∩ slab, exactly (``inf`` where it is
    empty: no zero in the box). If the box's nearest point to ``p`` is in the slab it
    is the answer; else the nearest point of box ∩ {g·q = s} (the slab's near face)
    is ``clip(p + λ g, lo, hi)`` for the ``λ`` where ``φ(λ) = g·clip(p + λ g, lo, hi)``,
    a non-decreasing piecewise linear function with a break where each coordinate
    meets a face of the box, reaches ``s`` (the projection onto a box and a hyperplane,
    as in the continuous quadratic knapsack). The breaks are sorted and ``φ`` is
    interpolated between the two around ``s``; all pairs at once."""
    q0 = np.clip(p, lo, hi)
    v0 = np.einsum("ij,ij->i", g, q0)
    above = v0 > s_hi
    outside = (v0 < s_lo) | above
    direction = np.where(above[:, None], -g, g)               # towards the slab
    target = np.where(above, -s_hi, s_lo)
    moving = direction != 0
    with np.errstate(divide="ignore", invalid="ignore"):
        breaks = np.concatenate([np.where(moving, (lo - p) / direction, np.inf),
                                 np.where(moving, (hi - p) / direction, np.inf)], axis=1)
    breaks = np.where(breaks > 0, breaks, np.inf)
    breaks = np.sort(np.concatenate([np.zeros((len(p), 1)), breaks], axis=1), axis=1)
    finite = np.isfinite(breaks)
    lam = np.where(finite, breaks, 0.0)                        # (m, 7)
    moved = np.clip(p[:, None] + lam[..., None] * direction[:, None], lo[:, None], hi[:, None])
    phi = np.where(finite, np.einsum("mkj,mj->mk", moved, direction), -np.inf)
    reached = phi >= target[:, None]
    first = np.argmax(reached, axis=1)
    found = reached.any(axis=1)
    before = np.maximum(first - 1, 0)[:, None]
    after = first[:, None]
    l0, l1 = np.take_along_axis(lam, before, 1)[:, 0], np.take_along_axis(lam, after, 1)[:, 0]
    f0, f1 = np.take_along_axis(phi, before, 1)[:, 0], np.take_along_axis(phi, after, 1)[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        step = np.where(f1 > f0, l0 + (target - f0) / (f1 - f0) * (l1 - l0), l1)
    step = np.where(found, step, 0.0)
    q = np.clip(p + step[:, None] * direction, lo, hi)
    d = np.where(outside, np.linalg.norm(q - p, axis=1), np.linalg.norm(q0 - p, axis=1))
    return np.where(outside & ~found, np.inf, d)


def _first_reach(start: np.ndarray, slope: np.ndarray, stop: np.ndarray, target: np.ndarray
                 ) -> np.ndarray:
    """The least ``t >= 0`` with ``start + sum_i slope_i min(t, stop_i) >= target`` (a
    concave, non-decreasing piecewise linear function; ``inf`` if never)."""
    order = np.argsort(stop, axis=1)
    tau = np.take_along_axis(stop, order, axis=1)
    k = np.take_along_axis(slope, order, axis=1)
    out = np.full(len(start), np.inf)
    base = start + np.sum(k * np.minimum(0.0, tau), axis=1)      # the value at t = 0
    out = np.where(base >= target, 0.0, out)
    left = np.zeros(len(start))
    value = base
    for j in range(4):                                            # segments between breaks
        right = tau[:, j] if j < 3 else np.full(len(start), np.inf)
        right = np.maximum(right, left)
        rate = np.sum(np.where(tau >= right[:, None], k, 0.0), axis=1) if j < 3 else \
            np.sum(np.where(np.isinf(tau), k, 0.0), axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = left + (target - value) / rate
        hit = np.isinf(out) & (rate > 0) & (t >= left) & (t <= right)
        out = np.where(hit, t, out)
        with np.errstate(invalid="ignore"):
            value = np.where(np.isfinite(right), value + rate * (right - left), value)
        left = right
    return out


def _linf_box_slab(p, w, lo, hi, g, s_lo, s_hi):
    """The weighted max-norm distance from ``p`` to (box ∩ slab), exactly: the cube
    ``C(p, t)`` meets it iff ``C(p, t) ∩ box`` (a box, non-empty from ``t = to_box``)
    reaches the slab, and the largest and smallest ``g·q`` over that box are concave
    and convex piecewise linear in ``t``, with a break per axis where the cube passes
    the box's face."""
    a = np.abs(g) * w
    up_stop = np.where(g >= 0, hi - p, p - lo) / w                 # where g·q stops rising
    down_stop = np.where(g >= 0, p - lo, hi - p) / w               # ... stops falling
    gp = np.einsum("ij,ij->i", g, p)
    t_up = _first_reach(gp, a, up_stop, s_lo)
    t_down = _first_reach(-gp, a, down_stop, -s_hi)
    return np.maximum(t_up, t_down)
