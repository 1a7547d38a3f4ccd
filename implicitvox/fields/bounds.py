"""The error bound of a suitable solid (Bærentzen §6.1) and ray directions.

Examples
--------
>>> round(float(analytic_error_bound(3.0)), 4)
0.2958
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["analytic_error_bound", "fibonacci_directions"]


def analytic_error_bound(r: Any) -> Any:
    """``3 / (8 (r - √3))`` voxels for ``r > √3`` (Bærentzen eq. 22), ``inf`` below."""
    r = np.asarray(r, dtype=np.float64)
    with np.errstate(divide="ignore"):
        out = np.where(r > math.sqrt(3), 3.0 / (8.0 * (r - math.sqrt(3))), np.inf)
    return out if out.ndim else float(out)


def fibonacci_directions(count: int) -> np.ndarray:
    """``count`` unit vectors spread evenly over the sphere."""
    k = np.arange(count) + 0.5
    z = 1 - 2 * k / count
    angle = np.pi * (1 + 5 ** 0.5) * k
    rho = np.sqrt(1 - z * z)
    return np.stack([rho * np.cos(angle), rho * np.sin(angle), z], axis=1)
