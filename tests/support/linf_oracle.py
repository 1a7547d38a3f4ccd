"""Vectorized brute-force oracles for max-norm distances to convex solids.

Independent of :mod:`implicitvox.linf` (no contact equations), fast enough
for 10^4 points per test:

* outside, by duality: for a convex ``K`` and ``p`` outside it,
  ``D_w(p, K) = max { u.p - h_K(u) : sum_i w_i |u_i| <= 1 }`` with ``h_K``
  the support function of ``K`` (the dual of the weighted max-norm is the
  weighted 1-norm). The objective is concave and 1-homogeneous, so the
  maximum lies on the boundary of the cross-polytope, whose 8 triangular
  faces are searched by nested golden sections (:func:`dual_distance`);
* inside: ``K`` is convex, so a box lies in ``K`` iff its 8 corners do; the
  largest such box around ``p`` by bisection on its size.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

SIGNS = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], dtype=float)


_GOLD = (np.sqrt(5.0) - 1.0) / 2.0


def _golden_max(f, lo, hi, iterations):
    """Maximum of functions ``f(t)`` unimodal on ``[lo, hi]`` (arrays), by golden section."""
    a, b = lo, hi
    c, d = b - _GOLD * (b - a), a + _GOLD * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        left = fc >= fd                      # the maximum is in [a, d]
        a, b = np.where(left, a, c), np.where(left, d, b)
        c_new = np.where(left, b - _GOLD * (b - a), d)
        d_new = np.where(left, c, a + _GOLD * (b - a))
        f_new = f(np.where(left, c_new, d_new))
        fc, fd = np.where(left, f_new, fd), np.where(left, fc, f_new)
        c, d = c_new, d_new
    return np.maximum(fc, fd)


def dual_distance(support: Callable[[np.ndarray], np.ndarray], p: np.ndarray, w: np.ndarray,
                  iterations: int = 56) -> np.ndarray:
    """``D_w(p, K)`` for points outside ``K``, by duality, to about 1e-12 relative.

    The objective ``F(u) = u.p - h(u)`` is concave, so on each of the 8 faces
    ``u = sigma * lam / w`` (``lam`` in the unit simplex) of the dual ball it
    is concave in ``lam``; its maximum over a face is a nested golden-section
    search (``max over lam_1`` of ``max over lam_2``, both concave, hence
    unimodal; kinks do not matter). The value at any ``u`` is a lower bound.
    """
    n = len(p)
    sigma = SIGNS[:, None, :]                                    # (8, 1, 3)
    P, W = p[None], w[None]                                      # (1, n, 3)

    def F(l1, l2):
        lam = np.stack([l1, l2, np.maximum(1.0 - l1 - l2, 0.0)], axis=-1)
        u = sigma * lam / W
        return np.sum(u * P, axis=-1) - support(u)

    def inner(l1):
        return _golden_max(lambda l2: F(l1, l2), np.zeros_like(l1), 1.0 - l1, iterations)

    zero = np.zeros((8, n))
    best = _golden_max(inner, zero, zero + 1.0, iterations)      # (8, n)
    return best.max(axis=0)


def corner_depth(inside: Callable[[np.ndarray], np.ndarray], p: np.ndarray, w: np.ndarray,
                 t_max: float = 10.0, iterations: int = 80) -> np.ndarray:
    """``-t`` for the largest box ``p + t [-w, w]`` whose 8 corners satisfy ``inside``
    (``inside(points (..., 3)) -> bool``); ``K`` convex."""
    lo = np.zeros(len(p))
    hi = np.full(len(p), t_max)
    for _ in range(iterations):
        t = 0.5 * (lo + hi)
        corners = p[:, None, :] + t[:, None, None] * SIGNS[None] * w[:, None, :]
        ok = inside(corners).all(axis=1)
        lo = np.where(ok, t, lo)
        hi = np.where(ok, hi, t)
    return -lo


def ellipsoid_support(center: np.ndarray, Qinv: np.ndarray):
    """``h(u) = u.c + sqrt(u^T Q^-1 u)`` of ``{x : (x - c)^T Q (x - c) <= 1}``."""
    def h(u):
        return u @ center + np.sqrt(np.einsum("...i,ij,...j->...", u, Qinv, u))
    return h


def frustum_support(base: np.ndarray, axis: np.ndarray, height: float, r1: float, r2: float):
    """``h(u)`` of the convex hull of the two end disks of a capped cone or frustum."""
    top = base + height * axis

    def h(u):
        perp = u - (u @ axis)[..., None] * axis     # not |u|^2 - (u.a)^2: that cancels
        across = np.sqrt(np.einsum("...i,...i->...", perp, perp))
        return np.maximum(u @ base + r1 * across, u @ top + r2 * across)
    return h


def torus_surface_distance(center: np.ndarray, axis, R: float, r: float, p: np.ndarray,
                           w: np.ndarray, nu: int = 256, nv: int = 128, basins: int = 6,
                           cells: float = 3.0, iterations: int = 56,
                           chunk: int = 64) -> np.ndarray:
    """``min ||p - q||_w`` over the torus surface ``q(u, v) = c + (R + r cos v)(cos u e1 +
    sin u e2) + r sin v a`` (``axis`` an index 0-2 or a vector ``a``): a dense ``nu x nv``
    sampling of the parameters, then nested golden sections (``u`` outside, ``v`` inside)
    over ``cells`` grid cells around each of the ``basins`` best samples that are local
    minima of the sampling. Unsigned."""
    if np.ndim(axis) == 0:
        a = np.eye(3)[int(axis)]
    else:
        a = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    helper = np.eye(3)[int(np.argmin(np.abs(a)))]
    e1 = helper - (helper @ a) * a
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    frame = np.stack([e1, e2, a])                       # rows
    q = p - center
    du, dv = 2 * np.pi / nu, 2 * np.pi / nv
    U, V = np.meshgrid(np.arange(nu) * du, np.arange(nv) * dv, indexing="ij")

    def cost(Q, W, u, v):
        ring = R + r * np.cos(v)
        local = (ring * np.cos(u), ring * np.sin(u), r * np.sin(v))
        out = None
        for i in range(3):
            s_i = local[0] * frame[0, i] + local[1] * frame[1, i] + local[2] * frame[2, i]
            term = np.abs(Q[..., i] - s_i) / W[..., i]
            out = term if out is None else np.maximum(out, term)
        return out

    best = np.empty(len(p))
    seeds = np.empty((len(p), basins), dtype=np.int64)
    for s in range(0, len(p), chunk):
        f = cost(q[s:s + chunk, None, None, :], w[s:s + chunk, None, None, :], U[None], V[None])
        local = np.ones(f.shape, dtype=bool)             # local minima of the periodic grid
        for ax in (1, 2):
            for shift in (1, -1):
                local &= f <= np.roll(f, shift, axis=ax)
        flat = f.reshape(len(f), -1)
        best[s:s + chunk] = flat.min(axis=1)
        seeds[s:s + chunk] = np.argsort(np.where(local.reshape(len(f), -1), flat, np.inf),
                                        axis=1)[:, :basins]
    # refine every (point, basin) at once
    Q = np.repeat(q, basins, axis=0)
    W = np.repeat(w, basins, axis=0)
    iu, iv = np.divmod(seeds.reshape(-1), nv)
    u0, v0 = iu * du, iv * dv

    def inner(u):
        return -_golden_max(lambda v: -cost(Q, W, u, v), v0 - cells * dv, v0 + cells * dv,
                            iterations)
    value = -_golden_max(lambda u: -inner(u), u0 - cells * du, u0 + cells * du, iterations)
    return np.minimum(best, value.reshape(len(p), basins).min(axis=1))


def quadric_box_range(A: np.ndarray, b: np.ndarray, c: float, lo: np.ndarray, hi: np.ndarray):
    """Exact least and greatest values of ``x^T A x + b.x + c`` over boxes ``[lo, hi]``.

    The extremes of a quadratic over a box are at stationary points of its
    restriction to one of the box's 27 faces (each coordinate at its low end,
    its high end, or free); a face whose restricted Hessian is singular has its
    extremes on its own boundary, a smaller face. So: every face, its
    stationary point if it lies on the face, and the least and greatest value.
    """
    import itertools
    n = len(lo)
    vmin, vmax = np.full(n, np.inf), np.full(n, -np.inf)
    for pattern in itertools.product((-1, 0, 1), repeat=3):
        free = [a for a in range(3) if pattern[a] == 0]
        fixed = [a for a in range(3) if pattern[a] != 0]
        x = np.empty((n, 3))
        for a in fixed:
            x[:, a] = lo[:, a] if pattern[a] < 0 else hi[:, a]
        ok = np.ones(n, dtype=bool)
        if free:
            M = A[np.ix_(free, free)]
            if abs(np.linalg.det(M)) <= 1e-14 * (1 + np.abs(M).max()) ** len(free):
                continue
            rhs = -0.5 * b[free] - (x[:, fixed] @ A[np.ix_(free, fixed)].T if fixed else 0.0)
            x[:, free] = np.broadcast_to(rhs, (n, len(free))) @ np.linalg.inv(M).T
            ok = np.all((x[:, free] >= lo[:, free]) & (x[:, free] <= hi[:, free]), axis=1)
        v = np.einsum("ni,ij,nj->n", x, A, x) + x @ b + c
        vmin = np.where(ok, np.minimum(vmin, v), vmin)
        vmax = np.where(ok, np.maximum(vmax, v), vmax)
    return vmin, vmax


def quadric_distance(A, b, c, p, w, t_max: float = 1e3) -> np.ndarray:
    """Unsigned max-norm distance to the surface ``Q = 0`` by bisection (on float bits)
    on the box size: the box meets the surface iff its least value of ``Q`` is
    ``<= 0 <=`` its greatest (``Q`` is continuous, the box connected)."""
    lo_bits = np.zeros(len(p), dtype=np.int64)
    hi_bits = np.full(len(p), t_max).view(np.int64).copy()
    for _ in range(64):
        mid = lo_bits + (hi_bits - lo_bits) // 2
        t = mid.view(np.float64)[:, None]
        vmin, vmax = quadric_box_range(A, b, c, p - t * w, p + t * w)
        meets = (vmin <= 0) & (vmax >= 0)
        active = hi_bits - lo_bits > 1
        hi_bits = np.where(active & meets, mid, hi_bits)
        lo_bits = np.where(active & ~meets, mid, lo_bits)
    t0 = lo_bits.view(np.float64)
    vmin, vmax = quadric_box_range(A, b, c, p - t0[:, None] * w, p + t0[:, None] * w)
    return np.where((vmin <= 0) & (vmax >= 0), t0, hi_bits.view(np.float64))
