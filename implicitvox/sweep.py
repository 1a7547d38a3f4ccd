"""Replication sweeps (Stolte §3): one model, repeated along axes or about an axis.

``repeat(expr, spacing, count)`` places instance ``k`` (per axis) at
``k * spacing``; a point belongs to the instance whose cell
``[(k - 1/2) s, (k + 1/2) s]`` holds it (Stolte's replication factor
``i = int((z +- b/2) / b)``, eq. 1), clamped to ``0 .. count - 1`` when the
count is finite, so points past the ends see the end instances. The value is
``expr`` at the point's local coordinates ``p - k s``.

``repeat_polar(expr, n, axis)`` makes ``n`` copies about an axis: the point
is turned back by ``k * 2 pi / n``, ``k`` the sector of its azimuth.

Intervals visit only the instances whose cells meet the box (Stolte §3.2,
``i0 .. i1``), and at most two local pieces per axis: the first instance's
clipped sub-box, and the union of the others (the whole cell once the box
spans three instances). So a box costs at most ``2**axes`` evaluations of
``expr`` however many instances it spans - a million as cheaply as one.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z, hypot
>>> torus = (hypot(x, y) - 0.6) ** 2 + z ** 2 - 0.1 ** 2
>>> stack = iv.repeat(torus, spacing=(None, None, 0.5))       # endless along z
>>> f = iv.compile(stack)
>>> float(f(0.6, 0.0, 5.0)) < 0 < float(f(0.6, 0.0, 5.25))
True
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, fields
from typing import Any, Sequence

import mpmath
import numpy as np

from . import interval as I
from . import rounding as R
from .eval_grad import evaluate_gradients
from .eval_interval import evaluate_intervals
from .eval_point import evaluate_points
from .expr import Expr, wrap, x, y, z

__all__ = ["repeat", "repeat_polar", "Sweep", "PolarSweep", "prepared"]

_FRAMES = {"z": (0, 1, 2), "x": (1, 2, 0), "y": (0, 2, 1)}


def _spacing_and_count(spacing: Any, count: Any) -> tuple[tuple, tuple]:
    try:
        sp = tuple(spacing)
    except TypeError:
        sp = (spacing,) * 3
    if len(sp) != 3:
        raise ValueError(f"spacing must be one number or three (None: no repetition), got {spacing!r}")
    out = []
    for a, s in zip("xyz", sp):
        if s is None:
            out.append(None)
            continue
        if isinstance(s, bool) or not isinstance(s, (int, float, np.integer, np.floating)) \
                or not math.isfinite(s) or s <= 0:
            raise ValueError(f"spacing on {a} must be a positive number or None, got {s!r}")
        out.append(float(s))
    if count is None or isinstance(count, (int, np.integer)):
        counts = (count,) * 3
    else:
        counts = tuple(count)
        if len(counts) != 3:
            raise ValueError(f"count must be None, one int or three, got {count!r}")
    for a, n in zip("xyz", counts):
        if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1):
            raise ValueError(f"count on {a} must be a positive int or None, got {n!r}")
    if all(s is None for s in out):
        raise ValueError("spacing repeats along no axis")
    return tuple(out), tuple(None if n is None else int(n) for n in counts)


def repeat(expr: Any, spacing: Any, count: Any = None) -> Expr:
    """Repeat ``expr`` every ``spacing`` along the axes (Stolte §3).

    Parameters
    ----------
    expr : Expr
        The model, around the origin.
    spacing : float or (sx, sy, sz)
        Distance between instances per axis; ``None`` for no repetition.
    count : int or (nx, ny, nz), optional
        Instances per axis (``0 .. n - 1``); ``None`` for endless.
    """
    sp, counts = _spacing_and_count(spacing, count)
    return Expr("repeat", (x, y, z), (wrap(expr), sp, counts))


def repeat_polar(expr: Any, n: int, axis: str = "z") -> Expr:
    """``n`` copies of ``expr`` turned about ``axis`` by ``2 pi / n`` each
    (gear teeth, bolt circles); copy 0 is ``expr`` itself, centred on the
    first of the other two axes."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be a positive int, got {n!r}")
    if axis not in _FRAMES:
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")
    return Expr("repeat_polar", (x, y, z), (wrap(expr), int(n), axis))


