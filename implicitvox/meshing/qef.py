"""Dual contouring's vertex: the quadric error function (Ju et al. 2002).

A cell's vertex minimises ``E(v) = Σ_i (n_i · (v - p_i))²`` over the edge
crossings ``p_i`` with normals ``n_i`` in the cell: on a flat patch that is
any point of the plane, at a sharp edge a point of the edge, at a corner the
corner. The normal equations ``A v = b`` (``A = Σ n_i n_iᵀ``,
``b = Σ n_i n_iᵀ p_i``) are solved about the mass point ``m`` (the mean of the
``p_i``) with the eigenvalues of ``A`` below ``TRUNCATE`` times the largest
set to zero (the pseudo-inverse Ju et al. and Lindstrom use; compiled,
:mod:`.qef_kernels`), so the free
directions of a flat or edge-like patch stay at ``m``. A vertex outside its
cell is clamped into it: the Hausdorff bound of
:mod:`implicitvox.meshing.adaptive` needs each vertex in its cell.

Examples
--------
>>> import numpy as np
>>> p = np.array([[1.0, 0.2, 0.5], [0.3, 1.0, 0.5]])       # on x = 1 and on y = 1
>>> n = np.array([[1.0, 0, 0], [0, 1.0, 0]])
>>> v = solve(np.zeros(2, dtype=np.int64), p, n, 1, np.zeros((1, 3)), np.full((1, 3), 2.0))
>>> v.round(6).tolist()                                   # the sharp edge, at the mean z
[[1.0, 1.0, 0.5]]
"""
from __future__ import annotations

from typing import Optional

import numpy as np

__all__ = ["solve", "TRUNCATE"]

#: relative eigenvalue threshold of the pseudo-inverse
TRUNCATE = 0.1


def solve(cell: np.ndarray, points: np.ndarray, normals: np.ndarray, n_cells: int,
          lo: np.ndarray, hi: np.ndarray, crossing: Optional[np.ndarray] = None
          ) -> np.ndarray:
    """The vertex ``(n_cells, 3)`` of each cell from its crossings.

    ``cell[i]`` is the cell of crossing ``i`` (of crossing ``crossing[i]`` when given:
    a crossing shared by several cells is stored once); ``lo, hi`` ``(n_cells, 3)``
    the cells' boxes. A cell without crossings gets its box centre."""
    from .qef_kernels import qef_vertices, quadric_sums          # (loads Numba)
    cell = np.asarray(cell, dtype=np.int64)
    crossing = np.arange(len(cell)) if crossing is None else \
        np.asarray(crossing, dtype=np.int64)
    count, mass, A, rhs = quadric_sums(cell, crossing,
                                       np.ascontiguousarray(points, dtype=np.float64),
                                       np.ascontiguousarray(normals, dtype=np.float64), n_cells)
    return qef_vertices(count, mass, A, rhs, np.ascontiguousarray(lo, dtype=np.float64),
                        np.ascontiguousarray(hi, dtype=np.float64), TRUNCATE)
