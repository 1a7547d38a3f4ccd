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

import numpy as np

from .primitives import (Box, ConvexPolyhedron, Cylinder, Ellipsoid, Polyhedron, Sphere,
                         Torus)
from .prism import Prism
from .tree_classifier import MeshClassifier
from .solid import Difference, Intersection, Solid, Transformed, Union, register_regularizer

__all__ = ["tree_mesh", "leaf_mesh", "mesh_volume", "NotAMesh", "regularized_classifier"]

_CURVED = (Sphere, Cylinder, Torus, Ellipsoid)


class NotAMesh(ValueError):
    """A 3D leaf with no triangle mesh (curved, or a kind with no mesh here), or a
    boolean whose operands are not closed meshes."""

    def __init__(self, message: str, curved: bool = False):
        super().__init__(message)
        #: the reason is a curved leaf (its facets would do)
        self.curved = curved


def mesh_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The signed volume of a closed triangle mesh (positive when oriented outward)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _hull_mesh(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The convex hull's triangles, each oriented by the hull's outward normal."""
    from scipy.spatial import ConvexHull
    hull = ConvexHull(points)
    f = hull.simplices.copy()
    a, b, c = (points[f[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), hull.equations[:, :3]) < 0
    f[inward] = f[inward][:, ::-1]
    return points, f


def leaf_mesh(solid: Solid, matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed triangle mesh (vertices, faces) of a polytope leaf, moved by
    ``matrix``, oriented outward.

    Raises
    ------
    NotAMesh
        A curved leaf (``curved`` set), or a kind of leaf with no mesh here.
    """
    if isinstance(solid, _CURVED):
        raise NotAMesh(f"a {type(solid).__name__} is curved: it has no mesh "
                       "(facet it first: read_openscad(..., facets='openscad'))", curved=True)
    if isinstance(solid, Polyhedron):
        v, f = solid.vertices, np.asarray(solid.faces)
    elif isinstance(solid, Prism):
        v, f = solid.mesh()
    elif isinstance(solid, ConvexPolyhedron) and solid.points is not None:
        v, f = _hull_mesh(np.asarray(solid.points, dtype=np.float64))
    elif isinstance(solid, Box):
        lo = -solid.size / 2 if solid.centered else np.zeros(3)
        corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
        v, f = _hull_mesh(lo + corners * solid.size)
    else:
        raise NotAMesh(f"a {type(solid).__name__} has no triangle mesh here (polyhedra, "
                       "imported meshes, surfaces, boxes and faceted primitives have)",
                       curved=type(solid).__name__ in ("LinearExtrude", "RotateExtrude"))
    v = v @ matrix[:3, :3].T + matrix[:3, 3]
    if mesh_volume(v, f) < 0:                 # given inward (or mirrored by the matrix)
        f = f[:, ::-1]
    return v, f


def _manifold(solid: Solid, matrix: np.ndarray):
    import manifold3d
    if isinstance(solid, Transformed):
        child, moved = solid.children[0], matrix @ solid.matrix
        if isinstance(child, (Union, Difference, Intersection)):
            # a boolean in its own frame, then moved (as OpenSCAD moves its result): faces
            # that coincide in that frame still coincide, where moving each operand's
            # vertices first would round them apart into slivers
            return _manifold(child, np.eye(4)).transform(np.ascontiguousarray(moved[:3, :4]))
        return _manifold(child, moved)
    if isinstance(solid, (Union, Difference, Intersection)):
        op = {Union: manifold3d.OpType.Add, Difference: manifold3d.OpType.Subtract,
              Intersection: manifold3d.OpType.Intersect}[type(solid)]
        return manifold3d.Manifold.batch_boolean([_manifold(c, matrix) for c in solid.children],
                                                 op)
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
    if not isinstance(solid, (Transformed, Union, Difference, Intersection)):
        return leaf_mesh(solid, matrix)
    result = _manifold(solid, matrix).to_mesh64()
    v = np.asarray(result.vert_properties, dtype=np.float64)[:, :3]
    return v, np.asarray(result.tri_verts, dtype=np.int64).reshape(-1, 3)


def regularized_classifier(solid: Solid):
    """The exact box test (:class:`~csg.tree_classifier.MeshClassifier`) of the boundary of
    the regularized ``solid``: its :func:`tree_mesh`, whose booleans keep no face
    shared inside the solid; None where the tree has no mesh (a curved leaf, an
    open mesh) or is empty."""
    try:
        v, f = tree_mesh(solid, np.eye(4))
    except (NotAMesh, ValueError):
        return None
    return MeshClassifier(v, f) if len(f) else None


register_regularizer(regularized_classifier)
