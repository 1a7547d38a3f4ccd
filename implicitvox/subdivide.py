"""Robust octree subdivision: interval arithmetic on a frontier of octants.

Stolte §2 (Fig. 1): evaluate the inclusion function over an octant; if the
interval excludes 0 the surface does not pass through it and the octant is
rejected, otherwise it is subdivided, down to the voxel level. Every octant
is one of

* EMPTY - ``flo > 0`` (or the function is undefined over it): outside;
* FULL - ``fhi < 0``: inside the solid, kept as one coarse octant (interior);
* AMBIGUOUS - neither: subdivided; at the target depth, a surface voxel.

Since each inclusion function encloses the exact range, an octant the
surface meets is never EMPTY or FULL: no surface voxel is ever missed.

The frontier is processed as a stack of chunks of octant coordinates (at
most ``chunk`` octants, one interval evaluation each), deepest first, so
memory stays bounded by ``8 * chunk * depth`` octants whatever the
resolution. Each chunk is an independent set of subtrees (the unit a
parallel driver hands out; Stolte §5.2).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from .function import Function
from .grid import Grid
from .mean_value import mean_value_enclosure
from .shape import AMBIGUOUS, EMPTY, FULL

__all__ = ["subdivide", "Subdivision", "classify", "CHUNK"]

#: octants classified per interval evaluation
CHUNK = 1 << 17
_CHILD_OFFSETS = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=np.int32)


@dataclass
class Subdivision:
    """What a subdivision found."""

    #: surface voxels (n, 3) int32, in no particular order
    surface: np.ndarray
    #: FULL octants per level: level -> (m, 3) int32 coordinates at that level
    interior: dict[int, np.ndarray] = field(default_factory=dict)
    #: octants classified (boxes evaluated)
    evaluated: int = 0


def _states(flo: np.ndarray, fhi: np.ndarray) -> np.ndarray:
    state = np.full(flo.shape[0], AMBIGUOUS, dtype=np.int8)
    state[fhi < 0.0] = FULL
    state[flo > 0.0] = EMPTY  # also the empty interval (inf, -inf): undefined
    return state


def classify(func: Function, grid: Grid, level: int, coords: np.ndarray,
             exact: Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]] = None,
             mean_value: bool = True) -> np.ndarray:
    """States (int8) of octants ``coords`` at ``level``: EMPTY, FULL or AMBIGUOUS.

    The natural interval extension decides first; octants it leaves
    AMBIGUOUS get the mean value form (:mod:`implicitvox.mean_value`) when
    ``mean_value``, then the shape's exact test. A box's state depends on the
    box alone, not on the level or the run, so ``Voxels.refine`` matches a
    direct voxelization.
    """
    lo, hi = grid.octant_boxes(level, coords)
    flo, fhi = func.interval_columns(lo, hi)
    state = _states(flo, fhi)
    if mean_value:
        amb = np.flatnonzero(state == AMBIGUOUS)
        if amb.size:
            sub_lo, sub_hi = tuple(c[amb] for c in lo), tuple(c[amb] for c in hi)
            mlo, mhi = mean_value_enclosure(func.tape, sub_lo, sub_hi, (flo[amb], fhi[amb]))
            state[amb] = _states(mlo, mhi)
    if exact is not None:
        amb = np.flatnonzero(state == AMBIGUOUS)
        if amb.size:
            lo_arr = np.stack([c[amb] for c in lo], axis=1)
            hi_arr = np.stack([c[amb] for c in hi], axis=1)
            state[amb] = exact(lo_arr, hi_arr)
    return state


def _children(grid: Grid, level: int, parents: np.ndarray) -> np.ndarray:
    """The 8 children of each parent at ``level + 1``, cropped to the grid."""
    kids = (parents[:, None, :] * 2 + _CHILD_OFFSETS[None, :, :]).reshape(-1, 3)
    scale = 1 << (grid.depth - level - 1)
    inside = np.all(kids * scale < np.asarray(grid.shape), axis=1)
    return kids[inside]


class _Progress:
    """Share of the estimated work done, reported non-decreasing.

    The number of octants to classify grows about 4 times per level near a
    surface (Stolte §4.1.3), so a pending chunk of ``m`` octants at level ``l``
    is estimated at ``m * (4**(depth - l + 1) - 1) / 3`` classifications.
    """

    def __init__(self, hook: Optional[Callable[[float], Any]], depth: int):
        self.hook, self.depth, self.done, self.last = hook, depth, 0, 0.0

    def estimate(self, m: int, level: int) -> float:
        return m * (4.0 ** (self.depth - level + 1) - 1.0) / 3.0

    def report(self, stack: list) -> None:
        if self.hook is None:
            return
        pending = sum(self.estimate(len(c), lvl) for lvl, c in stack)
        share = self.done / (self.done + pending) if pending else 1.0
        self.last = max(self.last, min(share, 1.0))
        self.hook(self.last)


def subdivide(func: Function, grid: Grid, *, start: Optional[tuple[int, np.ndarray]] = None,
              interior: bool = False, exact=None, progress=None, chunk: int = CHUNK,
              mean_value: bool = True) -> Subdivision:
    """Classify octants from the root (or from ``start``) down to the voxels.

    Parameters
    ----------
    func : Function
        The compiled implicit function.
    grid : Grid
        The voxel grid; the octree has ``grid.depth`` levels below the root.
    start : (level, coords), optional
        Octants to classify first (default: the root). ``Voxels.refine``
        passes the stored surface voxels' children here.
    interior : bool, default: False
        Record FULL octants.
    exact : callable, optional
        The shape's exact box test, applied to interval-AMBIGUOUS octants.
    progress : callable, optional
        Called with the estimated share of work done, in [0, 1].
    chunk : int
        Octants per interval evaluation.
    mean_value : bool, default: True
        Tighten AMBIGUOUS octants with the mean value form.
    """
    depth = grid.depth
    level0, coords0 = start if start is not None else (0, np.zeros((1, 3), dtype=np.int32))
    stack: list[tuple[int, np.ndarray]] = [
        (level0, coords0[s:s + chunk]) for s in range(0, max(len(coords0), 1), chunk)]
    surface: list[np.ndarray] = []
    interior_parts: dict[int, list[np.ndarray]] = {}
    meter = _Progress(progress, depth)
    evaluated = 0
    while stack:
        level, octants = stack.pop()
        if len(octants) == 0:
            continue
        state = classify(func, grid, level, octants, exact, mean_value)
        evaluated += len(octants)
        meter.done += len(octants)
        if interior:
            full = octants[state == FULL]
            if len(full):
                interior_parts.setdefault(level, []).append(full)
        ambiguous = octants[state == AMBIGUOUS]
        if level == depth:
            surface.append(ambiguous)
        elif len(ambiguous):
            kids = _children(grid, level, ambiguous)
            stack.extend((level + 1, kids[s:s + chunk]) for s in range(0, len(kids), chunk))
        meter.report(stack)
    empty = np.zeros((0, 3), dtype=np.int32)
    return Subdivision(
        surface=np.concatenate(surface).astype(np.int32) if surface else empty,
        interior={lvl: np.concatenate(parts).astype(np.int32)
                  for lvl, parts in sorted(interior_parts.items())},
        evaluated=evaluated)

