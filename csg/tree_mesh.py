"""The closed triangle mesh of a tree of polytopes: each leaf's mesh, and the
tree's 3D booleans computed on them by `Manifold <https://github.com/elalish/manifold>`_
(``manifold3d``, the mesh-boolean library OpenSCAD itself moved to after 2021.01).

OpenSCAD 2021.01 evaluates a boolean of polyhedra exactly (CGAL's Nef polyhedra)
and rounds the result to doubles; Manifold keeps every input vertex as it is and
computes the new ones (where faces of different operands cross) in doubles with
symbolic perturbation, so its result is a closed mesh of the same solid up to
that rounding. Needed where an operation takes a boolean's *result*, not its
operands: the shadow of a difference or intersection (:mod:`csg.projection`).

Leaves: :class:`~csg.primitives.Polyhedron` (imported meshes, ``surface``,
polyhedra), :class:`~csg.primitives.ConvexPolyhedron` given by points (OpenSCAD's
faceted spheres and cylinders), :class:`~csg.primitives.Box`,
:class:`~csg.prism.Prism` (OpenSCAD's straight extrusions), moved by any
``multmatrix``. Meshes come out oriented outward.

Examples
--------
>>> from csg import Box
>>> v, f = tree_mesh(Box((2, 2, 2), center=True) - Box((1, 1, 4), center=True), np.eye(4))
>>> float(mesh_volume(v, f))
6.0
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from implicitvox.expr.shape import EMPTY
from implicitvox.triangles.closed import mesh_volume

from .clipper2d import region_pieces
from .facets import extrusion_mesh_outlines
from .planar import LinearExtrude
from .prism import Prism
from .protocol import NotAMesh, NotFlat, fold
from .tree_classifier import MeshClassifier
from .solid import Solid, register_boundary, register_facets, register_regularizer

__all__ = ["tree_mesh", "leaf_mesh", "mesh_volume", "NotAMesh", "boundary_mesh",
           "regularized_classifier", "EmptyBoundary"]

def leaf_mesh(solid: Solid, matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed triangle mesh (vertices, faces) of a polytope leaf, moved by
    ``matrix``, oriented outward.

    Raises
    ------
    NotAMesh
        A curved leaf (``curved`` set), or a kind of leaf with no mesh here.
    """
    v, f = _closed_mesh(solid)
    v = v @ matrix[:3, :3].T + matrix[:3, 3]
    if mesh_volume(v, f) < 0:                 # given inward (or mirrored by the matrix)
        f = f[:, ::-1]
    return v, f


def _closed_mesh(solid: Solid) -> tuple[np.ndarray, np.ndarray]:
    """A leaf's :meth:`~csg.solid.Solid.closed_mesh`; an extrusion of a polygonal
    section scaled evenly, without twist (kept with its section's function in
    ``facets="openscad"``), is OpenSCAD's one slice of it: its walls are planar."""
    if isinstance(solid, LinearExtrude) and not isinstance(solid, Prism) and solid.twist == 0:
        try:
            pieces = region_pieces(solid.children[0])
        except NotFlat as err:
            raise NotAMesh(f"a linear_extrude of a curved section has no mesh ({err})",
                           curved=True) from None
        z0 = -solid.height / 2 if solid.centered else 0.0
        return extrusion_mesh_outlines(pieces, solid.height, 0.0, solid.scale_top, 1, z0)
    return solid.closed_mesh()


_MANIFOLD_OPS = {"union": "Add", "difference": "Subtract", "intersection": "Intersect"}


def _manifold(solid: Solid, matrix: np.ndarray):
    """The tree as a Manifold: each leaf's :func:`leaf_mesh`, each boolean computed in
    its own frame and then moved (as OpenSCAD moves its result: faces that coincide
    in that frame still coincide, where moving each operand's vertices first would
    round them apart into slivers)."""
    import manifold3d

    def combine(operation: str, parts: list):
        op = getattr(manifold3d.OpType, _MANIFOLD_OPS[operation])
        return manifold3d.Manifold.batch_boolean(parts, op)

    return fold(solid, _leaf_manifold, combine, matrix,
                moved=lambda made, m: made.transform(np.ascontiguousarray(m[:3, :4])))


def _leaf_manifold(solid: Solid, matrix: np.ndarray):
    import manifold3d
    v, f = leaf_mesh(solid, matrix)
    mesh = manifold3d.Mesh64(vert_properties=np.ascontiguousarray(v, dtype=np.float64),
                             tri_verts=np.ascontiguousarray(f, dtype=np.uint64))
    made = manifold3d.Manifold(mesh)
    if made.status() != manifold3d.Error.NoError:
        raise NotAMesh(f"a {type(solid).__name__} of {len(f):,} triangles is not a closed "
                       f"manifold mesh ({made.status().name}): its booleans are not defined")
    return made


def tree_mesh(solid: Solid, matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed triangle mesh (vertices, faces; oriented outward) of a tree of
    polytope leaves and booleans, moved by ``matrix``; an empty result has no faces.

    Raises
    ------
    NotAMesh
        A leaf as :func:`leaf_mesh` refuses, or one whose mesh is not closed and
        manifold (Manifold's status named).
    """
    if solid.operation not in ("transform", "union", "difference", "intersection"):
        return leaf_mesh(solid, matrix)
    result = _manifold(solid, matrix).to_mesh64()
    v = np.array(np.asarray(result.vert_properties, dtype=np.float64)[:, :3])   # (a copy:
    # a view would keep Manifold's mesh alive, and nanobind reports it as leaked at exit)
    return v, np.asarray(result.tri_verts, dtype=np.int64).reshape(-1, 3)


class EmptyBoundary:
    """The boundary of a regularized solid that is empty - parts that only touch, as
    the intersection of two cubes sharing a face: no box meets it (OpenSCAD 2021.01
    exports that face as a sheet, warning that the object "may not be a valid
    2-manifold"; the regularized solid has none)."""

    def classify(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """EMPTY for every box ``[lo, hi]``."""
        return np.full(len(lo), EMPTY, dtype=np.int8)


def boundary_mesh(solid: Solid) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """The regularized ``solid``'s boundary: its :func:`tree_mesh`, whose booleans keep
    no face shared inside the solid; None where the tree has no mesh (a curved leaf,
    an open mesh)."""
    try:
        return tree_mesh(solid, np.eye(4))
    except (NotAMesh, ValueError):
        return None


def regularized_classifier(solid: Solid):
    """The exact box test (:class:`~csg.tree_classifier.MeshClassifier`) of the boundary of
    the regularized ``solid`` (:attr:`~csg.solid.Solid.boundary_mesh`;
    :class:`EmptyBoundary` where it is empty); None where the tree has no mesh."""
    found = solid.boundary_mesh
    if found is None:
        return None
    v, f = found
    return MeshClassifier(v, f) if len(f) else EmptyBoundary()


def leaf_triangles(solid: Solid) -> Optional[np.ndarray]:
    """Every leaf's triangles ``(t, 3, 3)``, moved, through every boolean (no boolean is
    computed: for the normals of facets near the surface); leaves without a mesh are
    left out; None when none has one."""
    def leaf(node: Solid, matrix: np.ndarray) -> list:
        try:
            v, f = leaf_mesh(node, matrix)
        except (NotAMesh, ValueError):
            return []
        return [v[f]]

    parts = fold(solid, leaf, lambda operation, kids: [p for kid in kids for p in kid],
                 booleans=("union", "intersection", "difference", "complement"))
    return np.concatenate(parts) if parts else None


register_boundary(boundary_mesh)
register_regularizer(regularized_classifier)
register_facets(leaf_triangles)
