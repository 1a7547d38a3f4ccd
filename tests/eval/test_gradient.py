"""Forward-mode gradients against high-precision numerical differentiation."""
from __future__ import annotations

import mpmath
import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import implicitvox as ivx
from implicitvox import x, y, z
from tests.support.reference import mp_value
from tests.support.strategies import expression

SMOOTH_UNARY = ("neg", "square", "exp", "sin", "cos", "atan", "sqrt", "log")
SMOOTH_BINARY = ("add", "sub", "mul", "div", "hypot", "atan2")


@settings(max_examples=150, deadline=None)
@given(expr=expression(4, SMOOTH_UNARY, SMOOTH_BINARY),
       point=st.tuples(*[st.floats(0.2, 2.0)] * 3))
def test_gradient_matches_mpmath_derivative(expr, point):
    f = ivx.compile(expr)
    value, grad = f.gradient(*point)
    assume(np.isfinite(value) and np.all(np.isfinite(grad)) and abs(value) < 1e6)
    assume(np.all(np.abs(grad) < 1e6))
    # where doubles cannot compute f itself (an intermediate under- or overflows:
    # square(1e-291) is 0), its derivative is not theirs to match either
    exact_value = mp_value(expr, point, dps=30)
    assume(exact_value is not None and abs(value - float(exact_value)) <= 1e-9 * (1 + abs(value)))
    with mpmath.workdps(30):
        for axis in range(3):
            def along(t, axis=axis):
                p = list(point)
                p[axis] = t
                v = mp_value(expr, p, dps=30)
                if v is None:
                    raise ValueError
                return v
            at, h = mpmath.mpf(point[axis]), mpmath.mpf(10) ** -10
            try:
                exact = mpmath.diff(along, at, h=h)
                left = mpmath.diff(along, at, h=h, direction=-1)
                right = mpmath.diff(along, at, h=h, direction=1)
            except (ValueError, ZeroDivisionError):
                return
            # a kink (a sweep's fold, |t| at 0): no derivative there to match
            assume(abs(left - right) <= 1e-6 * (1 + abs(exact)))
            assert abs(grad[axis] - float(exact)) <= 1e-7 * (1 + abs(float(exact)))


def test_sphere_normals_point_outward():
    f = ivx.compile(ivx.sqrt(x * x + y * y + z * z) - 1)
    pts = np.random.default_rng(3).normal(size=(100, 3))
    _, grad = f.gradient(pts[:, 0], pts[:, 1], pts[:, 2])
    unit = pts / np.linalg.norm(pts, axis=1, keepdims=True)
    np.testing.assert_allclose(grad, unit, atol=1e-12)


def test_min_max_abs_floor_take_the_active_branch():
    f = ivx.compile(ivx.min(2 * x, 3 * y) + ivx.max(x, -z) + abs(y) + ivx.floor(z))
    _, g = f.gradient(np.array([1.0]), np.array([-1.0]), np.array([0.5]))
    # min picks 3y (-3 < 2), max picks x (1 > -0.5), |y| has slope -1 at y = -1.
    np.testing.assert_array_equal(g[0], [1.0, 3.0 - 1.0, 0.0])
