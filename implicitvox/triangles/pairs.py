"""Octree subdivision of a triangle set: the voxels whose closed boxes meet a triangle.

Stolte §6 voxelizes a polygon mesh by recursive subdivision with, per
octree node, the list of polygons that may cross it (his per-polygon
bitmaps). Here the lists are arrays of ``(node, triangle)`` pairs, level by
level in chunks of bounded size:

1. a pair's children are only those its triangle's bounding box reaches
   (exact float comparisons against the children's edges);
2. a child whose box holds the triangle's whole bounding box meets it (no
   test needed); the others go through the exact box-triangle test of
   :mod:`implicitvox.triangles.tribox`;
3. at the voxel level, the voxels met by any pair are the output.

A triangle whose bounding box reaches only a few voxels (at most
:data:`SMALL_VOXELS`; most triangles of a scanned mesh) skips the levels: each
of those voxels is tested against it directly, in compiled code
(:func:`implicitvox.triangles.pair_kernels.voxel_pairs`), with the same exact
test and the same float boxes.

Both filters are exact, so the result is exactly the set of voxels whose
closed box meets a triangle: nothing missed, nothing extra. Box corners are
the grid's edges (:meth:`Grid.edge`, one formula), so a voxel's box is the
same float box at every level and in every test.

Examples
--------
>>> import numpy as np
>>> from implicitvox.octree.grid import Grid
>>> from implicitvox.triangles.tribox import Triangles
>>> tri = Triangles(np.array([[[0.1, 0.1, 0.5], [0.9, 0.1, 0.5], [0.1, 0.9, 0.5]]]))
>>> codes = surface_codes(tri, Grid.from_bounds(((0, 0, 0), (1, 1, 1)), 4))
>>> len(codes)   # z = 0.5 is the edge between voxel layers 1 and 2: 13 voxels in each
26
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from ..octree import morton
from ..octree.grid import Grid
from .ranges import expand_boxes
from .tribox import Triangles
from .. import batches
from ..parallel import PIECES_PER_WORKER, Job, farm

__all__ = ["surface_codes", "start_pairs", "small_codes", "run_pairs", "split_pairs", "PairsJob",
           "sorted_unique", "CHUNK", "SMALL_VOXELS", "SMALL_TESTS"]

#: (node, triangle) pairs per chunk
CHUNK = batches.TRIANGLE_PAIRS
#: triangles whose bounding box reaches at most this many voxels have them all
#: tested at once: the descent's levels above would test little (the bunny at 512,
#: one worker: 1.59 s with none, 1.34 s at 64, 0.89 s at 256, 1.04 s at 512)
SMALL_VOXELS = 256
#: voxel tests per call for those (bounds the arrays: about 65 bytes each)
SMALL_TESTS = 1 << 20


def _boxes(grid: Grid, level: int, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Float corners ``(m, 3)`` of nodes at ``level``, cropped to the grid."""
    scale = 1 << (grid.depth - level)
    first = nodes * scale
    last = np.minimum(first + scale, np.asarray(grid.shape, dtype=np.int64))
    lo = np.empty(nodes.shape, dtype=np.float64)
    hi = np.empty(nodes.shape, dtype=np.float64)
    for a in range(3):
        lo[:, a] = grid.edge(a, first[:, a])
        hi[:, a] = grid.edge(a, last[:, a])
    return lo, hi


