"""The adaptive grid without complex cells (Varadhan et al. §5.2).

A cell is *complex* when the surface meets it but no edge of it shows a sign
change. Contouring cannot see such a surface: marching cubes or dual
contouring put nothing there, and where a coarse complex cell meets finer
cells that do see the surface, the mesh cracks (Varadhan Fig. 8). The grid
is therefore built as in §5.2:

1. the cells the surface may meet are found by the voxelizer
   (:func:`implicitvox.octree.subdivide.subdivide`: interval arithmetic,
   Stolte §2, and the shape's exact test where it has one, Varadhan §5.1)
   down to the *tolerance level*, whose cells are no larger than the
   tolerance allows;
2. below it, a cell the surface may meet is kept as a leaf when it is
   *simple*: some edge shows a sign change, and the interval gradient over
   the cell says the surface in it is one monotone sheet (every component of
   the gradient has one sign, or one component is bounded away from 0, so
   each line along that axis meets the surface once), or has no enclosure
   at all (sweeps, singular points: splitting would not tell more);
3. a cell whose corners all have one sign holds no surface point when the
   corners' enclosures (outward rounded) stay beyond the *leak* that the
   interval gradient allows (:func:`_monotone`; 0 where ``f`` is monotone
   along every axis, so its extremes are at corners), when its subtree shows
   that (:func:`_search`), or, for shapes with an exact test, when
   the surface touches only its boundary (:func:`_touch_only`). It is
   dropped;
4. a cell without a sign change whose subtree shows one within three
   levels (:func:`_search`) is subdivided, down to ``refine`` levels below
   the tolerance level; one whose subtree shows none, but is not cleared
   either, stays a *complex* leaf, as do cells still complex at the finest
   level (see below).

What this gives (the argument of §5.2, with this implementation's
rounding). Every point ``p`` of the surface lies in a leaf: cells are only
dropped on an outward-rounded enclosure or an exact test that excludes the
surface. A leaf with a sign change gets a contour vertex inside it
(:mod:`implicitvox.meshing.contour`), so ``p`` is within the leaf's size
``s`` of the mesh in the max norm (``s·√3`` Euclidean). Every mesh triangle
joins vertices of the cells around one edge that holds a zero of ``f`` (its
ends have opposite signs), so every mesh point is within the largest of
those cells' sizes of that zero. With every leaf no larger than ``h``, the
two-sided Hausdorff distance is at most ``h`` in the max norm and ``h·√3``
Euclidean. The exceptions are the uncertified cells (a surface detail
smaller than the search reaches, a tangency, or a zero set that changes no
sign, such as the face two parts of a union share, which is no boundary of
the solid): a complex leaf is covered when every point of it is within the
bound of a vertex of a leaf around it; the others are reported, never
hidden. Signs at corners are those of the float64
point values, computed by one formula per lattice point, so neighbours agree.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np

from ..eval.function import Function
from ..interval import rounding
from ..octree.grid import Grid
from ..octree.guard import MemoryGuard
from ..octree import morton
from ..octree.morton import CORNERS, NEIGHBOURS
from ..octree.octants import run_counts
from ..octree.subdivide import Subdivision, classify, subdivide
from ..expr.shape import AMBIGUOUS
from .cell_tapes import CellTapes

__all__ = ["AdaptiveGrid", "adaptive_grid", "corner_values", "BYTES_PER_CELL",
           "LEAF_LEVELS_UP"]

#: bytes per leaf cell at the peak: coordinates, level, 8 corner values, flags, and the
#: contouring's edges, crossings and quadric sums (``bench_mesh_memory.py``: the peak's
#: growth over the run's start is 885-1,193 bytes per leaf on the seven models at 256
#: and 512)
BYTES_PER_CELL = 1280
#: cells classified per numpy call below the tolerance level
_CHUNK = 1 << 14
#: the cells take the pruned tape of their ancestor this many levels above the
#: tolerance level's voxels (valid over them all). With a Python call per tape, a tape
#: per voxel or two cost more than the shorter tapes saved (the level-3 sponge at 128:
#: 24.5 s at 0, 11.9 at 3); on the pool's rows (:mod:`.cell_tapes`) 1 is best (2.85-3.14 s
#: at 1, 3.45-3.55 s at 3, alternately; the same mesh)
LEAF_LEVELS_UP = 1
#: a gradient component counts as one-signed when its other side is within this
#: share of the largest component (an exact 0 rounded outward)
_FLAT = 1e-9
#: the shrink of a cell, relative to its size, for :func:`_touch_only`
_SHRINK = 2.0 ** -20
#: levels a cell without a sign change is searched below for one (3 resolves a
#: sheet 0.1 of the tolerance thick: cells of tolerance / (8 √3) land in it)
_SEARCH = 3


@dataclass
class AdaptiveGrid:
    """The leaves of an adaptive grid (see the module docstring).

    Attributes
    ----------
    grid : Grid
        The finest grid: its voxels are the cells ``refine`` levels below the
        tolerance level, and ``grid.depth`` is that level.
    tolerance_level : int
        The level of the cells no larger than the tolerance allows; leaves are
        at this level or deeper.
    levels : ndarray of int8, (n,)
        Each leaf's level.
    coords : ndarray of int64, (n, 3)
        Each leaf's integer coordinates at its level.
    corners : ndarray of float64, (n, 8)
        ``f`` at the leaf's corners (corner ``c`` at offset
        ``(c & 1, c >> 1 & 1, c >> 2 & 1)``).
    simple : ndarray of bool, (n,)
        Sign change and one monotone sheet (the leaves above the finest level
        all are).
    complex : ndarray of bool, (n,)
        Leaves that the surface may meet but whose corners show no sign change
        (at the finest level, or where :func:`_search` found none below): they get no vertex, and the Hausdorff bound covers
        them only where a neighbour's vertex is near enough
        (:func:`implicitvox.meshing.contour.dual_contour` checks).
    cells_evaluated : int
        Cells classified below the tolerance level.
    tapes : CellTapes
        The pruned tapes of the voxelization (each of its pool's tapes once).
    tape_index : ndarray of int64, (n,)
        The tape valid over each leaf (that of the voxel holding it).
    """

    grid: Grid
    tolerance_level: int
    levels: np.ndarray
    coords: np.ndarray
    corners: np.ndarray
    simple: np.ndarray
    complex: np.ndarray
    cells_evaluated: int
    tapes: CellTapes
    tape_index: np.ndarray

    @property
    def count(self) -> int:
        """The number of leaves."""
        return len(self.levels)

    def sizes(self) -> np.ndarray:
        """Each leaf's edge length in world units (the longest axis for
        non-cubic cells)."""
        h = max(self.grid.voxel_size)
        return h * np.exp2(self.grid.depth - self.levels.astype(np.float64))


def corner_values(tapes: CellTapes, tid: np.ndarray, grid: Grid, level: int,
                  coords: np.ndarray) -> np.ndarray:
    """``f`` (float64) at the 8 corners of cells ``coords`` at ``level`` of
    ``grid``, each cell on tape ``tid[i]`` of ``tapes`` (valid over it); each lattice
    point's position comes from :meth:`Grid.edge`, so every cell sharing a corner
    sees the same value."""
    out = np.empty((len(coords), 8))
    for s in range(0, len(coords), _CHUNK):
        pos = corner_positions(grid, level, coords[s:s + _CHUNK])
        out[s:s + _CHUNK] = tapes.values(np.repeat(tid[s:s + _CHUNK], 8), *pos).reshape(-1, 8)
    return out


def corner_positions(grid: Grid, level: int, coords: np.ndarray) -> tuple[np.ndarray, ...]:
    """World ``x, y, z`` columns of the 8 corners of each cell (cell-major), by
    :meth:`Grid.edge` on the finest lattice: one position per lattice point."""
    scale = 1 << (grid.depth - level)
    idx = (coords[:, None, :].astype(np.int64) + CORNERS[None]) * scale     # (n, 8, 3)
    return tuple(grid.edge(a, np.minimum(idx[..., a], grid.shape[a])).ravel() for a in range(3))


def _monotone(tapes: CellTapes, tid: np.ndarray, grid: Grid, level: int, coords: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(weak, strict, leak)`` from the interval gradient over each cell.

    ``weak``: every component has one sign (up to ``_FLAT`` of the largest, the
    outward rounding of an exact 0), or there is no gradient enclosure (the
    sweeps' oracles give none; nor does a singular point), where splitting
    would tell no more; ``strict``: some component is bounded away
    from 0; ``leak``: an upper bound of how far ``f`` inside the cell can
    pass the range of its corner values. For each axis, moving from a point
    to the face on the mostly-downhill side changes ``f`` by at most the
    smaller one-sided slope times the width (the mean value theorem), so
    ``min(corners) - leak <= f <= max(corners) + leak`` over the cell;
    infinite where the mean value theorem may fail (domain edges, jumps)."""
    lo, hi = grid.octant_boxes(level, coords)
    _, _, glo, ghi, valid = tapes.interval_gradients(tid, lo, hi)
    with np.errstate(all="ignore"):
        glo, ghi = np.asarray(glo, dtype=np.float64), np.asarray(ghi, dtype=np.float64)
        valid = np.asarray(valid) & np.isfinite(glo).all(0) & np.isfinite(ghi).all(0)
        one_sided = np.minimum(np.maximum(ghi, 0.0), np.maximum(-glo, 0.0))       # (3, n)
        width = np.stack([h - l for l, h in zip(lo, hi)])
        leak = rounding.up_nonneg((one_sided * width).sum(0) * (1 + 1e-12))
        scale = np.maximum(np.abs(glo), np.abs(ghi)).max(0)
    leak = np.where(valid, leak, np.inf)
    # no gradient enclosure (a sweep's instances, a singular point): splitting tells no
    # more, so the cell counts as one sheet ("weak")
    weak = ~valid | (one_sided <= _FLAT * scale).all(0)
    strict = valid & ((glo > 0) | (ghi < 0)).any(0)
    return weak, strict, leak


