"""The comparison models the benchmarks share (issue #49's seven surfaces, and more).

Each is a factory returning a shape with its own bounds, so every benchmark that
names ``"torus"`` means the same torus.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np


def sphere() -> Any:
    from implicitvox.expr.examples import example
    return example("sphere")


def torus() -> Any:
    from implicitvox import hypot, sqrt, x, y, z
    from implicitvox.expr.shape import ExprShape
    return ExprShape(sqrt((hypot(x, y) - 0.7) ** 2 + z ** 2) - 0.25,
                     ((-1.0, -1.0, -0.3), (1.0, 1.0, 0.3)))


def gear() -> Any:
    from implicitvox.expr.examples import example
    return example("gear")


def sinsin34() -> Any:
    from implicitvox.expr.examples import example
    return example("sinsin34")


def sinsin918() -> Any:
    from implicitvox.expr.examples import example
    return example("sinsin918")


def blended_spheres() -> Any:
    """Ten blobby spheres (Stolte's blended spheres: a sum of Gaussians) of radius 0.3
    to 0.5, their centres in the unit cube."""
    from csg import Blobby
    rng = np.random.default_rng(10)
    centres = rng.uniform(-0.6, 0.6, size=(10, 3))
    radii = rng.uniform(0.3, 0.5, size=10)
    return Blobby(centres.tolist(), radii.tolist())


def menger3() -> Any:
    from implicitvox.expr.examples import menger
    return menger(3)


def sin1000() -> Any:
    """A surface that fills space: ``sin(1000x) sin(1000y) sin(1000z)`` in the unit cube."""
    from implicitvox import sin, x, y, z
    from implicitvox.expr.shape import ExprShape
    return ExprShape(sin(1000 * x) * sin(1000 * y) * sin(1000 * z), ((-1.0,) * 3, (1.0,) * 3))


#: the seven surfaces meshed against libfive (issue #49)
SEVEN: dict[str, Callable[[], Any]] = {
    "sphere": sphere, "torus": torus, "gear": gear, "sinsin34": sinsin34,
    "sinsin918": sinsin918, "blended spheres": blended_spheres, "menger3": menger3,
}
CASES: dict[str, Callable[[], Any]] = dict(SEVEN, sin1000=sin1000)
