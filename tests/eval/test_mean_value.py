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


def test_compiled_interval_gradients_are_the_array_evaluators_bit_for_bit():
    """On tapes the compiled kernel runs (min, max, abs, sqrt, floor, hypot, the
    distance forms and arithmetic), value and gradient enclosures and the lanes
    where the mean value theorem fails equal the array evaluator's, bit for bit,
    over boxes of every size, some degenerate, some straddling zeros and kinks."""
    import csg
    from implicitvox import x, y, z
    from implicitvox.eval.mean_value import array_interval_gradients
    from implicitvox.eval.mean_value_kernels import tape_interval_gradients
    from implicitvox.eval.tape import build_tape
    from implicitvox.expr.examples import menger, sphere_union
    from implicitvox.expr.shape import as_shape
    blend = (csg.Box((1.2, 1.0, 0.8), center=True) - csg.Cylinder(h=2.0, r=0.3, center=True)) \
        | csg.Sphere(0.4, center=(0.5, 0.4, 0.3))
    odd = ivx.sqrt(ivx.abs(x * y - 0.1) + z) / (x - 0.3) + ivx.floor(2 * y) \
        - ivx.max(x * x, y - z) * 0.5
    rng = np.random.default_rng(4)
    for expr in (menger(2).expr, sphere_union(12).expr, as_shape(blend).expr, odd):
        tape = build_tape(expr)
        centre = rng.uniform(-1, 1, (3, 3000))
        half = 10.0 ** rng.uniform(-6, 0, (3, 3000))
        half[:, :300] = 0.0                                   # points
        centre[:, 300:400] = 0.0                              # across zeros
        lo, hi = centre - half, centre + half
        ours = tape_interval_gradients(tape, lo, hi)
        assert ours is not None
        theirs = array_interval_gradients(tape, tuple(lo), tuple(hi))
        for a, b in zip(ours, theirs):
            np.testing.assert_array_equal(a, np.broadcast_to(b, np.shape(a)))
    assert tape_interval_gradients(build_tape(ivx.sin(x) - y), np.zeros((3, 1)),
                                   np.ones((3, 1))) is None
