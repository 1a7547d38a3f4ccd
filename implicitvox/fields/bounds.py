"""The error bound of a suitable solid (Bærentzen §6.1).

Examples
--------
>>> round(float(analytic_error_bound(3.0)), 4)
0.2958
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["analytic_error_bound"]


def analytic_error_bound(r: Any) -> Any:
    """``3 / (8 (r - √3))`` voxels for ``r > √3`` (Bærentzen eq. 22), ``inf`` below."""
    r = np.asarray(r, dtype=np.float64)
    with np.errstate(divide="ignore"):
        out = np.where(r > math.sqrt(3), 3.0 / (8.0 * (r - math.sqrt(3))), np.inf)
    return out if out.ndim else float(out)
