"""Replication sweeps: point, interval and gradient agree; bounded work; bad input."""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox import hypot, sqrt, x, y, z

TORUS = (hypot(x, y) - 0.6) ** 2 + z ** 2 - 0.1 ** 2
BALL = sqrt((x - 0.8) ** 2 + y ** 2 + z ** 2) - 0.15


def test_repeat_points_follow_the_replication_factor():
    f = ivx.compile(ivx.repeat(TORUS, spacing=(None, None, 0.5), count=(None, None, 4)))
    t = ivx.compile(TORUS)
    zs = np.linspace(-2, 3, 1001)
    k = np.clip(np.floor(zs / 0.5 + 0.5), 0, 3)   # Stolte eq. 1, clamped to 4 instances
    np.testing.assert_array_equal(f(0.6, 0.1, zs), t(0.6, 0.1, zs - 0.5 * k))


def test_repeat_polar_points_turn_back_to_the_first_copy():
    f = ivx.compile(ivx.repeat_polar(BALL, 8))
    for k in range(8):
        a = k * np.pi / 4
        assert float(f(0.8 * np.cos(a), 0.8 * np.sin(a), 0.0)) == pytest.approx(-0.15, abs=1e-12)
    g = ivx.compile(ivx.repeat_polar(BALL, 5, axis="y"))   # copies in the x-z plane
    for k in range(5):
        a = k * 2 * np.pi / 5
        assert float(g(0.8 * np.cos(a), 0.0, 0.8 * np.sin(a))) == pytest.approx(-0.15, abs=1e-12)


@pytest.mark.parametrize("expr", [
    ivx.repeat(TORUS, spacing=(None, None, 0.5)),
    ivx.repeat(BALL, spacing=(0.7, 0.9, None), count=(3, None, None)),
    ivx.repeat_polar(BALL, 7),
    ivx.repeat_polar(BALL, 2, axis="x"),
])
def test_intervals_hold_sampled_values_even_over_many_instances(expr):
    f = ivx.compile(expr)
    rng = np.random.default_rng(0)
    for width in (0.01, 0.3, 3.0, 1e6):
        lo = rng.uniform(-2, 2, (300, 3))
        hi = lo + rng.uniform(0, width, (300, 3))
        flo, fhi = f.interval(lo, hi)
        pts = lo[:, None, :] + rng.random((300, 40, 3)) * (hi - lo)[:, None, :]
        v = f(pts[..., 0], pts[..., 1], pts[..., 2])
        assert np.all(flo[:, None] <= v) and np.all(v <= fhi[:, None])


def test_repeat_interval_is_tight_within_one_instance():
    f = ivx.compile(ivx.repeat(TORUS, spacing=(None, None, 0.5)))
    g = ivx.compile(TORUS)
    lo, hi = [[0.5, -0.1, 10.01]], [[0.7, 0.1, 10.2]]
    np.testing.assert_allclose(f.interval(lo, hi), g.interval([[0.5, -0.1, 0.01]],
                                                              [[0.7, 0.1, 0.2]]), rtol=1e-12)


def test_gradients_match_finite_differences():
    for expr in (ivx.repeat(TORUS, spacing=0.9), ivx.repeat_polar(BALL, 6)):
        f = ivx.compile(expr)
        pts = np.random.default_rng(1).uniform(-1, 1, (200, 3))
        _, g = f.gradient(*pts.T)
        h = 1e-6
        for axis in range(3):
            d = np.zeros(3)
            d[axis] = h
            numeric = (f(*(pts + d).T) - f(*(pts - d).T)) / (2 * h)
            smooth = np.abs(numeric) < 50   # skip points straddling a cell boundary
            np.testing.assert_allclose(g[smooth, axis], numeric[smooth], atol=1e-5)


def test_sweeps_compose_and_remap():
    row = ivx.repeat(BALL, spacing=(None, 0.5, None), count=(None, 3, None))
    ring = ivx.repeat_polar(row.remap(z=z - 1), 4)
    f = ivx.compile(ring)
    assert float(f(0.8, 0.0, 1.0)) < 0 and float(f(0.0, 0.8, 1.0)) < 0
    assert float(f(0.8, 0.0, 0.0)) > 0


@pytest.mark.parametrize("call, match", [
    (lambda: ivx.repeat(BALL, spacing=(-1, None, None)), "positive finite number"),
    (lambda: ivx.repeat(BALL, spacing=(None, None, None)), "no axis"),
    (lambda: ivx.repeat(BALL, spacing=1.0, count=(0, 1, 1)), "positive int"),
    (lambda: ivx.repeat(BALL, spacing=(1, 2)), "three"),
    (lambda: ivx.repeat_polar(BALL, 0), "positive int"),
    (lambda: ivx.repeat_polar(BALL, 3, axis="w"), "axis"),
])
def test_bad_sweeps(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_the_reference_gives_no_value_past_its_precision():
    """Far out (3e152 over a spacing of 1.5) the instance index needs more digits than
    the reference works with: it gives no value (the property tests then skip the
    point) instead of a local coordinate that is all rounding (found by hypothesis:
    the reference said 1.9e137 for a function bounded by 0.65)."""
    from implicitvox.eval.reference import mp_evaluate
    shape = ivx.repeat((ivx.y ** 3) ** 0.5, spacing=(None, 1.5, None))
    far = shape.remap(x=ivx.x, y=ivx.x / -2.567437590812482e-153 - ivx.x, z=ivx.x)
    assert mp_evaluate(far, (-0.824344379397441, 0.0, 0.0)) is None
    assert abs(float(mp_evaluate(shape, (0.0, 3.3, 0.0))) - 0.3 ** 1.5) < 1e-15
