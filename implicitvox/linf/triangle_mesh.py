"""Max-norm distance to triangle meshes with bound culling (Varadhan §3.3, §4.1).

For each query point:

1. an upper bound: the exact distance to the triangles whose centroids are
   nearest in the max-norm (a k-d tree, :class:`scipy.spatial.cKDTree`);
2. culling (§4.1): a bounding volume hierarchy (triangles in Morton order,
   leaves of 2, boxes merged pairwise level by level) is walked from the
   root for all points at once; a (point, node) pair survives only if the
   node's box - a lower bound - is no farther than the upper bound;
3. the exact distance to each surviving triangle
   (:func:`~implicitvox.linf.polyhedron.triangle_distance`), and the minimum.

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

from typing import Any

import numpy as np

from ..triangles.crossings import RayWinding
from ..triangles.inputs import as_triangles
from ..octree import morton
from .box_tests import Primitive
from .norm import as_points, as_weights, in_blocks
from .polyhedron import triangle_distance
from .euclidean import triangle_distance as triangle_euclidean
from .. import batches

__all__ = ["TriangleMesh"]

_NEAREST = 2          # centroids whose triangles set the upper bound
_BLOCK = batches.LINF_MESH_POINTS
_LEAF = 2             # triangles per leaf of the hierarchy


class TriangleMesh(Primitive):
    """A triangle mesh ``(vertices, faces)``; signed if closed (each edge shared by
    exactly two faces), else unsigned."""

    def __init__(self, vertices: Any, faces: Any):
        from scipy.spatial import cKDTree
        v, f = as_triangles((vertices, faces))
        if not len(f):
            raise ValueError("the mesh has no triangles")
        self.tri = v[f]
        self.centroids = self.tri.mean(axis=1)
        self.tree = cKDTree(self.centroids)
        self._build_bvh()
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
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

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        """Weighted max-norm distance (negative inside a closed mesh)."""
        p = as_points(points)
        w = as_weights(weights, len(p))
        return self._signed(p, in_blocks(self._unsigned, p, w, _BLOCK))

    def euclidean_distance(self, points: Any) -> np.ndarray:
        """Euclidean distance (negative inside a closed mesh): the same hierarchy walk,
        with Euclidean bounds and point-triangle distances."""
        p = as_points(points)
        unsigned = in_blocks(lambda q, w: self._unsigned(q, w, euclidean=True), p,
                             np.ones((len(p), 3)), _BLOCK)
        return self._signed(p, unsigned)

    def _signed(self, p: np.ndarray, unsigned: np.ndarray) -> np.ndarray:
        if not self.closed:
            return unsigned
        if self._winding is None:
            self._winding = RayWinding(self.tri)
        inside = self._winding(p) != 0
        return np.where(inside & (unsigned > 0), -unsigned, unsigned)

    def _unsigned(self, p: np.ndarray, w: np.ndarray, euclidean: bool = False) -> np.ndarray:
        if euclidean:
            def gap(lo, hi, q, _w):
                return np.linalg.norm(np.maximum(np.maximum(lo - q, q - hi), 0), axis=1)

            def exact(q, tri, _w):
                return triangle_euclidean(q, tri)
        else:
            def gap(lo, hi, q, ww):
                return np.max(np.maximum(np.maximum(lo - q, q - hi), 0) / ww, axis=1)
            exact = triangle_distance
        k = min(_NEAREST, len(self.tri))
        _, near = self.tree.query(p / 1.0, k=k, p=2 if euclidean else np.inf)
        near = near.reshape(len(p), k)
        rows = np.repeat(np.arange(len(p)), k)
        d = exact(p[rows], self.tri[near.ravel()], w[rows]).reshape(len(p), k)
        upper = d.min(axis=1)
        # Varadhan §4.1: walk the hierarchy from the root, keeping (point, node) pairs
        # whose box is no farther than the point's upper bound (the lower bound culls)
        pt = np.arange(len(p))
        node = np.zeros(len(p), dtype=np.int64)
        for depth in range(1, len(self.levels)):
            blo, bhi = self.levels[depth]
            pt = np.repeat(pt, 2)
            node = (2 * np.repeat(node, 2)) + np.tile([0, 1], len(node))
            ok = node < len(blo)
            pt, node = pt[ok], node[ok]
            keep = gap(blo[node], bhi[node], p[pt], w[pt]) <= upper[pt]
            pt, node = pt[keep], node[keep]
        # the leaves' triangles, exactly
        pt = np.repeat(pt, _LEAF)
        idx = (np.repeat(node, _LEAF) * _LEAF) + np.tile(np.arange(_LEAF), len(node))
        ok = idx < len(self.tri)
        pt, idx = pt[ok], idx[ok]
        cand = self.order[idx]
        keep = gap(self.tri[cand].min(axis=1), self.tri[cand].max(axis=1), p[pt], w[pt]) \
            <= upper[pt]
        pt, cand = pt[keep], cand[keep]
        dist = exact(p[pt], self.tri[cand], w[pt])
        best = upper.copy()
        np.minimum.at(best, pt, dist)
        return best

    @property
    def bounds(self):
        return (tuple(self.tri.min(axis=(0, 1)).tolist()),
                tuple(self.tri.max(axis=(0, 1)).tolist()))

