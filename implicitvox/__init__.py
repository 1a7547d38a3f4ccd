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
from .expr import Expr, constant, wrap, x, y, z
from .coords import (Cylindrical, Spherical, cylindrical, elevation, phi, r, radius, rho,
                     spherical, theta)
from .function import Function, compile
from .grid import Grid
from .io import load
from .octree import Octree, PointerOctree
from .shape import AMBIGUOUS, EMPTY, FULL, Shape
from .sweep import repeat, repeat_polar
from .voxelizer import voxelize
from .mesh_voxelizer import voxelize_mesh
from .winding import winding_numbers
from .bezier import BezierPatch, utah_teapot, voxelize_bezier
from . import linf
from .linf import linf_distance
from .voxels import Voxels
from .functions import (abs, acos, asin, atan, atan2, clip, cos, exp, floor, hypot, log,
                        max, min, sin, sqrt, square, tan)

__version__ = "0.1.0"

__all__ = [
    "Expr", "constant", "wrap", "x", "y", "z",
    "Function", "compile",
    "r", "rho", "theta", "phi", "spherical", "cylindrical", "Spherical", "Cylindrical",
    "radius", "elevation", "repeat", "repeat_polar",
    "voxelize", "voxelize_mesh", "winding_numbers", "BezierPatch", "voxelize_bezier",
    "utah_teapot", "linf", "linf_distance", "Voxels", "Grid", "Octree", "PointerOctree", "load",
    "Shape", "EMPTY", "FULL", "AMBIGUOUS",
    "abs", "acos", "asin", "atan", "atan2", "clip", "cos", "exp", "floor", "hypot", "log",
    "max", "min", "sin", "sqrt", "square", "tan",
]
