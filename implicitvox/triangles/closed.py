"""Closed triangle meshes: the signed volume, the convex hull as an outward mesh, convexity.

Examples
--------
>>> import numpy as np
>>> corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 2)], float)
>>> v, f = hull_mesh(corners)
>>> mesh_volume(v, f), is_convex_mesh(v, f)
(2.0, True)
"""
from __future__ import annotations

import numpy as np

from .weld import weld

__all__ = ["mesh_volume", "hull_mesh", "is_convex_mesh", "is_closed_mesh", "CONVEX_TOLERANCE"]

#: a mesh is convex when its volume is its hull's within this share of the hull's
CONVEX_TOLERANCE = 1e-9


def mesh_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The signed volume of a closed triangle mesh (positive when oriented outward)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def is_closed_mesh(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Whether a triangle mesh is closed and consistently oriented, as a halfedge
    structure (CGAL's ``Polyhedron_3``) needs it: with vertices at equal coordinates
    taken as one and collapsed triangles left out, every directed edge occurs once
    and its reverse occurs too.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    >>> tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> is_closed_mesh(v, tet), is_closed_mesh(v, tet[:3])
    (True, False)
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not len(faces):
        return False
    _, same = weld(vertices)
    f = same.reshape(-1)[faces]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])]
    if not len(f):
        return False
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    n = int(same.max()) + 1
    forward = edges[:, 0] * n + edges[:, 1]
    unique = np.unique(forward)
    return len(unique) == len(forward) and bool(np.isin(edges[:, 1] * n + edges[:, 0],
                                                        unique).all())


def hull_mesh(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The convex hull of ``points`` (n, 3) as triangles ``(points, faces)``, each
    oriented by the hull's outward normal (scipy's Qhull).

    Raises
    ------
    ValueError
        The points span no volume (flat, or too small or too large for Qhull's
        arithmetic), so their hull has no closed mesh.
    """
    from scipy.spatial import ConvexHull, QhullError
    points = np.asarray(points, dtype=np.float64)
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError) as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ValueError(f"the convex hull of {len(points)} points has no volume, or its "
                         f"points are beyond Qhull's arithmetic ({first})") from None
    f = hull.simplices.copy()
    a, b, c = (points[f[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), hull.equations[:, :3]) < 0
    f[inward] = f[inward][:, ::-1]
    return points, f


def is_convex_mesh(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Whether a closed mesh is convex: its volume equals its hull's (within
    :data:`CONVEX_TOLERANCE`); False for a flat one."""
    from scipy.spatial import ConvexHull, QhullError
    volume = abs(mesh_volume(vertices, faces))
    try:
        whole = ConvexHull(vertices[np.unique(faces.ravel())]).volume
    except QhullError:
        return False
    return bool(abs(whole - volume) <= CONVEX_TOLERANCE * whole)
