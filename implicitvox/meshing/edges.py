"""Where the surface crosses cell edges: certified brackets and normals.

An edge whose ends have opposite signs holds a zero of ``f`` (``f`` is
continuous there: the adaptive grid keeps only cells whose enclosure is
defined). The zero is isolated by bisection on the signs (in compiled code for tapes
:mod:`implicitvox.eval.pool_gradients` runs, the same steps): each step halves
the bracket and keeps the half whose ends still differ, so after ``steps``
steps a zero lies in a bracket ``2**-steps`` of the edge long, whatever the
function does between samples. A single linear interpolation of the two end
values, the usual choice, can land anywhere on a curved or kinked edge. The
crossing is the bracket's midpoint, and its normal the unit gradient there
(Ju et al. 2002 use these as the Hermite data of dual contouring).

Examples
--------
>>> import numpy as np, implicitvox as iv
>>> from implicitvox import x, y, z
>>> f = iv.compile(x * x + y * y + z * z - 1)
>>> p, n = crossings(f, np.array([[0.0, 0, 0]]), np.array([[2.0, 0, 0]]))
>>> bool(abs(p[0, 0] - 1) <= 2.0 ** -STEPS), n[0].round(6).tolist()   # edge 2 long
(True, [1.0, 0.0, 0.0])
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..eval.function import Function
from ..eval.gradient import evaluate_gradients
from ..eval.point import evaluate_points

__all__ = ["crossings", "unit_normals", "STEPS"]

#: bisection steps: the bracket is 2**-STEPS of the edge
STEPS = 16


def crossings(func: Any, a: np.ndarray, b: np.ndarray, steps: int = STEPS
              ) -> tuple[np.ndarray, np.ndarray]:
    """Crossing points ``(n, 3)`` and unit normals ``(n, 3)`` of edges ``a -> b``
    whose ends have opposite signs (``f < 0`` at exactly one end); ``func`` is a
    :class:`Function` or a tape valid over the edges.

    The normal is zero where the gradient is zero or not finite."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    tape = func.tape if isinstance(func, Function) else func
    n = len(a)
    if n == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    from ..eval.pool_gradients import crossing_points, tape_gradients   # (loads Numba)
    compiled = crossing_points(tape, a, b, steps)
    if compiled is not None:             # the same points and gradients, in compiled code
        points = compiled
        _, g = tape_gradients(tape, *points.T)
        return points, unit_normals(g)
    with np.errstate(all="ignore"):
        inside_a = np.broadcast_to(evaluate_points(tape, *a.T), (n,)) < 0
        lo = np.zeros(n)
        hi = np.ones(n)
        d = b - a
        for _ in range(steps):
            mid = 0.5 * (lo + hi)
            p = a + mid[:, None] * d
            inside = np.broadcast_to(evaluate_points(tape, *p.T), (n,)) < 0
            same = inside == inside_a          # the zero is in the upper half
            lo = np.where(same, mid, lo)
            hi = np.where(same, hi, mid)
        points = a + (0.5 * (lo + hi))[:, None] * d
        _, g = evaluate_gradients(tape, *points.T)
    return points, unit_normals(g)


def unit_normals(g: np.ndarray) -> np.ndarray:
    """Gradients ``(3, n)`` (or broadcastable) as unit rows ``(n, 3)``; zero where
    the gradient is zero or not finite."""
    n = np.asarray(g).reshape(3, -1).shape[1]
    g = np.asarray(g, dtype=np.float64).reshape(3, -1).T
    norm = np.linalg.norm(g, axis=1, keepdims=True)
    with np.errstate(all="ignore"):
        return np.where((norm > 0) & np.isfinite(norm), g / norm, 0.0) if n else g
