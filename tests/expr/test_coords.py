"""Coordinates r, rho, theta, phi: exact intervals (Stolte §4.1.2), axes, the branch cut."""
from __future__ import annotations

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import implicitvox as ivx
from implicitvox import cos, sin
from tests.support.reference import contains, mp_value


def boundary_samples(lo, hi, k=41):
    """Points on the six faces of a box, ``k`` x ``k`` per face."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    t = np.linspace(0.0, 1.0, k)
    u, v = np.meshgrid(t, t, indexing="ij")
    faces = []
    for axis in range(3):
        a, b = [i for i in range(3) if i != axis]
        for side in (lo[axis], hi[axis]):
            p = np.empty((k * k, 3))
            p[:, axis] = side
            p[:, a] = lo[a] + u.ravel() * (hi[a] - lo[a])
            p[:, b] = lo[b] + v.ravel() * (hi[b] - lo[b])
            faces.append(p)
    return np.clip(np.concatenate(faces), lo, hi)  # lo + t (hi - lo) can round out of the box


@st.composite
def boxes(draw, special=True):
    """Random boxes, some touching or holding the axis, the origin or the cut."""
    lo, hi = [], []
    for _ in range(3):
        a = draw(st.floats(-2.0, 2.0))
        b = draw(st.floats(-2.0, 2.0))
        if special and draw(st.integers(0, 3)) == 0:
            a = draw(st.sampled_from([0.0, -0.0]))
        lo.append(min(a, b))
        hi.append(max(a, b))
    return lo, hi


SPH = ivx.spherical("z")
COORDS = {"r": SPH.r, "theta": SPH.theta, "phi": SPH.phi, "rho": ivx.rho,
          "r_y": ivx.spherical("y").r, "phi_y": ivx.spherical("y").phi,
          "theta_x": ivx.spherical("x").theta,
          "sin3theta": sin(3 * SPH.theta), "cos5theta+1": cos(5 * SPH.theta + 1.0),
          "sinsin": sin(3 * ivx.spherical("y").theta) * sin(4 * ivx.spherical("y").phi)}


@pytest.mark.parametrize("name", sorted(COORDS))
@settings(max_examples=150, deadline=None)
@given(box=boxes())
def test_coordinates_enclose_exact_values_at_the_axis_origin_and_cut(name, box):
    expr = COORDS[name]
    lo, hi = box
    flo, fhi = (float(v[0]) for v in ivx.compile(expr).interval([lo], [hi]))
    for p in boundary_samples(lo, hi, 7)[::3]:
        exact = mp_value(expr, p)
        if exact is not None:
            assert contains(flo, fhi, exact), f"{name} at {p}: {mpmath.nstr(exact, 17)}"


@pytest.mark.parametrize("name", ["r", "theta", "phi", "rho", "r_y", "phi_y", "theta_x"])
@settings(max_examples=100, deadline=None)
@given(corner=st.tuples(*[st.floats(0.05, 1.5)] * 3), size=st.tuples(*[st.floats(0.01, 0.5)] * 3),
       signs=st.tuples(*[st.sampled_from([-1.0, 1.0])] * 3))
def test_coordinates_are_tight_off_the_axis_and_cut(name, corner, size, signs):
    """Away from the axis and the cut, the interval is the exact range: the
    extremes lie on the boundary, which a fine sampling covers."""
    lo = [c if s > 0 else -c - d for s, c, d in zip(signs, corner, size)]
    hi = [c + d if s > 0 else -c for s, c, d in zip(signs, corner, size)]
    f = ivx.compile(COORDS[name])
    flo, fhi = (float(v[0]) for v in f.interval([lo], [hi]))
    pts = boundary_samples(lo, hi)
    values = f(pts[:, 0], pts[:, 1], pts[:, 2])
    vmin, vmax = values.min(), values.max()
    assert flo <= vmin and vmax <= fhi
    # the sampling step bounds how far inside the true extremes can be
    step = max(size) / 40 * 4
    assert vmin - flo <= step + 1e-12 and fhi - vmax <= step + 1e-12


def test_box_holding_the_axis_gives_the_full_angle_range():
    f = ivx.compile(ivx.theta)
    lo, hi = f.interval([[-0.1, -0.1, 0.5]], [[0.1, 0.1, 0.6]])
    assert lo[0] <= -np.pi and hi[0] >= np.pi
    lo, hi = ivx.compile(ivx.phi).interval([[-0.1, -0.1, 0.5]], [[0.1, 0.1, 0.6]])
    assert hi[0] >= np.pi / 2                                   # the pole is in the box
    assert lo[0] == pytest.approx(np.arctan2(0.5, np.hypot(0.1, 0.1)), abs=1e-14)  # exact


def test_periodic_functions_of_theta_stay_tight_across_the_cut():
    lo_box, hi_box = [-1.0, -0.05, 0.0], [-0.9, 0.05, 0.1]   # straddles the negative x axis
    plain = ivx.compile(ivx.theta).interval([lo_box], [hi_box])
    assert plain[0][0] <= -np.pi and plain[1][0] >= np.pi    # theta itself: full range
    f = ivx.compile(sin(3 * ivx.theta))
    flo, fhi = f.interval([lo_box], [hi_box])
    pts = boundary_samples(lo_box, hi_box)
    values = f(pts[:, 0], pts[:, 1], pts[:, 2])
    assert flo[0] <= values.min() and values.max() <= fhi[0]
    assert fhi[0] - flo[0] < 0.35                             # not [-1, 1]


def test_axis_frames():
    assert repr(ivx.spherical("y").theta) == "atan2(z, x)"
    assert repr(ivx.cylindrical("x").rho) == "hypot(y, z)"
    with pytest.raises(ValueError, match="axis must be"):
        ivx.spherical("w")
    f = ivx.compile(ivx.spherical("x").phi)
    assert float(f(0.0, 0.0, 1.0)) == 0.0 and float(f(2.0, 0.0, 0.0)) == pytest.approx(np.pi / 2)


def test_coordinate_gradients():
    pts = np.random.default_rng(4).normal(size=(50, 3))
    for expr, exact in [(ivx.r, lambda p: p / np.linalg.norm(p, axis=1, keepdims=True))]:
        _, g = ivx.compile(expr).gradient(pts[:, 0], pts[:, 1], pts[:, 2])
        np.testing.assert_allclose(g, exact(pts), atol=1e-12)
    f = ivx.compile(ivx.phi)
    h = 1e-6
    for axis in range(3):
        d = np.zeros(3)
        d[axis] = h
        numeric = (f(*(pts + d).T) - f(*(pts - d).T)) / (2 * h)
        np.testing.assert_allclose(f.gradient(*pts.T)[1][:, axis], numeric, atol=1e-6)
    g = ivx.compile(sin(3 * ivx.theta) * 2.0)
    for axis in range(3):
        d = np.zeros(3)
        d[axis] = h
        numeric = (g(*(pts + d).T) - g(*(pts - d).T)) / (2 * h)
        np.testing.assert_allclose(g.gradient(*pts.T)[1][:, axis], numeric, atol=1e-5)
