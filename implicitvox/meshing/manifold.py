"""Manifold output: vertices split where dual contouring joins two sheets.

One vertex per cell joins every sheet of surface in the cell. Where two
sheets meet a cell (a thin wall, a near contact, the tip where petals meet)
the mesh gets edges with four triangles and vertices whose triangles form
two fans. Schaefer, Ju and Warren (*Manifold dual contouring*, 2007) split
such vertices; this does the same after the fact, on the triangles:

1. at an edge with more than two triangles, the triangles are sorted by
   angle about the edge and paired across the solid's inside (the triangles
   are oriented outward, so the wedge after a triangle that runs the edge
   backwards is inside): the sheets bounding one wedge of solid are joined,
   the wedges stay apart;
2. a vertex's corners (its incidences in triangles) are joined across the
   manifold edges and those pairs; each connected group of corners becomes
   a vertex of its own (at the same position).

The result has every edge in at most two triangles, unless two sheets meet
along a single edge whose both ends stay joined (counted, not hidden).

Examples
--------
>>> import numpy as np
>>> # two tetrahedra sharing the edge 0-1 only
>>> p = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0.]])
>>> t = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3],
...               [0, 4, 1], [0, 1, 5], [0, 5, 4], [1, 4, 5]])
>>> q, f, left = split_nonmanifold(p, t)
>>> len(q), left
(8, 0)
"""
from __future__ import annotations

import numpy as np
__all__ = ["split_nonmanifold", "edge_counts"]


def edge_counts(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Undirected edges ``(e, 2)`` (sorted ends, in the order they first appear), the
    triangle-edge incidence's edge index ``(3 f,)`` (edge ``k`` of triangle ``t``
    at ``3 t + k``, from corner ``k`` to corner ``k + 1``) and each edge's triangle
    count (compiled: :func:`.manifold_kernels.edge_table`)."""
    from .manifold_kernels import edge_table          # (loads Numba)
    return edge_table(np.ascontiguousarray(faces, dtype=np.int64).reshape(-1, 3))


def split_nonmanifold(points: np.ndarray, faces: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, int]:
    """``(points, faces, left)``: the mesh with its non-manifold vertices split
    (module docstring); ``left`` counts the edges still in more than two
    triangles."""
    from .manifold_kernels import by_edge, corner_groups, corner_joins   # (loads Numba)
    nf = len(faces)
    if nf == 0:
        return points, faces, 0
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    edges, inc, counts = edge_counts(faces)
    # partner incidence of every incidence on a manifold edge (the other triangle)
    order, first = by_edge(inc, counts)
    two = np.flatnonzero(counts == 2)
    pairs = [np.stack([order[first[two]], order[first[two] + 1]], 1)]
    many = np.flatnonzero(counts > 2)
    if len(many):
        tri = np.arange(3 * nf) // 3
        k = np.arange(3 * nf) % 3
        start, end = faces[tri, k], faces[tri, (k + 1) % 3]
        pairs.append(_pair_around(points, faces, edges, inc, order, first, counts, many,
                                  start, end, tri, k))
    pair = np.concatenate(pairs)
    # join corners: incidence i runs start->end in triangle tri; its partner j runs
    # end->start; corner (tri_i, start_i) ~ (tri_j, end_j), (tri_i, end_i) ~ (tri_j, start_j)
    a, b = corner_joins(faces, np.ascontiguousarray(pair[:, 0]), np.ascontiguousarray(pair[:, 1]))
    label, first_corner = corner_groups(3 * nf, a, b)
    # each group of corners a vertex, numbered as its first corner comes
    out_points = points[faces.ravel()[first_corner]]
    out_faces = label.reshape(-1, 3)
    if not len(many):            # splitting vertices only parts an edge's triangles
        return out_points, out_faces, 0
    _, _, after = edge_counts(out_faces)
    return out_points, out_faces, int((after > 2).sum())


def _pair_around(points, faces, edges, inc, order, first, counts, many, start, end, tri, k):
    """Pairs of incidences at edges in more than two triangles: sorted by angle
    about the edge, each triangle that runs the edge backwards (against the
    edge's sorted direction) joined to the next one, across the inside wedge."""
    rows = np.concatenate([order[first[e]:first[e] + counts[e]] for e in many])
    edge = inc[rows]
    a, b = points[edges[edge, 0]], points[edges[edge, 1]]
    other = points[faces[tri[rows], (k[rows] + 2) % 3]]
    axis = b - a
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    helper = np.where(np.abs(axis[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    u = np.cross(axis, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    w = np.cross(axis, u)
    rel = other - a
    angle = np.arctan2(np.einsum("ij,ij->i", rel, w), np.einsum("ij,ij->i", rel, u))
    # the same frame for all triangles of one edge: u depends only on the edge
    srt = np.lexsort((angle, edge))
    rows, edge = rows[srt], edge[srt]
    backwards = start[rows] != edges[edge, 0]
    # next incidence in cyclic order about the same edge
    pos = np.arange(len(rows))
    group_start = np.searchsorted(edge, edge, side="left")
    group_end = np.searchsorted(edge, edge, side="right")
    nxt = np.where(pos + 1 < group_end, pos + 1, group_start)
    take = backwards & ~backwards[nxt]
    return np.stack([rows[take], rows[nxt[take]]], 1)
