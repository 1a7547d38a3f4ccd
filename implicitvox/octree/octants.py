"""What both subdivisions share: octant states, the exact tests' pass, the recheck's
suspects, Morton packing, progress, and the :class:`Subdivision` they return.

The subdivision runs in compiled code (:mod:`implicitvox.octree.descend`) for
every tape the compiled kernel takes, and on the array evaluator
(:mod:`implicitvox.octree.subdivide`) for the others (tapes with sweeps); both
classify a box the same way from its enclosure (Stolte §2):

* EMPTY - ``flo > 0`` (or the function is undefined over it): outside;
* FULL - ``fhi < 0``: inside the solid, kept as one coarse octant (interior);
* AMBIGUOUS - neither: subdivided; at the target depth, a surface voxel.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Iterator, Optional, Sequence

import numpy as np

from ..eval.function import Function
from ..eval.mean_value import mean_value_enclosure
from ..eval.tape import Tape
from ..expr.shape import AMBIGUOUS, FULL, Octants, takes_octants
from . import morton
from .grid import Grid
from .level_dtype import interval_dtype

__all__ = ["Subdivision", "PrunedTapes", "TapeRuns", "classify_root", "ROOT_CODE", "runs_compiled",
           "COMPILED_MIN_LENGTH", "MAX_SIDE", "run_counts", "recount", "states", "classify",
           "tighten", "pack", "axes", "unpack",
           "suspect_voxels", "inside_children", "Progress", "by_tapes", "RECHECK"]

#: default strength of the recheck (:func:`suspect_voxels`; measured in
#: tests/benchmarks/bench_voxelize.py): 1/4 selects the voxels whose sub-voxels
#: are predicted to settle them
RECHECK = 0.25
_CHILD_OFFSETS = morton.CORNERS.astype(np.int32)
#: tapes of at least this many instructions run on the compiled kernel even without a
#: branch (shorter formulas stay on the array evaluator's float32 kernels for now:
#: tests/benchmarks/bench_voxelize.py)
COMPILED_MIN_LENGTH = 16
#: the compiled subdivision tabulates child edges for grids up to this many voxels a
#: side (the recheck's grid, one level finer, included)
MAX_SIDE = 1 << 15
_SWEEPS = ("repeat", "repeat_polar")


#: the root octant's Morton code (one entry)
ROOT_CODE = np.zeros(1, dtype=np.uint64)


def classify_root(func: Function, grid: Grid, exact, exact_voxels, mean_value: bool,
                  interior: bool, interior_parts: dict, run: dict) -> bool:
    """Classify the root octant, the first step of both subdivisions: a FULL root
    goes into ``interior_parts`` (with ``interior``); returns whether it is
    AMBIGUOUS (to be subdivided, or a surface voxel on a one-voxel grid, where
    the voxels' exact test decides)."""
    state = classify(func, grid, 0, np.zeros((1, 3), dtype=np.int32),
                     exact_voxels if grid.depth == 0 else exact, mean_value, run=run)[0]
    if state == FULL and interior:
        interior_parts[0] = [ROOT_CODE.copy()]
    return state == AMBIGUOUS


def runs_compiled(tape: Tape, grid: Grid) -> bool:
    """Does the subdivision of ``tape`` on ``grid`` run on the compiled kernel
    (:mod:`implicitvox.octree.descend`)? Tapes without a sweep (the compiled
    kernel drives none) that have a branch to prune per box (``min``, ``max``,
    ``abs``) or :data:`COMPILED_MIN_LENGTH` instructions, on grids of at most
    :data:`MAX_SIDE` voxels a side. The rest runs on the array evaluator
    (:mod:`implicitvox.octree.subdivide`). A box's state depends on the box and
    this choice alone, so every run over a tape and grid agrees."""
    if max(grid.shape) >= MAX_SIDE or any(ins.op.name in _SWEEPS for ins in tape.instructions):
        return False
    return bool(tape.branches) or len(tape) >= COMPILED_MIN_LENGTH


class TapeRuns(Sequence):
    """Runs ``(count, tape)`` over a subdivision's voxels, each tape built when first
    read: the compiled subdivision gives thousands of regions their own tape
    (pool tapes, :mod:`implicitvox.eval.tape_pool`), and a plain voxelization
    reads none of them.

    Parameters
    ----------
    counts : array of int
        Voxels per run.
    build : callable
        ``build(i)``: the tape of run ``i``.
    pool : TapePool, optional
        The pool the tapes come from, with ``ids``, each run's pool tape (for
        compiled code that runs them without building them:
        :mod:`implicitvox.eval.pool_gradients`).
    """

    def __init__(self, counts: Any, build: Callable[[int], Tape], pool: Any = None,
                 ids: Any = None):
        self.counts = np.asarray(counts, dtype=np.int64)
        self._build = build
        self._built: dict[int, Tape] = {}
        self.pool = pool
        self.ids = None if ids is None else np.asarray(ids, dtype=np.int64)

    def __len__(self) -> int:
        return len(self.counts)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError(i)
        return int(self.counts[i]), self.tape(i)

    def __iter__(self) -> Iterator[tuple[int, Tape]]:
        return (self[i] for i in range(len(self)))

    def tape(self, i: int) -> Tape:
        """The tape of run ``i`` (built once)."""
        found = self._built.get(i)
        if found is None:
            found = self._built[i] = self._build(i)
        return found

    def __reduce__(self):
        """Pickled as a list of built runs (a worker's pruned tapes survive the process
        boundary; the pool they come from stays behind)."""
        return (list, (list(self),))

    def recounted(self, counts: Any) -> "TapeRuns":
        """The runs with ``counts`` voxels instead, runs of none dropped."""
        counts = np.asarray(counts, dtype=np.int64)
        kept = np.flatnonzero(counts)
        return TapeRuns(counts[kept], lambda i: self.tape(int(kept[i])), self.pool,
                        None if self.ids is None else self.ids[kept])


@dataclass(frozen=True)
class PrunedTapes:
    """The tapes of some octants in a pool of the compiled kernel: octant ``i`` has
    pool tape ``tapes[i]`` of ``pool`` (a :class:`~implicitvox.eval.tape_pool.TapePool`,
    which a subdivision continuing from them copies, never changes)."""

    pool: Any
    #: int32, one per octant
    tapes: np.ndarray

    def __len__(self) -> int:
        return len(self.tapes)

    def take(self, which: Any) -> "PrunedTapes":
        """The tapes of the octants ``which`` (an index, slice or mask)."""
        return PrunedTapes(self.pool, self.tapes[which])


def run_counts(runs: Sequence) -> np.ndarray:
    """Voxels per run of ``runs`` (a list of ``(count, tape)`` or :class:`TapeRuns`),
    without building a tape."""
    if isinstance(runs, TapeRuns):
        return runs.counts
    return np.array([n for n, _ in runs], dtype=np.int64)


def recount(runs: Sequence, counts: Any) -> Sequence:
    """``runs`` with ``counts`` voxels per run instead, runs of none dropped."""
    if isinstance(runs, TapeRuns):
        return runs.recounted(counts)
    return [(int(c), t) for c, (_, t) in zip(counts, runs) if c]


@dataclass
class Subdivision:
    """What a subdivision found."""

    #: Morton codes (uint64) of the surface voxels, in no particular order
    codes: np.ndarray
    #: FULL octants per level: level -> (m, 3) int32 coordinates at that level, in
    #: Morton order
    interior: dict[int, np.ndarray] = field(default_factory=dict)
    #: octants classified (boxes evaluated)
    evaluated: int = 0
    #: the tapes valid over the voxels, as runs ``(count, tape)`` in the order of
    #: :attr:`codes` (pruned tapes, :mod:`implicitvox.eval.pruning`; with
    #: ``leaf_level``, the tape of each code's ancestor at that level)
    tapes: list = field(default_factory=list)
    #: distinct pruned tapes built
    tapes_built: int = 0
    #: with ``until_level``: the AMBIGUOUS octants reached at that level (Morton
    #: codes, sorted), not subdivided further: the subtrees a parallel run hands out
    pending: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.uint64))
    #: on the compiled kernel: the pruned tapes of :attr:`pending` (a subdivision
    #: continued from them with ``start_tapes`` evaluates what this one would have)
    pending_tapes: Optional["PrunedTapes"] = None

    @property
    def surface(self) -> np.ndarray:
        """The surface voxels' coordinates, (n, 3) int32, in the order of :attr:`codes`."""
        return unpack(self.codes)


