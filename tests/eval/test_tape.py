"""The tape: deduplication, constant folding with enclosures, register reuse."""
from __future__ import annotations

import mpmath
import numpy as np

import implicitvox as ivx
from implicitvox import x, y, z
from implicitvox.eval.tape import build_tape
from tests.support.reference import contains


def names(tape):
    return [ins.op.name for ins in tape.instructions]


def test_equal_subexpressions_are_computed_once():
    a = ivx.sin(x * y)
    b = ivx.sin(x * y)  # built separately: equal, not identical
    assert names(build_tape(a + b)) == ["mul", "sin", "add"]


def test_constants_fold_into_sound_enclosures():
    tape = build_tape(x + ivx.sin(ivx.constant(1.0)) * 3.0)
    assert names(tape) == ["add"]  # the folded constant is inexact: no addc
    folded = [c for c in tape.constants if c.lo != c.hi]
    assert len(folded) == 1
    exact = mpmath.sin(1) * 3
    assert contains(folded[0].lo, folded[0].hi, exact)


def test_undefined_constant_makes_the_function_undefined():
    f = ivx.compile(x + ivx.sqrt(ivx.constant(-1.0)))
    assert f.tape.undefined
    assert np.isnan(f(1.0, 2.0, 3.0))
    lo, hi = f.interval([0, 0, 0], [1, 1, 1])
    assert lo[0] == np.inf and hi[0] == -np.inf


def test_mul_of_itself_becomes_square():
    f = ivx.compile((x - 1) * (x - 1))
    assert names(f.tape) == ["addc", "square"]
    lo, _ = f.interval([0.0, 0, 0], [2.0, 0, 0])
    assert lo[0] == 0.0


def test_registers_are_reused():
    e = x
    for k in range(200):
        e = ivx.sin(e) + k
    tape = build_tape(e)
    constants_and_inputs = len(tape.constants) + 1
    assert len(tape) == 400 and tape.n_registers - constants_and_inputs < 5


def test_values_match_a_direct_numpy_computation():
    rng = np.random.default_rng(1)
    X, Y, Z = rng.normal(size=(3, 1000))
    f = ivx.compile(ivx.sin(3 * ivx.atan2(z, x)) * ivx.exp(-y * y) - ivx.hypot(x, z))
    expected = np.sin(3 * np.arctan2(Z, X)) * np.exp(-Y * Y) - np.hypot(X, Z)
    np.testing.assert_allclose(f(X, Y, Z), expected, rtol=1e-14, atol=1e-14)


def test_constant_and_variable_outputs_broadcast():
    assert ivx.compile(ivx.constant(2.0))(np.zeros(4), 0, 0).shape == (4,)
    lo, hi = ivx.compile(y).interval(np.zeros((5, 3)), np.ones((5, 3)))
    assert lo.shape == (5,) and hi[0] == 1.0


def test_exact_identities_take_no_instruction_and_change_no_bit():
    """``a * 1``, ``a / 1`` and ``a - 0`` are ``a`` for every float (signed zeros,
    infinities, NaN, subnormals): no instruction, the same bits, no widening."""
    X = np.array([-0.0, 0.0, 1.5, -2.0 ** -1074, np.inf, -np.inf, np.nan, 1e308, -3.25])
    cases = [(x * 1.0, lambda a: a * 1.0), (1.0 * x, lambda a: 1.0 * a),
             (x / 1.0, lambda a: a / 1.0), (x - 0.0, lambda a: a - 0.0),
             (x + (-0.0), lambda a: a + -0.0), ((x - 0.0) * 1.0 / 1.0, lambda a: a)]
    for expr, numpy_form in cases:
        f = ivx.compile(expr)
        assert names(f.tape) == [], expr
        with np.errstate(all="ignore"):
            assert np.array_equal(f(X, 0, 0).view(np.int64), numpy_form(X).view(np.int64)), expr
        lo, hi = f.interval([0.1, 0, 0], [0.7, 0, 0])
        assert lo[0] == 0.1 and hi[0] == 0.7            # not widened by a rounding
    # a + 0.0 turns -0.0 into 0.0: it is no identity and stays
    f = ivx.compile(x + 0.0)
    assert names(f.tape) == ["addc"]
    assert np.signbit(f(np.array([-0.0]), 0, 0)).tolist() == [False]
    assert names(build_tape(ivx.sin(x * 1.0) * 2.0)) == ["sin", "mulc"]


