"""implicitvox: robust implicit modeling and voxelization.

Write a solid as an expression in ``x, y, z`` (negative inside), compile it to
point, interval and gradient evaluators, and voxelize it with an interval
octree that never misses a voxel the surface passes through.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z, sqrt
>>> f = iv.compile(sqrt(x**2 + y**2 + z**2) - 1)
>>> float(f(0.0, 0.0, 2.0))
1.0
"""
from .version import __version__
from .expr.nodes import Expr, constant, wrap, x, y, z
from .expr.coords import (Cylindrical, Spherical, cylindrical, elevation, phi, r, radius, rho,
                          spherical, theta)
from .expr.functions import (abs, acos, affine, asin, atan, atan2, clip, cos, exp, floor, hypot,
                             log, max, min, sin, sqrt, square, tan)
from .expr.shape import AMBIGUOUS, EMPTY, FULL, Shape
from .expr.sweeps import repeat, repeat_polar
from .eval.function import Function, compile
from .octree.grid import Grid
from .octree.store import Octree, PointerOctree
from .octree.voxels import Voxels
from .triangles.patches import BezierPatch, utah_teapot
from .triangles.winding import winding_numbers
from . import linf
from .linf import linf_distance
from .voxelizers.implicit import voxelize
from .voxelizers.mesh import voxelize_mesh
from .voxelizers.bezier import voxelize_bezier
from .meshing.mesher import mesh
from .fields import DistanceField, Suitability, distance_field, suitability
from .io.files import load
from .io.field_files import load_field

__all__ = [
    "Expr", "constant", "wrap", "x", "y", "z",
    "Function", "compile",
    "r", "rho", "theta", "phi", "spherical", "cylindrical", "Spherical", "Cylindrical",
    "radius", "elevation", "repeat", "repeat_polar",
    "voxelize", "voxelize_mesh", "mesh", "winding_numbers", "BezierPatch", "voxelize_bezier",
    "utah_teapot", "linf", "linf_distance", "Voxels", "Grid", "Octree", "PointerOctree", "load",
    "Shape", "EMPTY", "FULL", "AMBIGUOUS", "distance_field", "DistanceField", "load_field",
    "suitability", "Suitability",
    "abs", "acos", "affine", "asin", "atan", "atan2", "clip", "cos", "exp", "floor", "hypot",
    "log", "max", "min", "sin", "sqrt", "square", "tan",
]
