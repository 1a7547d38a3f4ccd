"""One level of the octree descent of ``(node, triangle)`` pairs, compiled.

:mod:`implicitvox.triangles.pairs` (Stolte §6: per node, the polygons that may
cross it) walks the pairs down level by level. Per pair, this loop finds the
children its triangle's bounding box reaches (exact float comparisons against
the children's edges), builds each child's box from the grid's one formula
(``origin + m * voxel_size``, :meth:`implicitvox.octree.grid.Grid.edge`, the
same float box at every level), and keeps the child if its box holds the
triangle's bounding box or if the exact box-triangle test
(:func:`implicitvox.triangles.tribox_kernels.meet_pair`) says they meet. Pairs
the test's filters leave unsure are returned apart, for the exact path.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE, down, up
from ..octree.morton_kernels import encode_one
from .tribox_kernels import meet_pair

__all__ = ["child_pairs", "voxel_pairs"]

#: slots of :func:`_voxel_pairs`'s table of voxels met (a power of two; 16³ neighbours)
_RECENT = 1 << 12


@njit(**COMPILE)
def _box_answer(v, tlo, thi, normal_sign, axis, planes, dilation, dilated, t, lo, hi, glo,
                ghi, test):
    """Triangle ``t`` against the box ``lo[0], hi[0]``: 1 when the box holds its
    bounding box; else, with ``test``, the exact test's 1, 0 or UNSURE (the box
    grown by the triangle's dilation, rounded outward), and 0 without. Compiled once,
    not inlined: both kernels call it (inlined, the test made each of them a long
    compile; on a cold cache the parallel mesh test took 217 s inlined, 57 s called)."""
    holds = True
    for a in range(3):
        holds = holds and lo[0, a] <= tlo[t, a] and thi[t, a] <= hi[0, a]
    if holds:
        return 1
    if not test:
        return 0
    for a in range(3):
        if dilated:
            glo[0, a] = down(lo[0, a] - dilation[t, a], 1)
            ghi[0, a] = up(hi[0, a] + dilation[t, a], 1)
        else:
            glo[0, a] = lo[0, a]
            ghi[0, a] = hi[0, a]
    return meet_pair(v, tlo, thi, normal_sign, axis, planes, t, lo, hi, glo, ghi, 0)


@njit(**COMPILE)
def _child_pairs(v, tlo, thi, normal_sign, axis, planes, dilation, dilated, origin, size,
                 shape, scale, nodes, tri, test, child, ctri, clo, chi, state):
    """Children of pairs ``(nodes, tri)`` at the level where a child spans ``scale``
    voxels; ``state``: 1 meets (or holds the bounding box), UNSURE; with ``test``
    False every child the bounding box reaches, its state 1 if it holds the
    bounding box, else 0 (untested). Returns the number of children written."""
    lo = np.empty((1, 3))
    hi = np.empty((1, 3))
    glo = np.empty((1, 3))
    ghi = np.empty((1, 3))
    first = np.empty(3, dtype=np.int64)
    out = 0
    for p in range(tri.size):
        t = tri[p]
        for octant in range(8):
            reach = True
            for a in range(3):
                split = (2 * nodes[p, a] + 1) * scale
                mid = origin[a] + min(split, shape[a]) * size[a]
                if (octant >> a) & 1:
                    reach = reach and split < shape[a] and thi[t, a] >= mid
                else:
                    reach = reach and tlo[t, a] <= mid
            if not reach:
                continue
            for a in range(3):
                first[a] = (2 * nodes[p, a] + ((octant >> a) & 1)) * scale
                lo[0, a] = origin[a] + first[a] * size[a]
                hi[0, a] = origin[a] + min(first[a] + scale, shape[a]) * size[a]
            answer = _box_answer(v, tlo, thi, normal_sign, axis, planes, dilation, dilated,
                                 t, lo, hi, glo, ghi, test)
            if answer == 0 and test:
                continue
            for a in range(3):
                child[out, a] = first[a] // scale
                clo[out, a] = lo[0, a]
                chi[out, a] = hi[0, a]
            ctri[out] = t
            state[out] = answer
            out += 1
    return out


def child_pairs(triangles, grid, level: int, nodes: np.ndarray, tri: np.ndarray,
                test: bool = True) -> tuple:
    """Children at ``level + 1`` of pairs ``(nodes, tri)`` (nodes: ``(m, 3)`` octant
    coordinates at ``level`` of ``grid``) that their triangle's bounding box reaches.

    Returns ``(child, tri, lo, hi, state)``: the children's coordinates, triangles
    and boxes, and per child 1 (it holds the triangle's bounding box, or, with
    ``test``, the exact test says they meet), :data:`UNSURE` (``test``: for the
    exact path) or 0 (without ``test``: not tested). With ``test``, children the
    test rules out are left out.
    """
    m = len(tri)
    child = np.empty((8 * m, 3), dtype=np.int64)
    ctri = np.empty(8 * m, dtype=np.int64)
    clo = np.empty((8 * m, 3))
    chi = np.empty((8 * m, 3))
    state = np.empty(8 * m, dtype=np.int8)
    n = 0
    if m:
        n = _child_pairs(*_kernel_arguments(triangles, grid), 1 << (grid.depth - level - 1),
                         np.ascontiguousarray(nodes, dtype=np.int64),
                         np.ascontiguousarray(tri, dtype=np.int64), bool(test),
                         child, ctri, clo, chi, state)
    return child[:n], ctri[:n], clo[:n], chi[:n], state[:n]


@njit(**COMPILE)
def _voxel_pairs(v, tlo, thi, normal_sign, axis, planes, dilation, dilated, origin, size,
                 shape, tri, first, last, codes, ctri, clo, chi, state):
    """Every voxel ``first[p] .. last[p]`` (per axis, inclusive) of each pair's triangle
    ``tri[p]`` tested (:func:`_box_answer`); those that meet or are unsure written
    with their Morton codes. Returns the number written.

    Neighbouring triangles share voxels: a voxel found to meet one is remembered
    (a small table indexed by the code's low bits, :data:`_RECENT`) and not tested
    against the next ones."""
    lo = np.empty((1, 3))
    hi = np.empty((1, 3))
    glo = np.empty((1, 3))
    ghi = np.empty((1, 3))
    recent = np.zeros(_RECENT, dtype=np.uint64)       # code + 1 of a voxel met; 0: none
    mask = np.uint64(_RECENT - 1)
    out = 0
    for p in range(tri.size):
        t = tri[p]
        for i in range(first[p, 0], last[p, 0] + 1):
            lo[0, 0] = origin[0] + i * size[0]
            hi[0, 0] = origin[0] + min(i + 1, shape[0]) * size[0]
            for j in range(first[p, 1], last[p, 1] + 1):
                lo[0, 1] = origin[1] + j * size[1]
                hi[0, 1] = origin[1] + min(j + 1, shape[1]) * size[1]
                for k in range(first[p, 2], last[p, 2] + 1):
                    lo[0, 2] = origin[2] + k * size[2]
                    hi[0, 2] = origin[2] + min(k + 1, shape[2]) * size[2]
                    code = encode_one(i, j, k)
                    if recent[code & mask] == code + np.uint64(1):
                        continue
                    answer = _box_answer(v, tlo, thi, normal_sign, axis, planes, dilation,
                                         dilated, t, lo, hi, glo, ghi, True)
                    if answer == 0:
                        continue
                    if answer == 1:
                        recent[code & mask] = code + np.uint64(1)
                    codes[out] = code
                    ctri[out] = t
                    for a in range(3):
                        clo[out, a] = lo[0, a]
                        chi[out, a] = hi[0, a]
                    state[out] = answer
                    out += 1
    return out


def voxel_pairs(triangles, grid, tri: np.ndarray, first: np.ndarray, last: np.ndarray
                ) -> tuple:
    """The voxels of ``grid`` from ``first[p]`` to ``last[p]`` (``(m, 3)`` voxel indices,
    inclusive, inside the grid) tested against triangle ``tri[p]``, all at once
    (for triangles that span a few voxels: the descent's levels would test little).

    Returns ``(codes, tri, lo, hi, state)``: the Morton codes, triangles and boxes of
    the voxels that meet their triangle (``state`` 1) or that the test leaves to
    the exact path (:data:`UNSURE`).
    """
    tri = np.ascontiguousarray(tri, dtype=np.int64)
    first = np.ascontiguousarray(first, dtype=np.int64)
    last = np.ascontiguousarray(last, dtype=np.int64)
    m = int(np.prod(last - first + 1, axis=1).sum()) if len(tri) else 0
    codes = np.empty(m, dtype=np.uint64)
    ctri = np.empty(m, dtype=np.int64)
    clo = np.empty((m, 3))
    chi = np.empty((m, 3))
    state = np.empty(m, dtype=np.int8)
    n = 0
    if m:
        n = _voxel_pairs(*_kernel_arguments(triangles, grid), tri, first, last, codes, ctri,
                         clo, chi, state)
    return codes[:n], ctri[:n], clo[:n], chi[:n], state[:n]


def _kernel_arguments(triangles, grid) -> tuple:
    """The triangles' arrays (with their dilation, zeros where none) and the grid's,
    as the kernels take them first."""
    dilated = triangles.dilation is not None
    dilation = triangles.dilation if dilated else np.zeros((1, 3))
    return (triangles.v, triangles.lo, triangles.hi, triangles.normal_sign, triangles.axis,
            triangles.planes.rows, dilation, dilated,
            np.asarray(grid.origin, dtype=np.float64),
            np.asarray(grid.voxel_size, dtype=np.float64),
            np.asarray(grid.shape, dtype=np.int64))