def _corners_exclude(tapes: CellTapes, tid: np.ndarray, grid: Grid, level: int,
                     coords: np.ndarray, leak: np.ndarray) -> np.ndarray:
    """True where the outward-rounded enclosures of ``f`` at all 8 corners lie
    beyond ``leak`` on one side of 0: then ``f`` has that sign on the whole cell."""
    pos = corner_positions(grid, level, coords)
    flo, fhi = tapes.intervals(np.repeat(tid, 8), pos, pos)
    with np.errstate(all="ignore"):
        flo, fhi = flo.reshape(-1, 8), fhi.reshape(-1, 8)
        return (rounding.down(flo.min(1) - leak) > 0) | (rounding.up(fhi.max(1) + leak) < 0)


def _children(grid: Grid, level: int, coords: np.ndarray, owner: Optional[np.ndarray] = None
              ) -> Any:
    """The children of cells at ``level``, cropped to the grid (and the
    ``owner`` of each, repeated from its parent's, when given)."""
    kids = (coords[:, None, :] * 2 + CORNERS[None]).reshape(-1, 3)
    scale = 1 << (grid.depth - level - 1)
    inside = (kids * scale < np.asarray(grid.shape)).all(1)
    if owner is None:
        return kids[inside]
    return kids[inside], np.repeat(owner, 8)[inside]


