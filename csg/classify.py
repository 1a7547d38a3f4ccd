"""Exact box classification of CSG trees with polyhedral leaves.

A CSG tree is flattened to world space: transforms are pushed into the
leaves (a :class:`~csg.primitives.Polyhedron`'s vertices are moved, a box's
or convex polyhedron's corners, a half-space's plane, a sphere under a
similarity; any other subtree becomes one compiled implicit function). Each
leaf classifies boxes as EMPTY, FULL or AMBIGUOUS:

* a polyhedron exactly - AMBIGUOUS iff a triangle meets the closed box
  (:class:`implicitvox.tribox.Triangles`), else FULL or EMPTY by the winding
  number at the box's centre;
* boxes, convex polyhedra, half-spaces, spheres and ellipsoids (under any
  affine map), capped cylinders and cones (under similarities) by their max-norm
  distance (Varadhan §5.1, :mod:`implicitvox.linf`): AMBIGUOUS iff the
  surface meets the box (up to rounding at exact ties);
* a function by its interval enclosure (sound; AMBIGUOUS may be a near miss).

The booleans combine the states: a union is FULL if a child is, EMPTY if all
are, else AMBIGUOUS; an intersection dually; a complement swaps FULL and
EMPTY. AMBIGUOUS combined with AMBIGUOUS stays AMBIGUOUS (the surfaces may
cancel inside the box: conservative, never a missed voxel).
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

import implicitvox as iv
from implicitvox.shape import AMBIGUOUS, EMPTY, FULL
from implicitvox.tribox import Triangles
from implicitvox.crossings import RayWinding
from implicitvox.mesh_subdivide import _sorted_unique
from implicitvox.ranges import buckets, expand_boxes, gather

__all__ = ["exact_classifier", "MeshClassifier"]


def _exact_types():
    from .primitives import (Box, ConvexPolyhedron, Cylinder, Ellipsoid, HalfSpace, Polyhedron,
                             Sphere)
    return (Polyhedron, Box, ConvexPolyhedron, HalfSpace, Sphere, Ellipsoid, Cylinder)


def _has_mesh(solid) -> bool:
    """Whether a leaf of the tree has an exact test (a polyhedron or a max-norm primitive)."""
    return isinstance(solid, _exact_types()) or any(_has_mesh(c) for c in solid.children)


def _similarity_scale(m: np.ndarray) -> Optional[float]:
    """The scale of ``m`` if it is a rotation (or reflection) times a scale, else None."""
    gram = m.T @ m
    scale2 = gram[0, 0]
    if np.allclose(gram, scale2 * np.eye(3), rtol=0, atol=1e-12 * scale2):
        return float(np.sqrt(scale2))
    return None


def _linf_leaf(solid, matrix: np.ndarray):
    """The leaf as a max-norm primitive in world space (implicitvox.linf), or None."""
    from implicitvox import linf
    from .primitives import Box, ConvexPolyhedron, Cylinder, Ellipsoid, HalfSpace, Sphere
    m, t = matrix[:3, :3], matrix[:3, 3]
    if isinstance(solid, Box):
        lo, hi = (np.asarray(b) for b in solid.bounds)
        corners = np.array([[(lo, hi)[(k >> a) & 1][a] for a in range(3)] for k in range(8)])
        return linf.ConvexPolytope.from_points(corners @ m.T + t)
    if isinstance(solid, ConvexPolyhedron):
        if solid._points is not None:
            return linf.ConvexPolytope.from_points(solid._points @ m.T + t)
        return linf.ConvexPolytope.from_planes(solid.normals, solid.offsets).transformed(matrix)
    if isinstance(solid, HalfSpace):
        n = np.linalg.solve(m.T, solid.normal)          # M^-T n
        return linf.HalfSpace(n, solid.offset + n @ t)
    k = _similarity_scale(m)
    if isinstance(solid, Sphere):
        if k is not None:
            return linf.Sphere(m @ solid.center + t, solid.r * k)
        return linf.Ellipsoid.from_affine(m * solid.r, m @ solid.center + t)
    if isinstance(solid, Ellipsoid):
        return linf.Ellipsoid.from_affine(m @ np.diag(solid.radii), m @ solid.center + t)
    if isinstance(solid, Cylinder):
        if k is not None:
            z0, _ = solid._z
            return linf.Frustum(m @ np.array([0.0, 0.0, z0]) + t, m[:, 2], solid.h * k,
                                solid.r1 * k, solid.r2 * k)
    return None


def world_linf(solid, matrix: Optional[np.ndarray] = None):
    """A single (transformed) primitive as a world-space max-norm primitive, or None."""
    from implicitvox import linf
    from .primitives import Polyhedron
    from .solid import Transformed
    matrix = np.eye(4) if matrix is None else matrix
    if isinstance(solid, Transformed):
        return world_linf(solid.children[0], matrix @ solid.matrix)
    if isinstance(solid, Polyhedron):
        v = solid.vertices @ matrix[:3, :3].T + matrix[:3, 3]
        return linf.TriangleMesh(v, solid.faces)
    if isinstance(solid, _exact_types()):
        return _linf_leaf(solid, matrix)
    return None


def _leaves(solid):
    if not solid.children:
        yield solid
    for c in solid.children:
        yield from _leaves(c)


def exact_classifier(solid) -> Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """The tree's box classifier, or None when no leaf has an exact test."""
    if not _has_mesh(solid):
        return None
    cache = solid.__dict__.setdefault("_classifier_cache", {})
    if "plan" not in cache:
        cache["plan"] = _plan(solid, np.eye(4))
    plan = cache["plan"]
    return lambda lo, hi: _run(plan, np.asarray(lo, dtype=float), np.asarray(hi, dtype=float))


