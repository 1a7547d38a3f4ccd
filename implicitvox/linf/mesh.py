"""Max-norm distance to triangle meshes with bound culling (Varadhan §3.3, §4.1).

For each query point:

1. an upper bound: the exact distance to the triangles whose centroids are
   nearest in the max-norm (a k-d tree, :class:`scipy.spatial.cKDTree`);
2. culling: only triangles whose bounding box lies within that bound (their
   lower bound, the distance to the box, does not exceed it) can be
   nearer - a ball query of the tree of box centres, widened by the largest
   box half-size;
3. the exact distance to each surviving triangle
   (:func:`~implicitvox.linf.polytope.triangle_distance`), and the minimum.

The sign comes from the exact winding number of a closed mesh
(:class:`~implicitvox.crossings.RayWinding`); open meshes give unsigned
distances.

Examples
--------
>>> import numpy as np
>>> import pyvista as pv
>>> from implicitvox.mesh_input import as_triangles
>>> mesh = TriangleMesh(*as_triangles(pv.Cube()))
>>> mesh.distance(np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.1]])).round(12).tolist()
[1.5, -0.4]
"""
from __future__ import annotations

from itertools import chain
from typing import Any

import numpy as np

from .norm import as_points, as_weights
from .polytope import triangle_distance

__all__ = ["TriangleMesh"]

_NEAREST = 8          # centroids whose triangles set the upper bound
_BLOCK = 1 << 15      # points per block
_CLASSES = 4          # triangle size classes


class TriangleMesh:
    """A triangle mesh ``(vertices, faces)``; signed if closed (each edge shared by
    exactly two faces), else unsigned."""

    def __init__(self, vertices: Any, faces: Any):
        from scipy.spatial import cKDTree
        from implicitvox.mesh_input import as_triangles
        v, f = as_triangles((vertices, faces))
        if not len(f):
            raise ValueError("the mesh has no triangles")
        self.tri = v[f]
        lo, hi = self.tri.min(axis=1), self.tri.max(axis=1)
        centre, half = 0.5 * (lo + hi), (0.5 * (hi - lo)).max(axis=1)
        self.centroids = self.tri.mean(axis=1)
        self.tree = cKDTree(self.centroids)
        # triangles in size classes, each with its own tree and widening (a big
        # triangle must not widen the search for all the small ones)
        edges = np.quantile(half, np.linspace(0, 1, _CLASSES + 1))
        cls = np.clip(np.searchsorted(edges, half, side="right") - 1, 0, _CLASSES - 1)
        self.classes = []
        for c in range(_CLASSES):
            members = np.flatnonzero(cls == c)
            if len(members):
                self.classes.append((members, cKDTree(centre[members]),
                                     float(half[members].max())))
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
        self.closed = bool(np.all(counts == 2))
        self._winding = None

    def distance(self, points: Any, weights: Any = None) -> np.ndarray:
        """Weighted max-norm distance (negative inside a closed mesh)."""
        p = as_points(points)
        w = as_weights(weights, len(p))
        out = np.empty(len(p))
        for s in range(0, len(p), _BLOCK):
            out[s:s + _BLOCK] = self._unsigned(p[s:s + _BLOCK], w[s:s + _BLOCK])
        if self.closed:
            from implicitvox.crossings import RayWinding
            if self._winding is None:
                self._winding = RayWinding(self.tri)
            inside = self._winding(p) != 0
            out = np.where(inside & (out > 0), -out, out)
        return out

    def _unsigned(self, p: np.ndarray, w: np.ndarray) -> np.ndarray:
        k = min(_NEAREST, len(self.tri))
        _, near = self.tree.query(p / 1.0, k=k, p=np.inf)
        near = near.reshape(len(p), k)
        rows = np.repeat(np.arange(len(p)), k)
        d = triangle_distance(p[rows], self.tri[near.ravel()], w[rows]).reshape(len(p), k)
        upper = d.min(axis=1)
        # any triangle nearer than `upper` (weighted) lies within upper * max(w) (plain)
        reach = upper * w.max(axis=1) * (1 + 1e-12)
        cands, owners = [], []
        for members, tree, half in self.classes:
            lists = tree.query_ball_point(p, reach + half, p=np.inf, return_sorted=False)
            counts = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
            flat = np.fromiter(chain.from_iterable(lists), dtype=np.int64,
                               count=int(counts.sum()))
            cands.append(members[flat])
            owners.append(np.repeat(np.arange(len(p)), counts))
        cand, owner = np.concatenate(cands), np.concatenate(owners)
        # cull by the lower bound: the distance to the triangle's box
        lo = self.tri[cand].min(axis=1)
        hi = self.tri[cand].max(axis=1)
        q, ww = p[owner], w[owner]
        gap = np.max(np.maximum(np.maximum(lo - q, q - hi), 0) / ww, axis=1)
        keep = gap <= upper[owner]
        cand, owner = cand[keep], owner[keep]
        dist = triangle_distance(p[owner], self.tri[cand], w[owner])
        best = upper.copy()
        np.minimum.at(best, owner, dist)
        return best

    @property
    def bounds(self):
        return (tuple(self.tri.min(axis=(0, 1)).tolist()),
                tuple(self.tri.max(axis=(0, 1)).tolist()))

    def classify_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        from .classify import classify_by_distance
        return classify_by_distance(self.distance, lo, hi, signed=self.closed)