def _touch_only(exact: Optional[Callable], grid: Grid, level: int, cells: np.ndarray
                ) -> np.ndarray:
    """True where the shape's exact test clears the cell shrunk by ``_SHRINK`` of
    its size: the surface meets the closed cell on its boundary at most (a face
    of the solid on a lattice plane). Such surface points are also in the cells
    across that boundary; the corner sign convention (0 counts as outside) gives
    the cells on the solid's side of such a face a sign change, so they hold
    the vertex. Without an exact test, nothing is cleared."""
    if exact is None or not len(cells):
        return np.zeros(len(cells), dtype=bool)
    lo, hi = grid.octant_boxes(level, cells)
    lo, hi = np.stack(lo, 1), np.stack(hi, 1)
    pad = (hi - lo) * _SHRINK
    return np.asarray(exact(lo + pad, hi - pad)) != AMBIGUOUS


def _search(func: Function, grid: Grid, level: int, cells: np.ndarray,
            exact: Optional[Callable], levels: int, tapes: CellTapes, tid: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """For cells without a sign change that no certificate empties: search their
    subtrees ``levels`` levels down (at most to ``grid.depth``), each with its
    cell's tape (tape ``tid[i]`` of ``tapes``).

    Returns ``(shows, empty)``: a descendant shows a sign change (surface the
    corners miss: a thin sheet, a bump through a face; the cell is split), or
    every descendant is rejected (interval or exact test, corners beyond the
    leak, boundary contact only; the cell is dropped). Cells with neither hold
    a zero set that changes no sign this deep (a face shared by two parts of a
    union, a tangency, detail below the search): complex leaves. Most such
    cells lie just beside the surface and empty in a level or two."""
    shows = np.zeros(len(cells), dtype=bool)
    undecided = np.zeros(len(cells), dtype=bool)
    owner = np.arange(len(cells))
    current = cells
    stop = min(grid.depth, level + levels)
    while len(current) and level < stop:
        current, owner = _children(grid, level, current, owner)
        level += 1
        states = classify(func, grid, level, current, exact, mean_value=True)
        current, owner = current[states == AMBIGUOUS], owner[states == AMBIGUOUS]
        if not len(current):
            break
        inside = corner_values(tapes, tid[owner], grid, level, current) < 0
        change = inside.any(1) & ~inside.all(1)
        shows[owner[change]] = True
        rest = ~change & ~shows[owner]
        if rest.any():
            sub, sub_tid = current[rest], tid[owner[rest]]
            _, _, leak = _monotone(tapes, sub_tid, grid, level, sub)
            keep = ~_corners_exclude(tapes, sub_tid, grid, level, sub, leak)
            keep[keep] = ~_touch_only(exact, grid, level, sub[keep])
            rest[rest] = keep
        current, owner = current[rest], owner[rest]
    undecided[owner] = True
    return shows, ~shows & ~undecided




def _beside(cells: np.ndarray, split: np.ndarray) -> np.ndarray:
    """Cells that are, or touch (faces, edges or corners), a cell marked ``split``.

    The cells split for showing no sign change are where the surface may poke
    through a face between corners. Splitting their neighbours too keeps the
    change of level a cell away, where the finer side's extra samples on a
    shared face show no crossing that the coarser side misses, so the contour
    stays manifold across it."""
    if not split.any():
        return split
    codes = morton.encode(cells)
    near = (cells[split][:, None, :] + NEIGHBOURS[None]).reshape(-1, 3)
    near = near[(near >= 0).all(1)]
    return split | np.isin(codes, morton.encode(near))


def adaptive_grid(func: Function, grid: Grid, refine: int, *,
                  exact: Optional[Callable] = None, exact_voxels: Optional[Callable] = None,
                  progress: Optional[Callable[[float], Any]] = None,
                  guard: Optional[MemoryGuard] = None, prune: bool = True,
                  voxels: Optional[Subdivision] = None) -> AdaptiveGrid:
    """Build the adaptive grid of the module docstring.

    Parameters
    ----------
    func : Function
        The compiled implicit function.
    grid : Grid
        The tolerance level's grid (its voxels are the largest leaves).
    refine : int
        Levels below ``grid`` that complex cells may be subdivided to.
    exact, exact_voxels : callable, optional
        The shape's exact box tests (:func:`implicitvox.expr.shape.exact_classifier`,
        :func:`~implicitvox.expr.shape.voxel_classifier`).
    progress : callable, optional
        Called with the share of work done (0 to 1).
    guard : MemoryGuard, optional
        Asked with the cells kept after every level.
    prune : bool, default: True
        Prune the tapes of the voxelization down to the tolerance level.
    voxels : Subdivision, optional
        That voxelization, done already (by workers:
        :func:`implicitvox.octree.subtrees.subdivide_in_parallel`, with its tapes).
        Its voxels are taken in Morton order, so the leaves, and the mesh, do
        not depend on the order the subdivision found them in.

    Examples
    --------
    >>> import implicitvox as iv
    >>> from implicitvox import x, y, z
    >>> from implicitvox.octree.grid import Grid
    >>> g = Grid.from_bounds(((-1.2,) * 3, (1.2,) * 3), 8)
    >>> a = adaptive_grid(iv.compile(x * x + y * y + z * z - 1), g, refine=2)
    >>> bool(a.simple.all()), int(a.complex.sum()), int(a.levels.min()) == g.depth
    (True, 0, True)
    """
    top = grid.depth
    fine = grid.finer(refine)
    depth = top + refine
    share = (lambda s: progress(s)) if progress is not None else (lambda s: None)
    if voxels is None:
        voxels = subdivide(func, grid, exact=exact, exact_voxels=exact_voxels, guard=guard,
                           prune=prune, progress=(lambda s: share(0.6 * s)),
                           leaf_level=max(top - LEAF_LEVELS_UP, 0))
    tapes, of_run = CellTapes.of_runs(voxels.tapes, func.tape)
    tid = np.repeat(of_run, run_counts(voxels.tapes)) \
        if len(voxels.tapes) else np.zeros(len(voxels.codes), dtype=np.int64)
    order = np.argsort(voxels.codes, kind="stable")
    cells = morton.decode(voxels.codes[order]).astype(np.int64)
    tid = tid[order]
    kept: dict[str, list] = {k: [] for k in ("levels", "coords", "corners", "simple",
                                             "complex", "tid")}
    evaluated = 0
    total = 0
    for level in range(top, depth + 1):
        if level > top and len(cells):
            states = np.concatenate([
                classify(func, fine, level, cells[s:s + _CHUNK], exact, mean_value=True)
                for s in range(0, len(cells), _CHUNK)])
            evaluated += len(cells)
            cells, tid = cells[states == AMBIGUOUS], tid[states == AMBIGUOUS]
        if not len(cells):
            break
        values = corner_values(tapes, tid, fine, level, cells)
        inside = values < 0
        change = inside.any(1) & ~inside.all(1)
        weak, strict, leak = _monotone(tapes, tid, fine, level, cells)
        simple = change & (weak | strict)
        empty = np.zeros(len(cells), dtype=bool)
        test = ~change & np.isfinite(leak)
        if test.any():
            empty[test] = _corners_exclude(tapes, tid[test], fine, level, cells[test],
                                           leak[test])
        test = ~change & ~empty
        if test.any():
            empty[test] = _touch_only(exact, fine, level, cells[test])
        stuck = np.zeros(len(cells), dtype=bool)     # complex, no sign change found below
        test = ~change & ~empty
        if test.any() and level < depth:
            shows, cleared = _search(func, fine, level, cells[test], exact, _SEARCH, tapes,
                                     tid[test])
            empty[test] = cleared
            stuck[test] = ~shows & ~cleared
        leaf = simple | stuck | ((level == depth) & ~empty)
        if level < depth:
            leaf &= ~_beside(cells, ~leaf & ~empty & ~change)
        for key, part in (("levels", np.full(int(leaf.sum()), level, dtype=np.int8)),
                          ("coords", cells[leaf]), ("corners", values[leaf]),
                          ("simple", simple[leaf]), ("complex", ~change[leaf]),
                          ("tid", tid[leaf])):
            kept[key].append(part)
        total += int(leaf.sum())
        split = ~leaf & ~empty
        if level < depth:
            cells, tid = _children(fine, level, cells[split], tid[split])
        else:
            cells, tid = cells[:0], tid[:0]
        if guard is not None:
            guard.check(voxels=total, octants=len(cells))
        share(0.6 + 0.4 * (level - top + 1) / (refine + 1))
    def join(key, shape, dtype):
        return np.concatenate(kept[key]) if kept[key] else np.zeros(shape, dtype=dtype)
    return AdaptiveGrid(fine, top, join("levels", (0,), np.int8), join("coords", (0, 3), np.int64),
                        join("corners", (0, 8), np.float64), join("simple", (0,), bool),
                        join("complex", (0,), bool), evaluated, tapes,
                        join("tid", (0,), np.int64))