def states(flo: np.ndarray, fhi: np.ndarray) -> np.ndarray:
    """EMPTY where ``flo > 0`` (also the empty interval ``(inf, -inf)``: undefined),
    else FULL where ``fhi < 0``, else AMBIGUOUS; branch-free (the masks are random)."""
    state = np.subtract(AMBIGUOUS, fhi < 0.0, dtype=np.int8)   # FULL = AMBIGUOUS - 1
    state *= flo <= 0.0                                         # EMPTY = 0
    return state


def classify(func: Function, grid: Grid, level: int, coords: np.ndarray,
             exact: Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]] = None,
             mean_value: bool = False, dtype=None, run: Optional[dict] = None) -> np.ndarray:
    """States (int8) of octants ``coords`` at ``level``: EMPTY, FULL or AMBIGUOUS.

    The natural interval extension decides first; octants it leaves
    AMBIGUOUS get the mean value form (:mod:`implicitvox.eval.mean_value`) when
    ``mean_value``, then the shape's exact test. A box's state depends on the
    box alone, not on the level or the run, so ``Voxels.refine`` matches a
    direct voxelization: the natural extension runs in the float type that
    :func:`implicitvox.octree.level_dtype.interval_dtype` picks for the box size
    (``dtype`` None), or in ``dtype``. ``run``: the subdivision's scratch space,
    for an exact test that takes the octants (:class:`~implicitvox.expr.shape.Octants`).
    """
    lo, hi = grid.octant_boxes(level, coords)
    if runs_compiled(func.tape, grid):       # in float64, as octree.descend
        from ..eval.compiled import compiled_tape, evaluate_boxes   # (loads Numba)
        flo, fhi = evaluate_boxes(compiled_tape(func.tape), np.stack(lo), np.stack(hi))
    else:
        if dtype is None:
            dtype = interval_dtype(func.tape, grid, level)
        flo, fhi = func.interval_columns(lo, hi, dtype)
    state = states(flo, fhi)
    octants = None if run is None else Octants(level, pack(coords), run)
    return tighten(func.tape, lo, hi, flo, fhi, state, exact, mean_value, octants)


