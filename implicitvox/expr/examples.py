"""Built-in example models (Stolte's Fig. 6 and Fig. 11 surfaces, and friends).

Each example is a :class:`~implicitvox.expr.shape.ExprShape` with bounds, so
``voxelize(example("sinsin34"), resolution=256)`` works as it is.

Examples
--------
>>> from implicitvox.expr.examples import EXAMPLES, example
>>> sorted(EXAMPLES)[:3]
['blobby', 'drilled-plate', 'flange']
>>> example("gear").bounds
((-1.0, -0.3, -1.0), (1.0, 0.3, 1.0))
"""
from __future__ import annotations

from typing import Callable

import builtins

import numpy as np

from .coords import cylindrical, spherical
from .nodes import x, y, z
from .functions import exp, max, min, sin, sqrt
from .shape import ExprShape
from .sweeps import repeat, repeat_polar

__all__ = ["EXAMPLES", "example", "sinsin", "gear", "replicated_torus", "flange", "blobby",
           "lobed_plate", "menger", "sphere_union", "drilled_plate"]


def sinsin(n: int, m: int) -> ExprShape:
    """``sin(n theta) sin(m phi) - r`` (Stolte Fig. 6 and Fig. 11), in Stolte's
    spherical coordinates about y (§4.1.2)."""
    r, theta, phi = spherical(axis="y")
    return ExprShape(sin(n * theta) * sin(m * phi) - r, ((-1.1,) * 3, (1.1,) * 3))


def gear(teeth: int = 32) -> ExprShape:
    """Stolte's gear (Fig. 11-c): teeth ``rho - (0.8 + 0.05 sin(32 theta))`` in
    cylindrical coordinates about y, cut to a slab, with a hub and a bore."""
    rho, theta, _ = cylindrical(axis="y")
    rim = max(rho - (0.8 + 0.05 * sin(teeth * theta)), abs(y) - 0.1)
    hub = max(rho - 0.3, abs(y) - 0.25)
    disc = min(rim, hub)
    bore = 0.12 - rho
    return ExprShape(max(disc, bore), ((-1.0, -0.3, -1.0), (1.0, 0.3, 1.0)))


def replicated_torus(spacing: float = 0.5, big: float = 0.6, small: float = 0.12) -> ExprShape:
    """Stolte §3, eq. 3: a torus about z repeated along z every ``spacing``,
    without end (:func:`implicitvox.repeat`)."""
    rho = cylindrical(axis="z").rho
    torus = (rho - big) ** 2 + z ** 2 - small ** 2
    return ExprShape(repeat(torus, spacing=(None, None, spacing)),
                     ((-0.9, -0.9, -1.5), (0.9, 0.9, 1.5)))


def flange(bolts: int = 8) -> ExprShape:
    """A flange with a bolt circle: a disc minus a bore minus ``bolts`` holes
    (:func:`implicitvox.repeat_polar`)."""
    rho = cylindrical(axis="z").rho
    disc = max(rho - 1.0, abs(z) - 0.12)
    hole = 0.09 - sqrt((x - 0.72) ** 2 + y ** 2)
    return ExprShape(max(disc, 0.35 - rho, repeat_polar(hole, bolts)),
                     ((-1.05, -1.05, -0.2), (1.05, 1.05, 0.2)))


