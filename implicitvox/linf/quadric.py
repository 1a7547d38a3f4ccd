"""Max-norm distance to a general quadric surface, by contact equations (Varadhan §3.2).

The solid is ``{x : x^T A x + b.x + c <= 0}`` for any symmetric ``A`` -
ellipsoids, hyperboloids of one or two sheets, paraboloids, cones, cylinders,
pairs of planes - in any position (:meth:`Quadric.from_local` moves one).
Around a point ``p`` write ``q = p + y``: ``Q(p + y) = y^T A y + g.y + Q(p)``
with ``g = 2 A p + b``. The growing box ``B(p, t) = p + t [-w, w]`` first
touches the surface ``Q = 0`` with

* a vertex: ``y = t (s * w)`` for signs ``s``: a quadratic in ``t``;
* an edge along ``e_k`` (``y_i = t s_i w_i``, ``y_j = t s_j w_j``,
  ``y_k = tau``), tangent to the surface: ``dQ/dy_k = 0`` is linear, so
  ``tau = alpha + beta t``, and ``Q = 0`` a quadratic in ``t``; valid if
  ``|tau| <= t w_k``. With ``A_kk = 0``, ``Q`` does not depend on ``tau``
  along a tangent edge, whose vertices then touch at the same time;
* a face ``y_i = t s_i w_i``, tangent: ``dQ/dy_j = dQ/dy_k = 0`` is a 2 x 2
  linear system, so the touching point moves linearly with ``t`` and
  ``Q = 0`` is a quadratic in ``t``; valid if the point is on the face. A
  singular system (the face touches along a line) is met by an edge first
  or at the same time.

The distance is the least valid contact time, whatever the side: every valid
time is a time when the box holds a surface point, and the first is one of
them. Negative inside (``Q(p) < 0``).

Examples
--------
>>> import numpy as np
>>> cone = Quadric(np.diag([1.0, 1.0, -1.0]), np.zeros(3), 0.0)   # x^2 + y^2 <= z^2
>>> cone.distance(np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 2.0]])).round(12).tolist()
[1.0, -0.828427124746]
"""
from __future__ import annotations

from typing import Any

import numpy as np

import implicitvox as iv

from .norm import as_points, as_weights

__all__ = ["Quadric"]

_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)],
                  dtype=np.float64)
_TOL = 1e-12


