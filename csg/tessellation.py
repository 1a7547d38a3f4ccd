"""The diagonal OpenSCAD 2021.01 cuts a polyhedron's quad face along.

A ``polyhedron`` face of four corners off one plane (a *bent* quad) is two
triangles, and which two is OpenSCAD's choice: its mesh, and so its STL, takes
the diagonal that libtess2 takes (``PolysetUtils::tessellate_faces`` ->
``GeometryUtils::tessellatePolygonWithHoles`` -> ``tessTesselate(...,
TESS_CONSTRAINED_DELAUNAY_TRIANGLES, ..., normal = NULL)``). The other diagonal
gives another solid, and its voxels differ along the whole face. This module
repeats libtess2's steps for one quad, in single precision as libtess2 computes
(``TESSreal`` is ``float``; OpenSCAD hands it the corners as ``Vector3f``):

1. the corners in reverse file order (OpenSCAD's ``insert_vertex`` puts each at
   the front);
2. libtess2's normal (``ComputeNormal``: the corners farthest apart along the
   axis of largest extent, and the corner making the largest triangle with
   them), and the projection that drops the normal's longest axis
   (``tessProjectPolygon``: ``s`` the next axis, ``t`` the one after, signed by
   the normal, then flipped so that the contour's area is positive:
   ``CheckOrientation``);
3. the monotone triangulation of the projected quad (``tessMeshTessellateMonoRegion``):
   for a quad it cuts along the diagonal through the lexicographically largest
   corner in ``(s, t)``, unless the smallest corner is the one opposite, where it
   cuts the other;
4. the Delaunay refinement (``tessMeshRefineDelaunay``): the diagonal flips when
   the two angles facing it sum to at least pi + 0.01 (``tesedgeIsLocallyDelaunay``).

Where the projected quad crosses itself (a bow tie: libtess2 inserts the
crossing point, OpenSCAD drops the triangles that use it and closes the hole
from an unordered map), the choice is not repeated here: :func:`quad_diagonals`
says ``-1`` and the caller keeps both diagonals as surface. Checked against
OpenSCAD 2021.01's own STL exports: every convex and every dart-shaped
projection of 1,281 random bent quads (``tests/csg/test_tessellation.py`` keeps a
sample), and every face of OpenSCAD's test model ``issue1061.scad``.

Examples
--------
>>> import numpy as np
>>> quad = np.array([[0, 0, 0], [1, 0, 0.3], [1, 1, 0], [0, 1, 0.3]])
>>> quad_diagonals(quad[None])     # corner 0 to corner 2
array([0], dtype=int8)
"""
from __future__ import annotations

import numpy as np

__all__ = ["quad_diagonals", "DELAUNAY_SLACK"]

#: libtess2 flips a diagonal when the angles facing it sum to at least pi plus this
DELAUNAY_SLACK = 0.01


