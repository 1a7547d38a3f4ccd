"""The exact sign predicates agree with rational arithmetic, near-degenerate input included."""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from implicitvox.triangles.predicates import FixedPlanes, det2_sign, exact_integers, orient3d_sign


def _sign(v: Fraction) -> int:
    return (v > 0) - (v < 0)


def det2_exact(a, b, p, q) -> int:
    F = Fraction
    return _sign((F(b[0]) - F(a[0])) * (F(q[1]) - F(p[1]))
                 - (F(b[1]) - F(a[1])) * (F(q[0]) - F(p[0])))


def orient3d_exact(a, b, c, d) -> int:
    F = Fraction
    u = [F(b[i]) - F(a[i]) for i in range(3)]
    v = [F(c[i]) - F(a[i]) for i in range(3)]
    w = [F(d[i]) - F(a[i]) for i in range(3)]
    return _sign(u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2])
                 + u[2] * (v[0] * w[1] - v[1] * w[0]))


finite = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e150, max_value=1e150)
tiny_or_huge = st.one_of(finite, st.floats(min_value=-1e-300, max_value=1e-300),
                         st.sampled_from([0.0, 1.0, -1.0, 0.5, 3.0, 1e300, -1e300]))


def nearly_collinear(rng: np.random.Generator, n: int, dim: int):
    """Points on a line through two random points, rounded or exact: the hard cases."""
    a = rng.uniform(-1, 1, (n, dim)) * 10.0 ** rng.integers(-3, 4, (n, 1))
    b = rng.uniform(-1, 1, (n, dim)) * 10.0 ** rng.integers(-3, 4, (n, 1))
    t = rng.uniform(-2, 3, (n, 1))
    exact = rng.random(n) < 0.3            # small integers and t = k/8: no rounding at all
    a[exact] = rng.integers(-1000, 1000, (exact.sum(), dim))
    b[exact] = rng.integers(-1000, 1000, (exact.sum(), dim))
    t[exact] = rng.integers(-16, 24, (exact.sum(), 1)) / 8
    q = a + t * (b - a)                     # rounded: within ulps of the line
    nudge = rng.integers(-2, 3, q.shape)
    q = np.where(nudge > 0, np.nextafter(q, np.inf), np.where(nudge < 0, np.nextafter(q, -np.inf), q))
    return a, b, q


def test_det2_nearly_collinear_matches_fractions():
    rng = np.random.default_rng(11)
    a, b, q = nearly_collinear(rng, 3000, 2)
    p = np.where(rng.random((3000, 1)) < 0.5, a, q[::-1])
    got = det2_sign(a, b, p, q)
    want = [det2_exact(*(x[i] for x in (a, b, p, q))) for i in range(3000)]
    assert got.tolist() == want
    assert 0 in want and 1 in want and -1 in want      # the cases were hard


def test_orient3d_nearly_coplanar_matches_fractions():
    rng = np.random.default_rng(12)
    n = 3000
    a, b, _ = nearly_collinear(rng, n, 3)
    c = rng.uniform(-1, 1, (n, 3))
    s, t = rng.uniform(-1, 2, (n, 1)), rng.uniform(-1, 2, (n, 1))
    exact = rng.random(n) < 0.3            # integer points, dyadic s, t: d exactly coplanar
    for m in (a, b, c):
        m[exact] = rng.integers(-1000, 1000, (exact.sum(), 3))
    s[exact] = rng.integers(-8, 16, (exact.sum(), 1)) / 8
    t[exact] = rng.integers(-8, 16, (exact.sum(), 1)) / 8
    d = a + s * (b - a) + t * (c - a)
    d = np.where(rng.random((n, 3)) < 0.3, np.nextafter(d, np.inf), d)
    got = orient3d_sign(a, b, c, d)
    want = [orient3d_exact(a[i], b[i], c[i], d[i]) for i in range(n)]
    assert got.tolist() == want
    assert 0 in want and 1 in want and -1 in want


def test_fixed_planes_match_fractions_nearly_coplanar():
    """orient3d against planes whose minors were computed once: the same exact signs,
    each plane asked about many points (near it, on it, in the hard cases)."""
    rng = np.random.default_rng(13)
    n = 600
    a, b, _ = nearly_collinear(rng, n, 3)
    c = rng.uniform(-1, 1, (n, 3))
    exact = rng.random(n) < 0.3
    for m in (a, b, c):
        m[exact] = rng.integers(-1000, 1000, (exact.sum(), 3))
    planes = FixedPlanes(a, b, c)
    which = rng.integers(0, n, 3000)
    s, t = rng.uniform(-1, 2, (3000, 1)), rng.uniform(-1, 2, (3000, 1))
    s[exact[which]] = rng.integers(-8, 16, (exact[which].sum(), 1)) / 8
    t[exact[which]] = rng.integers(-8, 16, (exact[which].sum(), 1)) / 8
    d = a[which] + s * (b[which] - a[which]) + t * (c[which] - a[which])
    d = np.where(rng.random((3000, 3)) < 0.3, np.nextafter(d, np.inf), d)
    got = planes.sign(which, d)
    want = [orient3d_exact(a[k], b[k], c[k], d[i]) for i, k in enumerate(which)]
    assert got.tolist() == want
    assert 0 in want and 1 in want and -1 in want