def _plan(solid, matrix: np.ndarray) -> tuple:
    from .primitives import Polyhedron
    from .solid import Complement, Difference, Intersection, Transformed, Union
    if not _has_mesh(solid):
        expr = Transformed(solid, matrix).expr if not np.array_equal(matrix, np.eye(4)) \
            else solid.expr
        return ("function", iv.compile(expr))
    if isinstance(solid, Polyhedron):
        v = solid.vertices @ matrix[:3, :3].T + matrix[:3, 3]
        flip = np.linalg.det(matrix[:3, :3]) < 0      # mirrored: the winding sign flips
        return ("mesh", MeshClassifier(v, solid.faces, flip))
    if isinstance(solid, _exact_types()):
        prim = _linf_leaf(solid, matrix)
        if prim is not None:
            return ("exact", prim)
        return ("function", iv.compile(Transformed(solid, matrix).expr))
    if isinstance(solid, Transformed):
        return _plan(solid.children[0], matrix @ solid.matrix)
    if not isinstance(solid, (Union, Intersection, Difference, Complement)):
        from .primitives import Polyhedron as _P
        if any(isinstance(leaf, _P) for leaf in _leaves(solid)):
            raise TypeError(f"{type(solid).__name__} with a polyhedron inside has no exact "
                            "test (only booleans and transforms combine them)")
        # another node (a blend, an extrusion): its own function, by intervals
        return ("function", iv.compile(Transformed(solid, matrix).expr
                                       if not np.array_equal(matrix, np.eye(4)) else solid.expr))
    kids = [_plan(c, matrix) for c in solid.children]
    if isinstance(solid, Union):
        return ("union", kids)
    if isinstance(solid, Intersection):
        return ("intersection", kids)
    if isinstance(solid, Difference):
        return ("intersection", [kids[0]] + [("complement", k) for k in kids[1:]])
    if isinstance(solid, Complement):
        return ("complement", kids[0])
    raise TypeError(f"{type(solid).__name__} with a polyhedron inside has no exact test")


