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
  and they are split until ``(U - L) / 2`` is below the tolerance (Varadhan §4.3
  refines a hardware estimate by local optimization; this refines by
  intervals, so the result is proved).

The field stores ``(U + L) / 2`` with the error bound ``(U - L) / 2``. Each
bound is computed in floating point and then moved outward by a relative
``2**-40`` (far above the few roundings it contains).

The search runs level by level over all pairs of a block of samples: the
enclosures of each box once, however many samples share it (compiled:
:func:`~implicitvox.eval.mean_value_kernels.tape_interval_gradients` and
:func:`~implicitvox.eval.compiled.evaluate_boxes`; the array evaluator for a
tape with a sweep), then each pair's bound and each sample's candidate
(:mod:`implicitvox.fields.certified_kernels`).

Examples
--------
>>> import numpy as np, implicitvox as iv
>>> from implicitvox import x, y, z, sqrt
>>> f = iv.compile(x * x + y * y + z * z - 1)        # not a distance: needs certifying
>>> lo, hi = np.array([[0.9, -0.1, -0.1]]), np.array([[1.1, 0.1, 0.1]])
>>> value, error = certified_distances(f, np.array([[1.2, 0.0, 0.0]]), "euclidean", None,
...                                    SurfaceBoxes(lo, hi), limit=1.0, tolerance=1e-9)
>>> bool(abs(value[0] - 0.2) <= error[0] <= 1e-9)
True
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from ..eval.function import Function
from ..eval.gradient import evaluate_gradients
from ..eval.interval import evaluate_intervals
from ..eval.mean_value import array_interval_gradients
from ..eval.point import evaluate_points
from ..eval.tape import Tape

__all__ = ["certified_distances", "SurfaceBoxes", "MAX_LEVELS", "MAX_PAIRS"]

#: box halvings below the voxels at most
MAX_LEVELS = 14
#: (point, box) pairs in flight at most; a block of points with more is split
MAX_PAIRS = 1 << 19
#: points per block
_BLOCK = 4096
_NEWTON = 8
_MARGIN = 2.0 ** -40
#: points from which Newton estimates come from the array evaluator
_ARRAY_ESTIMATES = 256


