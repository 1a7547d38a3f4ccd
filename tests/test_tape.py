"""The tape: deduplication, constant folding with enclosures, register reuse."""
from __future__ import annotations

import mpmath
import numpy as np

import implicitvox as ivx
from implicitvox import x, y, z
from implicitvox.tape import build_tape
from tests.reference import contains


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
