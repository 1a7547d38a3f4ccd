"""Max-norm distance to an ellipsoid under any rigid motion, by contact equations (Varadhan §3.2).

The ellipsoid is ``E = {x : (x - c)^T Q (x - c) <= 1}``. The growing box
``B(p, t) = p + t [-w, w]`` is axis-aligned in the world; ``Q`` carries the
rotation.

* Inside (Varadhan §3.1.1, "2^d directed distances"): ``E`` is convex, so the
  box is inside iff its 8 corners are; corner ``s`` leaves ``E`` along the ray
  ``p + t (s * w)`` at the positive root of a quadratic; the distance is
  minus the smallest of the 8.
* Outside: the box first touches ``E`` with a vertex (the same 8 rays, entry
  root), an edge (the edge's line meets ``E`` when its trace on the plane of
  the other two axes reaches the boundary of ``E``'s shadow - an ellipse, the
  Schur complement of ``Q`` - a quadratic; the contact is valid if the
  touching point lies on the edge), or a face (the support point of ``E``
  facing the face; valid if it lies on the face). The distance is the
  smallest valid contact time.

Examples
--------
>>> import numpy as np
>>> e = Ellipsoid((0, 0, 0), (2.0, 1.0, 0.5))
>>> e.distance(np.array([[3.0, 0.0, 0.0], [0.0, 0.0, 0.0]])).round(9).tolist()
[1.0, -0.43643578]
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

import implicitvox as iv

from .norm import as_points, as_weights

__all__ = ["Ellipsoid"]

_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)],
                  dtype=np.float64)
_EDGES = [(i, j, k) for k, (i, j) in enumerate([(1, 2), (2, 0), (0, 1)])]


def _roots(A, B, C):
    """Roots ``t1 <= t2`` of ``A t^2 + 2 B t + C = 0`` (A > 0), stable; NaN if none."""
    disc = B * B - A * C
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.sqrt(disc)
        q = -(B + np.copysign(s, B))          # no cancellation
        r1, r2 = q / A, C / q
    return np.minimum(r1, r2), np.maximum(r1, r2)


class Ellipsoid:
    """Ellipsoid with ``center``, semi-axes ``radii`` along the columns of ``rotation``
    (an orthonormal 3 x 3 matrix; identity by default)."""

    def __init__(self, center: Any, radii: Any, rotation: Optional[Any] = None):
        self.center = np.asarray(center, dtype=np.float64).reshape(3)
        self.radii = np.asarray(radii, dtype=np.float64).reshape(3)
        if not np.all(self.radii > 0):
            raise ValueError(f"radii must be positive, got {self.radii.tolist()}")
        R = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
        if R.shape != (3, 3) or not np.allclose(R.T @ R, np.eye(3), atol=1e-12):
            raise ValueError("rotation must be an orthonormal 3 x 3 matrix")
        self.rotation = R
        self.Q = R @ np.diag(1.0 / self.radii ** 2) @ R.T
        self.Qinv = R @ np.diag(self.radii ** 2) @ R.T

    @classmethod
    def from_affine(cls, shape: Any, center: Any) -> "Ellipsoid":
        """The image ``center + S u`` of the unit ball (``S`` any invertible 3 x 3 matrix):
        semi-axes and rotation from the eigen-decomposition of ``S S^T``."""
        S = np.asarray(shape, dtype=np.float64)
        vals, vecs = np.linalg.eigh(S @ S.T)
        if not np.all(vals > 0):
            raise ValueError("the affine map is singular")
        if np.linalg.det(vecs) < 0:
            vecs[:, 0] = -vecs[:, 0]
        return cls(center, np.sqrt(vals), vecs)

    @property
    def expr(self) -> iv.Expr:
        u = [iv.x - self.center[0], iv.y - self.center[1], iv.z - self.center[2]]
        local = [sum(float(self.rotation[r, a]) * u[r] for r in range(3)) / self.radii[a]
                 for a in range(3)]
        k = float(self.radii.min())
        return k * (iv.sqrt(local[0] ** 2 + local[1] ** 2 + local[2] ** 2) - 1)

    @property
    def bounds(self):
        half = np.sqrt(np.diag(self.Qinv))
        return tuple((self.center - half).tolist()), tuple((self.center + half).tolist())

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        p = as_points(points)
        w = as_weights(weights, len(p))
        y = p - self.center
        level = np.sum((y @ self.Q) * y, axis=1)
        out = np.empty(len(p))
        inside = level <= 1
        out[inside] = -self._depth(y[inside], w[inside], level[inside])
        out[~inside] = self._gap(y[~inside], w[~inside], level[~inside])
        return out

    def _ray(self, y, d, level, Qy=None):
        Qd = d @ self.Q
        A = np.sum(Qd * d, axis=1)
        B = np.sum(Qd * y, axis=1)
        return _roots(A, B, level - 1)

    def _depth(self, y, w, level):
        best = np.full(len(y), np.inf)
        for s in _SIGNS:
            _, t2 = self._ray(y, s * w, level)
            best = np.minimum(best, np.maximum(t2, 0.0))
        return best

    def _gap(self, y, w, level):
        best = np.full(len(y), np.inf)
        for s in _SIGNS:                                    # vertex contacts
            t1, _ = self._ray(y, s * w, level)
            best = np.fmin(best, np.where(t1 >= 0, t1, np.inf))
        Q = self.Q
        for i, j, k in _EDGES:                              # edge contacts
            P = Q[np.ix_([i, j], [i, j])] - np.outer(Q[[i, j], k], Q[k, [i, j]]) / Q[k, k]
            z0 = y[:, [i, j]]
            Pz0 = z0 @ P
            C = np.sum(Pz0 * z0, axis=1) - 1                   # the same for the 4 edges
            for si in (-1.0, 1.0):
                for sj in (-1.0, 1.0):
                    dz = np.stack([si * w[:, i], sj * w[:, j]], axis=1)
                    A = np.sum((dz @ P) * dz, axis=1)
                    B = np.sum(Pz0 * dz, axis=1)
                    t1, _ = _roots(A, B, C)
                    t1 = np.where((C > 0) & (t1 >= 0), t1, np.nan)
                    z = z0 + t1[:, None] * dz
                    yk = -(z @ Q[[i, j], k]) / Q[k, k]
                    ok = np.abs(yk - y[:, k]) <= t1 * w[:, k] * (1 + 1e-12) + 1e-300
                    best = np.fmin(best, np.where(ok, t1, np.inf))
        half = np.sqrt(np.diag(self.Qinv))
        for i in range(3):                                  # face contacts
            for sigma in (-1.0, 1.0):
                # the face with outward normal sigma e_i meets E's point extreme in -sigma e_i
                x_star = -sigma * self.Qinv[:, i] / half[i]
                t = sigma * (x_star[i] - y[:, i]) / w[:, i]
                others = [a for a in range(3) if a != i]
                ok = (t >= 0) & np.all(np.abs(x_star[others] - y[:, others])
                                       <= t[:, None] * w[:, others] * (1 + 1e-12), axis=1)
                best = np.fmin(best, np.where(ok, t, np.inf))
        return best

    def classify_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        from .classify import classify_by_distance
        return classify_by_distance(self.distance, lo, hi)
