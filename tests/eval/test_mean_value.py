"""The mean value form encloses the exact range too, and is tighter on small boxes."""
from __future__ import annotations

import itertools

import mpmath
import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import implicitvox as ivx
from implicitvox.eval.mean_value import evaluate_interval_gradients, mean_value_enclosure
from implicitvox.eval.opcodes import OPCODES
from tests.support.reference import contains, mp_value
from tests.support.strategies import expression


def columns(lo, hi):
    return tuple(np.array([v]) for v in lo), tuple(np.array([v]) for v in hi)


@st.composite
def small_box(draw):
    centre = [draw(st.floats(-2.0, 2.0)) for _ in range(3)]
    width = draw(st.sampled_from([1e-1, 1e-2, 1e-4]))
    lo = [c - width * draw(st.floats(0.0, 1.0)) for c in centre]
    hi = [c + width * draw(st.floats(0.0, 1.0)) for c in centre]
    return lo, hi


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(expr=expression(5), box=small_box(), seed=st.integers(0, 2**32 - 1))
def test_mean_value_enclosure_holds_exact_values(expr, box, seed):
    lo, hi = box
    f = ivx.compile(expr)
    flo, fhi = (float(v[0]) for v in mean_value_enclosure(f.tape, *columns(lo, hi)))
    rng = np.random.default_rng(seed)
    points = list(itertools.product(*zip(lo, hi))) + [
        tuple(np.clip(np.array(lo) + rng.random(3) * (np.array(hi) - np.array(lo)), lo, hi))
        for _ in range(8)]
    for p in points:
        exact = mp_value(expr, p)
        if exact is None:
            continue
        assert contains(flo, fhi, exact), f"{expr!r} at {p}: {mpmath.nstr(exact, 17)} " \
                                          f"not in [{flo!r}, {fhi!r}]"


@settings(max_examples=200, deadline=None)
@given(expr=expression(4), point=st.tuples(*[st.floats(-2.0, 2.0)] * 3),
       width=st.sampled_from([1e-3, 1e-1]))
def test_gradient_intervals_hold_point_gradients(expr, point, width):
    lo = [p - width for p in point]
    hi = [p + width for p in point]
    f = ivx.compile(expr)
    _, _, glo, ghi, valid = evaluate_interval_gradients(f.tape, *columns(lo, hi))
    if not valid[0]:
        return
    rng = np.random.default_rng(0)
    pts = np.array(lo) + rng.random((20, 3)) * (np.array(hi) - np.array(lo))
    value, grad = f.gradient(pts[:, 0], pts[:, 1], pts[:, 2])
    ok = np.isfinite(value) & np.all(np.isfinite(grad), axis=1)
    slack = 1e-9 * (1 + np.abs(grad[ok]))
    assert np.all(grad[ok] >= glo[:, 0] - slack) and np.all(grad[ok] <= ghi[:, 0] + slack)


def test_every_opcode_has_an_interval_derivative():
    assert all(op.interval_derivative is not None or op.oracle for op in OPCODES.values())


def test_mean_value_is_tighter_on_voxel_sized_boxes():
    from implicitvox import atan2, hypot, sin, sqrt, x, y, z
    f = ivx.compile(sin(3 * atan2(z, x)) * sin(4 * atan2(y, hypot(x, z))) - sqrt(x * x + y * y + z * z))
    rng = np.random.default_rng(0)
    lo = rng.uniform(0.2, 1.0, (2000, 3))
    hi = lo + 0.01
    L, H = tuple(lo.T.copy()), tuple(hi.T.copy())
    nlo, nhi = f.interval_columns(L, H)
    mlo, mhi = mean_value_enclosure(f.tape, L, H)
    assert np.all(mlo >= nlo) and np.all(mhi <= nhi)
    assert np.median(mhi - mlo) < 0.85 * np.median(nhi - nlo)
