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