@settings(max_examples=300)
@given(st.lists(tiny_or_huge, min_size=12, max_size=12))
def test_fixed_planes_any_floats(v):
    a, b, c, d = (np.array([v[3 * i:3 * i + 3]]) for i in range(4))
    got = int(FixedPlanes(a, b, c).sign(np.array([0]), d)[0])
    assert got == orient3d_exact(a[0], b[0], c[0], d[0])


@settings(max_examples=300)
@given(st.lists(tiny_or_huge, min_size=8, max_size=8))
def test_det2_any_floats(v):
    a, b, p, q = (np.array([[v[2 * i], v[2 * i + 1]]]) for i in range(4))
    assert int(det2_sign(a, b, p, q)[0]) == det2_exact(a[0], b[0], p[0], q[0])


@settings(max_examples=300)
@given(st.lists(tiny_or_huge, min_size=12, max_size=12))
def test_orient3d_any_floats(v):
    a, b, c, d = (np.array([v[3 * i:3 * i + 3]]) for i in range(4))
    assert int(orient3d_sign(a, b, c, d)[0]) == orient3d_exact(a[0], b[0], c[0], d[0])


def test_exact_integers_keep_ratios():
    cols = [np.array([0.1, 0.0, -3e-300]), np.array([3.0, 5e-324, 1e300])]
    ints = exact_integers(*cols)
    for k in range(3):
        x, y = Fraction(float(cols[0][k])), Fraction(float(cols[1][k]))
        i, j = ints[0][k], ints[1][k]
        assert x * j == y * i                  # the same scale on the row


def test_float_filter_alone_would_be_wrong():
    """A case where the plain float determinant has the wrong sign (so the exact path matters)."""
    a = np.array([[0.5, 0.5]])
    b = np.array([[12.0, 12.0]])
    q = np.array([[24.0, 24.0]])
    bad = None
    for k in range(1, 200):
        p = np.array([[0.5 + k * 2.0 ** -53, 0.5]])
        naive = np.sign((b[0, 0] - a[0, 0]) * (q[0, 1] - p[0, 1]) - (b[0, 1] - a[0, 1]) * (q[0, 0] - p[0, 0]))
        exact = det2_exact(a[0], b[0], p[0], q[0])
        if naive != exact:
            bad = p
            break
    assert bad is not None, "no float failure found: the test would prove nothing"
    assert int(det2_sign(a, b, bad, q)[0]) == det2_exact(a[0], b[0], bad[0], q[0])


def test_expansion_signs_are_the_exact_integers():
    """det2_exact and orient3d_exact (Shewchuk's expansions, compiled) give the sign of
    the exact determinant wherever they give one, on lattice ties and on random input,
    and decline (UNSURE) where a difference is not exact or a factor is out of range."""
    from implicitvox.triangles.expansions import UNSURE, det2_exact, orient3d_exact
    rng = np.random.default_rng(21)
    n = 3000
    grid = rng.integers(-2, 3, (n, 12)) / 4.0                 # ties: many zeros
    loose = rng.uniform(-1, 1, (n, 12)) * 2.0 ** rng.integers(-40, 40, (n, 1))
    near = grid + rng.integers(-1, 2, (n, 12)) * 2.0 ** -52    # off a tie by an ulp
    for cols in (grid, loose, near):
        c = [cols[:, i] for i in range(12)]
        want2 = det2_sign((c[0], c[1]), (c[2], c[3]), (c[4], c[5]), (c[6], c[7]))
        got2 = np.array([det2_exact(*row[:8]) for row in cols])
        want3 = orient3d_sign(cols[:, 0:3], cols[:, 3:6], cols[:, 6:9], cols[:, 9:12])
        got3 = np.array([orient3d_exact(*row) for row in cols])
        for got, want in ((got2, want2), (got3, want3)):
            given = got != UNSURE
            assert np.array_equal(got[given], want[given])
            if cols is grid:
                assert given.all() and (want == 0).mean() > 0.05
    assert det2_exact(0.0, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.3) == 1
    assert det2_exact(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 2.0 ** -250, 2.0 ** -250) == UNSURE
    assert det2_exact(1e-20, 0.0, 1.0, 1.0, 0.0, 0.0, 0.7, 0.2) == UNSURE   # 1 - 1e-20 rounds
