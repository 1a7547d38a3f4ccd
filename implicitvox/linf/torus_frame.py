"""Max-norm distance to a torus in any orientation, by contact equations (Varadhan §3.2).

The torus has centre ``c``, unit axis ``a``, an orthonormal frame
``e1, e2, a`` (``e1 x e2 = a``), major radius ``R > r`` and minor radius
``r``; its points are ``s(theta, phi) = c + (R + r cos phi) u(theta) +
r sin phi a`` with ``u(theta) = cos theta e1 + sin theta e2``, and the unit
normal there is ``n = cos phi u + sin phi a``.

The weighted max-norm distance ``min_s ||p - s||_w`` is reached where the
growing box ``B(p, t) = p + t [-w, w]`` first touches the surface, in the
relative interior of a face, of an edge, or at a vertex (Varadhan §3.2). At
the touching point, by the Lagrange conditions of ``max_i |p_i - s_i| / w_i``:

* **face** (normal to ``e_k``): ``n = ±e_k`` - four fixed points per axis:
  with ``v_k`` the unit projection of ``e_k`` across the axis
  (``e_k = beta_k v_k + a_k a``), ``s = c + eps (R + eps sigma r beta_k) v_k +
  sigma r a_k a`` for ``eps, sigma = ±1``;
* **edge** (along ``e_k``): ``n_k = 0`` - the point is on the torus's
  silhouette seen along ``e_k`` - and ``s`` lies in the plane through ``p``
  that holds the edge, ``(s_i - p_i) / w_i = ±(s_j - p_j) / w_j``;
* **vertex**: ``s`` lies on one of the four lines ``p + t (±w_0, ±w_1,
  w_2)``: a quartic in ``t``.

Every candidate is a point of the surface, so the least of their distances
is never below the true one, and the true one is among them: no validity
check is needed, only that no root is lost.

The edge equations are Varadhan's degree 8 "through symmetry". Here they
are solved without the polynomial. Seen along ``e_k`` the core circle is an
ellipse ``E(theta)`` and the silhouette is its two offset curves at distance
``r``, ``X(theta) = E(theta) ± r nu(theta)`` (``nu`` the outward normal),
whose derivative is ``(1 ± r kappa(theta)) E'(theta)``. So
``g(theta) = l . (X(theta) - p)`` (``l`` the normal of the edge plane) is
monotone between the zeros of ``l . E'`` (two angles, closed form) and, for
the inner offset, of ``1 - r kappa`` (the cusps: four angles, closed form,
when ``a_k^2 <= r / R``). Each monotone arc holds at most one root, found
by safeguarded Newton steps; an arc end where ``g`` is within rounding of
zero is a candidate too, so a root beside a rounded critical angle is never
lost. When the axis lies in the plane
across ``e_k`` (``a_k = 0``) the silhouette degenerates to four circles -
the two meridian circles in that plane and the two circles ``phi = ±pi/2``
- met by the edge plane in closed form; near that case (``|a_k| < 1e-3``)
both sets are used, and below ``|a_k| = 1e-14`` the circles alone (the
offset curves' parameter then resolves nothing). Tests hold both to 1e-9
against brute force at ``a_k = 0, 1e-17, 1e-9, 3e-8``.

The torus must be a ring torus (``R > r``), whose surface is smooth.

Examples
--------
>>> import numpy as np
>>> tor = TorusFrame(np.zeros(3), np.array([1.0, 1.0, 0.0]), 1.0, 0.25)
>>> p = np.array([[0.0, 0.0, 2.0], [0.0, 0.0, 1.0]])     # above; on the core circle
>>> tor.distance(p, np.ones((2, 3))).round(12).tolist()    # -r / sqrt(3): a box corner
[0.75, -0.144337567297]
"""
from __future__ import annotations

import numpy as np

from .products import dot

__all__ = ["TorusFrame"]