def tighten(tape: Tape, lo, hi, flo: np.ndarray, fhi: np.ndarray, state: np.ndarray,
             exact, mean_value: bool, octants: Optional[Octants] = None) -> np.ndarray:
    """Settle the AMBIGUOUS states further: the mean value form (reusing the
    natural bounds ``flo, fhi`` already computed), then the exact test (given
    the ``octants`` of the boxes when it takes them)."""
    if mean_value:
        amb = np.flatnonzero(state == AMBIGUOUS)
        if amb.size:
            sub_lo, sub_hi = tuple(c[amb] for c in lo), tuple(c[amb] for c in hi)
            mlo, mhi = mean_value_enclosure(tape, sub_lo, sub_hi, (flo[amb], fhi[amb]))
            state[amb] = states(mlo, mhi)
    if exact is not None:
        amb = np.flatnonzero(state == AMBIGUOUS)
        if amb.size:
            lo_arr = np.stack([c[amb] for c in lo], axis=1)
            hi_arr = np.stack([c[amb] for c in hi], axis=1)
            if octants is not None and takes_octants(exact):
                state[amb] = exact(lo_arr, hi_arr, octants.subset(amb))
            else:
                state[amb] = exact(lo_arr, hi_arr)
    return state



def pack(coords: np.ndarray) -> np.ndarray:
    return morton.encode(np.asarray(coords).reshape(-1, 3))


