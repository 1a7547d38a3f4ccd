"""Straight prisms: a 2D region extruded without twist or scale, with an exact box test.

OpenSCAD extrudes the result of its 2D booleans (Clipper's outlines); so does
:class:`Prism`, built from :func:`csg.clipper2d.region_pieces`. Its function is
the polygon's (:class:`~csg.planar.LinearExtrude`'s), exact in sign but loose
over a box near concave corners; its box test is exact:

* placed along the world axes (any translation, axis permutation, scale and
  mirror: ``rotate([90, 0, 0])`` and the like), by :class:`PrismClassifier`: a
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
from implicitvox.expr.shape import AMBIGUOUS, EMPTY, FULL
from implicitvox.triangles.predicates import det2_sign
from implicitvox.triangles.ranges import buckets, expand, expand_boxes, gather
from implicitvox.triangles.pairs import sorted_unique

from .tree_classifier import MeshClassifier
from .clipper2d import simple_pieces
from .facets import extrusion_mesh_outlines
from .planar import LinearExtrude, pieces_polygon
from .solid import Solid, box_bound

__all__ = ["Prism", "PrismClassifier", "axis_permutation", "bound_functions",
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


def axis_permutation(m: np.ndarray) -> Optional[tuple[int, int, int]]:
    """The world axes ``(a, b, c)`` that local x, y, z go to under the 3x3 part ``m``
    when it is a signed, scaled axis permutation (one non-zero per row and column),
    else None."""
    nonzero = m != 0
    if not (np.all(nonzero.sum(axis=0) == 1) and np.all(nonzero.sum(axis=1) == 1)):
        return None
    rows = nonzero.argmax(axis=0)                 # the world axis of each local axis
    return int(rows[0]), int(rows[1]), int(rows[2])


class PrismClassifier:
    """Exact EMPTY / FULL / AMBIGUOUS of boxes against an axis-aligned prism: the
    region of closed outlines ``rings`` (each (k, 2), in world axes ``a, b``),
    between ``zlo`` and ``zhi`` along world axis ``c`` (module docstring).

    Edges are bucketed in a uniform grid over the region's rectangle (for the
    boxes' rectangles) and in its rows (for the crossing number), as
    :class:`csg.tree_classifier.MeshClassifier` buckets triangles.
    """

    def __init__(self, rings: list[np.ndarray], axes: tuple[int, int, int], zlo: float,
                 zhi: float):
        self.axes = axes
        self.zlo, self.zhi = float(zlo), float(zhi)
        self.p = np.concatenate([np.asarray(r, dtype=np.float64) for r in rings])
        self.q = np.concatenate([np.roll(np.asarray(r, dtype=np.float64), -1, axis=0)
                                 for r in rings])
        lo2, hi2 = self.p.min(axis=0), self.p.max(axis=0)
        a, b, c = axes
        self.lo, self.hi = np.zeros(3), np.zeros(3)
        self.lo[[a, b, c]] = [lo2[0], lo2[1], self.zlo]
        self.hi[[a, b, c]] = [hi2[0], hi2[1], self.zhi]
        self.lo2 = lo2
        m = len(self.p)
        self.cells = int(np.clip(round(2 * np.sqrt(m)), 1, 256))
        self.cell_size = np.where(hi2 > lo2, hi2 - lo2, 1.0) / self.cells
        elo, ehi = np.minimum(self.p, self.q), np.maximum(self.p, self.q)
        self.elo, self.ehi = elo, ehi
        first, last = self._cell(elo), self._cell(ehi)
        edge, cell = expand_boxes(first, last)
        self.cell_edges, self.cell_start = buckets(cell[:, 0] * self.cells + cell[:, 1], edge,
                                                   self.cells ** 2)
        rows = last[:, 1] - first[:, 1] + 1
        owner, offset = expand(rows)
        self.row_edges, self.row_start = buckets(first[owner, 1] + offset, owner, self.cells)

    def _cell(self, p: np.ndarray) -> np.ndarray:
        """Each 2D point's cell, ``floor((p - lo) / size)`` clipped: monotone in
        floating point, so an edge meeting a rectangle shares a cell with it."""
        c = np.floor((p - self.lo2) / self.cell_size).astype(np.int64)
        return np.clip(c, 0, self.cells - 1)

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        a, b, c = self.axes
        state = np.full(len(lo), EMPTY, dtype=np.int8)
        near = np.flatnonzero(np.all((lo <= self.hi) & (hi >= self.lo), axis=1))
        if not len(near):
            return state
        rlo, rhi = lo[near][:, [a, b]], hi[near][:, [a, b]]
        edge_met = self._edges_meet(rlo, rhi)
        state[near[edge_met]] = AMBIGUOUS
        rest = ~edge_met
        inside = self._inside(rlo[rest])
        k = near[rest]
        within = (lo[k, c] > self.zlo) & (hi[k, c] < self.zhi)    # clear of both caps
        state[k] = np.where(inside, np.where(within, FULL, AMBIGUOUS), EMPTY)
        return state

    def _edges_meet(self, rlo: np.ndarray, rhi: np.ndarray) -> np.ndarray:
        """Whether an edge meets each closed rectangle (separating axes: the
        rectangle's, by the edge's box, and the edge's normal, by exact signs)."""
        first, last = self._cell(rlo), self._cell(rhi)
        box, cell = expand_boxes(first, last)
        key = cell[:, 0] * self.cells + cell[:, 1]
        pair, index = gather(self.cell_start[key], self.cell_start[key + 1] - self.cell_start[key])
        pb, pe = box[pair], self.cell_edges[index]
        met = np.zeros(len(rlo), dtype=bool)
        if not len(pb):
            return met
        n = len(self.p)
        codes = sorted_unique(pb.astype(np.int64) * n + pe)        # an edge once per box
        pb, pe = codes // n, codes % n
        ok = np.all((self.elo[pe] <= rhi[pb]) & (self.ehi[pe] >= rlo[pb]), axis=1)
        pb, pe = pb[ok], pe[ok]
        p, q = self.p[pe], self.q[pe]
        signs = np.stack([det2_sign(p, q, p, np.column_stack([xs[:, 0], ys[:, 1]]))
                          for xs in (rlo[pb], rhi[pb]) for ys in (rlo[pb], rhi[pb])])
        apart = np.all(signs > 0, axis=0) | np.all(signs < 0, axis=0)
        met[pb[~apart]] = True
        return met

    def _inside(self, points: np.ndarray) -> np.ndarray:
        """Whether each 2D point (on no edge) is inside the region: the parity of
        the edges crossing the ray from it towards +a."""
        if not len(points):
            return np.zeros(0, dtype=bool)
        row = self._cell(points)[:, 1]
        owner, index = gather(self.row_start[row], self.row_start[row + 1] - self.row_start[row])
        e = self.row_edges[index]
        y = points[owner, 1]
        p, q = self.p[e], self.q[e]
        straddle = (p[:, 1] > y) != (q[:, 1] > y)
        owner, e, p, q = owner[straddle], e[straddle], p[straddle], q[straddle]
        side = det2_sign(p, q, p, points[owner])
        up = np.where(q[:, 1] > p[:, 1], 1, -1)
        crossing = side * up > 0                        # the edge passes right of the point
        return np.bincount(owner[crossing], minlength=len(points)) % 2 == 1


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
