"""The weighted max-norm (Varadhan §5.1): ``||v||_w = max_i |v_i| / w_i``.

Its unit ball is the box of half-widths ``w``, so a voxel of half-size ``h``
around ``c`` is the ball of radius 1 in the norm weighted by ``h``; the dual
norm, which measures planes, is ``h_w(u) = sum_i |u_i| w_i`` (the support
function of that box).

Examples
--------
>>> import numpy as np
>>> as_weights(None, 2).tolist()
[[1.0, 1.0, 1.0], [1.0, 1.0, 1.0]]
>>> float(support(np.array([[1.0, -2.0, 0.0]]), np.array([[0.5, 1.0, 3.0]]))[0])
2.5
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .products import dot

__all__ = ["as_points", "as_weights", "support", "in_blocks", "float_bisection"]


def as_points(points: Any) -> np.ndarray:
    """``(n, 3)`` finite float points, or a ``ValueError`` naming the problem."""
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 1 and p.shape == (3,):
        p = p[None]
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError(f"points must be finite: row {int(np.argwhere(~np.isfinite(p))[0, 0])}")
    return p


def as_weights(weights: Any, n: int) -> np.ndarray:
    """Weights broadcast to ``(n, 3)``: ``None`` (the plain max-norm), 3 numbers, or one
    row per point; all positive and finite."""
    if weights is None:
        return np.ones((n, 3))
    w = np.asarray(weights, dtype=np.float64)
    try:
        w = np.broadcast_to(w, (n, 3))
    except ValueError:
        raise ValueError(f"weights must be 3 numbers or shape ({n}, 3), got {w.shape}") from None
    if not np.all(w > 0) or not np.all(np.isfinite(w)):
        raise ValueError("weights must be positive and finite")
    return w


def support(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``sum_i |u_i| w_i``: how far the box of half-widths ``w`` reaches along ``u``."""
    return dot(np.abs(u), np.ones(3)) if w is None else np.sum(np.abs(u) * w, axis=-1)


def in_blocks(fn, p: np.ndarray, w: np.ndarray, size: int) -> np.ndarray:
    """``fn(p, w)`` over blocks of ``size`` points (bounded temporaries), concatenated."""
    out = np.empty(len(p))
    for s in range(0, len(p), size):
        out[s:s + size] = fn(p[s:s + size], w[s:s + size])
    return out


def float_bisection(test, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)``: adjacent non-negative floats bracketing where the monotone ``test(t)``
    (false, then true; ``test(hi)`` true) turns true, by bisection on the bit patterns
    of non-negative floats (64 steps at most). ``lo`` is 0 where nothing below ``hi``
    was found false, so ``test(lo)`` may hold there (a point on the surface)."""
    lo_bits = np.zeros(len(hi), dtype=np.int64)
    hi_bits = np.asarray(hi, dtype=np.float64).view(np.int64).copy()
    for _ in range(64):
        active = hi_bits - lo_bits > 1
        if not active.any():
            break
        mid = lo_bits + (hi_bits - lo_bits) // 2
        ok = test(mid.view(np.float64))
        hi_bits = np.where(active & ok, mid, hi_bits)
        lo_bits = np.where(active & ~ok, mid, lo_bits)
    return lo_bits.view(np.float64), hi_bits.view(np.float64)
