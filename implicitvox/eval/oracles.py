"""Sweep oracles: compiled :func:`~implicitvox.expr.sweeps.repeat` and
:func:`~implicitvox.expr.sweeps.repeat_polar` nodes (Stolte §3).

A sweep is an *oracle* row of the opcode table (libfive's ``ORACLE``): its
tape instruction carries one of the objects below, holding the child model's
own tape, and every evaluator drives it, passing itself in (``run``) to
evaluate the child. So this module imports no evaluator and the opcode table
imports no sweep.

Intervals visit only the instances whose cells meet the box (Stolte §3.2,
``i0 .. i1``), and at most two local pieces per axis: the first instance's
clipped sub-box, and the union of the others (the whole cell once the box
spans three instances). So a box costs at most ``2**axes`` evaluations of
the child however many instances it spans - a million as cheaply as one.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Callable, Sequence

import numpy as np

from ..expr.nodes import Expr
from ..expr.sweeps import FRAMES
from ..interval import kernels
from ..interval import rounding

__all__ = ["Sweep", "PolarSweep", "compile_oracle", "REFERENCE_DIGITS"]

#: digits the exact reference keeps for a repeat's local coordinate: beyond
#: ``10**(dps - REFERENCE_DIGITS)`` instances the reference gives no value (the
#: instance index would eat the working precision, and the local coordinate with it)
REFERENCE_DIGITS = 20

# -- runtime forms (the tape's instruction parameters) -------------------------------
def _columns(arrays: Sequence[Any]) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """The broadcast shape of the arguments and each flattened to it."""
    shape = np.broadcast_shapes(*(np.shape(a) for a in arrays))
    return shape, [np.broadcast_to(a, shape).reshape(-1) for a in arrays]


class _Compiled:
    """A sweep's expression parameter ``(expr, ...)`` with the model's tape
    compiled once; the tape interns it by :meth:`key`.

    Every evaluating method takes ``run``, the evaluator of its domain
    (``evaluate_points``, ``evaluate_intervals``, ``evaluate_gradients``,
    ``evaluate_interval_gradients``, or the mpmath ``mp_evaluate``).
    """

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

    def point(self, args: tuple, run: Callable) -> np.ndarray:
        shape, cols = _columns(args)
        local = [c if self.spacing[a] is None else c - self._index(a, c) * self.spacing[a]
                 for a, c in enumerate(cols)]
        return run(self.tape, *local).reshape(shape)

    def derivative(self, v: tuple, g: tuple, out: np.ndarray, run: Callable) -> np.ndarray:
        cols = [np.asarray(a, dtype=np.float64).reshape(-1) for a in np.broadcast_arrays(*v)]
        local = [c if self.spacing[a] is None else c - self._index(a, c) * self.spacing[a]
                 for a, c in enumerate(cols)]
        _, child = run(self.tape, *local)
        return sum(child[a] * g[a] for a in range(3))

    def _pieces(self, axis: int, lo: np.ndarray, hi: np.ndarray):
        """Two local intervals per box on a replicated axis, and whether the
        box spans more than one instance."""
        s = self.spacing[axis]
        k0 = self._index(axis, lo, -1e-12)
        k1 = self._index(axis, hi, 1e-12)
        half = 0.5 * s
        a_lo = rounding.down(lo - rounding.up(k0 * s))
        b_hi = rounding.up(hi - rounding.down(k1 * s))
        a_lo = np.where(k0 * s == 0.0, lo, a_lo)  # instance 0: the local frame is the box
        b_hi = np.where(k1 * s == 0.0, hi, b_hi)
        same = k1 == k0
        a_hi = np.where(same, b_hi, np.maximum(half, a_lo))
        b_lo = np.where(same, a_lo, np.minimum(-half, b_hi))
        b_hi = np.where(same | (k1 == k0 + 1), b_hi, np.maximum(half, b_hi))
        return (a_lo, a_hi), (b_lo, b_hi), ~same

    def interval(self, los: tuple, his: tuple, run: Callable):
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
                    clo, chi = run(self.tape, (px[0], py[0], pz[0]), (px[1], py[1], pz[1]))
                    flo, fhi = np.minimum(flo, clo), np.maximum(fhi, chi)
        empty = flo > fhi  # every piece undefined
        flo, fhi = np.where(empty, 0.0, flo), np.where(empty, 0.0, fhi)
        return flo.reshape(shape), fhi.reshape(shape), empty.reshape(shape)

    def interval_derivative(self, v: tuple, g: tuple, out: tuple, run: Callable):
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
        _, _, clo, chi, valid = run(self.tape, local_lo, local_hi)
        glo, ghi = kernels.i_mul(clo[0], chi[0], *g[0])
        for a in (1, 2):
            glo, ghi = kernels.i_add(glo, ghi, *kernels.i_mul(clo[a], chi[a], *g[a]))
        return (glo, ghi), spans | ~valid  # a box over two instances may jump

    def reference(self, args: list, run: Callable):
        import mpmath
        local = []
        for a, t in enumerate(args):
            s, n = self.spacing[a], self.count[a]
            if s is None:
                local.append(t)
                continue
            u = t / mpmath.mpf(s)
            if abs(u) > mpmath.mpf(10) ** (mpmath.mp.dps - REFERENCE_DIGITS):
                return None     # the local coordinate is beyond the working precision
            k = mpmath.floor(u + mpmath.mpf(0.5))
            if n is not None:
                k = min(max(k, 0), n - 1)
            local.append(t - k * mpmath.mpf(s))
        return run(self.expr, local, mpmath.mp.dps)


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
        iu, iv, iw = FRAMES[self.axis]
        return cols[iu], cols[iv], cols[iw]

    def _xyz(self, u, v, w):
        iu, iv, iw = FRAMES[self.axis]
        out = [None, None, None]
        out[iu], out[iv], out[iw] = u, v, w
        return out

    def _turn(self, u, v):
        k = np.floor(np.arctan2(v, u) / self.step + 0.5)
        c, s = np.cos(k * self.step), np.sin(k * self.step)
        return u * c + v * s, v * c - u * s, c, s

    def point(self, args: tuple, run: Callable) -> np.ndarray:
        shape, cols = _columns(args)
        u, v, w = self._uvw(cols)
        lu, lv, _, _ = self._turn(u, v)
        return run(self.tape, *self._xyz(lu, lv, w)).reshape(shape)

    def derivative(self, vals: tuple, g: tuple, out: np.ndarray, run: Callable) -> np.ndarray:
        cols = [np.asarray(a, dtype=np.float64).reshape(-1) for a in np.broadcast_arrays(*vals)]
        u, v, w = self._uvw(cols)
        lu, lv, c, s = self._turn(u, v)
        _, child = run(self.tape, *self._xyz(lu, lv, w))
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
        ulps = 2 * rounding.TRANSCENDENTAL_ULPS
        clo, chi = rounding.down(c, ulps) - slack, rounding.up(c, ulps) + slack
        slo, shi = rounding.down(s, ulps) - slack, rounding.up(s, ulps) + slack
        lu = kernels.i_add(*kernels.i_mul(ulo, uhi, clo, chi), *kernels.i_mul(vlo, vhi, slo, shi))
        lv = kernels.i_sub(*kernels.i_mul(vlo, vhi, clo, chi), *kernels.i_mul(ulo, uhi, slo, shi))
        return lu, lv

    def _sector_box(self, ulo, uhi, vlo, vhi):
        """Bounding box of the fundamental sector between the box's radii."""
        rlo, rhi = kernels.i_hypot(ulo, uhi, vlo, vhi)
        half = self.step / 2
        if half >= np.pi / 2:  # n <= 2: a half plane or the whole plane
            ulo_s = -rhi if half > np.pi / 2 else np.zeros_like(rhi)
            return (ulo_s, rhi), (-rhi, rhi)
        c, s = rounding.down(np.cos(half), 8), rounding.up(np.sin(half), 8)
        reach = rounding.up_nonneg(rhi * s)
        return (rounding.down_nonneg(rlo * c), rhi), (-reach, reach)

    def interval(self, los: tuple, his: tuple, run: Callable):
        shape, cols = _columns(los + his)
        lo, hi = cols[:3], cols[3:]
        (ulo, vlo, wlo), (uhi, vhi, whi) = self._uvw(lo), self._uvw(hi)
        alo, ahi, whole = kernels.angle_interval(vlo, vhi, ulo, uhi)
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
            clo, chi = run(self.tape, tuple(xyz_lo), tuple(xyz_hi))
            flo, fhi = np.minimum(flo, clo), np.maximum(fhi, chi)
        empty = flo > fhi
        flo, fhi = np.where(empty, 0.0, flo), np.where(empty, 0.0, fhi)
        return flo.reshape(shape), fhi.reshape(shape), empty.reshape(shape)

    def interval_derivative(self, v: tuple, g: tuple, out: tuple, run: Callable):
        shape = np.broadcast_shapes(*(np.shape(a[0]) for a in v))
        n = int(np.prod(shape)) if shape else 1
        inf = np.full((3, n), np.inf)
        return (-inf, inf), np.ones(n, dtype=bool)  # the mean value form is not used here

    def reference(self, args: list, run: Callable):
        import mpmath
        iu, iv, iw = FRAMES[self.axis]
        u, v, w = args[iu], args[iv], args[iw]
        angle = mpmath.mpf(0) if u == 0 and v == 0 else mpmath.atan2(v, u)
        step = 2 * mpmath.pi / self.n
        k = mpmath.floor(angle / step + mpmath.mpf(0.5))
        c, s = mpmath.cos(k * step), mpmath.sin(k * step)
        local = [None, None, None]
        local[iu], local[iv], local[iw] = u * c + v * s, v * c - u * s, w
        return run(self.expr, local, mpmath.mp.dps)


def compile_oracle(op: str, param: Any, build_tape: Callable[[Expr], Any]) -> _Compiled:
    """The oracle of a ``repeat``/``repeat_polar`` node's parameter, its child
    compiled by ``build_tape``; a compiled one passes through."""
    if isinstance(param, (Sweep, PolarSweep)):
        return param
    return (Sweep if op == "repeat" else PolarSweep)(*param, build_tape(param[0]))
