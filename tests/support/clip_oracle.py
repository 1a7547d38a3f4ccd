"""An independent, exact box-triangle oracle: clip the triangle by the box's six
closed half-spaces in rational arithmetic (Sutherland-Hodgman) and see if
anything is left. Slow (pure Python, Fractions); for tests only."""
from __future__ import annotations

from fractions import Fraction

import numpy as np


def _clip(poly, axis, bound, keep_below):
    """Keep the part of polygon ``poly`` with ``p[axis] <= bound`` (or ``>=``)."""
    def inside(p):
        return p[axis] <= bound if keep_below else p[axis] >= bound
    if len(poly) == 1:
        return poly if inside(poly[0]) else []
    out = []
    for i, cur in enumerate(poly):
        prev = poly[i - 1]
        if inside(cur):
            if not inside(prev):
                out.append(_cross(prev, cur, axis, bound))
            out.append(cur)
        elif inside(prev):
            out.append(_cross(prev, cur, axis, bound))
    return out


def _cross(p, q, axis, bound):
    t = (bound - p[axis]) / (q[axis] - p[axis])
    return tuple(p[a] + t * (q[a] - p[a]) for a in range(3))


def triangle_meets_box(tri, lo, hi) -> bool:
    """Exact: does the closed triangle ``tri`` (3, 3) meet the closed box ``[lo, hi]``?"""
    poly = [tuple(Fraction(float(c)) for c in v) for v in np.asarray(tri)]
    for axis in range(3):
        poly = _clip(poly, axis, Fraction(float(hi[axis])), True)
        if not poly:
            return False
        poly = _clip(poly, axis, Fraction(float(lo[axis])), False)
        if not poly:
            return False
    return True
