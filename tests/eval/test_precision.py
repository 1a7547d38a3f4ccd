"""Interval evaluation in float32 (:mod:`implicitvox.eval.float32_tapes`): the same promise.

The kernels of the opcode rows marked ``float32`` run on float32 boxes (rounded outward from
the float64 ones) and must still enclose the exact range (mpmath, 60 digits);
numpy's float32 transcendentals must stay within the widening; the
subdivision picks float32 only where it is allowed, and its voxels hold every
voxel float64 finds.
"""
from __future__ import annotations

import itertools

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import implicitvox as ivx
from implicitvox.interval import kernels as iv
from implicitvox.interval import rounding
from implicitvox.octree import subdivide as subdivision
from implicitvox.eval.interval import apply_op
from implicitvox.expr.coords import cylindrical
from implicitvox.expr.examples import gear, sinsin
from implicitvox.octree.grid import Grid
from implicitvox.eval.opcodes import OPCODES
from implicitvox.eval.reference import apply_reference
from implicitvox.expr.shape import ExprShape
from implicitvox.eval.opcodes import OPCODES
from implicitvox.eval.float32_tapes import supports_float32
from implicitvox.interval.float32 import float32_bounds, outward_float32
from implicitvox.octree.level_dtype import interval_dtype, level_dtype
from tests.support.reference import DPS, contains
from tests.support.surface import found, surface_brackets
from tests.support.strategies import elements_for, interval, param_for, samples

F32 = np.float32


def _fit_param(name, param):
    """The parameter rounded to float32 where float32 needs it exact."""
    if name == "periodic_angle":
        return (param[0], param[1], float(F32(param[2])))
    if name == "distance":
        return tuple(float(F32(c)) for c in param)
    return param


FLOAT32_OPS = sorted(name for name, op in OPCODES.items() if op.float32)


@pytest.mark.parametrize("name", FLOAT32_OPS)
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_float32_kernels_enclose_the_exact_range(name, data):
    op = OPCODES[name]
    boxes = [data.draw(interval(elements_for(name))) for _ in range(op.arity)]
    param = _fit_param(name, data.draw(param_for(name)))
    los, his = zip(*(outward_float32(np.array([a]), np.array([b])) for a, b in boxes))
    with np.errstate(all="ignore"):
        result = apply_op(op, param, los, his, single=True)
    lo, hi = float(np.asarray(result[0])[0]), float(np.asarray(result[1])[0])
    assert np.asarray(result[0]).dtype == F32 or np.ndim(result[0]) == 0
    assert not (np.isnan(lo) or np.isnan(hi)), f"{name} gave a NaN bound on {boxes}"
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    per_arg = [samples(a, b, rng, 5 if op.arity == 1 else 2) for a, b in boxes]
    with mpmath.workdps(DPS):
        for point in itertools.product(*per_arg):
            exact = apply_reference(op, [mpmath.mpf(v) for v in point], param)
            if exact is not None:
                assert contains(lo, hi, exact), (
                    f"{name}{point} param={param}: {mpmath.nstr(exact, 20)} not in [{lo!r}, {hi!r}]")


@pytest.mark.parametrize("name, func, mpfunc, lo, hi", [
    ("sin", np.sin, mpmath.sin, -1e4, 1e4),
    ("cos", np.cos, mpmath.cos, -1e4, 1e4),
    ("exp", np.exp, mpmath.exp, -100.0, 100.0),
    ("arctan2", lambda v: np.arctan2(v, F32(0.75)), lambda v: mpmath.atan2(v, 0.75), -1e3, 1e3),
])
def test_numpy_float32_transcendental_error_is_within_the_margin(name, func, mpfunc, lo, hi):
    """numpy's float32 loops, measured in float32 ulps against mpmath."""
    xs = np.random.default_rng(3).uniform(lo, hi, 3000).astype(F32)
    with np.errstate(all="ignore"):
        values = func(xs)
    worst = 0.0
    with mpmath.workdps(40):
        for xv, fv in zip(xs, values):
            exact = mpfunc(mpmath.mpf(float(xv)))
            if mpmath.isinf(exact) or abs(exact) > float(np.finfo(F32).max):
                continue
            ulp = float(np.spacing(F32(abs(float(exact)))))
            worst = max(worst, float(abs(mpmath.mpf(float(fv)) - exact) / ulp))
    assert worst < rounding.TRANSCENDENTAL_ULPS, f"{name}: {worst:.2f} float32 ulp"


