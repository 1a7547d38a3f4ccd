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


def _csg_models():
    from implicitvox.expr.shape import ExprShape
    import csg
    from implicitvox.expr.examples import drilled_plate, menger, sphere_union
    blend = (csg.Box((1.2, 1.0, 0.8), center=True) - csg.Cylinder(h=2.0, r=0.3, center=True)) \
        | csg.Sphere(0.4, center=(0.5, 0.4, 0.3))
    return {"menger": menger(2), "spheres": sphere_union(20), "plate": drilled_plate(4, 4),
            "csg": blend, "floor": ExprShape(
                ivx.floor(3 * x) / 3 + ivx.abs(y) - ivx.min(z, 0.5 * x) - 0.4,
                ((-1.0,) * 3, (1.0,) * 3))}


def test_pool_gradients_are_the_array_evaluators_bit_for_bit(monkeypatch):
    """Compiled values and gradients on every pruned tape of a subdivision, at voxel
    centres and random points (on a tape's own voxels and elsewhere, where its
    branches may be wrong but its arithmetic is the same), equal the array
    evaluator's on the same tape, bit for bit; a pool with libm operations is
    declined."""
    from implicitvox.eval.gradient import evaluate_gradients
    from implicitvox.eval.pool_gradients import pool_gradients
    from implicitvox.expr.shape import as_shape
    from implicitvox.octree import descend
    from implicitvox.octree.grid import Grid
    from implicitvox.eval.function import Function
    monkeypatch.setattr(descend, "DERIVE_COST", 0)
    rng = np.random.default_rng(5)
    for name, model in _csg_models().items():
        shape = as_shape(model)
        grid = Grid.from_bounds(shape.bounds, 24)
        result = descend.descend(Function(shape.expr), grid)
        runs = result.tapes
        assert runs.pool is not None and len(runs) > 1, name
        counts = rng.integers(1, 40, len(runs))
        pts = rng.uniform(-1.2, 1.2, (3, int(counts.sum())))
        pts[:, :8] = 0.0                                   # ties of min, max and abs
        values, grads = pool_gradients(runs.pool, runs.ids, counts, *pts)
        start = 0
        for count, tape in zip(counts, (runs.tape(i) for i in range(len(runs)))):
            v, g = evaluate_gradients(tape, *pts[:, start:start + count])
            np.testing.assert_array_equal(values[start:start + count], v, err_msg=name)
            np.testing.assert_array_equal(grads[:, start:start + count], g, err_msg=name)
            start += count
    from implicitvox.eval.tape_pool import TapePool
    from implicitvox.eval.tape import build_tape
    wavy = TapePool(build_tape(ivx.min(ivx.sin(x) - y, z)))
    assert pool_gradients(wavy, np.array([0]), np.array([1]), *np.zeros((3, 1))) is None


def test_pool_values_enclosures_and_crossings_are_each_tapes_bit_for_bit(monkeypatch):
    """The mesher's calls on a pool's rows (values at points, value and gradient
    enclosures over boxes, crossings on edges, each row on its own pruned tape) equal
    the array evaluators' (and the bisection's) on each tape built alone, bit for bit;
    the enclosures also equal the plain interval evaluator's on point boxes."""
    from implicitvox.eval.function import Function
    from implicitvox.eval.interval import evaluate_intervals
    from implicitvox.eval.mean_value import array_interval_gradients
    from implicitvox.eval.mean_value_kernels import pool_interval_gradients
    from implicitvox.eval.point import evaluate_points
    from implicitvox.eval.pool_gradients import pool_crossings, pool_values
    from implicitvox.expr.shape import as_shape
    from implicitvox.meshing.edges import STEPS, crossings
    from implicitvox.octree import descend
    from implicitvox.octree.grid import Grid
    monkeypatch.setattr(descend, "DERIVE_COST", 0)
    rng = np.random.default_rng(6)
    for name, model in _csg_models().items():
        shape = as_shape(model)
        runs = descend.descend(Function(shape.expr), Grid.from_bounds(shape.bounds, 24)).tapes
        counts = rng.integers(1, 30, len(runs))
        n = int(counts.sum())
        pts = rng.uniform(-1.2, 1.2, (3, n))
        pts[:, :8] = 0.0                                   # ties of min, max and abs
        lo = pts - rng.uniform(0, 0.1, (3, n)) * (rng.uniform(size=n) < 0.8)
        hi = pts + rng.uniform(0, 0.1, (3, n))
        a = pts.T.copy()
        b = a + rng.uniform(-0.2, 0.2, (n, 3))
        values = pool_values(runs.pool, runs.ids, counts, *pts)
        enclosures = pool_interval_gradients(runs.pool, runs.ids, counts, lo, hi)
        points = pool_crossings(runs.pool, runs.ids, counts, a, b, STEPS)
        at_points = pool_interval_gradients(runs.pool, runs.ids, counts, pts, pts)
        start = 0
        for count, tape in zip(counts, (runs.tape(i) for i in range(len(runs)))):
            rows = slice(start, start + count)
            with np.errstate(all="ignore"):
                v = np.broadcast_to(evaluate_points(tape, *pts[:, rows]), (count,))
                want = array_interval_gradients(tape, tuple(lo[:, rows]), tuple(hi[:, rows]))
                flo, fhi = evaluate_intervals(tape, tuple(pts[:, rows]), tuple(pts[:, rows]))
            np.testing.assert_array_equal(values[rows], v, err_msg=name)
            for got, expect in zip(enclosures, want):
                np.testing.assert_array_equal(got[..., rows],
                                              np.broadcast_to(expect, got[..., rows].shape),
                                              err_msg=name)
            np.testing.assert_array_equal(at_points[0][rows], flo, err_msg=name)
            np.testing.assert_array_equal(at_points[1][rows], fhi, err_msg=name)
            np.testing.assert_array_equal(points[rows], crossings(tape, a[rows], b[rows])[0],
                                          err_msg=name)
            start += count
