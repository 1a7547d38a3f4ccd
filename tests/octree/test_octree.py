"""The pointer octree: bulk insert equals Stolte's incremental store; queries."""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox.octree import morton
from implicitvox.expr.examples import sinsin


def same_tree(a: ivx.Octree, b: ivx.Octree) -> bool:
    return (a.depth == b.depth and len(a.masks) == len(b.masks)
            and all(np.array_equal(p, q) for p, q in zip(a.masks, b.masks))
            and all(np.array_equal(p, q) for p, q in zip(a.first, b.first)))


@pytest.mark.parametrize("order", ["subdivision", "morton", "random"])
def test_bulk_insert_equals_incremental_store(order):
    vox = ivx.voxelize(sinsin(3, 4), resolution=32, normals=True)
    coords, normals = vox.coords(), vox.normals
    if order == "random":
        perm = np.random.default_rng(0).permutation(len(coords))
        coords, normals = coords[perm], normals[perm]
    incremental = ivx.PointerOctree(vox.grid.depth)
    for (i, j, k), n in zip(coords.tolist(), normals):
        incremental.store(i, j, k, n)
    built = incremental.to_octree()
    bulk = ivx.Octree.from_coords(coords, vox.grid.depth, {"value": normals})
    assert same_tree(built, bulk) and same_tree(bulk, vox.octree)
    np.testing.assert_array_equal(built.payload["value"], vox.normals)


def test_contains_matches_a_set_and_iteration_is_morton_ordered():
    rng = np.random.default_rng(1)
    coords = rng.integers(0, 50, (3000, 3))
    tree = ivx.Octree.from_coords(coords, 6)
    stored = {tuple(c) for c in coords.tolist()}
    queries = np.vstack([coords[:500], rng.integers(-3, 66, (3000, 3))])
    expected = [tuple(q) in stored for q in queries.tolist()]
    assert tree.contains(queries).tolist() == expected
    listed = list(tree)
    assert len(listed) == len(stored) == tree.count and set(listed) == stored
    codes = morton.encode(np.array(listed))
    assert np.all(np.diff(codes.astype(np.float64)) > 0)


def test_octree_is_compact():
    vox = ivx.voxelize(sinsin(3, 4), resolution=128)
    assert vox.octree.nbytes <= 4 * vox.count


def test_depth_zero_and_empty_trees():
    one = ivx.Octree.from_coords(np.zeros((1, 3), dtype=int), 0)
    assert one.count == 1 and one.contains(np.array([[0, 0, 0], [1, 0, 0]])).tolist() == [True, False]
    empty = ivx.Octree.from_coords(np.zeros((0, 3), dtype=int), 5)
    assert empty.count == 0 and empty.coords().shape == (0, 3)
    with pytest.raises(ValueError, match="lie in"):
        ivx.Octree.from_coords(np.array([[0, 0, 32]]), 5)


def test_morton_round_trip():
    c = np.random.default_rng(2).integers(0, 1 << 21, (10_000, 3))
    np.testing.assert_array_equal(morton.decode(morton.encode(c)), c)