class SurfaceBoxes:
    """The boxes whose union holds the surface (the voxelizer's surface voxels),
    indexed once for every call of :func:`certified_distances` on them: their
    corners, largest half-diagonal and side, extent, and their centres bucketed
    for the search's first pairs (:class:`~implicitvox.fields.certified_kernels.CentreGrid`;
    building it costs about as much as certifying a few hundred samples).

    Parameters
    ----------
    lo, hi : ndarray (m, 3)
        The boxes' corners.
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        from . import certified_kernels                          # (load Numba)
        self.lo = np.asarray(lo, dtype=np.float64).reshape(-1, 3)
        self.hi = np.asarray(hi, dtype=np.float64).reshape(-1, 3)
        m = len(self.lo)
        #: the largest half-diagonal and side of a box
        self.half_diag = float(np.max(np.linalg.norm(self.hi - self.lo, axis=1))) / 2 if m \
            else 0.0
        self.scale = float(np.max(self.hi - self.lo)) if m else 1.0
        #: the corners of their bounding box
        self.low = self.lo.min(axis=0) if m else np.zeros(3)
        self.high = self.hi.max(axis=0) if m else np.zeros(3)
        # (cells of 4 boxes: the balls reach a few boxes, so a few columns of cells each)
        self.centres = certified_kernels.CentreGrid(0.5 * (self.lo + self.hi),
                                                    4.0 * self.scale) if m else None

    def __len__(self) -> int:
        return len(self.lo)


class _Enclosures:
    """``f``'s enclosures at points and over boxes, and estimates for Newton steps:
    compiled where the tape has a compiled form, else the array evaluator."""

    def __init__(self, tape: Tape):
        from ..eval import compiled, mean_value_kernels          # (load Numba)
        from . import certified_kernels
        self.tape = tape
        self.kernels = certified_kernels
        self.evaluate_boxes = compiled.evaluate_boxes
        self.gradients = mean_value_kernels.tape_interval_gradients
        self.compiled = None if tape.undefined else compiled.compiled_tape(tape)

    def boxes(self, lo: np.ndarray, hi: np.ndarray) -> tuple:
        """``(vlo, vhi, glo, ghi, valid)`` over boxes ``lo, hi`` (3, m): values (m,),
        gradients (3, m), where the mean value theorem holds (m,)."""
        m = lo.shape[1]
        if self.compiled is not None:
            return self.gradients(self.tape, lo, hi, libm=True, closed=True)
        with np.errstate(all="ignore"):
            vlo, vhi, glo, ghi, valid = array_interval_gradients(self.tape, tuple(lo), tuple(hi))
        return (np.broadcast_to(vlo, (m,)), np.broadcast_to(vhi, (m,)),
                np.ascontiguousarray(np.broadcast_to(glo, (3, m))),
                np.ascontiguousarray(np.broadcast_to(ghi, (3, m))), np.broadcast_to(valid, (m,)))

    def at(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Enclosures ``(lo, hi)`` of ``f`` at the points ``q`` (3, n), rounded
        outward (empty, ``lo > hi``, outside the domain)."""
        n = q.shape[1]
        if self.compiled is not None:
            return self.evaluate_boxes(self.compiled, q, q)
        with np.errstate(all="ignore"):
            lo, hi = evaluate_intervals(self.tape, tuple(q), tuple(q))
        return np.broadcast_to(lo, (n,)), np.broadcast_to(hi, (n,))

    def estimates(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values (n,) and gradients (n, 3) near ``f``'s and ``∇f``'s at the points
        ``q`` (n, 3), for Newton steps: the midpoints of their compiled enclosures
        for a few points, the array evaluator's floats for many (its numpy calls
        cost less per point there) or for a tape with a sweep."""
        n = len(q)
        with np.errstate(all="ignore"):
            if self.compiled is not None and n < _ARRAY_ESTIMATES:
                qt = np.ascontiguousarray(q.T)
                vlo, vhi, glo, ghi, _ = self.gradients(self.tape, qt, qt, libm=True)
                return 0.5 * (vlo + vhi), (0.5 * (glo + ghi)).T
            v, g = evaluate_gradients(self.tape, *q.T)
        return (np.broadcast_to(v, (n,)),
                np.broadcast_to(np.asarray(g).reshape(3, -1), (3, n)).T)


def _length(v: np.ndarray, w: np.ndarray, euclidean: bool) -> np.ndarray:
    """The Euclidean norm of the rows of ``v``, or their max-norm weighted by ``w``."""
    if euclidean:
        return np.sqrt(np.einsum("ij,ij->i", v, v))
    return np.max(np.abs(v) / w, axis=1)


def _signs(ev: _Enclosures, q: np.ndarray) -> np.ndarray:
    """+1 / -1 where the sign of ``f(q)`` is proved (outward-rounded enclosure), else 0."""
    lo, hi = ev.at(np.ascontiguousarray(q.T))
    return np.where((lo > 0) & (lo <= hi), 1, np.where((hi < 0) & (lo <= hi), -1, 0))


def _certified_upper(ev: _Enclosures, euclidean: bool, p: np.ndarray, w: np.ndarray,
                     q: np.ndarray, direction: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Upper bounds from short segments through ``q`` whose ends have proved opposite
    signs (``inf`` where none): ``q ± delta·direction`` (across the surface where
    ``direction`` is its normal), and where that fails ``q ± delta·(q - p) / |q - p|``,
    along the ray from the point (across it where ``q`` is near the nearest zero,
    also at a kink of the surface, where the gradient at ``q`` is one side's)."""
    with np.errstate(all="ignore"):
        ray = (q - p) / np.linalg.norm(q - p, axis=1, keepdims=True)
    best = np.full(len(p), np.inf)
    todo = np.arange(len(p))
    for u in (direction, ray):
        u, at, d = u[todo], q[todo], delta[todo]
        a = at - d[:, None] * u
        b = at + d[:, None] * u
        finite = np.all(np.isfinite(a), axis=1) & np.all(np.isfinite(b), axis=1)
        a, b = np.where(finite[:, None], a, 0.0), np.where(finite[:, None], b, 0.0)
        ok = (_signs(ev, a) * _signs(ev, b) < 0) & finite
        far = np.maximum(_length(a - p[todo], w[todo], euclidean),
                         _length(b - p[todo], w[todo], euclidean))
        best[todo] = np.where(ok, far * (1 + _MARGIN), np.inf)
        todo = todo[~ok]
        if not len(todo):
            break
    return best