_TWO_PI = 2.0 * np.pi
#: below this |a_k| the degenerate silhouette's circles are candidates too
_NEAR_PLANAR = 1e-3
#: below this |a_k| only the circles are used (the offset curves' parameter is useless)
_PLANAR = 1e-14
#: a vertex root is kept if the point is this close to the surface (relative to size)
_ON_SURFACE = 1e-12
#: rows of an arc table: b, L0, L1, L2, M1, M2, n11, n12, n22, kappa0 (the arguments of
#: ``g``), then the edge axis k and the point's index
_G_ROWS = 10


class TorusFrame:
    """The geometry of one ring torus for the max-norm distance (see the module)."""

    def __init__(self, center: np.ndarray, axis: np.ndarray, R: float, r: float):
        self.c = np.asarray(center, dtype=np.float64)
        a = np.asarray(axis, dtype=np.float64)
        self.a = a / np.linalg.norm(a)
        helper = np.eye(3)[int(np.argmin(np.abs(self.a)))]
        e1 = helper - (helper @ self.a) * self.a
        self.e1 = e1 / np.linalg.norm(e1)
        self.e2 = np.cross(self.a, self.e1)
        self.R, self.r = float(R), float(r)
        self.faces = self._face_points()
        self._geo = [self._silhouette(k) for k in range(3)]
        #: the silhouette constants stacked by axis, for per-lane lookup
        self._f1, self._f2, self._sgn = (np.array([g[c] for g in self._geo])
                                         for c in ("f1", "f2", "sgn"))
        self._cusps = [self._cusp_angles(k) for k in range(3)]

    # -- the surface ---------------------------------------------------------------------
    def u(self, theta):
        """``cos theta e1 + sin theta e2`` as ``(..., 3)``."""
        return (np.cos(theta)[..., None] * self.e1 + np.sin(theta)[..., None] * self.e2)

    def point(self, theta, phi):
        """``s(theta, phi)`` as ``(..., 3)``."""
        ring = self.R + self.r * np.cos(phi)
        return (self.c + ring[..., None] * self.u(theta)
                + (self.r * np.sin(phi))[..., None] * self.a)

    def signed_euclidean(self, y):
        """Euclidean signed distance of ``y = x - c`` (``(..., 3)``) to the surface."""
        z = dot(y, self.a)
        perp = y - z[..., None] * self.a
        rho = np.sqrt(np.einsum("...i,...i->...", perp, perp))
        return np.hypot(rho - self.R, z) - self.r

    def _face_points(self) -> np.ndarray:
        """The points whose normal is ``±e_k``: ``n = sigma e_k = sigma (beta_k u + a_k a)``
        with ``u`` the unit projection of ``e_k`` across the axis, on both sides."""
        pts = []
        for k in range(3):
            beta = np.hypot(self.e1[k], self.e2[k])
            theta = np.arctan2(self.e2[k], self.e1[k])
            for eps in (0.0, np.pi):
                for sigma in (-1.0, 1.0):
                    cos_phi = sigma * beta * (1.0 if eps == 0.0 else -1.0)
                    phi = np.arctan2(sigma * self.a[k], cos_phi)
                    pts.append(self.point(np.array(theta + eps), np.array(phi)))
        return np.array(pts)

    # -- the distance --------------------------------------------------------------------
    def distance(self, p: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Signed weighted max-norm distance of ``p (n, 3)`` with weights ``w (n, 3)``."""
        best = _norm_w(p[:, None, :] - self.faces[None], w[:, None, :]).min(axis=1)
        best = np.minimum(best, self._vertex_times(p, w))
        best = np.minimum(best, self._edge_distances(p, w))
        inside = self.signed_euclidean(p - self.c) <= 0
        return np.where(inside, -best, best)

    # vertex contacts -----------------------------------------------------------------------
    def _vertex_times(self, p, w):
        """Least ``|t|`` over the real roots of the four line-torus quartics.

        Along ``y(t) = y0 + t d``: ``|y|^2 = A t^2 + 2 B t + C``, the height
        ``a.y = e t + g`` and ``rho^2 = A' t^2 + 2 B' t + rho0^2`` (squared distance to
        the axis); the torus is ``(|y|^2 + R^2 - r^2)^2 = 4 R^2 rho^2``. Roots come from
        :func:`_quartic_real_roots` (Newton-polished) and are kept only where the
        Euclidean signed distance at them is within rounding of zero, so every kept
        value is a point of the surface."""
        y0 = p - self.c
        R2, K = self.R ** 2, self.R ** 2 - self.r ** 2
        g = dot(y0, self.a)
        perp0 = y0 - g[:, None] * self.a
        C = np.einsum("ij,ij->i", y0, y0)
        rho2 = np.einsum("ij,ij->i", perp0, perp0)
        Cp = C + K
        size = (self.R + self.r + np.abs(y0).max(axis=1))[:, None]
        best = np.full(len(p), np.inf)
        A = np.einsum("ij,ij->i", w, w)                 # |d|^2, the same for the 4 lines
        c4 = A * A
        yw, aw = y0 * w, w * self.a                     # d = (sx, sy, 1) * w
        for sx in (-1.0, 1.0):
            for sy in (-1.0, 1.0):
                B = sx * yw[:, 0] + sy * yw[:, 1] + yw[:, 2]
                e = sx * aw[:, 0] + sy * aw[:, 1] + aw[:, 2]
                Ap = A - e * e                          # |d across the axis|^2
                Bp = B - g * e
                t = _quartic_real_roots(4 * A * B / c4,
                                        (4 * B * B + 2 * A * Cp - 4 * R2 * Ap) / c4,
                                        (4 * B * Cp - 8 * R2 * Bp) / c4,
                                        (Cp * Cp - 4 * R2 * rho2) / c4)
                rho = np.sqrt(np.maximum((Ap[:, None] * t + 2 * Bp[:, None]) * t
                                         + rho2[:, None], 0.0))
                gap = np.hypot(rho - self.R, e[:, None] * t + g[:, None]) - self.r
                near = np.abs(gap) <= _ON_SURFACE * size
                best = np.fmin(best, np.where(near, np.abs(t), np.inf).min(axis=1))
        return best

    # edge contacts -------------------------------------------------------------------------
    def _silhouette(self, k) -> dict:
        """Constants of the silhouette along ``e_k``: ``f1, f2`` with ``e_k x u'(theta) =
        -sin f1 + cos f2``; ``sgn`` making ``sgn (e_k x u') / |e_k x u'|`` the outward
        normal ``nu`` of the projected core circle; ``|e_k x u'|^2 = n11 s^2 - 2 n12 s c +
        n22 c^2``; its curvature is ``kappa0 / |e_k x u'|^3``."""
        ek = np.eye(3)[k]
        f1, f2 = np.cross(ek, self.e1), np.cross(ek, self.e2)
        return {"f1": f1, "f2": f2, "sgn": -np.sign(self.a[k]), "n11": f1 @ f1,
                "n12": f1 @ f2, "n22": f2 @ f2, "kappa0": abs(self.a[k]) / self.R}

    def _edge_normal(self, w, k, sigma):
        """The normal ``l`` of the planes ``(s_i - p_i) / w_i = sigma (s_j - p_j) / w_j``."""
        i, j = [m for m in range(3) if m != k]
        ell = np.zeros((len(w), 3))
        ell[:, i] = 1.0 / w[:, i]
        ell[:, j] = -sigma / w[:, j]
        return ell

    def _edge_distances(self, p, w):
        """Least ``||p - s||_w`` over all edge-contact candidates: the roots on every
        monotone arc of every offset curve, for the three edge directions and both
        diagonal planes, solved together."""
        best = np.full(len(p), np.inf)
        arcs, exact = [], []
        for k in range(3):
            if abs(self.a[k]) > _PLANAR:
                i, j = [m for m in range(3) if m != k]
                # l . v = v_i / w_i - sigma v_j / w_j: the two planes share the halves
                inv_i, inv_j = 1.0 / w[:, i], 1.0 / w[:, j]
                halves = [(inv_i * (self.c[i] - p[:, i]), inv_j * (self.c[j] - p[:, j]))]
                halves += [(inv_i * v[i], inv_j * v[j]) for v in
                           (self.e1, self.e2, self._geo[k]["f1"], self._geo[k]["f2"])]
                for sigma in (-1.0, 1.0):
                    dots = [hi_ - sigma * hj for hi_, hj in halves]
                    self._arcs(dots, k, arcs, exact)
            if abs(self.a[k]) < _NEAR_PLANAR:
                for sigma in (-1.0, 1.0):
                    self._circle_values(p, w, k, sigma, best)
        if not arcs:
            return best
        table = np.concatenate([a[0] for a in arcs], axis=1)   # rows: see _G_ROWS
        lo, hi, glo, ghi = (np.concatenate([a[1][i] for a in arcs]) for i in range(4))
        theta = _monotone_root(
            lambda x, idx: self._offset_g(x, *(table if len(idx) == table.shape[1]
                                               else table[:, idx])[:_G_ROWS]),
            lo, hi, glo, ghi)
        theta = np.concatenate([theta] + [e[0] for e in exact])
        b, k, owner = (np.concatenate([table[row]] + [e[1][i] for e in exact])
                       for i, row in enumerate((0, _G_ROWS, _G_ROWS + 1)))
        owner = owner.astype(np.intp)
        np.fmin.at(best, owner, self._silhouette_values(theta, b, k.astype(np.intp), p[owner],
                                                        w[owner]))
        return best

    def _arcs(self, dots, k, arcs, exact):
        """The monotone arcs of ``g(theta) = l . (X(theta) - p)`` (``dots``: ``l`` dotted
        with ``c - p, e1, e2, f1, f2``) on both offset curves along ``e_k`` that change
        sign (appended to ``arcs`` as ``(table, (lo, hi, g_lo, g_hi))``), and the arc ends
        within rounding of a root (to ``exact``: a root on the wrong side of a rounded
        critical angle is then not lost)."""
        geo = self._geo[k]
        l_c, l_e1, l_e2, l_f1, l_f2 = dots          # l.(c - p), l.e1, l.e2, l.f1, l.f2
        L0, L1, L2 = l_c, self.R * l_e1, self.R * l_e2
        M1, M2 = self.r * geo["sgn"] * l_f1, self.r * geo["sgn"] * l_f2
        theta0 = np.arctan2(L2, L1)                                 # l . E' = 0 there
        size = np.abs(L0) + np.hypot(L1, L2) + np.hypot(M1, M2)
        # both offsets at once: g = E-part + b * nu-part, on all critical angles
        crit = np.stack([theta0, theta0 + np.pi] + [theta0 + np.mod(c - theta0, _TWO_PI)
                                                    for c in self._cusps[k]], axis=1)
        s, co = np.sin(crit), np.cos(crit)
        N = np.sqrt(geo["n11"] * s * s - 2 * geo["n12"] * s * co + geo["n22"] * co * co)
        g_e = L0[:, None] + L1[:, None] * co + L2[:, None] * s
        g_nu = (M2[:, None] * co - M1[:, None] * s) / N
        for b in (1.0, -1.0):                                       # outer, inner offset
            if b > 0 or crit.shape[1] == 2:                         # outer: no cusps
                ends, gv = crit[:, :2], g_e[:, :2] + b * g_nu[:, :2]   # already in order
            else:
                order = np.argsort(crit, axis=1)
                ends = np.take_along_axis(crit, order, axis=1)
                gv = np.take_along_axis(g_e + b * g_nu, order, axis=1)
            ends = np.concatenate([ends, ends[:, :1] + _TWO_PI], axis=1)
            gv = np.concatenate([gv, gv[:, :1]], axis=1)
            owner, col = np.nonzero(np.abs(gv[:, :-1]) <= 1e-12 * size[:, None])
            exact.append((ends[owner, col], (np.full(len(owner), b), np.full(len(owner), k),
                                             owner)))
            owner, arc = np.nonzero(gv[:, :-1] * gv[:, 1:] <= 0)
            rows = [np.full(len(owner), b), L0[owner], L1[owner], L2[owner], M1[owner],
                    M2[owner]] + [np.full(len(owner), geo[c]) for c in ("n11", "n12", "n22",
                                                                        "kappa0")]
            rows += [np.full(len(owner), k), owner]
            arcs.append((np.stack(rows), (ends[owner, arc], ends[owner, arc + 1],
                                          gv[owner, arc], gv[owner, arc + 1])))

    def _offset_g(self, theta, b, l0, l1, l2, m1, m2, n11, n12, n22, kappa0):
        """``g(theta)`` and ``g'(theta) = (1 + b r kappa) l . E'(theta)``."""
        s, co = np.sin(theta), np.cos(theta)
        N = np.sqrt(n11 * s * s - 2 * n12 * s * co + n22 * co * co)
        value = l0 + l1 * co + l2 * s + b * (m2 * co - m1 * s) / N
        slope = (1.0 + b * self.r * kappa0 / (N * N * N)) * (l2 * co - l1 * s)
        return value, slope

    def _silhouette_values(self, theta, b, K, p, w):
        """``||p - s||_w`` for ``s = c + R u(theta) + b r nu(theta)`` on the silhouette
        along ``e_K`` (per lane; ``b = 1`` outer, ``-1`` inner offset), ``p, w`` per lane."""
        s, co = np.sin(theta), np.cos(theta)
        comps = [-s * self._f1[K, i] + co * self._f2[K, i] for i in range(3)]
        scale = b * self._sgn[K] * self.r / np.sqrt(comps[0] ** 2 + comps[1] ** 2 + comps[2] ** 2)
        out = None
        for i in range(3):
            point = self.c[i] + self.R * (co * self.e1[i] + s * self.e2[i]) + scale * comps[i]
            term = np.abs(p[:, i] - point) / w[:, i]
            out = term if out is None else np.maximum(out, term)
        return out

    def _circle_values(self, p, w, k, sigma, best):
        """Axis (nearly) across ``e_k``: the degenerate silhouette's circles met by the
        edge plane, as candidates (they are points of the surface whatever ``a_k``)."""
        theta, phi, owner = self._circle_points(p, self._edge_normal(w, k, sigma), k)
        if len(theta):
            np.fmin.at(best, owner, _norm_w(p[owner] - self.point(theta, phi), w[owner]))

    def _cusp_angles(self, k) -> list:
        """Where ``r kappa = 1`` on the projected core circle: ``u'_k(theta)^2 = m^2`` with
        ``m^2 = 1 - (r |a_k| / R)^(2/3)``; none unless ``a_k^2 <= r / R``."""
        a_k = abs(self.a[k])
        m2 = 1.0 - (self.r * a_k / self.R) ** (2.0 / 3.0)
        beta = np.hypot(self.e1[k], self.e2[k])     # u'_k = beta cos(theta - theta_k)
        if m2 < 0 or np.sqrt(m2) > beta * (1 + 1e-12):
            return []
        theta_k = np.arctan2(-self.e1[k], self.e2[k])
        alpha = np.arccos(min(np.sqrt(m2) / beta, 1.0))
        return [theta_k + alpha, theta_k - alpha, theta_k + np.pi - alpha,
                theta_k + np.pi + alpha]

    def _circle_points(self, p, ell, k):
        """The degenerate silhouette (``a_k = 0``): the circles ``phi = ±pi/2`` and the
        meridian circles across ``e_k``, met by the edge plane (closed form)."""
        thetas, phis, owners = [], [], []
        n = len(p)
        idx = np.arange(n)
        le1, le2 = dot(ell, self.e1), dot(ell, self.e2)
        # circles c ± r a + R u(theta):  l.(c ± r a - p) + R (le1 cos + le2 sin) = 0
        base = np.arctan2(le2, le1)
        amp = self.R * np.hypot(le1, le2)
        for side in (-1.0, 1.0):
            off = np.einsum("ij,ij->i", ell, self.c + side * self.r * self.a - p)
            with np.errstate(invalid="ignore", divide="ignore"):
                half = np.arccos(-off / amp)
            for pm in (-1.0, 1.0):
                th = base + pm * half
                ok = np.isfinite(th)
                thetas.append(th[ok]), phis.append(np.full(ok.sum(), side * np.pi / 2))
                owners.append(idx[ok])
        # meridian circles where u_k(theta) = 0
        theta_m = np.arctan2(-self.e1[k], self.e2[k])
        for th0 in (theta_m, theta_m + np.pi):
            um = self.u(np.array(th0))
            lu, la = dot(ell, um), dot(ell, self.a)
            off = np.einsum("ij,ij->i", ell, self.c - p) + self.R * lu
            with np.errstate(invalid="ignore", divide="ignore"):
                half = np.arccos(-off / (self.r * np.hypot(lu, la)))
            base_phi = np.arctan2(la, lu)
            for pm in (-1.0, 1.0):
                ph = base_phi + pm * half
                ok = np.isfinite(ph)
                thetas.append(np.full(ok.sum(), th0)), phis.append(ph[ok])
                owners.append(idx[ok])
        return np.concatenate(thetas), np.concatenate(phis), np.concatenate(owners)


def _norm_w(v: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``max_i |v_i| / w_i`` over the last axis."""
    q = np.abs(v) / w
    return np.maximum(np.maximum(q[..., 0], q[..., 1]), q[..., 2])


def _monotone_root(fn, lo, hi, g_lo, g_hi, iterations: int = 80):
    """The root of a function monotone on ``[lo, hi]`` (angles, ``|x| < 20``) that
    changes sign there (``g_lo``, ``g_hi`` its end values): from a half-cosine model,
    Newton steps kept inside the shrinking bracket, bisection otherwise; a lane is done
    when its Newton step is below 1e-9 (the error left is of the order of its square)
    or its bracket below 1e-13. ``fn(x, lanes)`` evaluates the function and its
    derivative; converged lanes leave the working set once they are half of it."""
    with np.errstate(invalid="ignore", divide="ignore"):
        # the arcs end at critical points (g' = 0): start from the root of the half
        # cosine with those end values and slopes
        x = lo + (hi - lo) / np.pi * np.arccos(np.clip((g_lo + g_hi) / (g_hi - g_lo),
                                                       -1.0, 1.0))
    x = np.where((x >= lo) & (x <= hi), x, 0.5 * (lo + hi))
    out = np.empty_like(x)
    lanes = np.arange(len(x))
    lo, hi, sign_lo = lo.copy(), hi.copy(), np.sign(g_lo)
    live = np.ones(len(x), dtype=bool)
    previous = np.full(len(x), np.nan)      # no estimate before the second Newton step
    for _ in range(iterations):
        n_live = np.count_nonzero(live)
        if n_live == 0:
            break
        if n_live < 0.5 * len(lanes):
            out[lanes[~live]] = x[~live]
            lanes, x, lo, hi, sign_lo, previous = (v[live] for v in (lanes, x, lo, hi,
                                                                     sign_lo, previous))
            live = np.ones(len(lanes), dtype=bool)
        value, slope = fn(x, lanes)
        below = np.sign(value) == sign_lo
        lo = np.where(below, x, lo)
        hi = np.where(below, hi, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = x - value / slope
        inside = (newton >= lo) & (newton <= hi)
        x_new = np.where(inside, newton, 0.5 * (lo + hi))
        step = np.abs(x_new - x)
        # quadratic convergence: the next error is about step^3 / previous step^2
        live &= ~((inside & ((step <= 1e-9) | (step ** 3 <= 1e-15 * previous ** 2)))
                  | (hi - lo <= 1e-13))
        previous = np.where(inside, step, np.nan)
        x = np.where(live, x_new, np.where(inside, x_new, x))
    out[lanes] = x
    return out


def _quartic_real_roots(b, c, d, e) -> np.ndarray:
    """Real roots ``(n, 4)`` (NaN where none) of ``t^4 + b t^3 + c t^2 + d t + e``, by
    Ferrari's method; near-double roots (a negative discriminant within rounding)
    are kept as double roots, and every root gets two Newton steps."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        shift = b / 4.0
        # depressed: y^4 + P y^2 + Q y + S, t = y - b / 4
        P = c - 6.0 * shift * shift
        Q = d - 2.0 * c * shift + 8.0 * shift ** 3
        S = e - d * shift + c * shift * shift - 3.0 * shift ** 4
        m = _largest_cubic_root(P, 0.25 * P * P - S, -0.125 * Q * Q)
        m = np.maximum(m, 0.0)
        scale = 1.0 + np.abs(P) + np.sqrt(np.abs(S))
        s = np.sqrt(2.0 * m)
        small = s <= 1e-9 * np.sqrt(scale)
        s_safe = np.where(small, 1.0, s)
        roots = []
        for sign in (1.0, -1.0):
            # y^2 - sign s y + (P / 2 + m + sign Q / (2 s)) = 0
            const = 0.5 * P + m + sign * Q / (2.0 * s_safe)
            disc = s * s - 4.0 * const
            disc = np.where(disc < 0, np.where(disc > -1e-6 * (s * s + 4 * np.abs(const)),
                                               0.0, np.nan), disc)
            root = np.sqrt(disc)
            roots += [0.5 * (sign * s + root), 0.5 * (sign * s - root)]
        y = np.stack(roots, axis=1)
        if np.any(small):
            # the biquadratic case Q = 0: y^2 = (-P ± sqrt(P^2 - 4 S)) / 2
            disc = P * P - 4.0 * S
            disc = np.where((disc < 0) & (disc > -1e-12 * (P * P + 4 * np.abs(S))), 0.0, disc)
            bi = []
            for sq in (1.0, -1.0):
                y2 = 0.5 * (-P + sq * np.sqrt(disc))
                y2 = np.where((y2 < 0) & (y2 > -1e-12 * scale), 0.0, y2)
                bi += [np.sqrt(y2), -np.sqrt(y2)]
            y = np.where(small[:, None], np.stack(bi, axis=1), y)
        t = y - shift[:, None]
        coef = [v[:, None] for v in (b, c, d, e)]
        for _ in range(2):
            value = (((t + coef[0]) * t + coef[1]) * t + coef[2]) * t + coef[3]
            slope = ((4.0 * t + 3.0 * coef[0]) * t + 2.0 * coef[1]) * t + coef[2]
            step = value / slope
            t = np.where(np.isfinite(step) & (np.abs(step) <= 1e-3 * (1 + np.abs(t))),
                         t - step, t)
    return t


def _largest_cubic_root(b, c, d) -> np.ndarray:
    """The largest real root of ``m^3 + b m^2 + c m + d`` (vectorized; one Newton step)."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        shift = b / 3.0
        P = c - b * shift
        Q = 2.0 * shift ** 3 - c * shift + d
        disc = 0.25 * Q * Q + P ** 3 / 27.0
        root_disc = np.sqrt(np.maximum(disc, 0.0))
        one = np.cbrt(-0.5 * Q + root_disc) + np.cbrt(-0.5 * Q - root_disc)
        rad = np.sqrt(np.maximum(-P / 3.0, 0.0))
        arg = np.clip(np.where(rad > 0, -0.5 * Q / np.where(rad > 0, rad, 1.0) ** 3, 0.0),
                      -1.0, 1.0)
        three = 2.0 * rad * np.cos(np.arccos(arg) / 3.0)
        z = np.where(disc > 0, one, three)
        m = z - shift
        value = ((m + b) * m + c) * m + d
        slope = (3.0 * m + 2.0 * b) * m + c
        step = value / slope
        return np.where(np.isfinite(step) & (np.abs(step) <= 1e-3 * (1 + np.abs(m))),
                        m - step, m)
