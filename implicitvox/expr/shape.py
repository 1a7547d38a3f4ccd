"""The ``Shape`` protocol: what :func:`implicitvox.voxelize` accepts.

A shape has

* ``expr`` - the implicit function (an :class:`~implicitvox.expr.nodes.Expr`),
  negative inside;
* ``bounds`` (optional) - ``((x0, y0, z0), (x1, y1, z1))`` holding the solid's
  surface, or ``None``;
* ``classify_boxes(lo, hi)`` (optional) - an exact test that maps boxes
  (``(n, 3)`` corner arrays) to :data:`EMPTY`, :data:`FULL` or
  :data:`AMBIGUOUS`, where AMBIGUOUS means the surface does meet the closed
  box (Varadhan §5.1). The voxelizer calls it on boxes that interval
  arithmetic left AMBIGUOUS; at the target depth a voxel is kept iff it says
  AMBIGUOUS;
* ``classify_voxels(lo, hi)`` (optional) - the same at the target depth, for
  shapes whose ``classify_boxes`` may leave a box undecided (AMBIGUOUS) to
  save work on octants that will be subdivided anyway (:mod:`csg` booleans).

* an exact test with the attribute ``takes_octants = True`` is called by the
  octree with the octants too: ``test(lo, hi, octants)``, an :class:`Octants`
  giving their level and Morton codes (the children of ``codes >> 3``) and a
  dict that lives for the one subdivision, where the test may keep what it
  found about a box for the box's children (:mod:`csg`'s mesh leaves keep the
  triangles each box meets). Other callers pass only ``lo, hi``.

* ``expression_is_exact`` (optional, default True) - False when ``expr``
  only bounds the solid (zero inside a polyhedron's bounding box, say) and
  the exact test alone knows the surface: :func:`implicitvox.mesh` needs point
  values, so it meshes such a shape by its ``boundary_mesh``;
* ``boundary_mesh`` (optional) - None, or the closed triangle mesh
  ``(vertices (m, 3), faces (k, 3))``, oriented outward, of the boundary of a
  shape whose ``expr`` only bounds it (a polyhedral solid: :mod:`csg`'s OpenSCAD
  facets and imported meshes, their booleans computed by Manifold);
* ``surface_normals`` (optional) - None, or a function from points ``(n, 3)`` to
  unit normals ``(n, 3)`` of the surface near them, for a shape whose ``expr``
  only bounds it (its gradient says nothing of the surface: OpenSCAD's facets);
  stored and rendered normals then come from it, never from the bound.

A bare expression is a shape without bounds or exact test.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Any, Callable, Optional, Protocol, runtime_checkable

import numpy as np

from .nodes import Expr

__all__ = ["Shape", "EMPTY", "FULL", "AMBIGUOUS", "as_shape", "ExprShape", "exact_classifier",
           "voxel_classifier", "expression_is_exact", "boundary_mesh", "surface_normals",
           "Octants", "takes_octants"]

#: octant states
EMPTY, FULL, AMBIGUOUS = 0, 1, 2


@dataclass(frozen=True)
class Octants:
    """The octants an exact test is asked about (see the module docstring).

    Attributes
    ----------
    level : int
        Their octree level (0: the root).
    codes : ndarray of uint64, (n,)
        Their Morton codes (:mod:`implicitvox.octree.morton`), one per box; a
        box's parent is ``codes >> 3`` at ``level - 1``.
    run : dict
        Scratch space for the whole subdivision (one per run and process),
        dropped when it ends.
    """

    level: int
    codes: np.ndarray
    run: dict

    def subset(self, which: np.ndarray) -> "Octants":
        """The octants ``which`` (an index or mask) of these."""
        return Octants(self.level, self.codes[which], self.run)


def takes_octants(test: Any) -> bool:
    """Whether an exact test wants the :class:`Octants` of its boxes."""
    return bool(getattr(test, "takes_octants", False))


@runtime_checkable
class Shape(Protocol):
    """A solid the voxelizer can read (see the module docstring)."""

    expr: Expr


class ExprShape:
    """A shape made of an expression, with optional bounds."""

    def __init__(self, expr: Expr, bounds: Any = None):
        self.expr = expr
        self.bounds = bounds

    def __repr__(self) -> str:
        return f"ExprShape({self.expr!r:.60}, bounds={self.bounds})"


def as_shape(obj: Any) -> Any:
    """Return ``obj`` as a shape: expressions are wrapped, shapes pass through."""
    if isinstance(obj, Expr):
        return ExprShape(obj)
    try:
        expr = getattr(obj, "expr", None)
    except RecursionError:       # a tree that builds its expression recursively, too deep
        raise ValueError(f"the {type(obj).__name__} is nested too deeply to compile (its tree "
                         f"is deeper than Python's recursion limit, {sys.getrecursionlimit()}): "
                         "nest it less deeply (one n-ary union of many parts, one transform "
                         "for a chain of them)") from None
    if isinstance(expr, Expr):
        return obj
    raise TypeError(f"expected an implicitvox expression or a shape with .expr, got "
                    f"{type(obj).__name__} {obj!r:.60}")


def exact_classifier(shape: Any) -> Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """The shape's exact box test, if it has one."""
    test = getattr(shape, "classify_boxes", None)
    return test if callable(test) else None


def voxel_classifier(shape: Any) -> Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """The shape's exact test at the voxel level (``classify_voxels``, else
    ``classify_boxes``), if it has one."""
    test = getattr(shape, "classify_voxels", None)
    return test if callable(test) else exact_classifier(shape)


def surface_normals(shape: Any) -> Optional[Callable[[np.ndarray], np.ndarray]]:
    """The shape's own normals (see the module docstring), or None: the gradient of
    its ``expr`` then gives them."""
    own = getattr(shape, "surface_normals", None)
    return own if callable(own) else None


def expression_is_exact(shape: Any) -> bool:
    """Whether the shape's ``expr`` is its own function (see the module docstring)."""
    return bool(getattr(shape, "expression_is_exact", True))


def boundary_mesh(shape: Any) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """The shape's closed boundary mesh ``(vertices, faces)`` where it gives one (see
    the module docstring), else None."""
    found = getattr(shape, "boundary_mesh", None)
    if found is None:
        return None
    vertices, faces = found
    return np.asarray(vertices, dtype=np.float64), np.asarray(faces, dtype=np.int64)