def _ray_upper(ev: _Enclosures, euclidean: bool, p: np.ndarray, w: np.ndarray, q: np.ndarray,
               span: np.ndarray, steps: int = 16) -> np.ndarray:
    """Upper bounds from a sign change on the ray from ``p`` through ``q``: where
    ``f``'s signs are proved opposite at distances ``|q - p| ∓ span`` along it, the
    segment is halved ``steps`` times, keeping ends of proved opposite signs, and
    its far end bounds the distance (``inf`` where the ends' signs are not
    opposite). Newton steps stall near a kink of the surface (an edge, a corner),
    where a short segment through their last point may not cross it; this finds
    the crossing anyway."""
    with np.errstate(all="ignore"):
        t = np.linalg.norm(q - p, axis=1)
        ray = (q - p) / t[:, None]
    ok = np.isfinite(t) & np.all(np.isfinite(ray), axis=1) & np.isfinite(span) & (t > 0)
    ray = np.where(ok[:, None], ray, 0.0)
    ta, tb = np.where(ok, np.maximum(t - span, 0.0), 0.0), np.where(ok, t + span, 0.0)
    sa = _signs(ev, p + ta[:, None] * ray)
    sb = _signs(ev, p + tb[:, None] * ray)
    ok &= sa * sb < 0
    live = ok.copy()
    for _ in range(steps):
        tm = 0.5 * (ta + tb)
        sm = _signs(ev, p + tm[:, None] * ray)
        live &= sm != 0
        ta = np.where(live & (sm == sa), tm, ta)
        tb = np.where(live & (sm == sb), tm, tb)
    far = _length(ray, w, euclidean) * tb
    return np.where(ok, far * (1 + _MARGIN) + _MARGIN * (1.0 + np.max(np.abs(p), axis=1)),
                    np.inf)


def _newton(ev: _Enclosures, q: np.ndarray, steps: int) -> np.ndarray:
    """Newton steps ``q <- q - f(q) ∇f / |∇f|²`` towards the surface (lanes where a
    step is not finite stay; lanes whose step falls below 2**-40 of their size
    stop)."""
    q = q.copy()
    live = np.arange(len(q))
    with np.errstate(all="ignore"):
        for _ in range(steps):
            v, g = ev.estimates(q[live])
            gg = np.einsum("ij,ij->i", g, g)
            move = np.where((gg > 0)[:, None], -(v / np.where(gg > 0, gg, 1))[:, None] * g, 0.0)
            moving = np.all(np.isfinite(move), axis=1)
            q[live[moving]] += move[moving]
            small = np.max(np.abs(move), axis=1) <= _MARGIN * (1.0 + np.max(np.abs(q[live]),
                                                                            axis=1))
            live = live[moving & ~small]
            if not len(live):
                break
    return q


def _newton_upper(ev: _Enclosures, euclidean: bool, p: np.ndarray, w: np.ndarray,
                  scale: float) -> np.ndarray:
    """Upper bounds from Newton projections ``q <- q - f(q) ∇f / |∇f|²`` of the points."""
    q = _newton(ev, p, _NEWTON)
    with np.errstate(all="ignore"):
        _, g = ev.estimates(q)
        unit = g / np.linalg.norm(g, axis=1, keepdims=True)
    unit = np.where(np.all(np.isfinite(unit), axis=1)[:, None], unit, 0.0)
    best = np.full(len(p), np.inf)
    todo = np.arange(len(p))
    for rel in (1e-9, 1e-6, 1e-3):          # the shortest segment that certifies
        best[todo] = _certified_upper(ev, euclidean, p[todo], w[todo], q[todo], unit[todo],
                                      np.full(len(todo), rel * scale))
        todo = todo[~np.isfinite(best[todo])]
    stalled = ~np.isfinite(best)
    best[stalled] = _ray_upper(ev, euclidean, p[stalled], w[stalled], q[stalled],
                               np.full(int(stalled.sum()), scale))
    return best


