"""Straight prisms: a 2D region extruded without twist or scale, with an exact box test.

OpenSCAD extrudes the result of its 2D booleans (Clipper's outlines); so does
:class:`Prism`, built from :func:`csg.clipper2d.region_pieces`. Its function is
the polygon's (:class:`~csg.planar.LinearExtrude`'s), exact in sign but loose
over a box near concave corners; its box test is exact:

* placed along the world axes (any translation, axis permutation, scale and
  mirror: ``rotate([90, 0, 0])`` and the like), by :class:`implicitvox.triangles.prism_classifier.PrismClassifier`: a
  closed box meets the prism's surface iff its span along the extrusion axis
  meets the prism's and its rectangle across meets an outline edge (exact
  orientation signs, :func:`implicitvox.triangles.predicates.det2_sign`), or its
  rectangle lies inside the region and its span reaches past a cap; a box off
  every edge is inside or outside the region by the crossing number at one of
  its corners (exact too);
* placed otherwise, by its mesh (:class:`csg.tree_classifier.MeshClassifier`).

The outlines are taken to world space as the mesh's vertices would be (one
rounding per coordinate), so both tests see the same prism.

Examples
--------
>>> import numpy as np
>>> ring = [(np.array([[0, 0], [4, 0], [4, 4], [0, 4.0]]),
...          [np.array([[1, 1], [1, 3], [3, 3], [3, 1.0]])])]
>>> p = Prism(ring, 2.0)
>>> from implicitvox.expr.shape import AMBIGUOUS, EMPTY, FULL
>>> lo = np.array([[1.5, 1.5, 0.5], [0.25, 0.25, 0.5], [0.5, 0.5, -1.0], [0.75, 2, 0.5]])
>>> p.classify_voxels(lo, lo + 0.5).tolist() == [EMPTY, FULL, EMPTY, AMBIGUOUS]
True
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from implicitvox import linf
from implicitvox.triangles.mesh_classifier import MeshClassifier
from implicitvox.triangles.prism_classifier import PrismClassifier, axis_permutation

from .clipper2d import simple_pieces
from .facets import extrusion_mesh_outlines
from .planar import LinearExtrude, pieces_polygon
from .solid import Solid, box_bound

__all__ = ["Prism", "bound_functions",
           "FUNCTION_VERTICES", "TREE_FUNCTION_VERTICES"]

#: outline vertices past which a Prism's function is only a bound (zero in its box,
#: as a Polyhedron's): the triangulated function of a long outline (text, a DXF
#: drawing) makes a tape of thousands of instructions that every box pays for, while
#: the exact test decides each box anyway (at 128³ over OpenSCAD's STL: children.scad,
#: four words of text, 9.1 s with the function, 1.9 s with the bound; sign.scad 2.8 s
#: and 0.3 s; text_on_cube, outlines of 54 to 119 vertices, 2.19 s and 0.40 s;
#: example017, 59 to 72, 1.11 and 0.37 s; the same voxels)
FUNCTION_VERTICES = 48
#: outline vertices of the prisms with a function that a model may hold in all, past
#: which every prism keeps only its bound (:func:`bound_functions`): every box pays
#: for every function in the tree, while a prism's exact test runs only on the boxes
#: that meet its own box. Measured at 128³ over OpenSCAD's STL (CPU s, function /
#: bound, the same voxels): example023, 51 prisms of 794 vertices, 1.75 / 0.66;
#: example021, 134 vertices under FUNCTION_VERTICES, 0.78 / 0.43; against example013,
#: 60 vertices, 1.02 / 1.14, example008, 53, 0.78 / 0.98, LetterBlock, 13, 0.21 / 0.24
TREE_FUNCTION_VERTICES = 100


class Prism(LinearExtrude):
    """A straight extrusion (no twist, no scale) of a 2D region given as parts
    ``(outer, [holes])`` (outer outlines counter-clockwise, holes clockwise, as
    :func:`csg.clipper2d.region_pieces` gives them), from ``z = 0`` (or centred)
    to ``height``; exact box test (module docstring)."""

    exact = True

    def __init__(self, pieces: list, height: float, center: bool = False):
        #: the region's parts, every ring simple (a ring touching itself is split:
        #: the same region)
        self.pieces = simple_pieces(pieces)
        if not self.pieces:
            raise ValueError("a Prism needs at least one outline")
        super().__init__(pieces_polygon(self.pieces), height, center=center)
        #: outline vertices, all parts
        self.vertex_count = sum(len(o) + sum(len(h) for h in hs) for o, hs in self.pieces)
        #: the function is only a bound: the exact test must classify every box
        self.needs_exact_test = self.vertex_count > FUNCTION_VERTICES

    @property
    def expr(self):
        return box_bound(*self.bounds) if self.needs_exact_test else super().expr

    def mesh(self, matrix: Optional[np.ndarray] = None) -> tuple[np.ndarray, np.ndarray]:
        """The prism's closed triangle mesh (vertices, faces), moved by ``matrix``."""
        v, f = extrusion_mesh_outlines(self.pieces, self.height, 0.0, np.ones(2), 1, self._z0)
        if matrix is not None:
            v = v @ matrix[:3, :3].T + matrix[:3, 3]
        return v, f

    def closed_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """Its walls and caps (:meth:`mesh`)."""
        return self.mesh()

    def exact_leaf(self, matrix: np.ndarray) -> tuple[str, Any]:
        axes = axis_permutation(matrix[:3, :3])
        if axes is None:
            v, f = self.mesh(matrix)
            return ("mesh", MeshClassifier(v, f, np.linalg.det(matrix[:3, :3]) < 0))
        a, b, c = axes
        rings = []
        for outer, holes in self.pieces:
            for r in (outer, *holes):
                local = np.column_stack([r, np.zeros(len(r))])
                world = local @ matrix[:3, :3].T + matrix[:3, 3]
                rings.append(world[:, [a, b]])
        ends = np.array([[0.0, 0.0, self._z0], [0.0, 0.0, self._z0 + self.height]])
        z = (ends @ matrix[:3, :3].T + matrix[:3, 3])[:, c]
        return ("prism", PrismClassifier(rings, axes, z.min(), z.max()))

    def world_linf(self, matrix: np.ndarray) -> linf.Primitive:
        return linf.TriangleMesh(*self.mesh(matrix))

    def __repr__(self) -> str:
        return (f"Prism({sum(1 + len(h) for _, h in self.pieces)} outlines, "
                f"height={self.height}, center={self.centered})")


def bound_functions(solid: Solid, limit: int = TREE_FUNCTION_VERTICES) -> int:
    """Let every :class:`Prism` of ``solid`` keep only its bound (zero in its box, as
    past :data:`FUNCTION_VERTICES`) when those that keep their triangulated function
    hold more than ``limit`` outline vertices in all; the number of prisms changed.

    The exact tests decide every box either way, so the voxels are the same; only
    the cost moves (:data:`TREE_FUNCTION_VERTICES`). Meant for a tree just built
    (:func:`csg.read_openscad` calls it): its prisms are changed in place.
    """
    prisms, stack, seen = [], [solid], set()
    while stack:                       # iterative: a model's tree may be deep
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, Prism) and not node.needs_exact_test:
            prisms.append(node)
        stack.extend(node.children)
    if sum(p.vertex_count for p in prisms) <= limit:
        return 0
    for p in prisms:
        p.needs_exact_test = True
    return len(prisms)
