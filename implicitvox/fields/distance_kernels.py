"""Which distance each kind of shape gets, and how exactly.

In the order tried:

1. **exact**: the shape's own distance function (``shape.distance_function(norm)``,
   the :mod:`implicitvox.linf` primitives and :mod:`csg` solids made of one):
   the max-norm distances of Varadhan §3 (contact equations, exact to
   rounding) and the Euclidean ones of :mod:`implicitvox.linf.euclidean`;
   triangle meshes by the bounding volume hierarchy with lower and upper
   bounds (Varadhan §4.1), all grid points at once. Error 0 (up to rounding).
2. **max-norm by the exact box test** (``norm="linf"``, shapes with an exact
   voxel test, such as :mod:`csg` booleans of exact primitives): the surface
   meets the cube of half-size ``t`` around ``p`` iff ``D∞(p) <= t``
   (Varadhan §5.1 read backwards), a predicate monotone in ``t``; bisection on
   the bits of ``t`` finds the least float where it holds. Error: one ulp.
3. **certified** (:mod:`.certified`): any expression; a lower and an upper
   bound per point, refined to the tolerance.

Examples
--------
>>> import numpy as np
>>> from implicitvox import linf
>>> kernel = choose_kernel(linf.Sphere((0, 0, 0), 1.0), "euclidean")
>>> kernel.kind, kernel(np.array([[0.0, 0, 3]]), None)[0].tolist()
('exact', [2.0])
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from ..expr.shape import AMBIGUOUS, FULL, voxel_classifier
from ..linf.box_tests import TIE_ULPS
from ..linf.norm import float_bisection

__all__ = ["Kernel", "choose_kernel", "exact_distance_function", "linf_by_box_test"]


class Kernel:
    """A distance kernel: ``kernel(points, weights) -> (value, error)``; ``kind`` is
    ``"exact"``, ``"box test"`` or ``"certified"``."""

    def __init__(self, kind: str, run: Callable[[np.ndarray, Any], tuple[np.ndarray, np.ndarray]]):
        self.kind = kind
        self._run = run

    def __call__(self, points: np.ndarray, weights: Any) -> tuple[np.ndarray, np.ndarray]:
        return self._run(points, weights)


def exact_distance_function(shape: Any, norm: str) -> Optional[Callable]:
    """The shape's own exact signed distance in ``norm``, or None."""
    provider = getattr(shape, "distance_function", None)
    return provider(norm) if callable(provider) else None


def choose_kernel(shape: Any, norm: str, certify: Optional[Callable] = None) -> Optional[Kernel]:
    """The most exact kernel the shape allows (see the module docstring); ``certify``
    builds the certified one (it needs the voxelization's boxes), and is returned
    when neither exact route applies."""
    exact = exact_distance_function(shape, norm)
    if exact is not None:
        if norm == "linf":
            return Kernel("exact", lambda p, w: (exact(p, w), np.zeros(len(p))))
        return Kernel("exact", lambda p, w: (exact(p), np.zeros(len(p))))
    classify = voxel_classifier(shape)
    if norm == "linf" and classify is not None:
        return Kernel("box test", lambda p, w: linf_by_box_test(classify, p, w))
    return None if certify is None else Kernel("certified", certify)


def linf_by_box_test(classify: Callable, points: np.ndarray, weights: Any,
                     limit: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
    """Signed weighted max-norm distances from an exact box test, by bisection on the
    bit patterns of the cube's half-size (64 steps at most); error one ulp of the
    distance plus the box test's allowance for rounding (``linf.box_tests.TIE_ULPS``).
    ``limit`` caps the search (points farther get ``±limit``)."""
    p = np.asarray(points, dtype=np.float64)
    n = len(p)
    w = np.ones((n, 3)) if weights is None else \
        np.broadcast_to(np.asarray(weights, dtype=np.float64), (n, 3))

    def meets(t: np.ndarray) -> np.ndarray:
        half = t[:, None] * w
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            return classify(p - half, p + half) == AMBIGUOUS

    hi = np.full(n, limit if np.isfinite(limit) else 1.0)
    if not np.isfinite(limit):          # grow until every cube meets the surface
        for _ in range(64):
            miss = ~meets(hi)
            if not miss.any():
                break
            hi = np.where(miss, hi * 4, hi)
    t_lo, t_hi = float_bisection(meets, hi)
    at_lo = meets(t_lo)
    t = np.where(at_lo, t_lo, t_hi)
    # the sign: the largest cube that does not meet the surface is inside or outside
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        inside = classify(p - t_lo[:, None] * w, p + t_lo[:, None] * w) == FULL
    far = ~meets(hi)
    t = np.where(far, hi, t)
    # the box test counts a cube within its rounding of touching as met
    # (linf.box_tests.TIE_ULPS, in units of the centre's ulp over the half-size): the
    # distance may be that much short, taken twice for the distance's own rounding
    reach = np.abs(p).max(axis=1) / w.min(axis=1)
    tie = 2 * TIE_ULPS * np.finfo(np.float64).eps * (2 * t + reach)
    return np.where(inside & ~at_lo, -t, t), np.where(far, 0.0, (t_hi - t_lo) * ~at_lo + tie)