# -- runtime forms (the tape's instruction parameters) -------------------------------
def _columns(arrays: Sequence[Any]) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """The broadcast shape of the arguments and each flattened to it."""
    shape = np.broadcast_shapes(*(np.shape(a) for a in arrays))
    return shape, [np.broadcast_to(a, shape).reshape(-1) for a in arrays]


class _Compiled:
    """A sweep's expression parameter ``(expr, ...)`` with the model's tape
    compiled once; the tape interns it by :meth:`key`."""

    @classmethod
    def prepare(cls, param: tuple):
        from .tape import build_tape
        return cls(*param, build_tape(param[0]))

    def key(self) -> tuple:
        return (type(self).__name__,) + tuple(
            getattr(self, f.name) for f in fields(self) if f.name != "tape")


@dataclass(frozen=True, eq=False)
class Sweep(_Compiled):
    """A compiled :func:`repeat`: the child's tape, spacing and counts."""

    expr: Expr
    spacing: tuple
    count: tuple
    tape: Any = field(repr=False)

    # instance index of coordinates (numpy), clamped to the count
    def _index(self, axis: int, t: np.ndarray, slack: float = 0.0) -> np.ndarray:
        s, n = self.spacing[axis], self.count[axis]
        u = t / s + 0.5
        k = np.floor(u + slack * (1.0 + np.abs(u)))
        return k if n is None else np.clip(k, 0, n - 1)

    def point(self, args: tuple, p: Any) -> np.ndarray:
        shape, cols = _columns(args)
        local = [c if self.spacing[a] is None else c - self._index(a, c) * self.spacing[a]
                 for a, c in enumerate(cols)]
        return evaluate_points(self.tape, *local).reshape(shape)

    def derivative(self, v: tuple, g: tuple, out: np.ndarray, p: Any) -> np.ndarray:
        cols = [np.asarray(a, dtype=np.float64).reshape(-1) for a in np.broadcast_arrays(*v)]
        local = [c if self.spacing[a] is None else c - self._index(a, c) * self.spacing[a]
                 for a, c in enumerate(cols)]
        _, child = evaluate_gradients(self.tape, *local)
        return sum(child[a] * g[a] for a in range(3))

    def _pieces(self, axis: int, lo: np.ndarray, hi: np.ndarray):
        """Two local intervals per box on a replicated axis, and whether the
        box spans more than one instance."""
        s = self.spacing[axis]
        k0 = self._index(axis, lo, -1e-12)
        k1 = self._index(axis, hi, 1e-12)
        half = 0.5 * s
        a_lo = R.down(lo - R.up(k0 * s))
        b_hi = R.up(hi - R.down(k1 * s))
        a_lo = np.where(k0 * s == 0.0, lo, a_lo)  # instance 0: the local frame is the box
        b_hi = np.where(k1 * s == 0.0, hi, b_hi)
        same = k1 == k0
        a_hi = np.where(same, b_hi, np.maximum(half, a_lo))
        b_lo = np.where(same, a_lo, np.minimum(-half, b_hi))
        b_hi = np.where(same | (k1 == k0 + 1), b_hi, np.maximum(half, b_hi))
        return (a_lo, a_hi), (b_lo, b_hi), ~same

    def interval(self, los: tuple, his: tuple, p: Any):
        shape, cols = _columns(los + his)
        lo, hi = cols[:3], cols[3:]
        options = []
        for a in range(3):
            if self.spacing[a] is None:
                options.append([(lo[a], hi[a])])
            else:
                first, rest, _ = self._pieces(a, lo[a], hi[a])
                options.append([first, rest])
        flo = np.full(lo[0].shape, np.inf)
        fhi = np.full(lo[0].shape, -np.inf)
        for px in options[0]:
            for py in options[1]:
                for pz in options[2]:
                    clo, chi = evaluate_intervals(self.tape, (px[0], py[0], pz[0]),
                                                  (px[1], py[1], pz[1]))
                    flo, fhi = np.minimum(flo, clo), np.maximum(fhi, chi)
        empty = flo > fhi  # every piece undefined
        flo, fhi = np.where(empty, 0.0, flo), np.where(empty, 0.0, fhi)
        return flo.reshape(shape), fhi.reshape(shape), empty.reshape(shape)

    def interval_derivative(self, v: tuple, g: tuple, out: tuple, p: Any):
        from .mean_value import evaluate_interval_gradients
        shape = np.broadcast_shapes(*(np.shape(a[0]) for a in v))
        lo = [np.broadcast_to(a[0], shape).reshape(-1) for a in v]
        hi = [np.broadcast_to(a[1], shape).reshape(-1) for a in v]
        spans = np.zeros(lo[0].shape, dtype=bool)
        local_lo, local_hi = [], []
        for a in range(3):
            if self.spacing[a] is None:
                local_lo.append(lo[a])
                local_hi.append(hi[a])
            else:
                (alo, ahi), _, more = self._pieces(a, lo[a], hi[a])
                local_lo.append(alo)
                local_hi.append(ahi)
                spans |= more
        _, _, clo, chi, valid = evaluate_interval_gradients(self.tape, local_lo, local_hi)
        glo, ghi = I.i_mul(clo[0], chi[0], *g[0])
        for a in (1, 2):
            glo, ghi = I.i_add(glo, ghi, *I.i_mul(clo[a], chi[a], *g[a]))
        return (glo, ghi), spans | ~valid  # a box over two instances may jump

    def reference(self, args: list, p: Any):
        from .reference import mp_evaluate
        local = []
        for a, t in enumerate(args):
            s, n = self.spacing[a], self.count[a]
            if s is None:
                local.append(t)
                continue
            k = mpmath.floor(t / mpmath.mpf(s) + mpmath.mpf(0.5))
            if n is not None:
                k = min(max(k, 0), n - 1)
            local.append(t - k * mpmath.mpf(s))
        return mp_evaluate(self.expr, local, mpmath.mp.dps)


