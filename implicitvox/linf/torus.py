"""Max-norm distance to a torus (Varadhan §3.2): exact, in any orientation.

A torus in general orientation (a ring torus, ``R > r``) is solved by its
contact equations in :mod:`implicitvox.linf.torus_frame`. When its axis is
parallel to a coordinate axis a simpler exact method applies, described here.

Varadhan et al. reduce the torus to polynomials of degree 8 "through
symmetry". When the torus axis is parallel to a coordinate axis the symmetry
goes further: in cylindrical coordinates about that axis ``(rho, z)`` the
growing box ``B(p, t) = p + t [-w, w]`` (axis-aligned) is a product of a
rectangle across the axis and an interval along it, so its image is the
rectangle ``[rho_min(t), rho_max(t)] x [z_lo(t), z_hi(t)]`` (the nearest and
farthest distances of the cross rectangle from the axis, and the box's range
along it), and the solid torus is the disk of radius ``r`` about ``(R, 0)``.
Hence, exactly:

* outside, ``B`` meets the torus iff the rectangle meets the disk: the
  distance from ``(R, 0)`` to the rectangle is at most ``r``;
* inside, ``B`` lies in the torus iff the rectangle does: its corner
  farthest from ``(R, 0)`` is within ``r``.

Both tests are monotone in ``t``, so the distance is the root of a monotone
function of one variable: bisection on the bit patterns of ``t`` finds it to
the last float in at most 64 steps, for every point at once, with no
polynomial to get wrong and no root to lose.

Examples
--------
>>> import numpy as np
>>> t = Torus((0, 0, 0), "z", R=1.0, r=0.25)
>>> t.distance(np.array([[2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])).round(12).tolist()
[0.75, -0.170492908303, 0.530330085890]
>>> tilted = Torus((0, 0, 0), (1.0, 1.0, 0.0), R=1.0, r=0.25)
>>> float(tilted.distance(np.array([[0.0, 0.0, 2.0]]))[0])
0.75
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .. import expr as ex

from .box_tests import Primitive
from .euclidean import meridian
from .norm import as_points, as_weights, float_bisection, in_blocks
from .torus_frame import TorusFrame

__all__ = ["Torus"]

_AXES = {"x": 0, "y": 1, "z": 2}


def _unit_axis(axis: Any) -> np.ndarray:
    """The axis as a unit vector (``'x'``, ``'y'``, ``'z'`` or any non-zero 3-vector)."""
    if isinstance(axis, str):
        if axis in _AXES:
            return np.eye(3)[_AXES[axis]]
        raise ValueError(f"axis must be 'x', 'y', 'z' or a non-zero 3-vector, got {axis!r}")
    a = np.asarray(axis, dtype=np.float64).reshape(-1)
    if a.shape == (3,) and np.all(np.isfinite(a)) and np.linalg.norm(a) > 0:
        return a / np.linalg.norm(a)
    raise ValueError(f"axis must be 'x', 'y', 'z' or a non-zero 3-vector, got {axis!r}")


def _aligned_index(a: np.ndarray):
    """The coordinate axis ``a`` is parallel to (within 1e-12), or None."""
    k = int(np.argmax(np.abs(a)))
    return k if np.allclose(np.abs(a), np.eye(3)[k], rtol=0, atol=1e-12) else None


class Torus(Primitive):
    """Torus with ``center``, ``axis`` (``'x'``, ``'y'``, ``'z'`` or any non-zero vector),
    major radius ``R`` (centre to tube centre) and minor radius ``r`` (the tube's).

    Off the coordinate axes the torus must be a ring torus (``R > r``): the
    contact equations need its smooth surface."""

    #: points per block in general orientation (bounded temporaries)
    BLOCK = 2048

    def __init__(self, center: Any, axis: Any, R: float, r: float):
        self.center = np.asarray(center, dtype=np.float64).reshape(3)
        if not np.all(np.isfinite(self.center)):
            raise ValueError(f"center must be finite, got {self.center.tolist()}")
        self.unit_axis = _unit_axis(axis)
        self.R, self.r = float(R), float(r)
        if not (np.isfinite(self.R) and np.isfinite(self.r) and self.R > 0 and self.r > 0):
            raise ValueError(f"R and r must be positive and finite, got R={R!r}, r={r!r}")
        #: the coordinate axis the torus axis is parallel to, or None (general orientation)
        self.axis = _aligned_index(self.unit_axis)
        if self.axis is None:
            if not self.R > self.r:
                raise ValueError(f"a torus off the coordinate axes must be a ring torus "
                                 f"(R > r), got R={R!r}, r={r!r}")
            self.frame = TorusFrame(self.center, self.unit_axis, self.R, self.r)
        else:
            #: the two axes across the torus axis, then the axis
            self.order = [a for a in range(3) if a != self.axis] + [self.axis]

    @property
    def expr(self) -> ex.Expr:
        q = [ex.x - self.center[0], ex.y - self.center[1], ex.z - self.center[2]]
        if self.axis is not None:
            u, v, w = (q[a] for a in self.order)
        else:
            u, v, w = (sum(float(e[i]) * q[i] for i in range(3))
                       for e in (self.frame.e1, self.frame.e2, self.frame.a))
        return ex.hypot(ex.hypot(u, v) - self.R, w) - self.r

    @property
    def bounds(self):
        across = np.sqrt(np.maximum(1.0 - self.unit_axis ** 2, 0.0))  # the core circle's extent
        half = self.R * across + self.r
        return tuple((self.center - half).tolist()), tuple((self.center + half).tolist())

    def distance_function(self, norm: str):
        """As :meth:`Primitive.distance_function`; a spindle torus (``R < r``) has no
        Euclidean one here (its tube surface runs through its own inside)."""
        if norm == "euclidean" and self.R < self.r:
            return None
        return super().distance_function(norm)

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Signed Euclidean distance ``hypot(rho - R, s) - r`` of a ring torus, from the
        point's meridian coordinates (:func:`implicitvox.linf.euclidean.meridian`)."""
        m = meridian(as_points(points), self.center, self.unit_axis)
        return np.hypot(m[:, 0] - self.R, m[:, 1]) - self.r

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        p = as_points(points)
        w = as_weights(weights, len(p))
        if self.axis is None:
            return in_blocks(self.frame.distance, p, w, self.BLOCK)
        q = np.abs(p - self.center)[:, self.order]          # the torus is symmetric in each
        w = w[:, self.order]
        inside = np.hypot(np.hypot(q[:, 0], q[:, 1]) - self.R, q[:, 2]) <= self.r
        out = np.empty(len(p))
        out[~inside] = self._first_time(q[~inside], w[~inside], self._meets)
        out[inside] = -self._first_time(q[inside], w[inside], self._leaves)
        return out

    # -- the two monotone tests on the (rho, z) rectangle of B(p, t) -------------------------
    def _rectangle(self, q, w, t):
        t = t[:, None]
        near = np.maximum(q[:, :2] - t * w[:, :2], 0.0)
        rho_min = np.hypot(near[:, 0], near[:, 1])
        far = q[:, :2] + t * w[:, :2]
        rho_max = np.hypot(far[:, 0], far[:, 1])
        z_near = np.maximum(q[:, 2] - t[:, 0] * w[:, 2], 0.0)
        z_far = q[:, 2] + t[:, 0] * w[:, 2]
        return rho_min, rho_max, z_near, z_far

    def _meets(self, q, w, t):
        """B(p, t) meets the solid torus: the rectangle comes within r of (R, 0)."""
        rho_min, rho_max, z_near, _ = self._rectangle(q, w, t)
        d_rho = np.maximum(np.maximum(rho_min - self.R, self.R - rho_max), 0.0)
        return np.hypot(d_rho, z_near) <= self.r

    def _leaves(self, q, w, t):
        """B(p, t) is not inside the solid torus: a corner of the rectangle is beyond r."""
        rho_min, rho_max, _, z_far = self._rectangle(q, w, t)
        d_rho = np.maximum(self.R - rho_min, rho_max - self.R)
        return np.hypot(d_rho, z_far) > self.r

    def _first_time(self, q, w, test) -> np.ndarray:
        """The least float ``t >= 0`` with ``test(t)`` (monotone: false, then true), by
        bisection on the bit patterns of non-negative floats (64 steps at most)."""
        n = len(q)
        if n == 0:
            return np.zeros(0)
        # an upper end where the test holds: a box reaching past the whole torus
        reach = (np.abs(q) + np.array([self.R + self.r, self.R + self.r, self.r])) / w
        hi = np.max(reach, axis=1) * 2.0 + 1.0
        t_lo, t_hi = float_bisection(lambda t: test(q, w, t), hi)
        # t = 0 itself may already hold (a point on the surface)
        return np.where(test(q, w, t_lo), t_lo, t_hi)

