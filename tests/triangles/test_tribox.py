"""The box-triangle test agrees exactly with an independent rational clipping oracle."""
from __future__ import annotations

import zlib

import numpy as np
import pytest

from implicitvox.triangles.tribox import Triangles
from tests.support.clip_oracle import triangle_meets_box


def _check(tri, lo, hi):
    got = Triangles(tri).meet_boxes(np.arange(len(tri)), lo, hi)
    want = np.array([triangle_meets_box(tri[i], lo[i], hi[i]) for i in range(len(tri))])
    assert got.tolist() == want.tolist()
    return want


@pytest.mark.parametrize("kind", ["general", "grid-aligned", "segment", "point", "axis-plane"])
def test_random_boxes(kind):
    rng = np.random.default_rng(zlib.crc32(kind.encode()))     # the same every run
    n = 1500
    tri = rng.uniform(-1, 1, (n, 3, 3))
    lo = rng.uniform(-1, 1, (n, 3))
    if kind == "grid-aligned":           # vertices and boxes on a 1/8 grid: ties everywhere
        tri = np.round(tri * 8) / 8
        lo = np.round(lo * 8) / 8
    elif kind == "segment":
        tri[:, 2] = tri[:, 0] + 0.5 * (tri[:, 1] - tri[:, 0])
    elif kind == "point":
        tri[:, 1] = tri[:, 2] = tri[:, 0]
    elif kind == "axis-plane":           # triangles in the plane z = 0.25, boxes touching it
        tri[:, :, 2] = 0.25
        lo = np.round(lo * 4) / 4
    hi = lo + rng.choice([0.125, 0.25, 0.5], (n, 1))
    if kind in ("segment", "point"):      # boxes near the degenerate triangles
        lo = tri[:, 0] + rng.uniform(-0.6, 0.1, (n, 3))
        hi = lo + 0.5
    want = _check(tri, lo, hi)
    assert 0.05 < want.mean() < 0.95     # both answers well represented


def test_boxes_touching_the_triangle_at_a_point():
    """Boxes with a corner or face exactly at a point of the triangle (tie: they meet),
    and the same boxes moved one ulp away (they may not)."""
    rng = np.random.default_rng(5)
    n = 2000
    tri = rng.uniform(-1, 1, (n, 3, 3))
    w = rng.dirichlet([1, 1, 1], n)
    w[: n // 3, 2] = 0                       # points on an edge
    w /= w.sum(axis=1, keepdims=True)
    w[n // 3: n // 2] = np.eye(3)[rng.integers(0, 3, n // 2 - n // 3)]   # vertices
    p = np.einsum("ni,nij->nj", w, tri)
    size = rng.choice([0.01, 0.1], (n, 1))
    lo = np.where(rng.integers(0, 2, (n, 3)) == 1, p, p - size)
    hi = lo + size
    _check(tri, lo, hi)
    away = rng.integers(-1, 2, (n, 3)).astype(float)
    _check(tri, np.nextafter(lo, lo + away), np.nextafter(hi, hi + away))


def test_dilation_covers_the_grown_triangle():
    """A dilated triangle meets every box within the dilation of a point of it."""
    rng = np.random.default_rng(6)
    n = 3000
    tri = rng.uniform(-1, 1, (n, 3, 3))
    d = rng.uniform(0, 0.05, (n, 3))
    w = rng.dirichlet([1, 1, 1], n)
    p = np.einsum("ni,nij->nj", w, tri) + rng.uniform(-1, 1, (n, 3)) * d * 0.999
    lo = p - rng.uniform(0, 0.01, (n, 3))
    hi = p + rng.uniform(0, 0.01, (n, 3))
    assert Triangles(tri, d).meet_boxes(np.arange(n), lo, hi).all()
    with pytest.raises(ValueError, match="dilation"):
        Triangles(tri, -d)


def _cases(n=1500, seed=11):
    """General, grid-aligned and degenerate pairs with boxes touching their triangles."""
    rng = np.random.default_rng(seed)
    tri = rng.uniform(-1, 1, (n, 3, 3))
    tri[n // 4: n // 2] = np.round(tri[n // 4: n // 2] * 8) / 8          # ties
    tri[n // 2: n // 2 + 100, 2] = tri[n // 2: n // 2 + 100, 0]          # segments
    tri[n // 2 + 100: n // 2 + 200, :, 2] = 0.25                         # axis planes
    size = rng.choice([0.125, 0.25, 0.5], (n, 1))
    near = np.einsum("ni,nij->nj", rng.dirichlet([1, 1, 1], n), tri)   # a point on each
    lo = near - size * rng.uniform(-0.5, 1, (n, 3))
    lo[: n // 2 + 200] = np.round(lo[: n // 2 + 200] * 8) / 8
    return tri, lo, lo + size


def test_the_compiled_kernel_is_the_array_path():
    """Every answer the compiled filter gives equals the array path's (exact predicates),
    and :meth:`Triangles.meet_boxes` (kernel, then the array path for the unsure pairs)
    equals it everywhere; scaled by 2**-1000 (products underflow: the kernel is unsure
    of nearly every sign) the answers are the same, settled by the exact path."""
    from implicitvox.triangles.tribox_kernels import UNSURE, meet_pairs
    tri, lo, hi = _cases()
    ids = np.arange(len(tri))
    t = Triangles(tri)
    want = t.meet_by_arrays(ids, lo, hi)
    assert 0.2 < want.mean() < 0.8
    raw = meet_pairs(t, ids, lo, hi)
    sure = raw != UNSURE
    assert sure.mean() > 0.9
    assert (raw[sure] == 1).tolist() == want[sure].tolist()
    assert t.meet_boxes(ids, lo, hi).tolist() == want.tolist()
    s = 2.0 ** -1000
    tiny = Triangles(tri * s)
    assert (meet_pairs(tiny, ids, lo * s, hi * s) == UNSURE).mean() > 0.5
    assert tiny.meet_boxes(ids, lo * s, hi * s).tolist() == want.tolist()


def test_plane_sides_and_witness_groups_are_the_array_path():
    """The compiled plane sides equal the array path's (ties at 0 included); a group
    of pairs meets iff one of its pairs does."""
    tri, lo, hi = _cases(seed=12)
    ids = np.arange(len(tri))
    t = Triangles(tri)
    want = t.plane_sides_by_arrays(ids, lo, hi)
    assert set(want.tolist()) == {-1, 0, 1}
    assert t.plane_sides(ids, lo, hi).tolist() == want.tolist()
    met = t.meet_by_arrays(ids, lo, hi)
    rng = np.random.default_rng(13)
    start = np.unique(np.concatenate([[0, len(ids)], rng.integers(0, len(ids), 300)]))
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    any_met = np.bincount(owner, weights=met, minlength=len(start) - 1) > 0
    assert 0.1 < any_met.mean() < 1.0
    assert t.meet_any(ids, lo, hi, start).tolist() == any_met.tolist()
    s = 2.0 ** -1000
    assert Triangles(tri * s).meet_any(ids, lo * s, hi * s, start).tolist() == any_met.tolist()
