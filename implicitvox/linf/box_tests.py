"""Exact voxel tests from max-norm distances (Varadhan §5.1).

A closed box with centre ``c`` and half-sizes ``h`` is the unit ball of the
max-norm weighted by ``h`` around ``c``, so the surface meets it iff the
weighted distance ``D_h(c) <= 1``; if ``D_h(c) < -1`` the box is inside the
solid (FULL), if ``> 1`` outside (EMPTY). A box touching the surface in a
single boundary point has ``D = 1`` exactly and counts as meeting it; so does
one within the rounding of ``c`` and ``D`` of 1 (:data:`TIE_ULPS`).
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from ..expr.shape import AMBIGUOUS, EMPTY, FULL

__all__ = ["classify_by_distance", "Primitive", "TIE_ULPS"]

#: the rounding, in units of the box's coordinates' ulp over its half-size, within
#: which a distance of 1 (a box touching the surface) counts as a tie
TIE_ULPS = 16


def classify_by_distance(distance: Callable, lo: np.ndarray, hi: np.ndarray,
                         signed: bool = True) -> np.ndarray:
    """EMPTY / FULL / AMBIGUOUS of boxes ``[lo, hi]`` from a signed (or unsigned)
    weighted max-norm distance function ``distance(points, weights)``."""
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    centre = 0.5 * (lo + hi)
    half_width = 0.5 * (hi - lo)
    half = np.where(half_width > 0, half_width, np.finfo(np.float64).tiny)
    # a flat or tiny box's weights divide to +-inf (or a sphere's centre meets a zero
    # weight): the weighted distance of a box farther than any float is that infinity,
    # the right value; where infinities meet (inf - inf) the distance is NaN, which
    # compares false both ways below and leaves the box AMBIGUOUS (subdivided, never
    # wrongly decided). Neither is a fault, so numpy says nothing of them here
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        d = distance(centre, half)
    # A tie (the surface touching the closed box) computes to 1 only up to the
    # rounding of the centre and of the distance: a box touching a face on a lattice
    # plane could come out EMPTY while its parent, touching the same face, came out
    # AMBIGUOUS. Within that rounding the box counts as met (never a missed voxel).
    # Per axis, the centre's rounding over the half-size; an axis of zero width has
    # an exact centre (and no rounding to allow for).
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(half_width > 0, np.maximum(np.abs(lo), np.abs(hi)) / half_width, 0.0)
    tie = TIE_ULPS * np.finfo(np.float64).eps * (1.0 + ratio.max(axis=1))
    out = np.full(len(lo), AMBIGUOUS, dtype=np.int8)
    out[d > 1 + tie] = EMPTY
    if signed:
        out[d < -1 - tie] = FULL
    return out


class Primitive:
    """Base of the max-norm primitives: a subclass gives ``distance(points,
    weights)`` (signed, weighted per axis) and ``expr``; the exact box test
    (§5.1) comes from the distance here, once for all of them."""

    #: is the distance signed (a closed solid)? An open mesh's is not.
    signed: bool = True

    def distance(self, points: Any, weights: Optional[Any] = None) -> np.ndarray:
        raise NotImplementedError

    def classify_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """EMPTY / FULL / AMBIGUOUS of boxes ``[lo, hi]`` (``(n, 3)`` each), exactly."""
        return classify_by_distance(self.distance, lo, hi, signed=self.signed)

    def distance_function(self, norm: str) -> Optional[Callable]:
        """The exact signed distance in ``norm`` (``"linf"``: ``distance(points,
        weights)``; ``"euclidean"``: ``euclidean_distance(points)``), or None where
        this primitive has none (:mod:`implicitvox.fields` then certifies one)."""
        if norm == "linf":
            return self.distance
        return getattr(self, "euclidean_distance", None)
