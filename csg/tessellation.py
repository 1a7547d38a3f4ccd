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
   them, the first found on ties in the order of libtess2's vertex list: the
   contour from its second corner on, its first corner last), and the projection
   that drops the normal's longest axis
   (``tessProjectPolygon``: ``s`` the next axis, ``t`` the one after, signed by
   the normal, then flipped so that the contour's area is positive:
   ``CheckOrientation``);
3. the monotone triangulation of the projected quad (``tessMeshTessellateMonoRegion``):
   for a quad it cuts along the diagonal through the lexicographically largest
   corner in ``(s, t)``, unless the smallest corner is the one opposite, where it
   cuts the other;
4. the Delaunay refinement (``tessMeshRefineDelaunay``): the diagonal flips when
   the two angles facing it sum to at least pi + 0.01 (``tesedgeIsLocallyDelaunay``).

A projection that is not convex is handled as libtess2 and OpenSCAD do: a dart
(one reflex corner) is cut through that corner; a bow tie (it crosses itself:
libtess2 inserts the crossing point, OpenSCAD drops the triangles that use it and
closes the loop that is left from hash maps) where that loop closing cuts, which
needs OpenSCAD's numbers of the corners (:func:`openscad_vertex_ids`); a quad
with one corner on the line through its neighbours as a triangle with a corner on
an edge (cut through it) or with a spike (the spike's corner is the ear). Two
corners on one point of the projection: neighbours are merged by libtess2
(``RemoveDegenerateEdges`` keeps the first corner of their edge in contour order,
the second for the edge out of the contour's first corner), which cuts the
triangle left, and OpenSCAD closes the face with the merged corner's triangle: the
diagonal runs through the corner kept; opposite corners leave a projection of no
area, nothing is cut, and OpenSCAD closes the loop as a bow tie's. A quad with no
normal (its corners on a line, or not finite) is not known: :func:`quad_diagonals`
says ``-1`` and the caller keeps both diagonals as surface. Checked against
OpenSCAD 2021.01's own STL exports: every diagonal of the 3,325 bent faces of 560
randomly bent boxes (bow ties and darts among them), of 2,300 random quads with two
corners on one projected point and 1,900 random integer quads (ties in the normal),
and of OpenSCAD's test models ``issue1061.scad``, ``issue964b.scad`` and
``issue964.scad`` (``tests/openscad/bent.scad``, ``tests/openscad/pinched.scad`` and
``tests/csg/test_tessellation.py`` keep samples).

Examples
--------
>>> import numpy as np
>>> quad = np.array([[0, 0, 0], [1, 0, 0.3], [1, 1, 0], [0, 1, 0.3]])
>>> quad_diagonals(quad[None])     # corner 0 to corner 2
array([0], dtype=int8)
"""
from __future__ import annotations

from typing import Optional

import numpy as np

__all__ = ["quad_diagonals", "openscad_vertex_ids", "DELAUNAY_SLACK"]

#: libtess2 flips a diagonal when the angles facing it sum to at least pi plus this
DELAUNAY_SLACK = 0.01


def quad_diagonals(quads: np.ndarray, corner_ids: Optional[np.ndarray] = None) -> np.ndarray:
    """The diagonal OpenSCAD 2021.01 takes across each quad face, as listed in a ``.csg``
    file's ``polyhedron(faces = ...)``.

    Parameters
    ----------
    quads : (n, 4, 3) array
        Each face's corners in the file's order.
    corner_ids : (n, 4) int array, optional
        OpenSCAD's numbers of those corners (:func:`openscad_vertex_ids` of their
        points), which decide a bow tie's diagonal; without them it is not known.

    Returns
    -------
    (n,) int8 array
        0: the diagonal from corner 0 to corner 2; 1: from corner 1 to corner 3;
        -1: not known here (a bow tie, or two opposite corners on one projected
        point, without ``corner_ids``; a quad with no normal).
    """
    quads = np.asarray(quads, dtype=np.float64).reshape(-1, 4, 3)
    n = len(quads)
    q = quads[:, ::-1].astype(np.float32)                 # OpenSCAD's (reversed) order
    rows = np.arange(n)
    # (libtess2's vertex list holds the contour from its second corner on, the first last:
    # ComputeNormal's "first found" on ties counts in that order)
    norm = _libtess_normal(np.roll(q, -1, axis=1))
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
    proper = (positive + negative == 4) & np.isfinite(norm).all(axis=1) & (absn.max(axis=1) > 0)
    dart = proper & ((positive == 1) | (positive == 3))
    bow_tie = proper & (positive == 2)
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
    # a dart: the only diagonal inside it, through its reflex corner (no flip passes it)
    odd_sign = np.where((positive == 1)[:, None], turn > 0, turn < 0)
    diagonal = np.where(dart, np.argmax(odd_sign, axis=1) % 2, diagonal)
    # one corner on the line through its neighbours: the quad is a triangle with a
    # corner on an edge (libtess2 cuts through that corner) or with a spike that turns
    # back at it (libtess2 keeps the triangle; the spike's corner is OpenSCAD's ear)
    corner = np.argmax(turn == 0, axis=1)
    back = ((s64[rows, corner] - s64[rows, (corner + 3) % 4]) *
            (s64[rows, (corner + 1) % 4] - s64[rows, corner]) +
            (t64[rows, corner] - t64[rows, (corner + 3) % 4]) *
            (t64[rows, (corner + 1) % 4] - t64[rows, corner])) < 0
    flat = np.isfinite(norm).all(axis=1) & (absn.max(axis=1) > 0) & \
        ((turn == 0).sum(axis=1) == 1) & (back | (positive == 3) | (negative == 3))
    diagonal = np.where(flat, np.where(back, (corner + 1) % 2, corner % 2), diagonal)
    # back to the file's order: corner k of the reversed quad is corner 3 - k, and
    # 3 - k has the parity of k + 1: the diagonal 0-2 there is 3-1 here
    out = (1 - diagonal).astype(np.int8)
    if corner_ids is not None and bow_tie.any():
        ids = np.asarray(corner_ids, dtype=np.int64).reshape(-1, 4)[bow_tie]
        out[bow_tie] = _bow_tie_diagonals(ids[:, ::-1])
    else:
        out[bow_tie] = -1
    out[~proper & ~flat] = -1
    # two neighbouring corners on one point of the projection: libtess2 merges them
    # (RemoveDegenerateEdges keeps the edge's first corner in its contour order, the
    # second for the edge out of the first corner added), cuts the triangle left, and
    # OpenSCAD closes the face with the merged corner's own triangle: the diagonal
    # runs through the corner kept
    same = (s == s[:, nxt]) & (t == t[:, nxt])
    distinct = ~((s[:, 0] == s[:, 2]) & (t[:, 0] == t[:, 2])) & \
        ~((s[:, 1] == s[:, 3]) & (t[:, 1] == t[:, 3]))
    merged = np.isfinite(norm).all(axis=1) & (absn.max(axis=1) > 0) & \
        (same.sum(axis=1) == 1) & distinct
    first = np.argmax(same, axis=1)
    kept = np.where(first == 0, 1, first)                 # in OpenSCAD's (reversed) order
    out[merged] = ((kept + 1) % 2)[merged]
    # two opposite corners on one point: a projection of no area, libtess2 cuts nothing
    # and OpenSCAD closes the whole loop itself, as it does a bow tie's
    pinched = np.isfinite(norm).all(axis=1) & (absn.max(axis=1) > 0) & \
        ~same.any(axis=1) & ~distinct
    if corner_ids is not None and pinched.any():
        ids = np.asarray(corner_ids, dtype=np.int64).reshape(-1, 4)[pinched]
        out[pinched] = _bow_tie_diagonals(ids[:, ::-1])
    return out


def openscad_vertex_ids(points: np.ndarray, faces: list) -> np.ndarray:
    """OpenSCAD's number of each point (``Reindexer<Vector3f>`` in ``tessellate_faces``):
    points at equal single-precision coordinates share one, numbered in order of
    first use over the faces in file order, each face's corners in reverse (the
    order OpenSCAD's polygons hold them); -1 for a point no face uses."""
    points = np.asarray(points, dtype=np.float64)
    _, key = np.unique(points.astype(np.float32), axis=0, return_inverse=True)
    key = key.reshape(-1)
    sequence = np.concatenate([np.asarray(f, dtype=np.int64)[::-1] for f in faces]) \
        if faces else np.zeros(0, dtype=np.int64)
    keys = key[sequence]
    first_keys, first_use = np.unique(keys, return_index=True)
    number = np.empty(len(first_keys), dtype=np.int64)
    number[np.argsort(first_use, kind="stable")] = np.arange(len(first_keys))
    per_key = np.full(int(key.max()) + 1 if len(key) else 0, -1, dtype=np.int64)
    per_key[first_keys] = number
    return per_key[key]


#: buckets of a small ``std::unordered_map`` in GCC 12's libstdc++ (its first allocation)
_BUCKETS = 13


def _bow_tie_diagonals(ids: np.ndarray) -> np.ndarray:
    """The diagonal OpenSCAD takes across bow ties whose corners carry OpenSCAD's numbers
    ``ids (n, 4)``, given in its polygon order (the file's reversed); returned in the
    file's order, as :func:`quad_diagonals` returns it (0: corners 0-2, 1: corners 1-3).

    libtess2 cuts a bow tie at its crossing point; OpenSCAD drops the triangles that
    use that new point (``tessellatePolygonWithHoles``) and closes the loop that is
    left from its ``EdgeDict`` (``triangulateLoops``): the ear at the first vertex of
    an ``unordered_map<int, list<int>>`` filled in the order of an
    ``unordered_map<pair<int, int>, int, boost::hash>`` of the edges. So the cut is
    the diagonal between that vertex's neighbours; iteration orders follow
    libstdc++ (13 buckets, a new bucket's node first, a node first in its bucket)
    and Boost 1.74's pair hash, as Debian's build of OpenSCAD 2021.01 has them
    (checked on every bow tie among the bent faces of 560 random boxes, and of
    OpenSCAD's test models, against OpenSCAD's own STL exports).
    """
    edges_from = ids
    edges_to = np.roll(ids, -1, axis=1)
    edge_order = _iteration_order(_boost_pair_hash(edges_from, edges_to))
    v2e_keys = np.take_along_axis(edges_from, edge_order, axis=1)   # inserted in that order
    first = np.take_along_axis(v2e_keys, _iteration_order(v2e_keys)[:, :1], axis=1)[:, 0]
    corner = np.argmax(ids == first[:, None], axis=1)            # the ear's corner
    # the ear at corner k cuts k - 1 to k + 1: the diagonal not through k; in the file's
    # order (reversed) corner k is 3 - k, of the other parity
    return (corner % 2).astype(np.int8)


def _boost_pair_hash(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """``boost::hash<std::pair<int, int>>`` of Boost 1.74 on a 64-bit ``size_t``."""
    m = np.uint64(0xC6A4A7935BD1E995)
    seed = np.zeros(first.shape, dtype=np.uint64)
    for value in (first, second):
        k = value.astype(np.int64).astype(np.uint64) * m
        k ^= k >> np.uint64(47)
        k *= m
        seed ^= k
        seed *= m
        seed += np.uint64(0xE6546B64)
    return seed


def _iteration_order(hashes: np.ndarray) -> np.ndarray:
    """For each row of distinct keys' hashes, inserted left to right into a fresh
    ``std::unordered_map`` of libstdc++: the positions in iteration order (the bucket
    first used last comes first; in a bucket, the node inserted last)."""
    bucket = (hashes.astype(np.uint64) % np.uint64(_BUCKETS)).astype(np.int64)
    k = hashes.shape[1]
    position = np.arange(k)
    same = bucket[:, :, None] == bucket[:, None, :]
    opened = np.where(same, position[None, None, :], k).min(axis=2)   # the bucket's first use
    return np.lexsort((-position[None, :].repeat(len(bucket), 0), -opened), axis=1)


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
