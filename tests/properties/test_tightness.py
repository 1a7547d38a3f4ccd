"""Tightness: for monotone operations the interval is the exact range up to a few ulps."""
from __future__ import annotations

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from implicitvox.interval import rounding
from implicitvox.eval.opcodes import OPCODES
from implicitvox.eval.reference import apply_reference
from implicitvox.eval.interval import apply_op
from tests.support.strategies import interval

# name -> (increasing?, argument strategy)
MONOTONE = {
    "sqrt": (True, st.floats(0.0, 1e6)),
    "exp": (True, st.floats(-700.0, 700.0)),
    "log": (True, st.floats(1e-300, 1e300)),
    "atan": (True, st.floats(-1e6, 1e6)),
    "asin": (True, st.floats(-1.0, 1.0)),
    "acos": (False, st.floats(-1.0, 1.0)),
    "neg": (False, st.floats(-1e6, 1e6)),
    "floor": (True, st.floats(-1e6, 1e6)),
    "sin": (True, st.floats(-1.5, 1.5)),        # a monotone piece
    "cos": (False, st.floats(0.05, 3.1)),
    "tan": (True, st.floats(-1.5, 1.5)),
}
# A widening by k floats moves an endpoint between k and 2k + 1 floats, one more for
# the function's own error; sin and cos are computed from tan, and widened more.
WIDENING = {"sin": rounding.SIN_ULPS, "cos": rounding.COS_ULPS}


def ulps_apart(computed: float, exact) -> float:
    if computed == float(exact):
        return 0.0
    return float(abs(mpmath.mpf(computed) - exact) / np.spacing(abs(float(exact)) or 1e-300))


@pytest.mark.parametrize("name", sorted(MONOTONE))
@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_monotone_unary_is_tight(name, data):
    increasing, elements = MONOTONE[name]
    a, b = data.draw(interval(elements))
    op = OPCODES[name]
    result = apply_op(op, None, (np.array([a]),), (np.array([b]),))
    lo, hi = float(result[0][0]), float(result[1][0])
    with mpmath.workdps(50):
        fa, fb = (apply_reference(op, [mpmath.mpf(v)], None) for v in (a, b))
        exact_lo, exact_hi = (fa, fb) if increasing else (fb, fa)
        # the end value is off by up to W floats, and the outward step |v| W eps
        # is W to 2 W floats of v's binade (2 W just below a power of two)
        bound = 3 * WIDENING.get(name, rounding.TRANSCENDENTAL_ULPS) + 2
        assert ulps_apart(lo, exact_lo) <= bound and ulps_apart(hi, exact_hi) <= bound


@pytest.mark.parametrize("name", ["add", "sub", "mul", "div", "hypot"])
@settings(max_examples=150, deadline=None)
@given(a=interval(st.floats(0.5, 1e3)), b=interval(st.floats(0.5, 1e3)))
def test_monotone_binary_is_tight(name, a, b):
    """On positive boxes the extremes are at corners.

    Correctly rounded operations land within 3.5 ulps (half an ulp of rounding,
    up to three of widening); ``hypot`` is widened by ``POW_ULPS`` more.
    """
    bound = 3.5 + (2 * rounding.POW_ULPS if name == "hypot" else 0)
    op = OPCODES[name]
    lo, hi = apply_op(op, None, (np.array([a[0]]), np.array([b[0]])),
                      (np.array([a[1]]), np.array([b[1]])))
    with mpmath.workdps(50):
        corners = [apply_reference(op, [mpmath.mpf(p), mpmath.mpf(q)], None) for p in a for q in b]
        assert ulps_apart(float(lo[0]), min(corners)) <= bound
        assert ulps_apart(float(hi[0]), max(corners)) <= bound