def _smallest_root(a, b, c):
    """Least root ``t >= 0`` of ``a t^2 + b t + c`` (inf if none), stable in every regime."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        disc = b * b - 4 * a * c
        s = np.sqrt(disc)
        q = -0.5 * (b + np.copysign(s, b))
        r1, r2 = q / a, c / q
        linear = -c / b
    quad = (a != 0) & (disc >= 0)
    cands = [np.where(quad, r1, np.nan), np.where(quad, r2, np.nan),
             np.where((a == 0) & (b != 0), linear, np.nan),
             np.where((a == 0) & (b == 0) & (c == 0), 0.0, np.nan)]
    best = np.full(np.shape(a), np.inf)
    for r in cands:
        best = np.fmin(best, np.where(r >= 0, r, np.inf))
    return best


class Quadric:
    """The solid ``x^T A x + b.x + c <= 0`` (``A`` symmetric 3 x 3)."""

    def __init__(self, A: Any, b: Any, c: float):
        A = np.asarray(A, dtype=np.float64)
        b = np.asarray(b, dtype=np.float64).reshape(-1)
        if A.shape != (3, 3) or not np.all(np.isfinite(A)):
            raise ValueError(f"A must be a finite 3 x 3 matrix, got shape {A.shape}")
        if not np.allclose(A, A.T, rtol=0, atol=1e-12 * (1 + np.abs(A).max())):
            raise ValueError("A must be symmetric")
        if b.shape != (3,) or not np.all(np.isfinite(b)) or not np.isfinite(c):
            raise ValueError("b must be 3 finite numbers and c finite")
        if not np.any(A) and not np.any(b):
            raise ValueError("A and b are both zero: no surface")
        self.A, self.b, self.c = 0.5 * (A + A.T), b, float(c)

    @classmethod
    def from_local(cls, A: Any, b: Any, c: float, rotation: Any = None,
                   translation: Any = (0, 0, 0)) -> "Quadric":
        """The quadric ``y^T A y + b.y + c <= 0`` of local coordinates ``y`` placed at
        ``x = rotation @ y + translation`` (a rigid motion)."""
        Rm = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
        if Rm.shape != (3, 3) or not np.allclose(Rm.T @ Rm, np.eye(3), atol=1e-12):
            raise ValueError("rotation must be an orthonormal 3 x 3 matrix")
        t = np.asarray(translation, dtype=np.float64).reshape(3)
        A, b = np.asarray(A, dtype=np.float64), np.asarray(b, dtype=np.float64)
        Aw = Rm @ A @ Rm.T
        bw = Rm @ b - 2 * Aw @ t
        cw = float(t @ Aw @ t - b @ (Rm.T @ t) + c)
        return cls(Aw, bw, cw)

    def value(self, points: Any) -> np.ndarray:
        p = np.asarray(points, dtype=np.float64)
        return np.einsum("ni,ij,nj->n", p, self.A, p) + p @ self.b + self.c

    @property
    def expr(self) -> iv.Expr:
        v = (iv.x, iv.y, iv.z)
        total = iv.constant(self.c)
        for i in range(3):
            if self.b[i]:
                total = total + float(self.b[i]) * v[i]
            if self.A[i, i]:
                total = total + float(self.A[i, i]) * iv.square(v[i])
            for j in range(i + 1, 3):
                if self.A[i, j]:
                    total = total + float(2 * self.A[i, j]) * v[i] * v[j]
        return total

    bounds = None

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        p = as_points(points)
        w = as_weights(weights, len(p))
        A = self.A
        q0 = self.value(p)
        g = 2 * p @ A + self.b
        best = np.where(q0 == 0, 0.0, np.inf)
        for s in _SIGNS[:4]:                                   # vertices: a line, both ways
            d = s * w
            a2 = np.einsum("ni,ij,nj->n", d, A, d)
            a1 = np.sum(g * d, axis=1)
            best = np.fmin(best, _smallest_root(a2, a1, q0))
            best = np.fmin(best, _smallest_root(a2, -a1, q0))
        for k in range(3):                                     # edges along e_k
            i, j = [a for a in range(3) if a != k]
            if abs(A[k, k]) <= _TOL * (1 + np.abs(A).max()):
                continue
            for si in (-1.0, 1.0):
                for sj in (-1.0, 1.0):
                    best = np.fmin(best, self._edge(p, w, g, q0, i, j, k, si, sj))
        for i in range(3):                                     # faces across e_i
            j, k = [a for a in range(3) if a != i]
            M = A[np.ix_([j, k], [j, k])]
            if abs(np.linalg.det(M)) <= _TOL * (1 + np.abs(M).max()) ** 2:
                continue
            for si in (-1.0, 1.0):
                best = np.fmin(best, self._face(p, w, g, q0, i, j, k, si, np.linalg.inv(M)))
        return np.where(q0 < 0, -best, best)

    def _contact(self, w, g, q0, y0, y1, check):
        """Least ``t >= 0`` with ``Q(p + y0 + t y1) = 0`` whose point passes ``check``."""
        A = self.A
        a2 = np.einsum("ni,ij,nj->n", y1, A, y1)
        a1 = 2 * np.einsum("ni,ij,nj->n", y0, A, y1) + np.sum(g * y1, axis=1)
        a0 = np.einsum("ni,ij,nj->n", y0, A, y0) + np.sum(g * y0, axis=1) + q0
        best = np.full(len(q0), np.inf)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            disc = a1 * a1 - 4 * a2 * a0
            s = np.sqrt(disc)
            qq = -0.5 * (a1 + np.copysign(s, a1))
            roots = [qq / a2, a0 / qq, np.where(a2 == 0, -a0 / a1, np.nan)]
        for t in roots:
            t = np.where(np.isfinite(t) & (t >= 0), t, np.nan)
            y = y0 + np.nan_to_num(t)[:, None] * y1
            ok = ~np.isnan(t) & check(y, np.nan_to_num(t))
            best = np.fmin(best, np.where(ok, t, np.inf))
        return best

    def _edge(self, p, w, g, q0, i, j, k, si, sj):
        A = self.A
        n = len(p)
        # dQ/dy_k = 2 (A y)_k + g_k = 0  ->  y_k = alpha + beta t
        y0, y1 = np.zeros((n, 3)), np.zeros((n, 3))
        y1[:, i], y1[:, j] = si * w[:, i], sj * w[:, j]
        y0[:, k] = -g[:, k] / (2 * A[k, k])
        y1[:, k] = -(A[k, i] * y1[:, i] + A[k, j] * y1[:, j]) / A[k, k]

        def on_edge(y, t):
            return np.abs(y[:, k]) <= t * w[:, k] * (1 + _TOL) + _TOL * np.abs(y[:, k])
        return self._contact(w, g, q0, y0, y1, on_edge)

    def _face(self, p, w, g, q0, i, j, k, si, Minv):
        A = self.A
        n = len(p)
        # (dQ/dy_j, dQ/dy_k) = 0 with y_i = t s_i w_i: (y_j, y_k) = alpha + beta t
        y0, y1 = np.zeros((n, 3)), np.zeros((n, 3))
        y1[:, i] = si * w[:, i]
        rhs0 = -0.5 * g[:, [j, k]]
        rhs1 = -np.outer(y1[:, i], A[[j, k], i])
        y0[:, [j, k]] = rhs0 @ Minv.T
        y1[:, [j, k]] = rhs1 @ Minv.T

        def on_face(y, t):
            return np.all(np.abs(y[:, [j, k]]) <= (t[:, None] * w[:, [j, k]]) * (1 + _TOL)
                          + _TOL * np.abs(y[:, [j, k]]), axis=1)
        return self._contact(w, g, q0, y0, y1, on_face)

    def classify_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        from .classify import classify_by_distance
        return classify_by_distance(self.distance, lo, hi)
