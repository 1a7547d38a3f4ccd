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
from .tribox_kernels import UNSURE, meet_pair

__all__ = ["child_pairs"]


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
            holds = True
            for a in range(3):
                first[a] = (2 * nodes[p, a] + ((octant >> a) & 1)) * scale
                last = min(first[a] + scale, shape[a])
                lo[0, a] = origin[a] + first[a] * size[a]
                hi[0, a] = origin[a] + last * size[a]
                holds = holds and lo[0, a] <= tlo[t, a] and thi[t, a] <= hi[0, a]
            answer = 1
            if not holds:
                if not test:
                    answer = 0
                else:
                    for a in range(3):
                        if dilated:
                            glo[0, a] = down(lo[0, a] - dilation[t, a], 1)
                            ghi[0, a] = up(hi[0, a] + dilation[t, a], 1)
                        else:
                            glo[0, a] = lo[0, a]
                            ghi[0, a] = hi[0, a]
                    answer = meet_pair(v, tlo, thi, normal_sign, axis, planes, t, lo, hi,
                                       glo, ghi, 0)
                    if answer == 0:
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
    dilated = triangles.dilation is not None
    dilation = triangles.dilation if dilated else np.zeros((1, 3))
    n = 0
    if m:
        n = _child_pairs(triangles.v, triangles.lo, triangles.hi, triangles.normal_sign,
                         triangles.axis, triangles.planes.rows, dilation, dilated,
                         np.asarray(grid.origin, dtype=np.float64),
                         np.asarray(grid.voxel_size, dtype=np.float64),
                         np.asarray(grid.shape, dtype=np.int64),
                         1 << (grid.depth - level - 1),
                         np.ascontiguousarray(nodes, dtype=np.int64),
                         np.ascontiguousarray(tri, dtype=np.int64), bool(test),
                         child, ctri, clo, chi, state)
    return child[:n], ctri[:n], clo[:n], chi[:n], state[:n]
