"""Points on a true surface, by bisection to machine precision, and voxel look-ups."""
from __future__ import annotations

from typing import Callable, Optional

import numpy as np

import implicitvox as ivx


def uniform_inside(func: ivx.Function, bounds) -> Callable:
    lo, hi = (np.asarray(b, dtype=float) for b in bounds)

    def sample(rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(lo, hi, (n, 3))
    return sample


def surface_brackets(func: ivx.Function, bounds, step: float, n_target: int,
                     rng: np.random.Generator, inside: Optional[Callable] = None,
                     batch: int = 200_000, max_rounds: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(a, b)`` of points, ``f(a) < 0 <= f(b)``, bisected until they meet.

    Segments start at points inside the solid (from ``inside`` or uniform
    samples) and run ``0.5 .. 8`` times ``step`` in a random direction; a
    true zero of ``f`` lies between the ends of each returned pair.
    """
    lo, hi = (np.asarray(b, dtype=float) for b in bounds)
    inside = inside or uniform_inside(func, bounds)
    got_a, got_b, total = [], [], 0
    for _ in range(max_rounds):
        a = inside(rng, batch)
        a = a[np.all((a >= lo) & (a <= hi), axis=1)]
        a = a[func(a[:, 0], a[:, 1], a[:, 2]) < 0]
        d = rng.normal(size=a.shape)
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        b = np.clip(a + d * rng.uniform(0.5, 8.0, (len(a), 1)) * step, lo, hi)
        fb = func(b[:, 0], b[:, 1], b[:, 2])
        a, b = a[fb > 0], b[fb > 0]
        for _ in range(80):
            mid = 0.5 * (a + b)
            fm = func(mid[:, 0], mid[:, 1], mid[:, 2])
            neg = fm < 0
            a = np.where(neg[:, None], mid, a)
            b = np.where(neg[:, None], b, mid)
        got_a.append(a)
        got_b.append(b)
        total += len(a)
        if total >= n_target:
            break
    return np.concatenate(got_a)[:n_target], np.concatenate(got_b)[:n_target]


def found(vox_contains: Callable[[np.ndarray], np.ndarray], grid: ivx.Grid,
          a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each bracket: is a voxel whose closed box holds either end in the output?"""
    hit = np.zeros(len(a), dtype=bool)
    for p in (a, b):
        for cand in grid.voxels_holding(p):
            ok = np.all(cand >= 0, axis=1)
            hit[ok] |= vox_contains(cand[ok])
    return hit


def corner_sign_voxels(func: ivx.Function, grid: ivx.Grid) -> np.ndarray:
    """The dense baseline (Frey & Borouchaki, as Stolte §1 describes it): a
    voxel is kept when ``f`` changes sign among its 8 corners."""
    axes = [grid.edge(a, np.arange(grid.shape[a] + 1)) for a in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    s = func(X, Y, Z) <= 0
    lo = np.ones(grid.shape, dtype=bool)
    hi = np.zeros(grid.shape, dtype=bool)
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                c = s[dx:dx + grid.shape[0], dy:dy + grid.shape[1], dz:dz + grid.shape[2]]
                lo &= c
                hi |= c
    return hi & ~lo