def _run(plan: tuple, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    kind = plan[0]
    if kind == "function":
        flo, fhi = plan[1].interval(lo, hi)
        state = np.full(len(lo), AMBIGUOUS, dtype=np.int8)
        state[flo > 0] = EMPTY
        state[fhi < 0] = FULL
        return state
    if kind == "mesh":
        return plan[1].classify(lo, hi)
    if kind == "exact":
        return plan[1].classify_boxes(lo, hi)
    if kind == "complement":
        s = _run(plan[1], lo, hi)
        return np.where(s == FULL, EMPTY, np.where(s == EMPTY, FULL, s)).astype(np.int8)
    states = [_run(k, lo, hi) for k in plan[1]]
    if kind == "union":
        full = np.any([s == FULL for s in states], axis=0)
        empty = np.all([s == EMPTY for s in states], axis=0)
    else:
        full = np.all([s == FULL for s in states], axis=0)
        empty = np.any([s == EMPTY for s in states], axis=0)
    out = np.full(len(lo), AMBIGUOUS, dtype=np.int8)
    out[full] = FULL
    out[empty] = EMPTY
    return out


class MeshClassifier:
    """Exact EMPTY / FULL / AMBIGUOUS of boxes against a closed triangle mesh.

    Triangles are bucketed in a uniform grid over the mesh's box, so each box
    is tested only against the triangles near it.
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, flip: bool = False):
        self.tris = Triangles(vertices[faces])
        self.flip = flip
        self.winding = RayWinding(self.tris)
        self.lo = self.tris.lo.min(axis=0)
        self.hi = self.tris.hi.max(axis=0)
        n = len(self.tris)
        self.cells = int(np.clip(round(2 * n ** (1 / 3)), 1, 64))
        span = np.where(self.hi > self.lo, self.hi - self.lo, 1.0)
        self.cell_size = span / self.cells
        first = self._cell(self.tris.lo)
        last = self._cell(self.tris.hi)
        tri, cell = expand_boxes(first, last)
        key = (cell[:, 0] * self.cells + cell[:, 1]) * self.cells + cell[:, 2]
        self.cell_tris, self.cell_start = buckets(key, tri, self.cells ** 3)

    def _cell(self, p: np.ndarray) -> np.ndarray:
        # a cell index per point, widened by one cell below so rounding cannot drop a triangle
        c = np.floor((p - self.lo) / self.cell_size).astype(np.int64)
        return np.clip(c, 0, self.cells - 1)

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        state = np.full(len(lo), EMPTY, dtype=np.int8)
        near = np.flatnonzero(np.all((lo <= self.hi) & (hi >= self.lo), axis=1))
        meets = np.zeros(len(lo), dtype=bool)
        if len(near):
            box, tri = self._pairs(near, lo, hi)
            if len(box):
                ok = self.tris.meet_boxes(tri, lo[box], hi[box])
                meets[box[ok]] = True
        state[meets] = AMBIGUOUS
        rest = near[~meets[near]]
        if len(rest):
            # off the surface: the whole box is on the side of its centre (a box corner
            # is exact and in the box: use it, the rounded centre could leave a thin box)
            w = self.winding(lo[rest])
            state[rest] = np.where(w != 0, FULL, EMPTY)
        return state

    def _pairs(self, boxes: np.ndarray, lo: np.ndarray, hi: np.ndarray):
        """(box, triangle) candidate pairs from the cells each box covers (one cell of
        slack on each side covers the cell computation's rounding)."""
        first = np.maximum(self._cell(lo[boxes]) - 1, 0)
        last = np.minimum(self._cell(hi[boxes]) + 1, self.cells - 1)
        b, cell = expand_boxes(first, last)
        key = (cell[:, 0] * self.cells + cell[:, 1]) * self.cells + cell[:, 2]
        pair, index = gather(self.cell_start[key], self.cell_start[key + 1] - self.cell_start[key])
        pb, pt = b[pair], self.cell_tris[index]
        # a triangle spanning several cells appears once per cell: keep one pair
        if len(pb):
            pair = _sorted_unique(pb.astype(np.int64) * len(self.tris) + pt)
            pb, pt = pair // len(self.tris), pair % len(self.tris)
        return boxes[pb], pt