def _children(tris: Triangles, grid: Grid, level: int, nodes: np.ndarray,
              tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Children at ``level + 1`` of pairs ``(nodes, tri)`` that meet their triangle
    (compiled: :func:`implicitvox.triangles.pair_kernels.child_pairs`; the pairs
    its filters leave unsure on the exact path)."""
    from .pair_kernels import child_pairs     # (loads Numba: not at import)
    from .tribox_kernels import settled
    child, tri, lo, hi, state = child_pairs(tris, grid, level, nodes, tri)
    keep = settled(state, tris.meet_by_arrays, tri, lo, hi) == 1
    return child[keep], tri[keep]


def _leaf_codes(tris: Triangles, grid: Grid, nodes: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Morton codes of the voxels (children of ``nodes``) that some triangle meets.

    A voxel needs one witness: the candidates (children the triangles' bounding
    boxes reach) are grouped by voxel (one sort), and each voxel's are tested
    in order until one meets
    (:meth:`~implicitvox.triangles.tribox.Triangles.meet_any`).
    """
    from .pair_kernels import child_pairs     # (loads Numba: not at import)
    child, tri, lo, hi, _ = child_pairs(tris, grid, grid.depth - 1, nodes, tri, test=False)
    codes = morton.encode(child)
    order = np.argsort(codes, kind="stable")
    codes, tri, lo, hi = codes[order], tri[order], lo[order], hi[order]
    new = np.empty(len(codes), dtype=bool)
    new[:1] = True
    np.not_equal(codes[1:], codes[:-1], out=new[1:])
    start = np.append(np.flatnonzero(new), len(codes))
    return codes[new][tris.meet_any(tri, lo, hi, start)]


def _first_voxel(grid: Grid, axis: int, t: np.ndarray) -> np.ndarray:
    """Smallest voxel index whose closed box reaches up to ``t`` (``edge(m + 1) >= t``)."""
    m = np.floor((t - grid.origin[axis]) / grid.voxel_size[axis])
    m = np.clip(np.nan_to_num(m), -1, grid.shape[axis]).astype(np.int64)
    for _ in range(2):  # correct the division's rounding against the edge formula
        m = np.where(grid.edge(axis, m + 1) < t, m + 1, m)
        m = np.where(grid.edge(axis, m) >= t, m - 1, m)
    return m


def _last_voxel(grid: Grid, axis: int, t: np.ndarray) -> np.ndarray:
    """Largest voxel index whose closed box reaches down to ``t`` (``edge(m) <= t``)."""
    m = np.floor((t - grid.origin[axis]) / grid.voxel_size[axis])
    m = np.clip(np.nan_to_num(m), -1, grid.shape[axis]).astype(np.int64)
    for _ in range(2):
        m = np.where(grid.edge(axis, m) > t, m - 1, m)
        m = np.where(grid.edge(axis, m + 1) <= t, m + 1, m)
    return m


def _start_pairs(tris: Triangles, grid: Grid) -> tuple[list, tuple]:
    """Each triangle's first ``(level, nodes)``: the deepest level whose nodes are at least
    as wide as its bounding box, and the (at most 3 per axis) nodes that box reaches.
    The levels above hold it in one node each: walking them would test nothing.

    Triangles whose bounding box reaches at most :data:`SMALL_VOXELS` voxels are
    returned apart, as ``(tri, first, last)`` (their voxel ranges): their voxels are
    tested at once.
    """
    n = len(tris)
    first = np.empty((n, 3), dtype=np.int64)
    last = np.empty((n, 3), dtype=np.int64)
    ratio = np.zeros(n)
    for a in range(3):
        first[:, a] = np.maximum(_first_voxel(grid, a, tris.lo[:, a]), 0)
        last[:, a] = np.minimum(_last_voxel(grid, a, tris.hi[:, a]), grid.shape[a] - 1)
        ratio = np.maximum(ratio, (tris.hi[:, a] - tris.lo[:, a]) / grid.voxel_size[a])
    inside = np.all(first <= last, axis=1)
    with np.errstate(divide="ignore"):
        up = np.ceil(np.log2(np.maximum(ratio, 1.0)))
    level = np.clip(grid.depth - up, 0, grid.depth).astype(np.int64)
    small = inside & (np.prod(last - first + 1, axis=1) <= SMALL_VOXELS)
    tri = np.flatnonzero(inside & ~small)
    level = level[tri]
    shift = (grid.depth - level)[:, None]
    lo_node, hi_node = first[tri] >> shift, last[tri] >> shift
    pair_tri, nodes = expand_boxes(lo_node, hi_node)
    out = []
    for lev in range(grid.depth + 1):
        sel = np.flatnonzero(level[pair_tri] == lev)
        if len(sel):
            out.append((lev, nodes[sel], tri[pair_tri[sel]]))
    small = np.flatnonzero(small)
    return out, (small, first[small], last[small])


def surface_codes(tris: Triangles, grid: Grid,
                  progress: Optional[Callable[[float], Any]] = None, *,
                  workers: int = 1, executor: Any = None) -> np.ndarray:
    """Sorted unique Morton codes of the voxels whose closed boxes meet a triangle.

    With ``workers`` > 1 or an ``executor``, the pairs are cut into subtrees
    (:func:`split_pairs`), the small triangles into runs of about equal tests, and
    both farmed out (:class:`PairsJob`); each piece's voxels are exactly the serial
    run's of it, so the result is the same array.
    """
    parallel = (workers > 1 or executor is not None) and grid.depth >= 3
    deferred: Optional[list] = [] if parallel else None
    stack, found = start_pairs(tris, grid, None if parallel else progress, small=deferred,
                               parts=PIECES_PER_WORKER * workers)
    if deferred is not None:
        _, pieces = split_pairs(tris, grid, stack, PIECES_PER_WORKER * workers) if stack \
            else (0, [])
        stack = []                  # every pair that may meet a voxel is in a piece
        if deferred:                # the first run here: its kernel is compiled (and cached)
            found.append(small_codes(tris, grid, deferred.pop(0)))   # before workers need it
        pieces = pieces + [("voxels",) + chunk for chunk in deferred]
        if pieces:
            job = PairsJob(tris, grid)
            weights = [sum(len(n) for _, n, _ in piece) if isinstance(piece, list) else
                       int(np.prod(piece[3] - piece[2] + 1, axis=1).sum()) for piece in pieces]
            for _, codes in farm(job, pieces, workers=workers, executor=executor,
                                 weights=weights, progress=progress,
                                 what=f"voxelizing the mesh at {grid.shape}"):
                found.append(codes)
    found.extend(run_pairs(tris, grid, stack, progress))
    if not found:
        return np.zeros(0, dtype=np.uint64)
    return sorted_unique(np.concatenate(found))


def start_pairs(tris: Triangles, grid: Grid,
                progress: Optional[Callable[[float], Any]] = None, *,
                small: Optional[list] = None, parts: int = 1) -> tuple[list, list[np.ndarray]]:
    """The first pairs of every triangle (:func:`_start_pairs`), tested: a stack of
    ``(level, nodes, tri, weight)`` above the voxels (weights: shares of the
    work, what the small triangles took left out) and the codes of voxels already
    found: the small triangles' voxels all found here (``progress`` told), or, given
    a list ``small``, their runs ``(tri, first, last)`` (at least ``parts`` of them
    where there are enough) appended to it for :func:`small_codes`."""
    starts, few = _start_pairs(tris, grid)
    total = sum(len(nodes) for _, nodes, _ in starts) or 1
    share = 0.0                     # of the progress, the small triangles' (run here)
    if small is None and len(few[0]):
        big = len(np.unique(np.concatenate([t for *_, t in starts]))) if starts else 0
        share = len(few[0]) / (len(few[0]) + big)
    stack: list[tuple[int, np.ndarray, np.ndarray, float]] = []
    found: list[np.ndarray] = []
    chunks = _small_chunks(few, parts if small is not None else 1)
    if small is not None:
        small.extend(chunks)
        chunks = []
    for k, chunk in enumerate(chunks):
        found.append(small_codes(tris, grid, chunk))
        if progress is not None:
            progress(share * (k + 1) / len(chunks))
    for level, nodes, tri in starts:
        # the start nodes only share a bounding box with their triangle: test them
        lo, hi = _boxes(grid, level, nodes)
        holds = np.all((lo <= tris.lo[tri]) & (tris.hi[tri] <= hi), axis=1)
        test = np.flatnonzero(~holds)
        holds[test] = tris.meet_boxes(tri[test], lo[test], hi[test])
        weight = (1.0 - share) * len(nodes) / total
        if level == grid.depth:
            found.append(sorted_unique(morton.encode(nodes[holds])))
        else:
            _push(stack, level, nodes[holds], tri[holds], weight)
    return stack, found


def _small_chunks(few: tuple, parts: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The small triangles ``(tri, first, last)`` in runs of at most :data:`SMALL_TESTS`
    voxel tests, and at least ``parts`` runs where there are that many triangles."""
    tests = np.cumsum(np.prod(few[2] - few[1] + 1, axis=1))
    if not len(tests):
        return []
    step = max(1, min(SMALL_TESTS, int(tests[-1]) // max(parts, 1)))
    cuts = np.unique(np.searchsorted(tests, np.arange(step, tests[-1], step), side="right"))
    return [tuple(c[a:b] for c in few) for a, b in zip(np.r_[0, cuts], np.r_[cuts, len(tests)])
            if b > a]


def small_codes(tris: Triangles, grid: Grid,
                chunk: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
    """Sorted codes of the voxels that the small triangles of ``chunk`` (``tri, first,
    last``: their voxel ranges) meet, each voxel tested directly
    (:func:`implicitvox.triangles.pair_kernels.voxel_pairs`, the unsure pairs settled
    on the exact path)."""
    from .pair_kernels import voxel_pairs       # (loads Numba: not at import)
    from .tribox_kernels import settled
    codes, tri, lo, hi, state = voxel_pairs(tris, grid, *chunk)
    return sorted_unique(codes[settled(state, tris.meet_by_arrays, tri, lo, hi) == 1])


def run_pairs(tris: Triangles, grid: Grid, stack: list,
              progress: Optional[Callable[[float], Any]] = None) -> list[np.ndarray]:
    """Subdivide the pairs on ``stack`` (depth first) to the voxels; the codes found."""
    found: list[np.ndarray] = []
    done = 1.0 - sum(weight for *_, weight in stack)
    while stack:
        level, nodes, t, weight = stack.pop()
        if level == grid.depth - 1:
            found.append(_leaf_codes(tris, grid, nodes, t))
            done += weight
        else:
            child, ct = _children(tris, grid, level, nodes, t)
            if len(child):
                _push(stack, level + 1, child, ct, weight)
            else:
                done += weight
        if progress is not None:
            progress(min(done, 1.0))
    return found


def split_pairs(tris: Triangles, grid: Grid, stack: list, pieces: int
                ) -> tuple[int, list[list[tuple[int, np.ndarray, np.ndarray]]]]:
    """Cut the pairs on ``stack`` into at most ``pieces`` sets of whole subtrees.

    The split level ``L`` is the first with at least four nodes per piece (or
    two levels above the voxels); pairs above it are subdivided down to it
    here (the tests the serial run makes), and every pair goes with its node's
    ancestor at ``L``. The ancestors, in Morton order, are cut into contiguous
    runs of about equal pair counts: each piece is a list of ``(level, nodes,
    tri)``. Returns ``(L, pieces)``; no pieces when the grid is too shallow.
    """
    if grid.depth < 3 or not stack:
        return 0, []
    entries = [(lvl, nodes, t) for lvl, nodes, t, _ in stack]
    level = 0
    while level < grid.depth - 2:
        level += 1
        deep = [morton.encode(n >> (lvl - level)) for lvl, n, _ in entries if lvl >= level]
        if deep and len(np.unique(np.concatenate(deep))) >= 4 * pieces:
            break
    expanded = []
    for lvl, nodes, t in entries:
        while lvl < level and len(nodes):
            nodes, t = _children(tris, grid, lvl, nodes, t)
            lvl += 1
        if len(nodes):
            expanded.append((lvl, nodes, t, morton.encode(nodes >> (lvl - level))))
    if not expanded:
        return level, []
    keys = np.concatenate([a for *_, a in expanded])
    ancestors, counts = np.unique(keys, return_counts=True)
    # contiguous runs of ancestors with about equal pair counts
    before = np.cumsum(counts) - counts
    piece_of = (before * pieces) // counts.sum()
    out: list[list] = [[] for _ in range(pieces)]
    for lvl, nodes, t, anc in expanded:
        piece = piece_of[np.searchsorted(ancestors, anc)]
        order = np.argsort(piece, kind="stable")
        piece, nodes, t = piece[order], nodes[order], t[order]
        edges = np.searchsorted(piece, np.arange(pieces + 1))
        for k in range(pieces):
            if edges[k + 1] > edges[k]:
                out[k].append((lvl, nodes[edges[k]:edges[k + 1]], t[edges[k]:edges[k + 1]]))
    return level, [p for p in out if p]


class PairsJob(Job):
    """The triangles and the grid, shared by every piece of a parallel mesh voxelization."""

    def __init__(self, tris: Triangles, grid: Grid):
        super().__init__()
        self.tris, self.grid = tris, grid

    def run(self, piece: Any) -> np.ndarray:
        """The sorted codes of the voxels met in the subtrees of ``piece`` (a list of
        ``(level, nodes, tri)``), or by its small triangles (``("voxels", tri, first,
        last)``: :func:`small_codes`)."""
        if isinstance(piece, tuple):
            return small_codes(self.tris, self.grid, piece[1:])
        stack: list = []
        for level, nodes, t in piece:
            _push(stack, level, nodes, t, 0.0)
        found = run_pairs(self.tris, self.grid, stack)
        return sorted_unique(np.concatenate(found)) if found else np.zeros(0, dtype=np.uint64)


def sorted_unique(codes: np.ndarray) -> np.ndarray:
    """``np.unique`` by sorting (numpy's hash-based unique is slower on uint64 codes)."""
    codes.sort()
    keep = np.empty(len(codes), dtype=bool)
    keep[:1] = True
    np.not_equal(codes[1:], codes[:-1], out=keep[1:])
    return codes[keep]


def _push(stack, level, nodes, tri, weight) -> None:
    """Push pairs in chunks of at most ``CHUNK``, last chunk on top (depth first)."""
    n = len(nodes)
    if n == 0:
        return
    if level > 0 and n > CHUNK:
        # keep spatial locality: sort pairs by node before cutting
        order = np.argsort(morton.encode(nodes), kind="stable")
        nodes, tri = nodes[order], tri[order]
    pieces = range(0, n, CHUNK)
    for s in reversed(pieces):
        e = min(s + CHUNK, n)
        stack.append((level, nodes[s:e], tri[s:e], weight * (e - s) / n))