#: (expression, its fused centre, the same sum written in numpy)
SPHERES = [
    (ivx.sqrt((x - 0.3) ** 2 + (y + 0.2) ** 2 + (z - 1e-3) ** 2), (0.3, -0.2, 1e-3),
     lambda X, Y, Z: np.sqrt(np.square(X - 0.3) + np.square(Y + 0.2) + np.square(Z - 1e-3))),
    (ivx.sqrt(x * x + y * y + z * z), (0.0, 0.0, 0.0),
     lambda X, Y, Z: np.sqrt(X * X + Y * Y + Z * Z)),
    (ivx.sqrt(ivx.square(z - 2.5) + ivx.square(x)), (2.5, 0.0, 0.0),
     lambda X, Y, Z: np.sqrt(np.square(Z - 2.5) + np.square(X))),
]


def test_distance_from_a_centre_is_fused_with_the_same_point_values():
    rng = np.random.default_rng(5)
    pts = rng.uniform(-3, 3, (3, 20_000))
    for expr, centre, unfused in SPHERES:
        tape = build_tape(expr)
        assert names(tape) == ["distance"] and tape.instructions[0].param == centre
        assert np.array_equal(ivx.compile(expr)(*pts), unfused(*pts))  # bit for bit


def test_distance_is_not_fused_from_other_sums():
    for expr in (ivx.sqrt(x * x + y), ivx.sqrt(x * x + y * y + z * z + 1.0),
                 ivx.sqrt(x * y + z * z), ivx.hypot(x - 1, y)):
        assert "distance" not in names(build_tape(expr)), expr


def test_fused_distance_is_the_exact_range_rounded_outward():
    """Nearest and farthest box points from the centre, at 60 digits, inside and close."""
    rng = np.random.default_rng(6)
    centre = (0.3, -0.2, 1e-3)
    f = ivx.compile(SPHERES[0][0])
    lo = rng.uniform(-1, 1, (2000, 3)) * rng.choice([1e-9, 1.0, 1e6], (2000, 1))
    hi = lo + rng.uniform(0, 1, (2000, 3)) * rng.choice([0.0, 1e-9, 1.0], (2000, 1))
    flo, fhi = f.interval(lo, hi)
    with mpmath.workdps(60):
        for i in range(0, 2000, 7):
            a = [mpmath.mpf(v) for v in lo[i]]
            b = [mpmath.mpf(v) for v in hi[i]]
            c = [mpmath.mpf(v) for v in centre]
            near = [max(a[k] - c[k], c[k] - b[k], 0) for k in range(3)]
            far = [max(abs(a[k] - c[k]), abs(b[k] - c[k])) for k in range(3)]
            dmin = mpmath.sqrt(sum(t * t for t in near))
            dmax = mpmath.sqrt(sum(t * t for t in far))
            assert flo[i] <= dmin and dmax <= fhi[i], i
            # tight: a few ulps wide beyond the exact range (no looser than 8 ulps + underflow)
            assert dmin - flo[i] <= 8 * np.spacing(float(dmin)) + 2.0 ** -530
            assert fhi[i] - dmax <= 8 * np.spacing(float(dmax)) + 2.0 ** -530


def test_fused_distance_survives_overflow_and_infinite_ends():
    f = ivx.compile(SPHERES[1][0])
    lo, hi = f.interval([[1e200, 0, 0], [-np.inf, 1.0, 1.0]], [[2e200, 1, 1], [np.inf, 2.0, 2.0]])
    assert 1e154 < lo[0] <= 1e200 and hi[0] == np.inf      # the squares overflow
    assert lo[1] <= np.sqrt(2.0) and hi[1] == np.inf and not np.isnan(lo).any()
