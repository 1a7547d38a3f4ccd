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

from .. import expr as ex

from .box_tests import Primitive
from .norm import as_points, as_weights
from .products import dot

__all__ = ["Ellipsoid", "quadratic_roots"]

#: the 8 corner rays as 4 lines through p: directions (sx, sy, 1) * w
_LINE_SIGNS = [(sx, sy) for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)]
_EDGES = [(i, j, k) for k, (i, j) in enumerate([(1, 2), (2, 0), (0, 1)])]


def quadratic_roots(A, B, C):
    """Roots ``t1 <= t2`` of ``A t^2 + 2 B t + C = 0`` (A > 0), stable; NaN if none."""
    disc = B * B - A * C
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.sqrt(disc)
        q = -(B + np.copysign(s, B))          # no cancellation
        r1, r2 = q / A, C / q
    return np.minimum(r1, r2), np.maximum(r1, r2)


class Ellipsoid(Primitive):
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
    def expr(self) -> ex.Expr:
        u = [ex.x - self.center[0], ex.y - self.center[1], ex.z - self.center[2]]
        local = [sum(float(self.rotation[r, a]) * u[r] for r in range(3)) / self.radii[a]
                 for a in range(3)]
        k = float(self.radii.min())
        return k * (ex.sqrt(local[0] ** 2 + local[1] ** 2 + local[2] ** 2) - 1)

    @property
    def bounds(self):
        half = np.sqrt(np.diag(self.Qinv))
        return tuple((self.center - half).tolist()), tuple((self.center + half).tolist())

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Signed Euclidean distance (Eberly, *Distance from a Point to an Ellipse, an
        Ellipsoid, or a Hyperellipsoid*, 2013). In the ellipsoid's frame, with ``y`` the
        point's absolute coordinates and ``e`` the semi-axes, the nearest point is
        ``x_i = e_i² y_i / (t + e_i²)`` for the root ``t > -e_min²`` of the decreasing
        ``F(t) = Σ (e_i y_i / (t + e_i²))² - 1``, found by bisection to the last float.
        Where ``y`` vanishes along the shortest axes and ``F`` stays negative there, the
        nearest point leaves that plane (a point on the medial disc): the other
        coordinates take ``t = -e_min²`` and the shortest axes the rest of the unit
        norm. Both candidates are points of the surface (the first is kept only where
        it is one to 1e-9, which rounding near the disc can spoil), so the nearer of
        them is the distance."""
        p = as_points(points)
        y = np.abs(dot(p - self.center, self.rotation))            # local, first octant
        e = self.radii
        e2 = e * e
        inside = np.sum((y / e) ** 2, axis=1) < 1.0
        lo = np.full(len(p), -float(e2.min()))
        hi = float(e.max()) * np.linalg.norm(y, axis=1)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                F = np.sum((e * y / (mid[:, None] + e2)) ** 2, axis=1) - 1.0
                done = (mid <= lo) | (mid >= hi)
                lo = np.where(done | (F <= 0), lo, mid)
                hi = np.where(done | (F > 0), hi, mid)
                if done.all():
                    break
            t = 0.5 * (lo + hi)
            x = e2 * y / (t[:, None] + e2)
            # a candidate only where it is on the surface (not where t + e² rounded away)
            on = np.all(np.isfinite(x), axis=1) & \
                (np.abs(np.sum((x / e) ** 2, axis=1) - 1.0) <= 1e-9)
            regular = np.where(on, np.linalg.norm(np.where(on[:, None], x, 0.0) - y, axis=1),
                               np.inf)
            # the medial-disc candidate: t = -e_min² for the other axes, the rest of the
            # unit norm along the shortest ones (parallel to the point's own component)
            short = e == e.min()
            others = ~short
            xo = e2[others] * y[:, others] / (e2[others] - e2.min())
            rest = 1.0 - np.sum((xo / e[others]) ** 2, axis=1)
            along = np.linalg.norm(y[:, short], axis=1)
            off = np.sqrt(np.sum((xo - y[:, others]) ** 2, axis=1)
                          + (e.min() * np.sqrt(np.maximum(rest, 0.0)) - along) ** 2)
            medial = np.where(rest >= 0, off, np.inf)
        d = np.fmin(regular, medial)
        return np.where(inside, -d, d)

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        p = as_points(points)
        w = as_weights(weights, len(p))
        y = np.ascontiguousarray((p - self.center).T)         # columns: fast row sums
        w = np.ascontiguousarray(w.T)
        Qy = dot(self.Q, y)                                   # Q y, no BLAS
        level = y[0] * Qy[0] + y[1] * Qy[1] + y[2] * Qy[2]
        C = level - 1.0
        # Vertex contacts (outside) and corner exits (inside), 8 rays as 4 lines
        # through p: on the line p + t d both meet-times come from one quadratic.
        best = self._vertex_times(w, Qy, C)
        outside = C > 0
        if np.any(outside):
            sub = np.flatnonzero(outside)
            gap = np.fmin(best[sub], self._edge_and_face_times(y[:, sub], w[:, sub]))
            best[sub] = gap
        return np.where(outside, best, -best)

    def _vertex_times(self, w, Qy, C):
        """Per point, the least time at which a corner ray of the growing box meets the
        boundary: ``|C| / (|B| + sqrt(B^2 - A C))`` per line (both roots at once: the
        ray moving towards E enters at it when outside; the nearer exit when inside)."""
        Q = self.Q
        w2 = w * w
        diag = Q[0, 0] * w2[0] + Q[1, 1] * w2[1] + Q[2, 2] * w2[2]
        c01, c02, c12 = (2 * Q[0, 1] * w[0] * w[1], 2 * Q[0, 2] * w[0] * w[2],
                         2 * Q[1, 2] * w[1] * w[2])
        wq = w * Qy
        best = np.full(C.shape, np.inf)
        with np.errstate(invalid="ignore", divide="ignore"):
            for sx, sy in _LINE_SIGNS:
                A = diag + (sx * sy) * c01 + sx * c02 + sy * c12
                B = np.abs(sx * wq[0] + sy * wq[1] + wq[2])
                t = np.abs(C) / (B + np.sqrt(B * B - A * C))
                best = np.fmin(best, t)
        return best

    def _edge_and_face_times(self, y, w):
        Q = self.Q
        best = np.full(y.shape[1], np.inf)
        with np.errstate(invalid="ignore", divide="ignore"):
            for i, j, k in _EDGES:                              # edge contacts
                P = Q[np.ix_([i, j], [i, j])] - np.outer(Q[[i, j], k], Q[k, [i, j]]) / Q[k, k]
                yi, yj = y[i], y[j]
                Pz_i, Pz_j = P[0, 0] * yi + P[0, 1] * yj, P[1, 0] * yi + P[1, 1] * yj
                C = yi * Pz_i + yj * Pz_j - 1.0             # the same for the 4 parallel edges
                wi, wj = w[i], w[j]
                base = P[0, 0] * wi * wi + P[1, 1] * wj * wj
                cross = 2.0 * P[0, 1] * wi * wj
                gi, gj = Pz_i * wi, Pz_j * wj
                for sj in (1.0, -1.0):                      # the edge pairs (s, -s) share a line
                    A = base + sj * cross
                    B = gi + sj * gj
                    t = C / (np.abs(B) + np.sqrt(B * B - A * C))
                    toward = -np.sign(B)                    # the direction that approaches
                    zi, zj = yi + t * toward * wi, yj + t * (toward * sj) * wj
                    yk = -(zi * Q[i, k] + zj * Q[j, k]) / Q[k, k]
                    ok = (C > 0) & (np.abs(yk - y[k]) <= t * w[k] * (1 + 1e-12) + 1e-300)
                    best = np.fmin(best, np.where(ok, t, np.inf))
            half = np.sqrt(np.diag(self.Qinv))
            for i in range(3):                                  # face contacts
                others = [a for a in range(3) if a != i]
                for sigma in (-1.0, 1.0):
                    # the face with outward normal sigma e_i meets E's point extreme in -sigma e_i
                    x_star = -sigma * self.Qinv[:, i] / half[i]
                    t = sigma * (x_star[i] - y[i]) / w[i]
                    slack = t * (1 + 1e-12)
                    ok = ((t >= 0) & (np.abs(x_star[others[0]] - y[others[0]])
                                      <= slack * w[others[0]])
                          & (np.abs(x_star[others[1]] - y[others[1]]) <= slack * w[others[1]]))
                    best = np.fmin(best, np.where(ok, t, np.inf))
        return best

