"""Max-norm distance to triangle meshes with bound culling (Varadhan §3.3, §4.1).

A bounding volume hierarchy (triangles in Morton order of their centroids,
leaves of 2, boxes merged pairwise level by level) is walked per query point
in compiled code (:mod:`implicitvox.linf.mesh_walk`): depth first, the nearer
child first, a node dropped when its box - a lower bound - lies farther than
the least exact distance found so far - an upper bound (Varadhan §4.1); at the
leaves, the exact distance to each triangle
(:func:`~implicitvox.linf.polyhedron.triangle_distance`'s separating axes, or
the Euclidean closest point), and the minimum.

The sign comes from the exact winding number of a closed mesh
(:class:`~implicitvox.triangles.crossings.RayWinding`); open meshes give unsigned
distances.

Examples
--------
>>> import numpy as np
>>> import pyvista as pv
>>> from implicitvox.triangles.inputs import as_triangles
>>> mesh = TriangleMesh(*as_triangles(pv.Cube()))
>>> mesh.distance(np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.1]])).round(12).tolist()
[1.5, -0.4]
"""
from __future__ import annotations

import functools
from typing import Any

import numpy as np

from ..triangles.crossings import RayWinding
from ..triangles.inputs import as_triangles
from ..octree import morton
from .box_tests import Primitive
from .norm import as_points, as_weights, in_blocks
from .. import batches

__all__ = ["TriangleMesh"]

_BLOCK = batches.LINF_MESH_POINTS
_LEAF = 2             # triangles per leaf of the hierarchy


class TriangleMesh(Primitive):
    """A triangle mesh ``(vertices, faces)``; signed if closed (each edge shared by
    exactly two faces), else unsigned."""

    def __init__(self, vertices: Any, faces: Any):
        v, f = as_triangles((vertices, faces))
        if not len(f):
            raise ValueError("the mesh has no triangles")
        self.tri = np.ascontiguousarray(v[f], dtype=np.float64)
        self.centroids = self.tri.mean(axis=1)
        self._build_bvh()
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        # one integer per edge (a sort of int64, not of rows: 0.16 s -> 0.02 s on the bunny)
        _, counts = np.unique(edges[:, 0].astype(np.int64) * len(v) + edges[:, 1],
                              return_counts=True)
        self.closed = bool(np.all(counts == 2))
        self.signed = self.closed
        self._winding = None

    def _build_bvh(self) -> None:
        """A bounding volume hierarchy in arrays: triangles in Morton order of their
        centroids, leaves of ``_LEAF`` consecutive triangles, each level's boxes the
        union of two boxes of the level below (a complete binary tree)."""
        c = self.centroids
        lo, hi = c.min(axis=0), c.max(axis=0)
        q = ((c - lo) / np.where(hi > lo, hi - lo, 1.0) * ((1 << 20) - 1)).astype(np.int64)
        self.order = np.argsort(morton.encode(q), kind="stable")
        tri = self.tri[self.order]
        n_leaves = -(-len(tri) // _LEAF)
        pad = n_leaves * _LEAF - len(tri)
        tlo = np.concatenate([tri.min(axis=1), np.full((pad, 3), np.inf)])
        thi = np.concatenate([tri.max(axis=1), np.full((pad, 3), -np.inf)])
        levels = [(tlo.reshape(n_leaves, _LEAF, 3).min(axis=1),
                   thi.reshape(n_leaves, _LEAF, 3).max(axis=1))]
        while len(levels[-1][0]) > 1:
            blo, bhi = levels[-1]
            if len(blo) % 2:
                blo = np.concatenate([blo, np.full((1, 3), np.inf)])
                bhi = np.concatenate([bhi, np.full((1, 3), -np.inf)])
            levels.append((np.minimum(blo[0::2], blo[1::2]), np.maximum(bhi[0::2], bhi[1::2])))
        self.levels = levels[::-1]                       # root first
        # the same, flattened for compiled code: level d in rows first[d]:first[d] + sizes[d]
        self.sizes = np.array([len(lo) for lo, _ in self.levels], dtype=np.int64)
        self.first = np.concatenate([[0], np.cumsum(self.sizes)[:-1]]).astype(np.int64)
        self.box_lo = np.ascontiguousarray(np.concatenate([lo for lo, _ in self.levels]))
        self.box_hi = np.ascontiguousarray(np.concatenate([hi for _, hi in self.levels]))

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        """Weighted max-norm distance (negative inside a closed mesh)."""
        p = as_points(points)
        w = as_weights(weights, len(p))
        return self.with_sign(p, in_blocks(self._unsigned, p, w, _BLOCK))

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Euclidean distance (negative inside a closed mesh): the same hierarchy walk,
        with Euclidean bounds and point-triangle distances."""
        p = as_points(points)
        unsigned = in_blocks(lambda q, w: self._unsigned(q, w, euclidean=True), p,
                             np.ones((len(p), 3)), _BLOCK)
        return self.with_sign(p, unsigned)

    def with_sign(self, points: np.ndarray, unsigned: np.ndarray) -> np.ndarray:
        """``unsigned`` distances at ``points`` (n, 3), negative inside a closed mesh
        (its exact winding number is nonzero there); as they are for an open one."""
        p = as_points(points)
        if not self.closed:
            return unsigned
        if self._winding is None:
            self._winding = RayWinding(self.tri)
        inside = self._winding(p) != 0
        return np.where(inside & (unsigned > 0), -unsigned, unsigned)

    def _unsigned(self, p: np.ndarray, w: np.ndarray, euclidean: bool = False) -> np.ndarray:
        """The culled walk of the hierarchy per point, in compiled code
        (:func:`implicitvox.linf.mesh_walk.nearest_distances`)."""
        from .mesh_walk import nearest_distances      # (loads Numba: not at import)
        out = np.empty(len(p))
        nearest_distances(np.ascontiguousarray(p, dtype=np.float64),
                          np.ascontiguousarray(w, dtype=np.float64), self.box_lo, self.box_hi,
                          self.first, self.sizes, self.tri, self.axes, self.order, _LEAF,
                          euclidean, out)
        return out

    @functools.cached_property
    def axes(self) -> np.ndarray:
        """The triangles' separating axes, projected once (m, 47):
        :func:`implicitvox.linf.triangle_axes.axis_rows` (built on first use)."""
        from .triangle_axes import axis_rows           # (loads Numba: not at import)
        return axis_rows(self.tri)

    @property
    def bounds(self):
        return (tuple(self.tri.min(axis=(0, 1)).tolist()),
                tuple(self.tri.max(axis=(0, 1)).tolist()))