def axes(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    c = morton.decode(keys)
    return c[:, 0], c[:, 1], c[:, 2]


def unpack(keys: np.ndarray) -> np.ndarray:
    return morton.decode(keys).astype(np.int32)



def suspect_voxels(flo: np.ndarray, fhi: np.ndarray, m: int, recheck: float,
                   inside: Optional[np.ndarray] = None) -> np.ndarray:
    """Which voxels (the ``8 m`` children of ``m`` octants, child-major, with
    enclosures ``[flo, fhi]``) to recheck on their sub-voxels.

    A natural interval enclosure of width ``W`` overestimates the true range
    ``w`` of ``f`` over a voxel (by the triangle inequality, where the terms of
    ``f`` partly cancel; Stolte §1). The 8 children of one octant sit on a
    2 x 2 x 2 lattice one voxel apart, so the spread of their enclosures'
    midpoints (each ``f`` at a child centre, to second order) estimates ``w``
    without further evaluation: ``rho = spread / W`` (for linear ``f``, exactly
    ``w / W``). A sub-voxel's enclosure is about ``W / 2`` wide and centred up
    to ``w / 4`` nearer 0 than the voxel's midpoint ``c``, so all 8 exclude 0
    when ``|c| > (W + w) / 4``: when 0 lies within ``(1 - rho) / 4`` of the
    width from an end. A voxel is a suspect when 0 lies within ``recheck (1 -
    rho) W`` of an end: ``recheck = 1/4`` is the prediction itself, larger
    values recheck more. Children outside the grid (``inside`` False) do not
    count in the spread. For affine ``f`` the prediction is exact
    (``tests/test_voxelize.py``).

    Examples
    --------
    One octant whose 8 children have enclosures of width 1 and midpoints
    spread over 0.49 (``rho = 0.49``): the suspects are those with 0 within
    ``0.25 * 0.51`` of an end.

    >>> import numpy as np
    >>> mid = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.45, 0.48, 0.49])
    >>> suspect_voxels(mid - 0.5, mid + 0.5, 1, 0.25)
    array([False, False, False, False,  True,  True,  True,  True])
    """
    with np.errstate(invalid="ignore"):   # in float64 also for float32 bounds (exactly)
        twice_mid = np.add(flo, fhi, dtype=np.float64).reshape(8, m)
        if inside is not None:
            twice_mid[~inside.reshape(8, m)] = np.nan
        spread = np.fmax.reduce(twice_mid, axis=0)          # fmax, fmin: NaN ignored
        spread -= np.fmin.reduce(twice_mid, axis=0)
        spread *= 0.5
        margin = np.subtract(fhi, flo, dtype=np.float64)
        margin.reshape(8, m)[...] -= spread
        margin *= recheck
        return np.minimum(-flo, fhi) <= margin



def inside_children(grid: Grid, level: int, axes) -> Optional[np.ndarray]:
    """Which children (child-major, ``8 m``) at ``level`` of the parents with
    coordinates ``axes`` meet the grid (None: all)."""
    if all(n == 1 << grid.depth for n in grid.shape):
        return None
    limits = [-(-n // (1 << (grid.depth - level))) for n in grid.shape]  # octants per axis
    inside = np.ones((8, len(axes[0])), dtype=bool)
    for a in range(3):
        inside &= (axes[a][None, :] * 2 + _CHILD_OFFSETS[:, a, None]) < limits[a]
    return inside.reshape(-1)


class Progress:
    """Share of the estimated work done, reported non-decreasing.

    The number of octants to classify grows about 4 times per level near a
    surface (Stolte §4.1.3), so the children of ``m`` pending octants at level
    ``l`` are estimated at ``8 m (4**(depth - l) - 1) / 3`` classifications.
    """

    def __init__(self, hook: Optional[Callable[[float], Any]], depth: int):
        self.hook, self.depth, self.done, self.last = hook, depth, 0, 0.0

    def estimate(self, m: int, level: int) -> float:
        return 8.0 * m * (4.0 ** (self.depth - level) - 1.0) / 3.0

    def report(self, frontier: Any) -> None:
        if self.hook is None:
            return
        pending = sum(self.estimate(count, lvl) for lvl, count in frontier.sizes())
        share = self.done / (self.done + pending) if pending else 1.0
        self.last = max(self.last, min(share, 1.0))
        self.hook(self.last)



def by_tapes(parts: list) -> list:
    """Parts ``(codes, tape, leaf_tape)`` merged where both tapes are the same objects."""
    merged: dict[tuple[int, int], tuple[list, Any, Any]] = {}
    for codes, tape, leaf_tape in parts:
        merged.setdefault((id(tape), id(leaf_tape)), ([], tape, leaf_tape))[0].append(codes)
    return [(np.concatenate(c) if len(c) > 1 else c[0], tape, leaf_tape)
            for c, tape, leaf_tape in merged.values()]
