"""Outward rounding: switched off, crafted inputs escape; the transcendental margin holds."""
from __future__ import annotations

import mpmath
import numpy as np
import pytest

import implicitvox as ivx
from implicitvox.interval import rounding
from tests.support.reference import contains, mp_value

X = ivx.x

# Inputs where round-to-nearest lands on the wrong side of the exact result.
CRAFTED = [
    (X + 0.7, (0.1, 0.0, 0.0)),          # 0.1 + 0.7 rounds below the exact sum
    (X + 0.2, (0.1, 0.0, 0.0)),          # 0.1 + 0.2 rounds above it
    (X * 3.0, (0.1, 0.0, 0.0)),
    (X / 3.0, (1.0, 0.0, 0.0)),
    (ivx.sqrt(X), (2.0, 0.0, 0.0)),
    (ivx.exp(X), (1.0, 0.0, 0.0)),       # e rounds below
    (ivx.log(X), (10.0, 0.0, 0.0)),
    (ivx.sin(X), (1.0, 0.0, 0.0)),
    (ivx.atan(X), (1.0, 0.0, 0.0)),
]


def escapes(expr, point):
    """Does the degenerate-box enclosure miss the exact value?"""
    lo, hi = ivx.compile(expr).interval([point], [point])
    return not contains(float(lo[0]), float(hi[0]), mp_value(expr, point))


@pytest.fixture
def rounding_off(monkeypatch):
    identity = lambda a, *args: a  # noqa: E731
    for name in ("down", "up", "down_nonneg", "up_nonneg"):
        monkeypatch.setattr(rounding, name, identity)


def test_crafted_inputs_are_enclosed_with_rounding_on():
    assert not any(escapes(expr, p) for expr, p in CRAFTED)


def test_crafted_inputs_escape_with_rounding_off(rounding_off):
    escaped = [repr(expr) for expr, p in CRAFTED if escapes(expr, p)]
    # Each side of the nearest rounding shows up at least once.
    assert "x + 0.7" in escaped and "x + 0.2" in escaped
    assert len(escaped) >= len(CRAFTED) // 2


@pytest.mark.parametrize("name, func, mpfunc, lo, hi", [
    ("exp", np.exp, mpmath.exp, -700.0, 700.0),
    ("log", np.log, mpmath.log, 1e-300, 1e300),
    ("sin", np.sin, mpmath.sin, -1e6, 1e6),
    ("cos", np.cos, mpmath.cos, -1e6, 1e6),
    ("tan", np.tan, mpmath.tan, -1e3, 1e3),
    ("arctan", np.arctan, mpmath.atan, -1e3, 1e3),
    ("arcsin", np.arcsin, mpmath.asin, -1.0, 1.0),
    ("arccos", np.arccos, mpmath.acos, -1.0, 1.0),
])
def test_numpy_transcendental_error_is_within_the_margin(name, func, mpfunc, lo, hi):
    """Measure numpy's error in ulps against mpmath; the margin must exceed it."""
    rng = np.random.default_rng(7)
    if name == "log":
        xs = 10.0 ** rng.uniform(-300, 300, 3000)
    else:
        xs = rng.uniform(lo, hi, 3000)
    values = func(xs)
    worst = 0.0
    with mpmath.workdps(40):
        for xv, fv in zip(xs, values):
            exact = mpfunc(mpmath.mpf(float(xv)))
            ulp = np.spacing(abs(float(exact)))
            worst = max(worst, float(abs(mpmath.mpf(float(fv)) - exact) / ulp))
    assert worst < rounding.TRANSCENDENTAL_ULPS, f"{name}: {worst:.2f} ulp"


def _sine_cosine_arguments() -> np.ndarray:
    """Arguments where sin and cos from tan are hardest: random at every scale,
    next to the zeros of sin (the poles of tan(a/2)) and of cos (those of
    tan a), subnormals, and the double nearest a multiple of pi/2."""
    rng = np.random.default_rng(11)
    with mpmath.workdps(60):
        near_pi = [float(int(k) * mpmath.pi / 2) for k in rng.integers(1, 10 ** 6, 1500)]
    parts = [
        rng.uniform(-1e3, 1e3, 1500),
        rng.choice([-1.0, 1.0], 1500) * 10.0 ** rng.uniform(-300, 300, 1500),
        np.array(near_pi),
        np.nextafter(np.array(near_pi), np.inf),
        np.array([5e-324 * k for k in range(1, 60)] + [2.0 ** -1021, 2.0 ** -1022]),
        np.array([0.0, np.pi, np.pi / 2, 6381956970095103 * 2.0 ** 797]),
    ]
    xs = np.concatenate(parts)
    return np.concatenate([xs, -xs])


@pytest.mark.parametrize("name", ["sin", "cos"])
def test_sine_and_cosine_from_tan_are_enclosed(name):
    """The interval kernels compute sin and cos from numpy's tan; on degenerate
    intervals their widened values hold the exact ones (mpmath, 60 digits), and
    the computed values stay within the stated floats of them."""
    from implicitvox.interval import kernels as iv
    values = iv.sin_values if name == "sin" else iv.cos_values
    kernel = iv.i_sin if name == "sin" else iv.i_cos
    bound = rounding.SIN_ULPS if name == "sin" else rounding.COS_ULPS
    mpfunc = mpmath.sin if name == "sin" else mpmath.cos
    xs = _sine_cosine_arguments()
    with np.errstate(all="ignore"):
        computed = values(xs)
    lo, hi = kernel(xs, xs)
    worst = 0.0
    with mpmath.workdps(60):
        for x, c, a, b in zip(xs, computed, lo, hi):
            exact = mpfunc(mpmath.mpf(float(x)))
            assert contains(float(a), float(b), exact), (name, float(x))
            if exact != 0 and abs(exact) > 1e-300:
                worst = max(worst, float(abs(mpmath.mpf(float(c)) - exact) / abs(exact)) / 2.0 ** -52)
    assert worst < bound, f"{name}: {worst:.2f} floats"
