"""What users write: expressions, functions, coordinates, sweeps and the ``Shape`` protocol.

The first layer of the data flow; it imports nothing else of implicitvox.

* :mod:`.nodes` - ``Expr`` (immutable nodes, structural hash), ``x, y, z``;
* :mod:`.functions` - ``sin``, ``sqrt``, ``min``, ``max``, ... on expressions;
* :mod:`.coords` - ``r, rho, theta, phi``, ``spherical``, ``cylindrical`` (Stolte §4.1);
* :mod:`.sweeps` - ``repeat``, ``repeat_polar`` (Stolte §3);
* :mod:`.shape` - the ``Shape`` protocol, octant states, default bounds;
* :mod:`.examples` - the built-in models (Stolte's figures).
"""
from .nodes import Expr, constant, wrap, x, y, z
from .coords import (Cylindrical, Spherical, cylindrical, elevation, phi, r, radius, rho,
                     spherical, theta)
from .functions import (abs, acos, affine, asin, atan, atan2, clip, cos, exp, floor, hypot, log,
                        max, min, sin, sqrt, square, tan)
from .sweeps import repeat, repeat_polar
from .shape import AMBIGUOUS, EMPTY, FULL, ExprShape, Shape, as_shape

__all__ = ["Expr", "constant", "wrap", "x", "y", "z", "Cylindrical", "Spherical", "cylindrical",
           "elevation", "phi", "r", "radius", "rho", "spherical", "theta", "repeat",
           "repeat_polar", "AMBIGUOUS", "EMPTY", "FULL", "ExprShape", "Shape", "as_shape",
           "abs", "acos", "affine", "asin", "atan", "atan2", "clip", "cos", "exp", "floor", "hypot",
           "log", "max", "min", "sin", "sqrt", "square", "tan"]
