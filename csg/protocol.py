"""The leaf protocol: what a node of a CSG tree provides, and the one walker of trees.

A tree is **booleans** (``operation`` ``"union"``, ``"intersection"``,
``"difference"``, ``"complement"``) and **transforms** (``"transform"``: a
``matrix``) over **leaves**: every other node (a primitive, a 2D shape, an
extrusion, a blend) is a leaf to the walkers, whatever it holds. The kernel and
the algorithms of ``csg`` (exact box tests, hulls and Minkowski sums, meshes and
their booleans, 2D outlines and projections, JSON scenes) learn everything they
need of a leaf through these members, and name no leaf class, so a new primitive
is one class in one file (with its tests).

Required of every leaf class (:class:`csg.solid.Solid` leaves them abstract;
``tests/test_layout.py`` checks every leaf class in ``csg``):

``expr``
    The implicit function, negative inside (:class:`implicitvox.Expr`).
``bounds``
    A box holding the solid (``((x0, y0, z0), (x1, y1, z1))``), or None.
``scene_node()``
    Its node of a JSON scene (:mod:`csg.scene`).

Optional (:class:`~csg.solid.Solid` has the defaults named):

``dim``
    3, or 2 for a planar region (a prism along z, for extrusions). Default 3.
``curved``
    True where the leaf's surface has true curves: it has no vertices, mesh or
    outlines, and saying so (``curved=True`` on the errors below) tells a user to
    facet it. Default False.
``world_linf(matrix)``
    The leaf moved by ``matrix`` as a max-norm primitive of :mod:`implicitvox.linf`
    (an exact box test and distances), or None. Default None.
``exact_leaf(matrix)``
    Its exact box test for :mod:`csg.tree_classifier`; default from ``world_linf``.
    ``exact`` and ``needs_exact_test`` (class attributes) say whether it has one,
    and whether its ``expr`` only bounds it (a polyhedron).
``polytope_vertices(convex, pieces)``
    The points whose convex hull is the leaf (``(n, 3)``; z = 0 in 2D), for hulls
    and Minkowski sums (:mod:`csg.polytopes`); with ``convex`` the leaf must be
    convex. ``pieces(shape, convex)`` gives the convex pieces of a child tree
    (an extrusion's section). Default: :class:`NotAPolytope`.
``closed_mesh()``
    Its closed triangle mesh ``(vertices (n, 3), faces (m, 3))`` in its own frame,
    for mesh booleans, projections and the regularized boundary
    (:mod:`csg.tree_mesh`). Default: :class:`NotAMesh`.
``outlines()``
    A 2D leaf's closed outlines (a list of ``(k, 2)`` arrays, filled even-odd), for
    Clipper (:mod:`csg.clipper2d`). Default: :class:`NotFlat`.

Examples
--------
>>> from csg import Box, Sphere
>>> tree = (Box((2, 2, 2)) - Sphere(1)).translate((1, 0, 0))
>>> fold(tree, lambda leaf, matrix: (type(leaf).__name__, float(matrix[0, 3])),
...      lambda operation, parts: (operation, parts))
('difference', [('Box', 1.0), ('Sphere', 1.0)])
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

__all__ = ["fold", "BOOLEANS", "REQUIRED", "OPTIONAL", "NotAPolytope", "NotAMesh",
           "NotFlat"]

#: the booleans :func:`fold` combines by default
BOOLEANS = ("union", "intersection", "difference")
#: what every leaf class defines
REQUIRED = ("expr", "bounds", "scene_node")
#: the hooks a leaf class may define, with their parameters
OPTIONAL = {"world_linf": ("matrix",), "exact_leaf": ("matrix",),
            "polytope_vertices": ("convex", "pieces"), "closed_mesh": (), "outlines": ()}


class NotAPolytope(ValueError):
    """A solid whose hull or Minkowski sum is not a polytope here (a curved leaf:
    ``curved`` is set), or that has no vertex set (an empty boolean: ``empty`` is set)."""

    def __init__(self, message: str, curved: bool = False, empty: bool = False):
        super().__init__(message)
        self.curved = curved
        self.empty = empty


class NotAMesh(ValueError):
    """A solid with no closed triangle mesh here (a curved leaf: ``curved`` is set)."""

    def __init__(self, message: str, curved: bool = False):
        super().__init__(message)
        self.curved = curved


class NotFlat(ValueError):
    """A 2D tree with a leaf that has no outline (a true circle: facet it first)."""


def fold(solid: Any, leaf: Callable[[Any, np.ndarray], Any],
         combine: Callable[[str, list], Any], matrix: Optional[np.ndarray] = None, *,
         booleans: tuple = BOOLEANS,
         moved: Optional[Callable[[Any, np.ndarray], Any]] = None) -> Any:
    """Walk a tree with its transforms pushed into the leaves.

    ``leaf(node, matrix)`` is called for every node that is neither a transform
    nor one of ``booleans`` (the world matrix above it), and
    ``combine(operation, results)`` for each of ``booleans``, with its children's
    results in order. With ``moved(result, matrix)``, a boolean under a transform
    is walked in its own frame and its result moved, as OpenSCAD moves a
    boolean's result (faces that coincide in that frame still coincide, where
    moving each operand first would round them apart).
    """
    matrix = np.eye(4) if matrix is None else matrix
    while solid.operation == "transform":
        child, matrix = solid.children[0], matrix @ solid.matrix
        if moved is not None and child.operation in booleans:
            return moved(fold(child, leaf, combine, None, booleans=booleans, moved=moved),
                         matrix)
        solid = child
    if solid.operation in booleans:
        return combine(solid.operation, [fold(c, leaf, combine, matrix, booleans=booleans,
                                              moved=moved) for c in solid.children])
    return leaf(solid, matrix)
