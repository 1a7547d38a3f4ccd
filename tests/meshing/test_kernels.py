"""The mesher's compiled loops against numpy and scipy doing the same job."""
import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from implicitvox.meshing.contour_kernels import changed_edges, unique_edges
from implicitvox.meshing.manifold_kernels import by_edge, corner_groups, edge_table
from implicitvox.meshing.qef import solve
from implicitvox.meshing.qef_kernels import eigh3


@pytest.mark.parametrize("rank", [1, 2, 3])
def test_jacobi_eigenpairs_are_lapacks(rank):
    rng = np.random.default_rng(rank)
    for _ in range(500):
        normals = rng.normal(size=(rank + int(rng.integers(0, 4)), 3))
        if rank == 1:
            normals = normals[:1] * rng.choice([-1.0, 1.0], size=(3, 1))
        elif rank == 2:                      # in one plane
            normals[:, 2] = normals[:, 0] + normals[:, 1]
        A = normals.T @ normals * 10.0 ** rng.integers(-3, 4)
        w, V = eigh3(A)
        scale = np.abs(A).max()
        assert np.allclose(np.sort(w), np.linalg.eigvalsh(A), rtol=0, atol=1e-13 * scale)
        assert np.allclose(V @ np.diag(w) @ V.T, A, rtol=0, atol=1e-13 * scale)
        assert np.allclose(V.T @ V, np.eye(3), rtol=0, atol=1e-13)


def test_qef_vertices_are_the_lapack_pseudo_inverse():
    rng = np.random.default_rng(5)
    n = 400
    cell = np.sort(rng.integers(0, n, size=3 * n))
    points = rng.uniform(0, 1, size=(3 * n, 3))
    normals = rng.normal(size=(3 * n, 3))
    normals[::7] = normals[1::7][:len(normals[::7])]          # repeated normals: rank 1-2
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    lo, hi = np.full((n, 3), -5.0), np.full((n, 3), 6.0)
    got = solve(cell, points, normals, n, lo, hi)
    for c in range(n):                                        # the textbook form, per cell
        p, nr = points[cell == c], normals[cell == c]
        if not len(p):
            assert np.array_equal(got[c], 0.5 * (lo[c] + hi[c]))
            continue
        m = p.mean(0)
        A = nr.T @ nr
        b = nr.T @ np.einsum("ij,ij->i", nr, p - m)
        w, V = np.linalg.eigh(A)
        keep = w > 0.1 * max(w[-1], 1e-300)
        x = V[:, keep] @ ((V[:, keep].T @ b) / w[keep])
        assert np.allclose(got[c], np.clip(m + x, lo[c], hi[c]), rtol=0, atol=1e-9)


def test_unique_edges_are_numpys():
    rng = np.random.default_rng(2)
    start = rng.integers(0, 4, size=(3000, 3)) * 2
    axis = rng.integers(0, 3, size=3000)
    length = 1 << rng.integers(0, 3, size=3000)
    first, inverse, code = unique_edges(start, axis, length)
    rows = np.column_stack([start, axis, length])
    _, expect_first, expect_inverse = np.unique(rows, axis=0, return_index=True,
                                                return_inverse=True)
    assert np.array_equal(np.sort(first), np.sort(expect_first))
    assert np.array_equal(rows[first][inverse], rows)          # each row names its edge
    assert len(first) == len(expect_first)
    assert (np.diff(first) > 0).all()                           # in order of first sight


def test_changed_edges_are_the_sign_changes():
    rng = np.random.default_rng(3)
    corners = rng.normal(size=(200, 8))
    levels = rng.integers(2, 5, size=200).astype(np.int8)
    coords = rng.integers(0, 4, size=(200, 3))
    leaf, start, axis, length, low = changed_edges(corners, levels, coords, 5)
    count = 0
    for i in range(200):
        size = 1 << (5 - int(levels[i]))
        for a in range(3):
            for c in range(8):
                if (c >> a) & 1:
                    continue
                d = c | (1 << a)
                if (corners[i, c] < 0) != (corners[i, d] < 0):
                    offset = np.array([c & 1, c >> 1 & 1, c >> 2 & 1])
                    rows = np.flatnonzero((leaf == i) & (axis == a)
                                          & (start == (coords[i] + offset) * size).all(1))
                    assert len(rows) == 1 and length[rows[0]] == size
                    assert low[rows[0]] == (corners[i, c] < 0)
                    count += 1
    assert count == len(leaf)


def test_edge_table_and_corner_groups_are_numpys_and_scipys():
    rng = np.random.default_rng(4)
    faces = rng.integers(0, 60, size=(300, 3))
    edges, inc, counts = edge_table(faces)
    ends = np.sort(np.stack([faces, np.roll(faces, -1, axis=1)], -1).reshape(-1, 2), axis=1)
    assert np.array_equal(edges[inc], ends)
    keys, expect = np.unique(ends, axis=0, return_counts=True)
    assert len(edges) == len(keys)
    assert np.array_equal(counts[np.lexsort(edges.T[::-1])], expect)
    assert (np.diff(edges[:, 0]) >= 0).all()                  # by their lower end
    order, first = by_edge(inc, counts)
    assert np.array_equal(order, np.argsort(inc, kind="stable"))
    a, b = rng.integers(0, 500, size=(2, 300))
    labels, first_corner = corner_groups(500, a, b)
    _, expect = connected_components(coo_matrix((np.ones(300), (a, b)), shape=(500, 500)),
                                     directed=False)
    assert np.array_equal(labels, expect)
    assert np.array_equal(first_corner, np.unique(expect, return_index=True)[1])
