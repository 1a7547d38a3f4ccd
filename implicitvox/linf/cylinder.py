"""Max-norm distance to a capped cylinder in any position, by contact equations (Varadhan §3.2).

The cylinder has base centre ``c``, unit axis ``a``, height ``h`` and radius
``r``: ``K = {x : 0 <= s <= h, rho <= r}`` with ``y = x - c``, ``s = y.a`` and
``rho = |y - s a|``. ``K`` is convex; the growing box ``B(p, t)`` is
axis-aligned in the world.

* Inside: the box is in ``K`` iff its 8 corners are; each corner leaves along
  its ray at ``min(slab exit, cylinder exit)`` (a linear and a quadratic
  equation).
* Outside, the first contact is one of:

  - a box vertex entering ``K`` (the ray's entry: the later of the slab and
    cylinder entries, if before both exits);
  - a box edge (a line along ``e_k``) touching the side (its trace on the
    plane of the other two axes reaches the shadow of the infinite cylinder,
    a quadratic; the touching point must lie on the edge and between the
    caps), a cap's rim (the line's crossing with the cap plane enters the cap
    disk, a quadratic), or a cap's face (a line parallel to the cap plane
    reaches it: linear; the chord must meet the edge);
  - a box face touching the support set of ``K``: a rim point, or a side
    segment (face normal across the axis), or a cap disk (face normal along
    the axis), which must meet the face.

  The distance is the smallest valid contact time.

Examples
--------
>>> import numpy as np
>>> cyl = Cylinder((0, 0, 0), (0, 0, 1), h=2.0, r=1.0)
>>> cyl.distance(np.array([[3.0, 0, 1], [0, 0, 1], [0, 0, 4]])).round(12).tolist()
[2.0, -0.707106781187, 2.0]
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .. import expr as ex

from .ellipsoid import quadratic_roots
from .box_tests import Primitive
from .euclidean import meridian, segment_distance
from .norm import as_points, as_weights
from .products import dot

__all__ = ["Cylinder", "Frustum"]

_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)],
                  dtype=np.float64)
_TOL = 1e-12


class Frustum(Primitive):
    """Capped cone or frustum: base centre, axis direction (any length), height, radius
    ``r1`` at the base and ``r2`` at the top (one of them may be 0: a cone)."""

    def __init__(self, base: Any, axis: Any, h: float, r1: float, r2: float):
        self.c = np.asarray(base, dtype=np.float64).reshape(3)
        a = np.asarray(axis, dtype=np.float64).reshape(3)
        if not np.linalg.norm(a) > 0:
            raise ValueError("axis must not be zero")
        self.a = a / np.linalg.norm(a)
        self.h, self.r1, self.r2 = float(h), float(r1), float(r2)
        if not (self.h > 0 and self.r1 >= 0 and self.r2 >= 0 and max(r1, r2) > 0):
            raise ValueError(f"h must be positive and the radii >= 0 (not both 0), got "
                             f"h={h!r}, r1={r1!r}, r2={r2!r}")
        if self.r2 == 0.0:
            # a cone is kept with its apex at the base: the quadric below is then
            # homogeneous in y = x - apex, so it keeps its precision near the apex,
            # where the terms of an off-apex origin would cancel to rounding noise
            self.c, self.a = self.c + self.h * self.a, -self.a
            self.r1, self.r2 = 0.0, self.r1
        self.k = (self.r2 - self.r1) / self.h             # radius slope along the axis
        self.r = max(self.r1, self.r2)
        self.M = np.eye(3) - np.outer(self.a, self.a)
        # rho^2 - R(s)^2 = y^T G y + 2 g.y + c0
        self.G = self.M - self.k ** 2 * np.outer(self.a, self.a)
        self.g = -self.r1 * self.k * self.a
        self.c0 = -self.r1 ** 2

    def radius(self, s: Any) -> Any:
        return self.r1 + self.k * s

    @property
    def expr(self) -> ex.Expr:
        y = [ex.x - self.c[0], ex.y - self.c[1], ex.z - self.c[2]]
        s = self.a[0] * y[0] + self.a[1] * y[1] + self.a[2] * y[2]
        perp = [y[i] - self.a[i] * s for i in range(3)]
        rho = ex.sqrt(perp[0] ** 2 + perp[1] ** 2 + perp[2] ** 2)
        side = (rho - (self.r1 + self.k * s)) / float(np.hypot(1.0, self.k))
        return ex.max(side, -s, s - self.h)

    @property
    def bounds(self):
        ends = np.array([self.c, self.c + self.h * self.a])
        ext = self.r * np.sqrt(np.maximum(1 - self.a ** 2, 0))
        return tuple((ends.min(0) - ext).tolist()), tuple((ends.max(0) + ext).tolist())

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Signed Euclidean distance: in the point's meridian half-plane the solid is
        the trapezoid ``0 <= s <= h, rho <= r1 + k s``, and the nearest surface point
        lies on its bottom, side or top segment (the axis is no boundary)."""
        m = meridian(as_points(points), self.c, self.a)
        n = len(m)
        corners = np.array([[0.0, 0.0], [self.r1, 0.0], [self.r2, self.h], [0.0, self.h]])
        d = np.min([segment_distance(m, np.broadcast_to(corners[i], (n, 2)),
                                     np.broadcast_to(corners[i + 1], (n, 2))) for i in range(3)],
                   axis=0)
        inside = (m[:, 1] >= 0) & (m[:, 1] <= self.h) & (m[:, 0] <= self.radius(m[:, 1]))
        return np.where(inside, -d, d)

    # -- pieces ----------------------------------------------------------------------------
    def _inside(self, y):
        s = dot(y, self.a)
        perp = y - s[:, None] * self.a             # |y|^2 - s^2 would cancel near the axis
        rho2 = np.sum(perp * perp, axis=1)
        return (s >= 0) & (s <= self.h) & (rho2 <= self.radius(s) ** 2)

    def _ray(self, y, d):
        """Entry and exit times of rays ``y + t d`` (NaN if they miss ``K``)."""
        s0, ds = dot(y, self.a), dot(d, self.a)
        with np.errstate(divide="ignore", invalid="ignore"):
            t_a, t_b = -s0 / ds, (self.h - s0) / ds
        slab_in = np.where(ds != 0, np.minimum(t_a, t_b), np.where((s0 >= 0) & (s0 <= self.h),
                                                                   -np.inf, np.nan))
        slab_out = np.where(ds != 0, np.maximum(t_a, t_b), np.where((s0 >= 0) & (s0 <= self.h),
                                                                    np.inf, np.nan))
        # rho^2 - R^2 <= 0 along the ray: A t^2 + 2 B t + C <= 0
        Gd = dot(d, self.G)
        A = np.sum(Gd * d, axis=1)
        B = np.sum(Gd * y, axis=1) + dot(d, self.g)
        C = np.sum(dot(y, self.G) * y, axis=1) + 2 * dot(y, self.g) + self.c0
        with np.errstate(divide="ignore", invalid="ignore"):
            t1, t2 = quadratic_roots(np.where(A != 0, A, 1.0), B, C)
            lin = -C / (2 * B)
        real = ~np.isnan(t1)
        inf = np.full_like(t1, np.inf)
        # the (at most two) intervals where the quadric is <= 0; within the slab only one
        # of them belongs to the real cone (the other nappe has R < 0)
        lo1 = np.where(A > 0, np.where(real, t1, np.nan),
                       np.where(A < 0, -inf, np.where(B > 0, -inf, np.where(
                           B < 0, lin, np.where(C <= 0, -inf, np.nan)))))
        hi1 = np.where(A > 0, np.where(real, t2, np.nan),
                       np.where(A < 0, np.where(real, t1, inf), np.where(
                           B > 0, lin, np.where(B < 0, inf, np.where(C <= 0, inf, np.nan)))))
        lo2 = np.where((A < 0) & real, t2, np.nan)
        hi2 = np.where((A < 0) & real, inf, np.nan)
        t_in = np.full_like(t1, np.nan)
        t_out = np.full_like(t1, np.nan)
        for lo_q, hi_q in ((lo1, hi1), (lo2, hi2)):
            a_in = np.maximum(slab_in, lo_q)
            a_out = np.minimum(slab_out, hi_q)
            ok = (a_in <= a_out) & np.isnan(t_in)
            t_in = np.where(ok, a_in, t_in)
            t_out = np.where(ok, a_out, t_out)
        return t_in, t_out

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        p = as_points(points)
        w = as_weights(weights, len(p))
        y = p - self.c
        inside = self._inside(y)
        out = np.empty(len(p))
        yi, wi = y[inside], w[inside]
        depth = np.full(len(yi), np.inf)
        for s in _SIGNS:
            _, t_out = self._ray(yi, s * wi)
            depth = np.fmin(depth, np.maximum(t_out, 0.0))
        out[inside] = -depth
        out[~inside] = self._gap(y[~inside], w[~inside])
        return out

    def _gap(self, y, w):
        best = np.full(len(y), np.inf)
        for s in _SIGNS:                                              # vertices
            t_in, _ = self._ray(y, s * w)
            best = np.fmin(best, np.where(t_in >= 0, t_in, np.inf))
        for k in range(3):                                            # edges along e_k
            i, j = [a for a in range(3) if a != k]
            for si in (-1.0, 1.0):
                for sj in (-1.0, 1.0):
                    best = np.fmin(best, self._edge(y, w, i, j, k, si, sj))
        for i in range(3):                                            # faces
            for sigma in (-1.0, 1.0):
                best = np.fmin(best, self._face(y, w, i, sigma))
        return best

    def _on_edge(self, yk, y, w, k, t):
        return np.abs(yk - y[:, k]) <= t * w[:, k] * (1 + _TOL) + _TOL * np.abs(yk)

    def _edge(self, y, w, i, j, k, si, sj):
        a, M, h, r = self.a, self.M, self.h, self.r1
        n = len(y)
        z0 = y[:, [i, j]]
        dz = np.stack([si * w[:, i], sj * w[:, j]], axis=1)
        best = np.full(n, np.inf)
        # the side: the line touches rho = R(s) where rho^2 - R^2, minimised along it, is 0
        G, gv, Gkk = self.G, self.g, self.G[k, k]
        if Gkk > _TOL:
            zi = [i, j]
            P = G[np.ix_(zi, zi)] - np.outer(G[zi, k], G[k, zi]) / Gkk
            lv = gv[zi] - G[zi, k] * gv[k] / Gkk
            c1 = self.c0 - gv[k] ** 2 / Gkk
            Pz0 = dot(z0, P)
            A = np.sum(dot(dz, P) * dz, axis=1)
            B = np.sum(Pz0 * dz, axis=1) + dot(dz, lv)
            C = np.sum(Pz0 * z0, axis=1) + 2 * dot(z0, lv) + c1
            # every time the line is tangent to the (double) quadric is a candidate: a
            # tangency on the real cone, at a point of the edge, is a genuine contact
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                r1, r2 = quadratic_roots(np.where(A != 0, A, 1.0), B, C)
                lin = np.where(B != 0, -C / (2 * B), np.nan)
            for t1 in (np.where(A != 0, r1, lin), np.where(A != 0, r2, np.nan)):
                t1 = np.where(t1 >= 0, t1, np.nan)
                z = z0 + t1[:, None] * dz
                yk = -(dot(z, G[zi, k]) + gv[k]) / Gkk
                full = np.empty((n, 3))
                full[:, i], full[:, j], full[:, k] = z[:, 0], z[:, 1], yk
                s = dot(full, a)
                ok = (s >= -_TOL * h) & (s <= h * (1 + _TOL)) & self._on_edge(yk, y, w, k, t1)
                best = np.fmin(best, np.where(ok, t1, np.inf))
        elif self.k != 0:
            pass        # a line steeper than the cone crosses its side: contacts are at rims
        else:
            # axis along e_k: the trace reaches the circle; the edge must overlap the slab
            A = np.sum(dz * dz, axis=1)
            B = np.sum(z0 * dz, axis=1)
            C = np.sum(z0 * z0, axis=1) - r * r
            t1, _ = quadratic_roots(A, B, C)
            t1 = np.where((C > 0) & (t1 >= 0), t1, np.nan)
            lo_k, hi_k = sorted((0.0, h * a[k]))
            ok = (y[:, k] - t1 * w[:, k] <= hi_k * (1 + _TOL) + _TOL) & \
                (y[:, k] + t1 * w[:, k] >= lo_k - _TOL * (1 + abs(lo_k)))
            best = np.fmin(best, np.where(ok, t1, np.inf))
        # the caps
        for s_cap, r in ((0.0, self.r1), (h, self.r2)):
            if r == 0:
                continue                      # an apex: met by a face or a vertex first
            if abs(a[k]) > _TOL:
                # the line crosses the cap plane at y_k = (s_cap - a_i z_i - a_j z_j) / a_k
                def point(t):
                    z = z0 + t[:, None] * dz
                    yk = (s_cap - dot(z, a[[i, j]])) / a[k]
                    return z, yk
                zc0, ykc0 = point(np.zeros(n))
                dyk = -dot(dz, a[[i, j]]) / a[k]
                q0 = np.zeros((n, 3))
                q0[:, i], q0[:, j], q0[:, k] = zc0[:, 0], zc0[:, 1], ykc0
                dq = np.zeros((n, 3))
                dq[:, i], dq[:, j], dq[:, k] = dz[:, 0], dz[:, 1], dyk
                q0p = q0 - s_cap * a                 # relative to the cap centre (in-plane)
                A = np.sum(dq * dq, axis=1)
                B = np.sum(q0p * dq, axis=1)
                C = np.sum(q0p * q0p, axis=1) - r * r
                with np.errstate(divide="ignore", invalid="ignore"):
                    t1, _ = quadratic_roots(np.where(A > 0, A, 1.0), B, C)
                t1 = np.where((A > 0) & (C > 0) & (t1 >= 0), t1, np.nan)
                _, yk = point(np.nan_to_num(t1))
                ok = self._on_edge(yk, y, w, k, t1)
                best = np.fmin(best, np.where(ok, t1, np.inf))
            else:
                # the line is parallel to the cap plane: it reaches the plane at one time
                ds = dot(dz, a[[i, j]])
                s0 = dot(z0, a[[i, j]])
                with np.errstate(divide="ignore", invalid="ignore"):
                    t1 = (s_cap - s0) / ds
                t1 = np.where((ds != 0) & (t1 >= 0), t1, np.nan)
                z = z0 + t1[:, None] * dz
                # the line's chord through the disk: its points y_k with |y - s_cap a| <= r
                q = np.zeros((n, 3))
                q[:, i], q[:, j] = z[:, 0], z[:, 1]
                qp = q - s_cap * a                   # in-plane offset, but for the k part
                # |qp + y_k e_k|^2 <= r^2, a quadratic in y_k (e_k lies in the cap plane)
                Bk, Ck = qp[:, k], np.sum(qp * qp, axis=1) - r * r
                disc = Bk * Bk - Ck
                with np.errstate(invalid="ignore"):
                    root = np.sqrt(disc)
                chord_lo, chord_hi = -Bk - root, -Bk + root
                ok = (disc >= 0) & (chord_lo <= y[:, k] + t1 * w[:, k] * (1 + _TOL)) & \
                    (chord_hi >= y[:, k] - t1 * w[:, k] * (1 + _TOL))
                best = np.fmin(best, np.where(ok, t1, np.inf))
        return best

    def _face(self, y, w, i, sigma):
        """The face with outward normal ``sigma e_i`` against K's support set there."""
        a, h = self.a, self.h
        u = np.zeros(3)
        u[i] = -sigma                                 # K's extreme point toward the box
        others = [b for b in range(3) if b != i]
        au = a @ u
        perp = u - au * a
        pn = np.linalg.norm(perp)
        # the support value of each cap's rim; equal: a side segment (a generatrix)
        v0, vh = self.r1 * pn, h * au + self.r2 * pn
        if vh > v0 + _TOL * (abs(v0) + abs(vh) + h):
            ends = [h]
        elif v0 > vh + _TOL * (abs(v0) + abs(vh) + h):
            ends = [0.0]
        else:
            ends = [0.0, h]
        if pn > _TOL:
            dirn = perp / pn
            pts = [s * a + self.radius(s) * dirn for s in ends]
            x_i = pts[0][i]
            t = sigma * (x_i - y[:, i]) / w[:, i]
            if len(pts) == 1:
                ok = (t >= 0) & np.all(np.abs(pts[0][others] - y[:, others])
                                       <= t[:, None] * w[:, others] * (1 + _TOL) + _TOL, axis=1)
            else:                                     # segment pts[0] -> pts[1] meets the face?
                lo_s, hi_s = np.zeros(len(y)), np.ones(len(y))
                d = pts[1] - pts[0]
                for b in others:
                    lo_b = y[:, b] - t * w[:, b] * (1 + _TOL) - _TOL
                    hi_b = y[:, b] + t * w[:, b] * (1 + _TOL) + _TOL
                    if abs(d[b]) > 0:
                        s1, s2 = (lo_b - pts[0][b]) / d[b], (hi_b - pts[0][b]) / d[b]
                        lo_s = np.maximum(lo_s, np.minimum(s1, s2))
                        hi_s = np.minimum(hi_s, np.maximum(s1, s2))
                    else:
                        inside = (pts[0][b] >= lo_b) & (pts[0][b] <= hi_b)
                        hi_s = np.where(inside, hi_s, -1.0)
                ok = (t >= 0) & (lo_s <= hi_s)
            return np.where(ok, t, np.inf)
        # the axis is along e_i: the support set is a cap disk in the plane x_i = const
        centre = ends[0] * a
        r = self.radius(ends[0])
        t = sigma * (centre[i] - y[:, i]) / w[:, i]
        gap = np.maximum(np.abs(centre[others] - y[:, others]) - t[:, None] * w[:, others], 0)
        ok = (t >= 0) & (np.sqrt(np.sum(gap * gap, axis=1)) <= r * (1 + _TOL))
        return np.where(ok, t, np.inf)



class Cylinder(Frustum):
    """Capped cylinder: base centre, axis direction (any length), height, radius."""

    def __init__(self, base: Any, axis: Any, h: float, r: float):
        if not float(r) > 0:
            raise ValueError(f"h and r must be positive, got h={h!r}, r={r!r}")
        super().__init__(base, axis, h, r, r)