def test_kernel_constants_round_up_in_float32():
    """pi, pi/2 and 2 pi bounds the kernels compare with stay bounds in float32."""
    with mpmath.workdps(40):
        assert mpmath.mpf(float(F32(iv.PI_UP))) >= mpmath.pi
        assert mpmath.mpf(float(F32(iv.HALF_PI_UP))) >= mpmath.pi / 2
        assert mpmath.mpf(float(F32(iv.TWO_PI_UP))) >= 2 * mpmath.pi


@given(st.floats(-1e30, 1e30), st.floats(-1e30, 1e30))
def test_outward_float32_holds_the_box(a, b):
    lo, hi = min(a, b), max(a, b)
    lo32, hi32 = outward_float32(np.array([lo]), np.array([hi]))
    assert lo32.dtype == F32 and float(lo32[0]) <= lo and float(hi32[0]) >= hi
    # and at most two float32s beyond the nearest ones outward
    assert float(lo32[0]) >= lo - 3 * float(np.spacing(F32(abs(lo)))) - 2.0 ** -149
    assert float(hi32[0]) <= hi + 3 * float(np.spacing(F32(abs(hi)))) + 2.0 ** -149
    below, above = float32_bounds(lo)
    assert float(below) <= lo <= float(above)


@pytest.mark.parametrize("resolution, level", [(64, 4), ((100, 37, 70), 5), (64, 0)])
def test_tabulated_float32_child_boxes_are_the_rounded_float64_ones(resolution, level):
    """The subdivision looks the float32 child bounds up in a table of rounded
    edges: the same bounds as rounding the float64 ones, past the grid too."""
    grid = Grid.from_bounds(((-1.1, -0.3, 0.1), (1.3, 0.7, 2.0)), resolution)
    n = 1 << level
    axes = tuple(np.arange(n, dtype=np.uint32)[np.random.default_rng(level).integers(0, n, 500)]
                 for _ in range(3))
    lo32, hi32 = subdivision._child_boxes(grid, level, axes, single=True)
    lo64, hi64 = subdivision._child_boxes(grid, level, axes)
    for a in range(3):
        want_lo, want_hi = outward_float32(lo64[a], hi64[a])
        assert lo32[a].dtype == np.float32 and hi32[a].dtype == np.float32
        np.testing.assert_array_equal(lo32[a], want_lo)
        np.testing.assert_array_equal(hi32[a], want_hi)


def test_float32_is_chosen_only_where_allowed():
    tape = ivx.compile(sinsin(9, 18).expr).tape
    assert supports_float32(tape)
    assert interval_dtype(tape, Grid.from_bounds(sinsin(9, 18).bounds, 1024)) == F32
    # far from the origin, a voxel is too few float32 spacings wide
    far = Grid.from_bounds(((1e4, 0, 0), (1e4 + 1, 1, 1)), 1024)
    assert interval_dtype(tape, far) == np.float64
    # by level: coarse boxes of a very fine grid are float32, its voxels float64
    fine = Grid.from_bounds(sinsin(9, 18).bounds, 1 << 20)
    assert level_dtype(fine, 5) == F32 and level_dtype(fine, fine.depth) == np.float64
    # an operation without a float32 kernel keeps the tape in float64
    assert not supports_float32(ivx.compile(ivx.tan(ivx.x) - ivx.y).tape)
    assert not supports_float32(ivx.compile(ivx.log(ivx.x + 2) - ivx.y).tape)
    # constants past float32's range (3.4e38) too; exact ones and intervals of two fit
    assert not supports_float32(ivx.compile(ivx.x * 1e35 - ivx.y).tape)
    assert supports_float32(ivx.compile(ivx.x * 0.1 + 0.3 - ivx.y).tape)