def certified_distances(func: Function, points: np.ndarray, norm: str, weights: Optional[Any],
                        boxes: SurfaceBoxes, *, limit: float,
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
    boxes : SurfaceBoxes
        Boxes whose union holds every surface point within ``limit`` of a point
        (the voxelizer's surface voxels), indexed once for all calls.
    limit : float
        Where to look first: the pairs are the boxes within ``limit`` (or the
        point's Newton bound); a point with no zero proved within it is searched
        again 4 times farther, up to the boxes' whole extent. A point with no
        surface anywhere in the boxes gets ``inf``.
    tolerance : float
        Stop refining a point when its error bound, ``(U - L) / 2`` moved outward,
        is at most ``tolerance``.
    stats : dict, optional
        Receives counts: ``"pairs"`` (point-box pairs evaluated) and ``"capped"``
        (points left above the tolerance when their pairs outgrew :data:`MAX_PAIRS`).

    Returns
    -------
    value, error : ndarray (n,)
        ``|value - d| <= error`` for the true signed distance ``d`` to the surface
        held in the boxes.
    """
    euclidean = norm == "euclidean"
    p = np.asarray(points, dtype=np.float64)
    n = len(p)
    w = np.ones((n, 3)) if weights is None or euclidean else \
        np.broadcast_to(np.asarray(weights, dtype=np.float64), (n, 3))
    value = np.zeros(n)
    error = np.zeros(n)
    if n == 0:
        return value, error
    ev = _Enclosures(func.tape)
    span = np.maximum(boxes.high, p.max(axis=0)) - np.minimum(boxes.low, p.min(axis=0)) \
        if len(boxes) else np.zeros(3)
    max_reach = max(limit, float(np.max(span / (1.0 if euclidean else np.min(w)))) * 2.0)
    sign = _point_signs(ev, p)
    # the gap U - L at which a point's error, with _bracket's outward margins (at
    # most _MARGIN (L + 1 + |p|)), is within the tolerance
    gap = 2.0 * tolerance - _MARGIN * (max_reach + 1.0 + float(np.max(np.abs(p))))
    gap = max(gap, tolerance)
    stats = {} if stats is None else stats
    stats.setdefault("pairs", 0)
    stats.setdefault("capped", 0)
    for s in range(0, n, _BLOCK):
        rows = np.arange(s, min(s + _BLOCK, n))
        reach = limit
        while len(rows):
            lo_b, up_b = _bracket(ev, euclidean, p[rows], w[rows], boxes, reach, gap,
                                  max_levels, stats)
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


def _point_signs(ev: _Enclosures, p: np.ndarray) -> np.ndarray:
    """Signs of ``f`` at the points: proved where the enclosure excludes 0; where it
    does not, the point is within rounding of the surface and the float value's
    sign is taken (the distance there is 0 within the error)."""
    proved = _signs(ev, p)
    with np.errstate(all="ignore"):
        v = np.broadcast_to(evaluate_points(ev.tape, *p.T), (len(p),))
    return np.where(proved != 0, proved, np.where(v < 0, -1.0, 1.0)).astype(np.float64)


def _bracket(ev, euclidean, p, w, boxes, limit, gap, max_levels, stats):
    """``(L, U)`` for one block of points (see the module docstring)."""
    n = len(p)
    centres = boxes.centres
    if centres is None:                    # no box may hold the surface: none within reach
        return np.full(n, limit), np.full(n, np.inf)
    upper = _newton_upper(ev, euclidean, p, w, boxes.scale)
    # the initial pairs: boxes whose centre is within reach (a superset, then exact),
    # gathered for groups of points with at most MAX_PAIRS pairs between them
    reach = np.minimum(upper, limit)
    euclid_reach = reach * (1.0 if euclidean else np.sqrt(3) * float(np.max(w))) + \
        boxes.half_diag
    counts = centres.pairs(p, euclid_reach)
    lower = np.where(counts == 0, reach, 0.0)     # no box within reach: nothing nearer
    state = {"upper": upper, "lower": lower, "open": counts > 0, "parked": np.full(n, np.inf),
             # the domain the boxes cover (their bounding box): a nearest zero inside it
             # meets the Fritz John condition (certified_kernels.pair_bounds)
             "interior_lo": boxes.low, "interior_hi": boxes.high}
    group = np.cumsum(counts) // MAX_PAIRS
    for g in np.unique(group[counts > 0]):
        rows = np.flatnonzero((group == g) & (counts > 0))
        pt, box = centres.pairs(p[rows], euclid_reach[rows], counts[rows])
        used, box = np.unique(box, return_inverse=True)
        pt = rows[pt]
        _refine(ev, euclidean, p, w, pt, box.reshape(-1), np.ascontiguousarray(boxes.lo[used].T),
                np.ascontiguousarray(boxes.hi[used].T), 0, state, limit, gap, max_levels, stats)
    lower, upper = state["lower"], state["upper"]
    # outward: a relative margin, and one for the roundings of coordinates of this size
    slack = _MARGIN * (1.0 + float(np.max(np.abs(p))))
    return np.maximum(lower * (1 - _MARGIN) - slack, 0.0), upper


def _refine(ev, euclidean, p, w, pt, box, lo, hi, level, state, limit, gap, max_levels,
            stats, parent=None):
    """Bound, prune and split the pairs ``(pt, box)`` level by level (``pt`` sorted;
    ``box`` indexes the boxes ``lo, hi`` (3, m) of this level, each evaluated once;
    ``parent``: the per-box arrays of their parents, box ``b``'s being ``b >> 3``);
    where the children would exceed :data:`MAX_PAIRS`, the points are halved and each
    half refined on its own (a point's pairs stay together, so its bounds come from
    all of them)."""
    upper, lower, open_, parked = state["upper"], state["lower"], state["open"], state["parked"]
    inner = (state["interior_lo"], state["interior_hi"])
    kernels = ev.kernels
    n = len(p)
    while len(pt):
        keep = np.empty(len(pt), dtype=bool)
        reach = np.minimum(upper, limit)
        alive = np.zeros(n, dtype=bool)
        kernels.shell_pairs(euclidean, p, w, pt, lo, hi, box, lower, reach, parent is not None,
                            *(parent or _NO_PARENT), *inner, keep, alive)
        # a point left without pairs has no zero nearer than its reach but in its
        # parked boxes
        gone = pt[np.r_[True, pt[1:] != pt[:-1]]]
        gone = gone[~alive[gone]]
        lower[gone] = np.where(open_[gone], np.minimum(parked[gone], reach[gone]), lower[gone])
        open_[gone] = False
        pt, box, lo, hi, _ = _kept_boxes(pt[keep], box[keep], lo, hi)
        if not len(pt):
            return
        mine = pt[np.r_[True, pt[1:] != pt[:-1]]]
        vlo, vhi, glo, ghi, valid = ev.boxes(lo, hi)
        clo, chi = ev.at(0.5 * (lo + hi))
        m = lo.shape[1]
        slabs = (np.empty((3, m)), np.empty(m), np.empty(m), np.empty(m, dtype=bool))
        kernels.box_slabs(lo, hi, vlo, vhi, glo, ghi, valid, clo, chi, *slabs)
        lb = np.empty(len(pt))
        lead = np.full(n, -1, dtype=np.int64)
        lead_q, lead_unit, lead_delta = np.empty((n, 3)), np.empty((n, 3)), np.empty(n)
        kernels.pair_bounds(euclidean, p, w, pt, box, lo, hi, *slabs, glo, ghi, valid, *inner,
                            lb, lead, lead_q, lead_unit, lead_delta)
        # a candidate zero for each point, from its box of least bound: the point's
        # nearest point on the slab's middle plane, clipped to the box, then two
        # Newton steps, certified by a short segment across the surface
        r = np.flatnonzero(lead >= 0)
        q = _newton(ev, lead_q[r], steps=2)
        cand = _certified_upper(ev, euclidean, p[r], w[r], q, lead_unit[r], lead_delta[r])
        stalled = ~np.isfinite(cand)
        cand[stalled] = _ray_upper(ev, euclidean, p[r[stalled]], w[r[stalled]], q[stalled],
                                   1e4 * lead_delta[r[stalled]])
        upper[r] = np.minimum(upper[r], cand)
        reach = np.minimum(upper, limit)
        best = np.full(n, np.inf)
        keep = np.empty(len(pt), dtype=bool)
        kernels.settle_pairs(pt, lb, reach, best, keep)
        pt, box, lb = pt[keep], box[keep], lb[keep]
        least = np.minimum(np.minimum(best[mine], parked[mine]), reach[mine])
        lower[mine] = np.where(open_[mine], least, lower[mine])
        open_[mine] &= reach[mine] - lower[mine] > gap
        # a pair whose bound is within the gap of the reach needs no splitting:
        # it is parked, its bound kept in the point's lower bound
        park = lb >= reach[pt] - gap
        np.minimum.at(parked, pt[park], lb[park])
        still = open_[pt] & ~park
        pt, box = pt[still], box[still]
        if level == max_levels or not len(pt):
            return
        pt, box, lo, hi, used = _split(pt, box, lo, hi)
        parent = [a[..., used] for a in (*slabs, glo, ghi, valid)]
        level += 1
        stats["pairs"] += len(pt)
        if len(pt) > MAX_PAIRS:
            points = pt[np.r_[True, pt[1:] != pt[:-1]]]
            if len(points) == 1:            # one point's pairs alone are too many: stop here
                stats["capped"] += 1
                return
            first = pt < points[len(points) // 2]
            for half in (first, ~first):
                _refine(ev, euclidean, p, w, pt[half], box[half], lo, hi, level, state, limit,
                        gap, max_levels, stats, parent)
            return


#: the parents' arrays of :func:`certified_kernels.shell_pairs` at the first level (none)
_NO_PARENT = (np.empty((3, 0)), np.empty(0), np.empty(0), np.empty(0, dtype=bool),
              np.empty((3, 0)), np.empty((3, 0)), np.empty(0, dtype=bool))


def _kept_boxes(pt, box, lo, hi):
    """The pairs ``(pt, box)`` on a box table holding only the boxes they name (and
    which of the old ones those are)."""
    from . import certified_kernels as kernels
    index = np.full(lo.shape[1], -1, dtype=np.int64)
    count = kernels.number_boxes(box, index)
    new_box = np.empty_like(box)
    new_lo, new_hi = np.empty((3, count)), np.empty((3, count))
    kernels.gather_boxes(box, index, lo, hi, new_box, new_lo, new_hi)
    return pt, new_box, new_lo, new_hi, index >= 0


def _split(pt, box, lo, hi):
    """Each box that still has pairs into its 8 children (box ``k`` of those kept
    becomes boxes ``8k .. 8k + 7``), each pair into 8; and which boxes were kept."""
    from . import certified_kernels as kernels
    pt, box, ulo, uhi, used = _kept_boxes(pt, box, lo, hi)
    m, n = ulo.shape[1], len(pt)
    child_lo, child_hi = np.empty((3, 8 * m)), np.empty((3, 8 * m))
    child_pt, child_box = np.empty(8 * n, dtype=np.int64), np.empty(8 * n, dtype=np.int64)
    kernels.split_boxes(pt, box, ulo, uhi, child_pt, child_box, child_lo, child_hi)
    return child_pt, child_box, child_lo, child_hi, used
