"""OpenSCAD's ``projection``: a 3D tree of polytopes and meshes flattened to 2D.

* ``cut=True``: the section by the plane z = 0. A section distributes over
  every boolean (the section of ``A − B`` is the section of ``A`` minus that of
  ``B``), so each leaf's triangle mesh is sliced (the crossing point of each
  mesh edge is computed once, so neighbouring triangles share it exactly, and
  the segments chain into closed outlines) and the outlines are combined by
  the tree's booleans with Clipper (:mod:`csg.clipper2d`), as OpenSCAD
  combines 2D shapes. A vertex on the plane counts as below it: the cut is
  that of the plane just above z = 0, so a part resting on z = 0 gives its
  footprint, as in OpenSCAD (whose exact cut also gives the face of a part
  hanging from z = 0, where this gives nothing).
* ``cut=False``: the shadow on z = 0, the union of every triangle projected,
  as OpenSCAD's ``PolysetUtils::project`` and Clipper's non-zero union make it.
  A shadow distributes over unions only: below a difference or intersection the
  boolean's result is computed as a mesh first (:func:`csg.tree_mesh.tree_mesh`,
  by Manifold), as OpenSCAD computes it (CGAL) before projecting.

Leaves: those of :func:`csg.tree_mesh.leaf_mesh` (polyhedra, imported meshes,
surfaces, boxes, faceted primitives), moved by any ``multmatrix``. A curved
leaf raises :class:`~csg.tree_mesh.NotAMesh` (``curved`` set: the reader then
takes OpenSCAD's facets, with a warning).

Examples
--------
>>> from csg import Box
>>> section = projection(Box((2, 2, 2), center=True) - Box((1, 1, 4), center=True), cut=True)
>>> len(section.paths), section.bounds
(2, ((-1.0, -1.0, 0.0), (1.0, 1.0, 0.0)))
>>> shadow = projection(Box((1, 1, 1)) | Box((1, 1, 1)).translate((3, 0, 0)), cut=False)
>>> len(shadow.paths)
2
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from .clipper2d import boolean_paths, clip, to_clipper, to_polygon
from .planar import Polygon
from .protocol import NotAMesh, fold
from .solid import Solid
from .tree_mesh import leaf_mesh, tree_mesh

__all__ = ["projection", "leaf_mesh", "section_outlines", "NotAMesh"]

def section_outlines(vertices: np.ndarray, faces: np.ndarray) -> list[np.ndarray]:
    """The closed outlines (each (k, 2)) where the plane z = 0 cuts a closed mesh
    (a vertex on the plane counts as below it: the plane just above z = 0)."""
    above = vertices[:, 2] > 0
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    crossing = above[edges[:, 0]] != above[edges[:, 1]]
    tri_cross = crossing.reshape(3, -1).T                  # per face: which edges cross
    cut = tri_cross.sum(axis=1) == 2
    if not cut.any():
        return []
    key = np.sort(edges, axis=1)
    unique, inverse = np.unique(key[crossing], axis=0, return_inverse=True)
    a, b = vertices[unique[:, 0]], vertices[unique[:, 1]]
    t = a[:, 2] / (a[:, 2] - b[:, 2])
    points = a[:, :2] + t[:, None] * (b[:, :2] - a[:, :2])
    edge_id = np.full(len(edges), -1)
    edge_id[np.flatnonzero(crossing)] = inverse.ravel()
    ids = edge_id.reshape(3, -1).T[cut]                    # (m, 3), two of them >= 0
    ends = np.sort(ids, axis=1)[:, 1:]                     # each cut face: its two points
    neighbours: dict[int, list[int]] = {}
    for p, q in ends.tolist():
        neighbours.setdefault(p, []).append(q)
        neighbours.setdefault(q, []).append(p)
    seen: set[int] = set()
    loops = []
    for start in neighbours:
        if start in seen:
            continue
        loop, previous, current = [start], None, start
        seen.add(start)
        while True:
            options = [n for n in neighbours[current] if n != previous] or neighbours[current]
            nxt = options[0]
            if nxt == start or nxt in seen:
                break
            loop.append(nxt)
            seen.add(nxt)
            previous, current = current, nxt
        if len(loop) >= 3:
            loops.append(points[loop])
    return loops


def _cut_paths(solid: Solid, matrix: np.ndarray) -> list:
    """The section by z = 0 through every boolean (a section distributes over them):
    each leaf's mesh sliced, the outlines combined by Clipper."""
    def leaf(node: Solid, moved: np.ndarray) -> list:
        loops = section_outlines(*leaf_mesh(node, moved))
        return clip([to_clipper(loop) for loop in loops], [], "CT_UNION", "PFT_EVENODD")

    return fold(solid, leaf, boolean_paths, matrix)


def _shadow_paths(solid: Solid, matrix: np.ndarray) -> list:
    """The shadow on z = 0 through the unions; below a difference or intersection, the
    shadow of the boolean's result (its mesh by Manifold), as OpenSCAD projects it."""
    return fold(solid, _result_shadow, boolean_paths, matrix, booleans=("union",))


def _result_shadow(solid: Solid, matrix: np.ndarray) -> list:
    v, f = tree_mesh(solid, matrix)
    if not len(f):
        return []
    tri = v[f][:, :, :2]
    u, w = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    area = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    tri = tri[area != 0]
    tri[area[area != 0] < 0] = tri[area[area != 0] < 0][:, ::-1]     # all counter-clockwise
    return clip([to_clipper(t) for t in tri], [], "CT_UNION")


def projection(solid: Solid, cut: bool = False) -> Optional[Polygon]:
    """OpenSCAD's ``projection`` of a 3D tree: its section by z = 0 (``cut``) or its
    shadow on z = 0, as a :class:`~csg.planar.Polygon`; None when empty.

    Raises
    ------
    NotAMesh
        A curved leaf, or (``cut=False``) a boolean of meshes that are not closed.
    """
    paths = _cut_paths(solid, np.eye(4)) if cut else _shadow_paths(solid, np.eye(4))
    return to_polygon(paths)