def quad_diagonals(quads: np.ndarray) -> np.ndarray:
    """The diagonal OpenSCAD 2021.01 takes across each quad face, as listed in a ``.csg``
    file's ``polyhedron(faces = ...)``.

    Parameters
    ----------
    quads : (n, 4, 3) array
        Each face's corners in the file's order.

    Returns
    -------
    (n,) int8 array
        0: the diagonal from corner 0 to corner 2; 1: from corner 1 to corner 3;
        -1: not known here (the projected quad crosses itself or is degenerate).
    """
    quads = np.asarray(quads, dtype=np.float64).reshape(-1, 4, 3)
    n = len(quads)
    q = quads[:, ::-1].astype(np.float32)                 # OpenSCAD's (reversed) order
    rows = np.arange(n)
    norm = _libtess_normal(q)
    absn = np.abs(norm)
    axis = np.zeros(n, dtype=np.int64)                    # LongAxis: the first largest
    axis[absn[:, 1] > absn[:, 0]] = 1
    axis[absn[:, 2] > absn[rows, axis]] = 2
    s = q[rows[:, None], np.arange(4), ((axis + 1) % 3)[:, None]]
    t = q[rows[:, None], np.arange(4), ((axis + 2) % 3)[:, None]]
    t = np.where((norm[rows, axis] > 0)[:, None], t, -t)
    nxt = np.roll(np.arange(4), -1)
    area = ((s - s[:, nxt]) * (t + t[:, nxt])).sum(axis=1, dtype=np.float32)
    t = np.where((area < 0)[:, None], -t, t)              # CheckOrientation
    # the contour's turns: all one sign (convex), one odd (a dart) or two and two (a bow tie)
    prv = np.roll(np.arange(4), 1)
    s64, t64 = s.astype(np.float64), t.astype(np.float64)
    turn = (s64 - s64[:, prv]) * (t64[:, nxt] - t64) - (t64 - t64[:, prv]) * (s64[:, nxt] - s64)
    positive, negative = (turn > 0).sum(axis=1), (turn < 0).sum(axis=1)
    known = (positive + negative == 4) & (positive != 2) & np.isfinite(norm).all(axis=1) & \
        (absn.max(axis=1) > 0)
    # lexicographic order in (s, t) (libtess2's VertLeq): the largest corner and the smallest
    ranked = np.lexsort((t64, s64), axis=1)
    largest, smallest = ranked[:, 3], ranked[:, 0]
    opposite = (largest + 2) % 4
    # monotone triangulation: through R and its opposite, unless L is that opposite
    through_r = smallest != opposite
    diagonal = np.where(through_r, largest % 2, (largest + 1) % 2)   # 0: corners 0-2
    # Delaunay refinement: the angles at the two corners off the diagonal
    off_a = np.where(diagonal == 0, 1, 0)
    total = _angle(s, t, off_a) + _angle(s, t, off_a + 2)
    diagonal = np.where(total >= np.pi + DELAUNAY_SLACK, 1 - diagonal, diagonal)
    # back to the file's order: corner k of the reversed quad is corner 3 - k, and
    # 3 - k has the parity of k + 1: the diagonal 0-2 there is 3-1 here
    out = (1 - diagonal).astype(np.int8)
    out[~known] = -1
    return out


def _libtess_normal(q: np.ndarray) -> np.ndarray:
    """libtess2's ``ComputeNormal`` for each quad ``(n, 4, 3)`` float32: the cross
    product of the corners farthest apart along the axis of largest extent with the
    corner that makes the largest triangle with them (first found on ties)."""
    n = len(q)
    rows = np.arange(n)
    lo, hi = q.min(axis=1), q.max(axis=1)
    low, high = q.argmin(axis=1), q.argmax(axis=1)        # the first extreme corner
    extent = hi - lo
    axis = np.zeros(n, dtype=np.int64)
    axis[extent[:, 1] > extent[:, 0]] = 1
    axis[extent[:, 2] > extent[rows, axis]] = 2
    v1 = q[rows, low[rows, axis]]
    v2 = q[rows, high[rows, axis]]
    d1 = v1 - v2
    d2 = q - v2[:, None]
    cross = np.stack([d1[:, None, 1] * d2[:, :, 2] - d1[:, None, 2] * d2[:, :, 1],
                      d1[:, None, 2] * d2[:, :, 0] - d1[:, None, 0] * d2[:, :, 2],
                      d1[:, None, 0] * d2[:, :, 1] - d1[:, None, 1] * d2[:, :, 0]], axis=2)
    length = (cross[:, :, 0] * cross[:, :, 0] + cross[:, :, 1] * cross[:, :, 1]) + \
        cross[:, :, 2] * cross[:, :, 2]
    best = np.argmax(length, axis=1)
    norm = cross[rows, best]
    norm[length[rows, best] <= 0] = 0                    # collinear: left unknown
    return norm


def _angle(s: np.ndarray, t: np.ndarray, at: np.ndarray) -> np.ndarray:
    """libtess2's ``calcAngle`` at corner ``at`` of each quad, between its neighbours
    (float32 arithmetic, ``acos`` in double, as in C)."""
    rows = np.arange(len(s))
    before, after = (at + 3) % 4, (at + 1) % 4
    a0, a1 = s[rows, after] - s[rows, at], t[rows, after] - t[rows, at]
    b0, b1 = s[rows, before] - s[rows, at], t[rows, before] - t[rows, at]
    num = a0 * b0 + a1 * b1
    den = (np.sqrt((a0 * a0 + a1 * a1).astype(np.float64)) *
           np.sqrt((b0 * b0 + b1 * b1).astype(np.float64))).astype(np.float32)
    num = np.where(den > 0, num / np.where(den > 0, den, 1), num)
    return np.arccos(np.clip(num.astype(np.float64), -1.0, 1.0))
