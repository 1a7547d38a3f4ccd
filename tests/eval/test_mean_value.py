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


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(expr=expression(4), box=small_box(), seed=st.integers(0, 2**32 - 1))
def test_compiled_libm_gradient_enclosures_hold_exact_values_and_point_gradients(expr, box, seed):
    """With ``libm=True`` the compiled kernel takes every operation (sin, exp, atan2,
    the coordinate forms, ...): its value enclosure holds the exact values (mpmath)
    and, with ``closed=True`` where it says the box is valid, its gradient enclosure
    holds the gradients at every point of the box, faces and degenerate boxes
    included (where the point evaluator picks one side of a kink)."""
    from implicitvox.eval.mean_value_kernels import tape_interval_gradients
    lo, hi = box
    f = ivx.compile(expr)
    got = tape_interval_gradients(f.tape, np.array(lo)[:, None], np.array(hi)[:, None],
                                  libm=True, closed=True)
    if got is None:                     # a sweep or an undefined tape: the array path runs
        assert f.tape.undefined or any(i.op.oracle for i in f.tape.instructions)
        return
    vlo, vhi, glo, ghi, valid = (np.asarray(a)[..., 0] for a in got)
    rng = np.random.default_rng(seed)
    pts = np.array(lo) + rng.random((8, 3)) * (np.array(hi) - np.array(lo))
    pts = np.concatenate([pts, np.array(list(itertools.product(*zip(lo, hi))))])
    for p in map(tuple, pts):
        exact = mp_value(expr, p)
        if exact is not None:
            assert contains(float(vlo), float(vhi), exact), f"{expr!r} at {p}"
    if not valid:
        return
    value, grad = f.gradient(pts[:, 0], pts[:, 1], pts[:, 2])
    ok = np.isfinite(value) & np.all(np.isfinite(grad), axis=1)
    slack = 1e-9 * (1 + np.abs(grad[ok]))
    assert np.all(grad[ok] >= glo - slack) and np.all(grad[ok] <= ghi + slack)


def test_compiled_libm_gradients_match_the_array_evaluator():
    """``libm=True``: bit for bit the array evaluator's enclosures on the operations
    whose compiled and array rules agree (exp, log, tan, the inverse functions,
    atan2, powers), where numpy's functions are the C library's; within a few ulps, with the same valid lanes, where sin, cos
    or the periodic angle call a different libm."""
    from implicitvox import x, y, z
    from implicitvox.eval.mean_value import array_interval_gradients
    from implicitvox.eval.mean_value_kernels import tape_interval_gradients
    from implicitvox.eval.tape import build_tape
    from implicitvox.expr.examples import example
    from tests.support.libm import assert_same_rule
    exact_ops = ivx.exp(x * 0.3) + ivx.log(ivx.abs(y) + 0.5) + ivx.tan(z * 0.4) \
        + ivx.atan(x * y) + ivx.asin(x * 0.5) - ivx.acos(y * 0.5) + ivx.atan2(y, x) + x ** 3 \
        + ivx.abs(z) ** 0.7
    rng = np.random.default_rng(5)
    for expr, bitwise in ((exact_ops, True), (example("sinsin34").expr, False),
                          (ivx.sin(3 * x) * ivx.cos(y - z) - 0.2, False)):
        tape = build_tape(expr)
        centre = rng.uniform(-1, 1, (3, 2000))
        half = 10.0 ** rng.uniform(-6, 0, (3, 2000))
        half[:, :200] = 0.0                                   # points
        centre[:, 200:300] = 0.0                              # across the origin and cuts
        lo, hi = centre - half, centre + half
        assert tape_interval_gradients(tape, lo, hi) is None  # not without libm
        ours = tape_interval_gradients(tape, lo, hi, libm=True)
        theirs = array_interval_gradients(tape, tuple(lo), tuple(hi))
        np.testing.assert_array_equal(ours[4], theirs[4])
        for a, b in zip(ours[:4], theirs[:4]):
            b = np.broadcast_to(b, np.shape(a))
            if bitwise:
                assert_same_rule(a, b)
            else:
                np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-300)


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
