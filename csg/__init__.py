"""csg: solids, booleans and transforms on top of the implicitvox kernel.

Primitives compile to implicitvox expressions (intervals, points,
gradients); polyhedral leaves add an exact box classification. ``csg``
imports ``implicitvox``; the kernel never imports ``csg``.

Examples
--------
>>> from csg import Box, Cylinder, Sphere
>>> part = (Box((2, 2, 1), center=True) | Sphere(0.8).translate((0, 0, 0.5))) \\
...     - Cylinder(r=0.3, h=4, center=True)
>>> vox = part.voxelize(resolution=48, interior=True)
>>> vox.count > 0 and vox.interior_count > 0
True
"""
from .solid import (Complement, Difference, ExprSolid, Intersection, Solid, Transformed, Union,
                    rotation_matrix)
from .primitives import (Box, Capsule, ConvexPolyhedron, Cylinder, Ellipsoid, HalfSpace,
                         Polyhedron, Sphere, Torus)
from .planar import Circle, Polygon, Rectangle, linear_extrude, rotate_extrude
from .blends import Blobby, smooth_difference, smooth_intersection, smooth_union
from .polytopes import NotAPolytope, hull, minkowski
from .openscad import read_openscad
from .openscad_parser import OpenSCADError, OpenSCADWarning
from .scad import OpenSCADNotFound
from .scene import SceneError, load_json

__all__ = [
    "Solid", "Union", "Intersection", "Difference", "Complement", "Transformed", "ExprSolid",
    "rotation_matrix",
    "Sphere", "Box", "Cylinder", "Torus", "Ellipsoid", "Capsule", "HalfSpace",
    "ConvexPolyhedron", "Polyhedron",
    "Circle", "Rectangle", "Polygon", "linear_extrude", "rotate_extrude",
    "smooth_union", "smooth_intersection", "smooth_difference", "Blobby",
    "hull", "minkowski", "NotAPolytope",
    "read_openscad", "OpenSCADError", "OpenSCADWarning", "OpenSCADNotFound", "load_json",
    "SceneError",
]
