"""Max-norm (l-infinity) distances and exact voxel tests (Varadhan et al. §3-§5.1).

Each primitive gives the signed weighted max-norm distance of points (negative
inside; ``weights`` per axis, or per point, for non-cubic voxels) and
``classify_boxes(lo, hi)``: EMPTY / FULL / AMBIGUOUS, where AMBIGUOUS means
the surface meets the closed box - exactly, up to rounding at ties
(:mod:`implicitvox.linf.box_tests`).

* :class:`HalfSpace`, :class:`ConvexPolyhedron` (boxes, oriented boxes, any
  bounded intersection of half-spaces or convex hull) - §3.1.1, §3.1.2;
* :class:`Sphere`, :class:`Ellipsoid`, the capped :class:`Cylinder` and the
  cone or :class:`Frustum` (any rigid motion) - §3.2 (contact equations:
  vertex, edge and face contacts of the box);
* :func:`triangle_distance` and :class:`TriangleMesh` (culling by upper and
  lower bounds) - §3.3, §4.1.

* general quadrics ``x^T A x + b.x + c <= 0`` (:class:`Quadric`:
  hyperboloids, paraboloids, cones, cylinders, in any position) - §3.2;
* the :class:`Torus`: with its axis along x, y or z (any centre) its
  symmetry reduces the distance to a monotone function of one variable; in
  general orientation (ring tori) the contact equations are solved on the
  monotone arcs of the silhouette's offset curves
  (:mod:`implicitvox.linf.torus_frame`).

Examples
--------
>>> import numpy as np
>>> from implicitvox import linf
>>> linf_distance(linf.Sphere((0, 0, 0), 1.0), np.array([[2.0, 0.0, 0.0]])).tolist()
[1.0]
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .box_tests import Primitive, classify_by_distance
from .triangle_mesh import TriangleMesh
from .polyhedron import ConvexPolyhedron, HalfSpace, convex_hull_faces, triangle_distance
from .sphere import Sphere
from .ellipsoid import Ellipsoid
from .cylinder import Cylinder, Frustum
from .torus import Torus
from .quadric import Quadric

__all__ = ["linf_distance", "HalfSpace", "ConvexPolyhedron", "Sphere", "Ellipsoid", "Cylinder", "Frustum",
           "Torus", "Quadric", "TriangleMesh",
           "triangle_distance", "convex_hull_faces", "classify_by_distance", "Primitive"]


def linf_distance(shape: Any, points: Any, weights: Any = None) -> np.ndarray:
    """Signed weighted max-norm distance from ``points (n, 3)`` to ``shape``.

    ``shape`` is a primitive of this module or any object with a
    ``linf_distance(points, weights)`` method (as :mod:`csg` solids with
    exact leaves have).
    """
    if isinstance(shape, Primitive):
        return shape.distance(points, weights)
    method = getattr(shape, "linf_distance", None)
    if callable(method):
        return method(points, weights)
    raise TypeError(f"no max-norm distance for {type(shape).__name__}: use a primitive of "
                    "implicitvox.linf (HalfSpace, ConvexPolyhedron, Sphere, Ellipsoid, Cylinder, "
                    "Frustum, Torus, Quadric, TriangleMesh)")
