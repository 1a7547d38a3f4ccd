"""Bad input to compile and the evaluators: clear errors, documented NaN/inf results."""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox import x, y, z

F = ivx.compile(x * x + y - z)


@pytest.mark.parametrize("bad, match", [(3.0, "got float"), ("x + 1", "got str"),
                                        (None, "got NoneType"), (lambda p: p, "got function")])
def test_compile_refuses_non_expressions(bad, match):
    with pytest.raises(TypeError, match=match):
        ivx.compile(bad)


def test_compile_accepts_a_shape_with_expr():
    class Ball:
        expr = x * x + y * y + z * z - 1
    assert float(ivx.compile(Ball())(1, 0, 0)) == 0.0


def test_interval_rejects_inverted_boxes_with_location():
    with pytest.raises(ValueError, match="box 1 has lo > hi on axis y"):
        F.interval([[0, 0, 0], [0, 2, 0]], [[1, 1, 1], [1, 1, 1]])


@pytest.mark.parametrize("lo, hi, match", [
    (np.zeros((4, 2)), np.ones((4, 2)), r"shape \(n, 3\)"),
    (np.zeros((4, 3)), np.ones((5, 3)), "same shape"),
    ([[0, 0, np.nan]], [[1, 1, 1]], "lo holds NaN"),
    ("abc", [[1, 1, 1]], "real array"),
])
def test_interval_rejects_bad_shapes_and_nan(lo, hi, match):
    with pytest.raises(ValueError, match=match):
        F.interval(lo, hi)


def test_points_must_broadcast():
    with pytest.raises(ValueError, match="broadcastable"):
        F(np.zeros(3), np.zeros(4), 0.0)


def test_nan_and_inf_inputs_give_documented_results():
    assert np.isnan(F(np.nan, 0.0, 0.0))
    assert F(np.inf, 0.0, 0.0) == np.inf
    lo, hi = F.interval([[-np.inf, 0, 0]], [[np.inf, 0, 0]])
    assert lo[0] == 0.0 - 0.0 or lo[0] <= 0.0
    assert hi[0] == np.inf
    lo, hi = ivx.compile(ivx.sin(x)).interval([[-np.inf, 0, 0]], [[0.0, 0, 0]])
    assert (lo[0], hi[0]) == (-1.0, 1.0)