TORUS = ExprShape((cylindrical(axis="z").rho - 0.6) ** 2 + ivx.z ** 2 - 0.12 ** 2,
                  ((-0.8, -0.8, -0.2), (0.8, 0.8, 0.2)))
SPHERE = ExprShape(ivx.sqrt((ivx.x - 0.25) ** 2 + (ivx.y + 0.125) ** 2 + ivx.z ** 2) - 0.7,
                   ((-0.5, -0.9, -0.75), (1.0, 0.6, 0.75)))


@pytest.mark.parametrize("name, shape", [("sinsin(9,18)", sinsin(9, 18)), ("gear", gear()),
                                         ("torus", TORUS), ("sphere", SPHERE)])
def test_float32_voxels_hold_every_surface_point(name, shape, monkeypatch):
    """The float32 run keeps every voxel a bisected surface point lies in, and
    about as many voxels as float64 (they are different enclosures)."""
    func = ivx.compile(shape.expr)
    assert supports_float32(func.tape)
    grid = Grid.from_bounds(shape.bounds, 96)
    assert level_dtype(grid, grid.depth) == F32
    single = subdivision.subdivide(func, grid).surface
    monkeypatch.setattr(subdivision, "supports_float32", lambda tape: False)
    double = subdivision.subdivide(func, grid).surface
    assert abs(len(single) - len(double)) <= 0.01 * len(double)
    keys = set(map(tuple, single))
    a, b = surface_brackets(func, shape.bounds, float(max(grid.voxel_size)), 20_000,
                            np.random.default_rng(2))
    hit = found(lambda c: np.array([tuple(v) in keys for v in c], dtype=bool), grid, a, b)
    assert hit.all(), f"{name}: {np.count_nonzero(~hit)} surface points missed in float32"


def test_the_never_miss_models_run_in_float32():
    """So tests/properties/test_never_misses.py checks the float32 path on most models."""
    from tests.properties.test_never_misses import MODELS
    single = {name for name, make in MODELS.items() if supports_float32(ivx.compile(make()[0]).tape)}
    assert single >= {"sphere", "torus", "gear", "sinsin34", "sinsin918", "blobby", "thin-sheet",
                      "csg-box-minus-ball", "lobed-plate"}, single


@pytest.mark.parametrize("name", ["sin", "cos"])
def test_float32_extrema_of_huge_arguments_are_found(name):
    """Intervals of two neighbouring float32s around an extremum of sin or cos
    far from 0, where converting to periods in float32 is off by about 1e-2
    periods: the kernel's slack must still see the extremum inside."""
    kernel = iv.i_sin if name == "sin" else iv.i_cos
    rng = np.random.default_rng(5)
    misses = []
    with mpmath.workdps(40):
        for k in rng.integers(10 ** 5, 10 ** 6, 300):
            quarter = 1 if name == "sin" else 0            # phase of the maximum, in quarter turns
            peak = (4 * int(k) + quarter) * mpmath.pi / 2
            below, above = float32_bounds(float(peak))
            if float(below) == float(above):
                continue
            lo, hi = kernel(np.array([below]), np.array([above]))
            inside = float(peak)                            # a float64 point of the box
            exact = (mpmath.sin if name == "sin" else mpmath.cos)(mpmath.mpf(inside))
            if not contains(float(lo[0]), float(hi[0]), exact):
                misses.append(int(k))
    assert not misses, f"{name}: extremum lost for k = {misses[:5]}"