def blobby(n: int = 6, seed: int = 3, threshold: float = 0.5) -> ExprShape:
    """Blobby spheres (Stolte §2): ``threshold - sum(exp(-a |p - c_i|^2))``."""
    rng = np.random.default_rng(seed)
    centers = rng.uniform(-0.5, 0.5, (n, 3))
    field = sum(exp(-12.0 * ((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2))
                for cx, cy, cz in centers)
    return ExprShape(threshold - field, ((-1.0,) * 3, (1.0,) * 3))


def lobed_plate() -> ExprShape:
    """Stolte Fig. 11-d: contour ``rho - (1.2 + 0.05 sin(3 theta))`` cut to a plate."""
    rho, theta, _ = cylindrical(axis="y")
    return ExprShape(max(rho - (1.2 + 0.05 * sin(3 * theta)), abs(y) - 0.15, 0.4 - rho),
                     ((-1.3, -0.2, -1.3), (1.3, 0.2, 1.3)))


def menger(level: int = 3) -> ExprShape:
    """The Menger sponge of ``level``: the cube ``[-1, 1]^3`` minus, at each level
    ``k``, the ``3 * 9**(k - 1)`` square bars of side ``2 / 3**k`` through it
    along x, y and z (273 bars at level 3): a CSG model of many parts, with
    sharp edges everywhere."""
    bars = []
    for k in range(1, level + 1):
        half = 1.0 / 3 ** k
        centres = [-1.0 + (2 * i + 1) / 3 ** (k - 1) for i in range(3 ** (k - 1))]
        for u in centres:
            for v in centres:
                bars.append(max(abs(y - u) - half, abs(z - v) - half))   # along x
                bars.append(max(abs(z - u) - half, abs(x - v) - half))   # along y
                bars.append(max(abs(x - u) - half, abs(y - v) - half))   # along z
    cube = max(abs(x), abs(y), abs(z)) - 1.0
    return ExprShape(max(cube, -min(*bars)) if bars else cube, ((-1.0,) * 3, (1.0,) * 3))


def sphere_union(n: int = 100, seed: int = 1) -> ExprShape:
    """The union of ``n`` spheres at random centres in ``[-1, 1]^3``, of radius
    ``0.6 / n**(1/3)`` (a CSG model whose parts each matter only nearby)."""
    rng = np.random.default_rng(seed)
    radius = 0.6 / n ** (1.0 / 3.0)
    spheres = [sqrt((x - a) ** 2 + (y - b) ** 2 + (z - c) ** 2) - radius
               for a, b, c in rng.uniform(-1.0, 1.0, (n, 3))]
    reach = 1.0 + radius
    return ExprShape(min(*spheres) if n > 1 else spheres[0], ((-reach,) * 3, (reach,) * 3))


def drilled_plate(rows: int = 20, columns: int = 20) -> ExprShape:
    """A 2 x 2 x 0.2 plate with a ``rows`` x ``columns`` grid of cylindrical holes
    drilled through it along z (a typical OpenSCAD part)."""
    plate = max(abs(x) - 1.0, abs(y) - 1.0, abs(z) - 0.1)
    radius = 0.3 / builtins.max(rows, columns)
    holes = [radius - sqrt((x - (-1.0 + (2 * i + 1) / columns)) ** 2
                           + (y - (-1.0 + (2 * j + 1) / rows)) ** 2)
             for i in range(columns) for j in range(rows)]
    return ExprShape(max(plate, *holes), ((-1.0, -1.0, -0.1), (1.0, 1.0, 0.1)))


def _sphere() -> ExprShape:
    return ExprShape(sqrt(x * x + y * y + z * z) - 1.0, ((-1.1,) * 3, (1.1,) * 3))


#: name -> (description, factory)
EXAMPLES: dict[str, tuple[str, Callable[[], ExprShape]]] = {
    "sinsin34": ("sin(3 theta) sin(4 phi) - r (Stolte Fig. 6)", lambda: sinsin(3, 4)),
    "sinsin56": ("sin(5 theta) sin(6 phi) - r (Stolte Fig. 6)", lambda: sinsin(5, 6)),
    "sinsin910": ("sin(9 theta) sin(10 phi) - r (Stolte Fig. 6)", lambda: sinsin(9, 10)),
    "sinsin918": ("sin(9 theta) sin(18 phi) - r (Stolte Fig. 6, Fig. 11)", lambda: sinsin(9, 18)),
    "gear": ("32-tooth gear in cylindrical coordinates (Stolte Fig. 11-c)", gear),
    "lobed-plate": ("rho - (1.2 + 0.05 sin(3 theta)) plate (Stolte Fig. 11-d)", lobed_plate),
    "torus-sweep": ("torus replicated along z without end (Stolte §3, Fig. 2)", replicated_torus),
    "flange": ("a flange with a bolt circle (repeat_polar)", flange),
    "blobby": ("six blobby spheres (sum of Gaussians)", blobby),
    "sphere": ("the unit sphere", _sphere),
    "menger": ("the level-2 Menger sponge: a cube minus 30 bars", lambda: menger(2)),
    "spheres": ("the union of 30 random spheres", lambda: sphere_union(30)),
    "drilled-plate": ("a plate with 8 x 8 holes drilled through it", lambda: drilled_plate(8, 8)),
}


def example(name: str) -> ExprShape:
    """The built-in example ``name`` (see :data:`EXAMPLES`)."""
    try:
        return EXAMPLES[name][1]()
    except KeyError:
        raise ValueError(f"unknown example {name!r}; choose one of {', '.join(EXAMPLES)}") \
            from None
