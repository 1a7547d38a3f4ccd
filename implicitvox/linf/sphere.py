"""Max-norm distance to a sphere, by solving for the contact (Varadhan §3.2).

Outside, the box ``B(p, t) = p + t [-w, w]`` first touches the ball when the
Euclidean distance from the centre to the box reaches ``r``:
``sum_i max(a_i - t w_i, 0)^2 = r^2`` with ``a = |p - c|``. Between the
breakpoints ``t = a_i / w_i`` the active axes are fixed and the equation is a
quadratic (a face, edge or vertex contact of the box). Inside, the box first
leaves the ball at its farthest corner: ``sum_i (a_i + t w_i)^2 = r^2``.

Examples
--------
>>> import numpy as np
>>> Sphere((0, 0, 0), 1.0).distance(np.array([[2.0, 0, 0], [0, 0, 0], [1.0, 1.0, 1.0]])).round(6).tolist()
[1.0, -0.57735, 0.42265]
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .. import expr as ex

from .box_tests import Primitive
from .norm import as_points, as_weights

__all__ = ["Sphere"]


def _smaller_root(A, B, C):
    """Smaller root of ``A t^2 - 2 B t + C = 0`` (stable form), NaN if none."""
    disc = B * B - A * C
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.sqrt(disc)
        return np.where(B > 0, C / (B + s), (B - s) / A)


class Sphere(Primitive):
    """Sphere with ``center`` and radius ``r`` (negative distances inside)."""

    def __init__(self, center: Any, r: float):
        self.center = np.asarray(center, dtype=np.float64).reshape(3)
        self.r = float(r)
        if not self.r > 0:
            raise ValueError(f"r must be positive, got {r!r}")

    @property
    def expr(self) -> ex.Expr:
        cx, cy, cz = self.center
        return ex.sqrt((ex.x - cx) ** 2 + (ex.y - cy) ** 2 + (ex.z - cz) ** 2) - self.r

    @property
    def bounds(self):
        return tuple((self.center - self.r).tolist()), tuple((self.center + self.r).tolist())

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Signed Euclidean distance ``|p - c| - r`` (Bærentzen eq. 5)."""
        return np.linalg.norm(as_points(points) - self.center, axis=1) - self.r

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        p = as_points(points)
        w = as_weights(weights, len(p))
        a = np.abs(p - self.center)
        r2 = self.r * self.r
        norm2 = np.einsum("ij,ij->i", a, a)
        out = np.empty(len(p))
        inside = norm2 < r2
        # inside: the farthest corner reaches the sphere
        ai, wi = a[inside], w[inside]
        A = np.einsum("ij,ij->i", wi, wi)
        B = -np.einsum("ij,ij->i", ai, wi)
        C = np.einsum("ij,ij->i", ai, ai) - r2
        disc = np.sqrt(np.maximum(B * B - A * C, 0))
        out[inside] = C / (disc - B)            # = -(B + disc) / A, without cancellation
        # outside: the nearest face, edge or vertex contact
        ao, wo = a[~inside], w[~inside]
        t_break = np.sort(ao / wo, axis=1)
        order = np.argsort(ao / wo, axis=1)
        best = np.full(len(ao), np.nan)
        lower = np.zeros(len(ao))
        for k in range(3):                      # active axes: those with a break above t
            upper = t_break[:, k]
            act = np.zeros_like(ao, dtype=bool)
            np.put_along_axis(act, order[:, k:], True, axis=1)
            aa, ww = np.where(act, ao, 0.0), np.where(act, wo, 0.0)
            A = np.einsum("ij,ij->i", ww, ww)
            B = np.einsum("ij,ij->i", aa, ww)
            C = np.einsum("ij,ij->i", aa, aa) - r2
            t = _smaller_root(A, B, C)
            ok = np.isnan(best) & (t >= lower - 1e-12 * (1 + upper)) & \
                (t <= upper + 1e-12 * (1 + upper))
            best = np.where(ok, np.clip(t, lower, upper), best)
            lower = upper
        out[~inside] = np.maximum(best, 0.0)
        return out

