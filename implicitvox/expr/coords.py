"""Spherical and cylindrical coordinates as expression nodes (Stolte §4.1).

``r`` (distance to the origin), ``rho`` (distance to the axis), ``theta``
(azimuth about the axis, in ``(-pi, pi]``) and ``phi`` (elevation from the
plane normal to the axis, in ``[-pi/2, pi/2]``), about ``z`` by default.
:func:`spherical` and :func:`cylindrical` give them about another axis:
``spherical(axis="y")`` is Stolte's frame (``theta = atan2(z, x)``,
``phi = atan2(y, hypot(x, z))``).

Their intervals over a box are exact up to rounding (Stolte §4.1.2): ``r``
and ``rho`` from the box's nearest and farthest points, ``theta`` from the
two silhouette corners (the full range when the box holds the axis),
``phi`` from the corners of the ``(rho, w)`` rectangle (Fig. 5). Across the
branch cut of ``theta`` (the negative first axis), ``theta`` itself gets
``[-pi, pi]``, but the tape rewrites ``sin(k*theta + c)`` and
``cos(k*theta + c)`` for integer ``k`` into one node evaluated on the
*unwrapped* angle interval, so periodic functions of ``theta`` stay tight
there.

Examples
--------
>>> import implicitvox as iv
>>> r, theta, phi = iv.spherical(axis="y")
>>> theta
atan2(z, x)
>>> f = iv.compile(iv.sin(3 * theta) * iv.sin(4 * phi) - r)
>>> lo, hi = f.interval([[-0.5, 0.1, -0.01]], [[-0.4, 0.2, 0.01]])  # across the cut
>>> bool(hi[0] - lo[0] < 1.0)
True
"""
from __future__ import annotations

from typing import NamedTuple

from .nodes import Expr, x, y, z
from .nodes import wrap
from .functions import atan2, hypot

__all__ = ["r", "rho", "theta", "phi", "spherical", "cylindrical", "Spherical", "Cylindrical",
           "radius", "elevation"]

_FRAMES = {"z": (x, y, z), "x": (y, z, x), "y": (x, z, y)}


class Spherical(NamedTuple):
    r: Expr
    theta: Expr
    phi: Expr


class Cylindrical(NamedTuple):
    rho: Expr
    theta: Expr
    height: Expr


def _frame(axis: str) -> tuple[Expr, Expr, Expr]:
    try:
        return _FRAMES[axis]
    except (KeyError, TypeError):
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}") from None


def radius(u, v, w) -> Expr:
    """``sqrt(u**2 + v**2 + w**2)`` with the exact box interval (nearest/farthest point)."""
    return Expr("radius", (wrap(u), wrap(v), wrap(w)))


def elevation(u, v, w) -> Expr:
    """``atan2(w, hypot(u, v))`` in ``[-pi/2, pi/2]``, exact over boxes (Stolte Fig. 5)."""
    return Expr("elevation", (wrap(u), wrap(v), wrap(w)))


def spherical(axis: str = "z") -> Spherical:
    """``(r, theta, phi)`` about ``axis``: theta turns from the first of the two
    other axes (in x, y, z order) towards the second; phi rises towards ``axis``."""
    u, v, w = _frame(axis)
    return Spherical(radius(u, v, w), atan2(v, u), elevation(u, v, w))


def cylindrical(axis: str = "z") -> Cylindrical:
    """``(rho, theta, height)`` about ``axis``."""
    u, v, w = _frame(axis)
    return Cylindrical(hypot(u, v), atan2(v, u), w)


r, theta, phi = spherical("z")
rho = cylindrical("z").rho
