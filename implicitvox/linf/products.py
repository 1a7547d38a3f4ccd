"""Products with a short inner dimension, in plain numpy arithmetic (no BLAS).

``a @ b`` on float64 arrays goes to the BLAS. For the tall products of the
distance kernels (``(n, 3) @ (3, m)``, ``n`` in the tens of thousands) OpenBLAS
wakes its worker threads, which then spin-wait for a while after the call: on
the 2-core test machine that doubled the CPU time of OpenSCAD's rotated-cubes
model (``examples/Old/example014.scad`` at 128³: 0.39 s of CPU over 0.22 s of
wall time, 0.22 s with ``OPENBLAS_NUM_THREADS=1``), and in a parallel run such
threads take the other worker's core. With an inner dimension of 2 or 3 the
BLAS buys nothing; :func:`dot` sums the terms in a fixed order instead, so the
result is also the same on every machine and BLAS build.

Examples
--------
>>> import numpy as np
>>> p = np.array([[1.0, 2.0, 3.0], [0.0, 1.0, 0.0]])
>>> dot(p, np.array([1.0, 0.0, -1.0])).tolist()
[-2.0, 0.0]
>>> dot(p, np.eye(3)[:, :2]).tolist()
[[1.0, 2.0], [0.0, 1.0]]
"""
from __future__ import annotations

import numpy as np

__all__ = ["dot"]


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b`` for ``a`` of shape ``(..., k)`` and ``b`` of shape ``(k,)`` or
    ``(k, m)``, ``k`` small: ``sum_i a[..., i] b[i]``, summed left to right."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if b.ndim == 1:
        out = a[..., 0] * b[0]
        for i in range(1, b.shape[0]):
            out = out + a[..., i] * b[i]
        return out
    out = a[..., 0, None] * b[0]
    for i in range(1, b.shape[0]):
        out += a[..., i, None] * b[i]
    return out