@dataclass(frozen=True, eq=False)
class PolarSweep(_Compiled):
    """A compiled :func:`repeat_polar`."""

    expr: Expr
    n: int
    axis: str
    tape: Any = field(repr=False)

    @property
    def step(self) -> float:
        return 2.0 * np.pi / self.n

    def _uvw(self, cols: Sequence[np.ndarray]):
        iu, iv, iw = _FRAMES[self.axis]
        return cols[iu], cols[iv], cols[iw]

    def _xyz(self, u, v, w):
        iu, iv, iw = _FRAMES[self.axis]
        out = [None, None, None]
        out[iu], out[iv], out[iw] = u, v, w
        return out

    def _turn(self, u, v):
        k = np.floor(np.arctan2(v, u) / self.step + 0.5)
        c, s = np.cos(k * self.step), np.sin(k * self.step)
        return u * c + v * s, v * c - u * s, c, s

    def point(self, args: tuple, p: Any) -> np.ndarray:
        shape, cols = _columns(args)
        u, v, w = self._uvw(cols)
        lu, lv, _, _ = self._turn(u, v)
        return evaluate_points(self.tape, *self._xyz(lu, lv, w)).reshape(shape)

    def derivative(self, vals: tuple, g: tuple, out: np.ndarray, p: Any) -> np.ndarray:
        cols = [np.asarray(a, dtype=np.float64).reshape(-1) for a in np.broadcast_arrays(*vals)]
        u, v, w = self._uvw(cols)
        lu, lv, c, s = self._turn(u, v)
        _, child = evaluate_gradients(self.tape, *self._xyz(lu, lv, w))
        gu, gv, gw = self._uvw(list(child))
        du, dv = gu * c - gv * s, gu * s + gv * c   # turn the gradient back
        grads = self._xyz(du, dv, gw)
        return sum(grads[a] * g[a] for a in range(3))

    def _rotated(self, k, ulo, uhi, vlo, vhi):
        """Box turned back by ``k`` steps (interval rotation, Stolte §2)."""
        angle = k * self.step
        c, s = np.cos(angle), np.sin(angle)
        # The float angle is off the exact k * 2 pi / n by a few ulps of the angle;
        # cos and sin move at most that much (slope <= 1), an *absolute* error
        # (sin(float(pi)) is 1.2e-16, not 0), so widen by it as well as by the
        # functions' own relative error.
        slack = np.abs(angle) * (8 * 2.0 ** -52) + 2.0 ** -1000
        ulps = 2 * R.TRANSCENDENTAL_ULPS
        clo, chi = R.down(c, ulps) - slack, R.up(c, ulps) + slack
        slo, shi = R.down(s, ulps) - slack, R.up(s, ulps) + slack
        lu = I.i_add(*I.i_mul(ulo, uhi, clo, chi), *I.i_mul(vlo, vhi, slo, shi))
        lv = I.i_sub(*I.i_mul(vlo, vhi, clo, chi), *I.i_mul(ulo, uhi, slo, shi))
        return lu, lv

    def _sector_box(self, ulo, uhi, vlo, vhi):
        """Bounding box of the fundamental sector between the box's radii."""
        rlo, rhi = I.i_hypot(ulo, uhi, vlo, vhi)
        half = self.step / 2
        if half >= np.pi / 2:  # n <= 2: a half plane or the whole plane
            ulo_s = -rhi if half > np.pi / 2 else np.zeros_like(rhi)
            return (ulo_s, rhi), (-rhi, rhi)
        c, s = R.down(np.cos(half), 8), R.up(np.sin(half), 8)
        return (R.down_nonneg(rlo * c), rhi), (-R.up_nonneg(rhi * s), R.up_nonneg(rhi * s))

    def interval(self, los: tuple, his: tuple, p: Any):
        shape, cols = _columns(los + his)
        lo, hi = cols[:3], cols[3:]
        (ulo, vlo, wlo), (uhi, vhi, whi) = self._uvw(lo), self._uvw(hi)
        alo, ahi, whole = I.angle_interval(vlo, vhi, ulo, uhi)
        k0 = np.floor(alo / self.step + 0.5 - 1e-9)
        k1 = np.floor(ahi / self.step + 0.5 + 1e-9)
        many = whole | (k1 - k0 >= 2)
        boxes = [self._rotated(k0, ulo, uhi, vlo, vhi), self._rotated(k1, ulo, uhi, vlo, vhi)]
        su, sv = self._sector_box(ulo, uhi, vlo, vhi)
        flo = np.full(ulo.shape, np.inf)
        fhi = np.full(ulo.shape, -np.inf)
        for (lu, lv) in boxes:
            bu = (np.where(many, su[0], lu[0]), np.where(many, su[1], lu[1]))
            bv = (np.where(many, sv[0], lv[0]), np.where(many, sv[1], lv[1]))
            xyz_lo = self._xyz(bu[0], bv[0], wlo)
            xyz_hi = self._xyz(bu[1], bv[1], whi)
            clo, chi = evaluate_intervals(self.tape, tuple(xyz_lo), tuple(xyz_hi))
            flo, fhi = np.minimum(flo, clo), np.maximum(fhi, chi)
        empty = flo > fhi
        flo, fhi = np.where(empty, 0.0, flo), np.where(empty, 0.0, fhi)
        return flo.reshape(shape), fhi.reshape(shape), empty.reshape(shape)

    def interval_derivative(self, v: tuple, g: tuple, out: tuple, p: Any):
        shape = np.broadcast_shapes(*(np.shape(a[0]) for a in v))
        n = int(np.prod(shape)) if shape else 1
        inf = np.full((3, n), np.inf)
        return (-inf, inf), np.ones(n, dtype=bool)  # the mean value form is not used here

    def reference(self, args: list, p: Any):
        from .reference import mp_evaluate
        iu, iv, iw = _FRAMES[self.axis]
        u, v, w = args[iu], args[iv], args[iw]
        angle = mpmath.mpf(0) if u == 0 and v == 0 else mpmath.atan2(v, u)
        step = 2 * mpmath.pi / self.n
        k = mpmath.floor(angle / step + mpmath.mpf(0.5))
        c, s = mpmath.cos(k * step), mpmath.sin(k * step)
        local = [None, None, None]
        local[iu], local[iv], local[iw] = u * c + v * s, v * c - u * s, w
        return mp_evaluate(self.expr, local, mpmath.mp.dps)



@functools.lru_cache(maxsize=256)
def prepared(op: str, param: tuple):
    """The compiled sweep of an expression parameter (cached: the mpmath
    reference calls this once per point); a compiled one passes through."""
    if isinstance(param, (Sweep, PolarSweep)):
        return param
    return (Sweep if op == "repeat" else PolarSweep).prepare(param)
