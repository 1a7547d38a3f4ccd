"""``Solid``: a node of a CSG tree that the implicitvox kernel can voxelize.

Every solid is an implicit function, negative inside (:attr:`Solid.expr`,
for intervals and points), with conservative :attr:`Solid.bounds`. Booleans
are ``|`` (union), ``&`` (intersection), ``-`` (difference) and ``~``
(complement); transforms are :meth:`Solid.translate`, :meth:`Solid.rotate`,
:meth:`Solid.scale`, :meth:`Solid.mirror` and :meth:`Solid.transform` (any
invertible affine 4 x 4 matrix). A transformed solid is its child's function
at the pre-image of each point, so non-uniform scales and shears are exact.

Solids with a :class:`~csg.primitives.Polyhedron` leaf also have an exact box
classification (:attr:`Solid.classify_boxes`, see :mod:`csg.tree_classifier`), which
the voxelizer uses on boxes the intervals leave ambiguous.

Examples
--------
>>> from csg import Box, Cylinder
>>> bracket = Box((4, 2, 1)) - Cylinder(r=0.4, h=3, center=True).translate((1, 1, 0))
>>> bracket.bounds
((0.0, 0.0, 0.0), (4.0, 2.0, 1.0))
>>> vox = bracket.voxelize(resolution=32)
>>> vox.resolution, vox.voxel_size[0] == vox.voxel_size[2]
((32, 17, 9), True)
"""
from __future__ import annotations

import functools
import json
import math
from typing import Any, Callable, Optional, Sequence

import numpy as np

import implicitvox as iv
from implicitvox import Expr, validate, x, y, z
from implicitvox.voxelizers.mesh import nearest_triangle_normals

from .protocol import NotAMesh, NotAPolytope, NotFlat
from .tree_classifier import exact_classifier, plan, world_primitive

__all__ = ["Solid", "Union", "Intersection", "Difference", "Complement", "Transformed",
           "ExprSolid", "Bounds", "rotation_matrix", "vector", "box_bound", "SCENE_FORMAT"]

#: the version of the JSON scene format (:mod:`csg.scene`)
SCENE_FORMAT = 1

Bounds = Optional[tuple[tuple[float, float, float], tuple[float, float, float]]]


#: scene node type -> the solid class that reads it (:meth:`Solid.from_scene`): each class
#: names its type (``scene_type``) and registers itself when it is defined, so a new solid
#: is read by :func:`csg.load_json` without a line elsewhere
SCENE_TYPES: dict[str, type] = {}


#: what builds a tree's :attr:`Solid.regularized_boundary` (the meshes and their
#: booleans live above the solids: :mod:`csg.tree_mesh` registers it on import)
_REGULARIZERS: list[Callable[["Solid"], Optional[Any]]] = []


#: what builds a tree's :attr:`Solid.boundary_mesh` (:mod:`csg.tree_mesh` registers it)
_BOUNDARIES: list[Callable[["Solid"], Optional[tuple]]] = []


#: what gives a tree's facets (its leaves' triangles, moved) for its normals: the meshes
#: live above the solids, :mod:`csg.tree_mesh` registers it on import
_FACETS: list[Callable[["Solid"], Optional[np.ndarray]]] = []


def register_facets(build: Callable[["Solid"], Optional[np.ndarray]]) -> None:
    """Make ``build(solid)`` (its leaves' triangles ``(t, 3, 3)``, or None) what
    :attr:`Solid.surface_normals` falls back on."""
    _FACETS.append(build)


def register_boundary(build: Callable[["Solid"], Optional[tuple]]) -> None:
    """Make ``build(solid)`` (the closed mesh ``(vertices, faces)`` of the regularized
    solid's boundary, or None) what :attr:`Solid.boundary_mesh` asks."""
    _BOUNDARIES.append(build)


def register_regularizer(build: Callable[["Solid"], Optional[Any]]) -> None:
    """Make ``build(solid)`` (a box test of the regularized solid's boundary, or
    None) what :attr:`Solid.regularized_boundary` asks."""
    _REGULARIZERS.append(build)


class Solid:
    """Base class of CSG nodes (see the module docstring); what a leaf must and may
    provide is the leaf protocol of :mod:`csg.protocol`."""

    #: 3 for solids; 2 for planar regions (infinite prisms along z, for extrusions)
    dim = 3
    #: whether the surface has true curves (no vertices, mesh or outlines: facet it)
    curved = False
    #: what the exact classifier (:mod:`csg.tree_classifier`) reads of a node: its
    #: operation ("union", "intersection", "difference", "complement",
    #: "transform"; None for leaves and other nodes), whether it is a leaf with
    #: an exact test, and whether it has nothing but one (a polyhedron)
    operation: Optional[str] = None
    exact = False
    needs_exact_test = False
    #: the ``"type"`` of this class's JSON scene nodes (None: it is not read from scenes)
    scene_type: Optional[str] = None

    def __init_subclass__(cls, **kwargs: Any):
        super().__init_subclass__(**kwargs)
        kind = cls.__dict__.get("scene_type")
        if kind is not None:
            if kind in SCENE_TYPES and SCENE_TYPES[kind] is not cls:
                raise TypeError(f"scene type {kind!r} is {SCENE_TYPES[kind].__name__}'s "
                                f"already, not {cls.__name__}'s")
            SCENE_TYPES[kind] = cls

    # -- what subclasses provide -------------------------------------------------
    @property
    def expr(self) -> Expr:
        """The implicit function, negative inside."""
        raise NotImplementedError

    @property
    def bounds(self) -> Bounds:
        """A box holding the solid, or None if unbounded."""
        raise NotImplementedError

    @property
    def children(self) -> tuple["Solid", ...]:
        return ()

    # -- booleans ------------------------------------------------------------------
    # A chain of operators (``a | b | c``, a loop ``u = u | part``) makes one n-ary
    # boolean, as OpenSCAD's union() of many children: the same function (min and max
    # chain left to right either way), and a tree as shallow as the model, not as deep
    # as its parts are many (the tree's walks are recursive).
    def __or__(self, other: "Solid") -> "Solid":
        other = _check_solid(other, "|")
        return Union(*_operands(self, Union), *_operands(other, Union))

    def __and__(self, other: "Solid") -> "Solid":
        other = _check_solid(other, "&")
        return Intersection(*_operands(self, Intersection), *_operands(other, Intersection))

    def __sub__(self, other: "Solid") -> "Solid":
        other = _check_solid(other, "-")
        return Difference(*_operands(self, Difference), other)

    def __invert__(self) -> "Solid":
        return Complement(self)

    def __bool__(self) -> bool:
        raise TypeError("a Solid has no truth value; combine solids with |, & and -")

    # -- transforms --------------------------------------------------------------------
    def transform(self, matrix: Any) -> "Solid":
        """Apply an invertible affine 4 x 4 matrix (last row ``0 0 0 1``)."""
        return Transformed(self, matrix)

    def translate(self, offset: Sequence[float]) -> "Solid":
        m = np.eye(4)
        m[:3, 3] = vector(offset, "offset")
        return Transformed(self, m)

    def rotate(self, axis: Any, degrees: float) -> "Solid":
        """Rotate by ``degrees`` about ``axis`` (``"x"``, ``"y"``, ``"z"`` or a vector)
        through the origin, counter-clockwise looking down the axis."""
        m = np.eye(4)
        m[:3, :3] = rotation_matrix(axis, degrees)
        return Transformed(self, m)

    def scale(self, factor: Any) -> "Solid":
        """Scale by a number or per axis (non-zero)."""
        f = np.broadcast_to(np.asarray(factor, dtype=np.float64), (3,))
        if not np.all(np.isfinite(f)) or np.any(f == 0):
            raise ValueError(f"scale factor must be finite and non-zero, got {factor!r}")
        return Transformed(self, np.diag([*f, 1.0]))

    def mirror(self, normal: Sequence[float]) -> "Solid":
        """Reflect in the plane through the origin with this normal (OpenSCAD ``mirror``)."""
        n = vector(normal, "normal")
        length = float(np.linalg.norm(n))
        if length == 0:
            raise ValueError("mirror normal must not be zero")
        n = n / length
        m = np.eye(4)
        m[:3, :3] -= 2.0 * np.outer(n, n)
        return Transformed(self, m)

    # -- exact tests ----------------------------------------------------------------
    def world_linf(self, matrix: np.ndarray) -> Any:
        """This leaf under the affine ``matrix`` as a max-norm primitive
        (:mod:`implicitvox.linf`), or None (the default: no exact form)."""
        return None

    # -- the optional hooks of the leaf protocol (csg.protocol) ---------------------------
    def polytope_vertices(self, convex: bool, pieces: Callable[["Solid", bool], list]
                          ) -> np.ndarray:
        """The points (n, 3) whose convex hull is this leaf, for hulls and Minkowski
        sums (:mod:`csg.polytopes`); by default it has none.

        Raises
        ------
        NotAPolytope
            This leaf has no vertex set (curved ones say so).
        """
        name = type(self).__name__
        if self.curved:
            raise NotAPolytope(f"a {name} is curved: its hull or Minkowski sum is no polytope "
                               "(facet it first, as OpenSCAD does: read_openscad(..., "
                               "facets='openscad'))", curved=True)
        raise NotAPolytope(f"a {name} has no vertex set here (hull and minkowski take boxes, "
                           "polyhedra, polygons, straight extrusions, moved and united)")

    def closed_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """This leaf's closed triangle mesh ``(vertices, faces)`` in its own frame
        (:mod:`csg.tree_mesh`); by default it has none.

        Raises
        ------
        NotAMesh
            This leaf has no mesh (curved ones say so).
        """
        name = type(self).__name__
        if self.curved:
            raise NotAMesh(f"a {name} is curved: it has no mesh (facet it first: "
                           "read_openscad(..., facets='openscad'))", curved=True)
        raise NotAMesh(f"a {name} has no triangle mesh here (polyhedra, imported meshes, "
                       "surfaces, boxes and faceted primitives have)")

    def outlines(self) -> list[np.ndarray]:
        """A 2D leaf's closed outlines ((k, 2) arrays, filled even-odd) for Clipper
        (:mod:`csg.clipper2d`); by default it has none.

        Raises
        ------
        NotFlat
            This is no 2D leaf with outlines.
        """
        raise NotFlat(f"a {type(self).__name__} is not a 2D shape with outlines")

    def exact_leaf(self, matrix: np.ndarray) -> Optional[tuple[str, Any]]:
        """This leaf's exact box test under ``matrix`` for :mod:`csg.tree_classifier`."""
        prim = self.world_linf(matrix)
        return None if prim is None else ("exact", prim)

    @functools.cached_property
    def exact_plan(self) -> Optional[tuple]:
        """The tree flattened for exact classification (:func:`csg.tree_classifier.plan`),
        or None when no leaf has an exact test; built once per solid."""
        return plan(self)

    @property
    def expression_is_exact(self) -> bool:
        """Whether :attr:`expr` is the solid's own function (zero on its surface,
        negative inside); False when a leaf's is only a bound (a polyhedron:
        OpenSCAD's facets, imported meshes), whose geometry only the exact test
        knows. :func:`implicitvox.mesh` needs point values, so it needs this."""
        stack = [self]
        while stack:
            node = stack.pop()
            if node.needs_exact_test:
                return False
            stack.extend(node.children)
        return True

    # -- voxelization --------------------------------------------------------------
    @property
    def surface_normals(self) -> Optional[Callable[[np.ndarray], np.ndarray]]:
        """Normals from the solid's own facets where its function only bounds it
        (:attr:`expression_is_exact` False: OpenSCAD's facets, imported meshes): the
        normal of the regularized boundary's triangle nearest to each point
        (:attr:`regularized_boundary`; where the tree has none, as when a leaf's mesh is
        not manifold, the nearest of its leaves' triangles); None where the function is
        exact (its gradient is the normal) or no leaf has a mesh."""
        if self.expression_is_exact:
            return None
        mesh = getattr(self.regularized_boundary, "tris", None)   # none where it is empty
        triangles = mesh.v if mesh is not None else (_FACETS[-1](self) if _FACETS else None)
        if triangles is None or not len(triangles):
            return None
        return lambda points: nearest_triangle_normals(triangles, np.asarray(points, float))

    @property
    def classify_boxes(self) -> Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]]:
        """Exact box test (:mod:`csg.tree_classifier`) if a leaf has one, else None."""
        return exact_classifier(self.exact_plan)

    @property
    def classify_voxels(self) -> Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]]:
        """The exact test at the voxel level: as :attr:`classify_boxes`, and where two
        exact surfaces meet a box, decided by subdividing it (:mod:`csg.tree_classifier`), and
        where they touch (a tie no halving settles) by :attr:`regularized_boundary`."""
        return exact_classifier(self.exact_plan, settle=True,
                                regularized=lambda: self.regularized_boundary)

    @functools.cached_property
    def boundary_mesh(self) -> Optional[tuple[np.ndarray, np.ndarray]]:
        """The closed triangle mesh ``(vertices (m, 3), faces (k, 3))``, oriented
        outward, of the regularized solid's boundary where every leaf is a polytope
        (OpenSCAD's facets, imported meshes, boxes, extrusions of outlines; the
        booleans computed by Manifold: :func:`csg.tree_mesh.tree_mesh`), no faces
        where it is empty; None where the tree has no such mesh (a curved leaf, an open
        mesh). :func:`implicitvox.mesh` returns it for solids whose function only
        bounds them. Built once."""
        return None if _BOUNDARIES == [] else _BOUNDARIES[-1](self)

    @functools.cached_property
    def regularized_boundary(self) -> Optional[Any]:
        """The exact box test of the boundary of the regularized solid - the closed
        mesh of a tree of polytopes, with its booleans computed by Manifold
        (:func:`csg.tree_mesh.regularized_classifier`, registered by
        :func:`register_regularizer`), which keeps no face shared inside the solid
        (and a test no box meets where it is empty: parts that only touch) - or
        None when the tree has no such mesh (a curved leaf, an open mesh). Built
        once, on the first tie."""
        return None if _REGULARIZERS == [] else _REGULARIZERS[-1](self)

    def voxelize(self, resolution: Any = None, **options: Any) -> iv.Voxels:
        """:func:`implicitvox.voxelize` this solid, with the same arguments
        (``bounds`` default to the solid's own, padded by the one rule)."""
        if self.dim != 3:
            raise ValueError("a 2D shape has no volume: extrude it first "
                             "(linear_extrude or rotate_extrude)")
        if options.get("bounds") is None and self.bounds is None:
            raise ValueError("the solid is unbounded (a complement or half-space): pass bounds")
        return iv.voxelize(self, resolution, **options)

    def linf_distance(self, points: Any, weights: Any = None) -> np.ndarray:
        """Signed weighted max-norm distance (Varadhan §3; :mod:`implicitvox.linf`) for a
        primitive with one - box, convex polyhedron, half-space, sphere, ellipsoid,
        cylinder, torus or polyhedron (a triangle mesh) - under any transforms.

        Raises
        ------
        TypeError
            For other solids (booleans, blends, ...): their exact box test combines
            their leaves' tests instead (:attr:`classify_boxes`).
        """
        prim = world_primitive(self)
        if prim is None:
            raise TypeError(f"no max-norm distance for {type(self).__name__}: only single "
                            "primitives have one (booleans classify boxes leaf by leaf)")
        return prim.distance(points, weights)

    def distance_function(self, norm: str) -> Optional[Callable]:
        """The exact signed distance in ``norm`` (``"linf"`` or ``"euclidean"``) of a
        single primitive under transforms (:meth:`implicitvox.linf.Primitive.distance_function`),
        or None (booleans, blends, or a primitive without one, such as a scaled sphere's
        ellipsoid in the Euclidean norm): :func:`implicitvox.distance_field` then uses
        the exact box test or certifies the distances."""
        prim = world_primitive(self)
        return None if prim is None else prim.distance_function(norm)

    # -- scenes ------------------------------------------------------------------------
    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> "Solid":
        """The solid of a scene node of :attr:`scene_type`, its fields taken with the
        reader ``read`` (:class:`csg.scene.SceneReader`: ``num``, ``flag``, ``array``,
        ``child``, ``kids``, ``expression``, each checking and naming the field)."""
        raise TypeError(f"{cls.__name__} is not read from scenes")

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`); each kind of solid writes its own."""
        raise TypeError(f"{type(self).__name__} has no JSON form")

    def to_json(self, indent: Any = None) -> str:
        """The solid as a JSON scene (:mod:`csg.scene`, read back by :func:`csg.load_json`)."""
        return json.dumps({"implicitvox_scene": SCENE_FORMAT, "root": self.scene_node()},
                          indent=indent, allow_nan=False)

    def __repr__(self) -> str:
        args = ", ".join(repr(c) for c in self.children)
        return f"{type(self).__name__}({args})"


def _operands(solid: "Solid", kind: type) -> tuple:
    """The operands ``solid`` brings to a boolean of ``kind``: its children if it is
    one (exactly that class), else itself."""
    return solid.children if type(solid) is kind else (solid,)


def _check_solid(other: Any, op: str) -> "Solid":
    if not isinstance(other, Solid):
        raise TypeError(f"cannot combine a Solid with {type(other).__name__} by {op}")
    return other


def vector(v: Any, name: str, *, planar: bool = True, scalar: bool = False) -> np.ndarray:
    """3 finite floats, or a ``ValueError`` naming ``name``; with ``planar`` 2 numbers
    get z = 0 (transforms of 2D shapes), with ``scalar`` one number fills all three."""
    try:
        a = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be 3 numbers, got {v!r}") from None
    if planar and a.shape == (2,):
        a = np.append(a, 0.0)
    if scalar and a.shape == ():
        a = np.full(3, float(a))
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be 3 finite numbers, got {v!r}")
    return a


def box_bound(lo: Any, hi: Any) -> Expr:
    """The expression of a leaf whose geometry only its exact test knows (a
    polyhedron, a long-outlined prism): positive off the box ``lo .. hi``, zero
    in it, which intervals read as "ask the exact test".

    >>> f = iv.compile(box_bound((0, 0, 0), (1, 1, 1)))
    >>> f(np.array([2.0, 0.5]), np.array([0.5, 0.5]), np.array([0.5, 0.5])).tolist()
    [1.0, 0.0]
    """
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    c, h = (lo + hi) / 2, (hi - lo) / 2
    outside = iv.max(abs(x - c[0]) - h[0], abs(y - c[1]) - h[1], abs(z - c[2]) - h[2])
    return iv.max(outside, 0.0)


def rotation_matrix(axis: Any, degrees: float) -> np.ndarray:
    """3 x 3 rotation; exact for multiples of 90 degrees."""
    if isinstance(axis, str):
        if axis not in ("x", "y", "z"):
            raise ValueError(f"axis must be 'x', 'y', 'z' or a vector, got {axis!r}")
        axis = np.eye(3)["xyz".index(axis)]
    u = vector(axis, "axis")
    norm = float(np.linalg.norm(u))
    if norm == 0:
        raise ValueError("rotation axis must not be zero")
    u = u / norm
    degrees = float(degrees)
    if not math.isfinite(degrees):
        raise ValueError(f"degrees must be finite, got {degrees}")
    quarter = degrees / 90.0
    if quarter == round(quarter):
        c, s = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][int(round(quarter)) % 4]
    else:
        c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return c * np.eye(3) + s * k + (1 - c) * np.outer(u, u)


class _NaryBoolean(Solid):
    """A union or intersection of one or more solids (``combine`` is min or max)."""

    _symbol = ""
    _name = ""

    def __init__(self, *solids: Solid):
        if not solids:
            raise ValueError(f"{self._name} needs at least one solid")
        self._children = tuple(_check_solid(s, self._symbol) for s in solids)
        self.dim = max(s.dim for s in self._children)

    @staticmethod
    def _combine(*exprs: Expr) -> Expr:
        raise NotImplementedError

    @property
    def children(self):
        return self._children

    @property
    def expr(self) -> Expr:
        return self._combine(*[c.expr for c in self._children]) if len(self._children) > 1 \
            else self._children[0].expr

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": self.operation, "children": [c.scene_node() for c in self.children]}


class Union(_NaryBoolean):
    """Points in any child: ``min`` of the functions."""

    _symbol, _name = "|", "a union"
    operation = "union"
    scene_type = "union"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> "Solid":
        """``children [NODE...]``."""
        return cls(*read.kids(node, path, depth))
    _combine = staticmethod(iv.min)

    @property
    def bounds(self) -> Bounds:
        bs = [c.bounds for c in self._children]
        if any(b is None for b in bs):
            return None
        return (tuple(np.min([b[0] for b in bs], axis=0).tolist()),
                tuple(np.max([b[1] for b in bs], axis=0).tolist()))


class Intersection(_NaryBoolean):
    """Points in every child: ``max`` of the functions."""

    _symbol, _name = "&", "an intersection"
    operation = "intersection"
    scene_type = "intersection"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> "Solid":
        """``children [NODE...]``."""
        return cls(*read.kids(node, path, depth))
    _combine = staticmethod(iv.max)

    @property
    def bounds(self) -> Bounds:
        bs = [c.bounds for c in self._children if c.bounds is not None]
        if not bs:
            return None
        lo = np.max([b[0] for b in bs], axis=0)
        hi = np.min([b[1] for b in bs], axis=0)
        hi = np.maximum(hi, lo)              # disjoint: an empty box
        return tuple(lo.tolist()), tuple(hi.tolist())


class Difference(Solid):
    """The first solid minus the others: ``max(a, -b, ...)``."""

    operation = "difference"
    scene_type = "difference"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> "Solid":
        """``children [NODE...]``: the first minus the rest."""
        return cls(*read.kids(node, path, depth))

    def __init__(self, first: Solid, *others: Solid):
        self._children = (_check_solid(first, "-"),) + tuple(_check_solid(s, "-") for s in others)
        self.dim = first.dim

    @property
    def children(self):
        return self._children

    @property
    def expr(self) -> Expr:
        if len(self._children) == 1:
            return self._children[0].expr
        return iv.max(self._children[0].expr, *[-c.expr for c in self._children[1:]])

    @property
    def bounds(self) -> Bounds:
        return self._children[0].bounds

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "difference", "children": [c.scene_node() for c in self.children]}


class Complement(Solid):
    """Everything outside the solid: ``-f`` (unbounded)."""

    operation = "complement"
    scene_type = "complement"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> "Solid":
        """``child NODE``."""
        return cls(read.child(node, path, depth))

    def __init__(self, solid: Solid):
        self._children = (_check_solid(solid, "~"),)
        self.dim = solid.dim

    @property
    def children(self):
        return self._children

    @property
    def expr(self) -> Expr:
        return -self._children[0].expr

    @property
    def bounds(self) -> Bounds:
        return None

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "complement", "child": self.children[0].scene_node()}


class Transformed(Solid):
    """A solid moved by an affine map ``p -> A p + t`` (its function at the pre-image)."""

    operation = "transform"
    scene_type = "transform"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> "Solid":
        """``matrix [[4] x 4], child NODE``."""
        return cls(read.child(node, path, depth), read.array(node, path, "matrix", (4, 4)))

    def __init__(self, solid: Solid, matrix: Any):
        m = np.array(matrix, dtype=np.float64)
        if m.shape == (3, 3):
            m = np.block([[m, np.zeros((3, 1))], [np.zeros((1, 3)), np.ones((1, 1))]])
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            raise ValueError(f"transform must be a finite 4 x 4 (or 3 x 3) matrix, got shape "
                             f"{m.shape}")
        if not np.array_equal(m[3], [0, 0, 0, 1]):
            raise ValueError(f"transform must be affine (last row 0 0 0 1), got {m[3].tolist()}")
        det = float(np.linalg.det(m[:3, :3]))
        if not abs(det) > 1e-300:
            raise ValueError("transform is singular (determinant 0): a solid would collapse "
                             "to a plane, line or point")
        if solid.dim == 2 and not (np.allclose(m[2], [0, 0, 1, 0]) and
                                   np.allclose(m[:2, 2], 0)):
            raise ValueError("a 2D shape can only be moved within its plane")
        self._children = (solid,)
        self.matrix = m
        self.dim = solid.dim

    @property
    def children(self):
        return self._children

    @property
    def inverse(self) -> np.ndarray:
        return np.linalg.inv(self.matrix)

    @property
    def expr(self) -> Expr:
        inv = self.inverse
        u = [iv.affine(inv[i, :3], (x, y, z), inv[i, 3]) for i in range(3)]
        return self._children[0].expr.remap(x=u[0], y=u[1], z=u[2])

    @property
    def bounds(self) -> Bounds:
        b = self._children[0].bounds
        if b is None:
            return None
        lo, hi = np.asarray(b[0], dtype=float), np.asarray(b[1], dtype=float)
        if self.dim == 2:
            lo[2], hi[2] = -1.0, 1.0        # placeholder depth of a planar region
        corners = np.array([[(lo, hi)[(k >> a) & 1][a] for a in range(3)] for k in range(8)])
        moved = corners @ self.matrix[:3, :3].T + self.matrix[:3, 3]
        span = np.abs(moved).max() + 1.0
        new_lo = moved.min(axis=0) - 1e-12 * span   # conservative: the products rounded
        new_hi = moved.max(axis=0) + 1e-12 * span
        if self.dim == 2:
            new_lo[2], new_hi[2] = b[0][2], b[1][2]
        return tuple(new_lo.tolist()), tuple(new_hi.tolist())

    def __repr__(self) -> str:
        return f"Transformed({self._children[0]!r}, matrix={self.matrix.tolist()})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "transform", "matrix": self.matrix.tolist(),
                "child": self.children[0].scene_node()}


class ExprSolid(Solid):
    """A raw implicitvox expression as a solid (negative inside)."""

    scene_type = "expression"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> "Solid":
        """``expr`` (implicitvox syntax, by a whitelist), ``bounds [2 x 3]`` (optional)."""
        bounds = node.get("bounds")
        if bounds is not None:
            bounds = read.array(node, path, "bounds", (2, 3))
        return cls(read.expression(node, path, "expr"), bounds)

    def __init__(self, expr: Any, bounds: Bounds = None):
        self._expr = iv.wrap(expr)
        if bounds is not None:
            bounds = validate.bounds(bounds)
        self._bounds = bounds

    @property
    def expr(self) -> Expr:
        return self._expr

    @property
    def bounds(self) -> Bounds:
        return self._bounds

    def __repr__(self) -> str:
        return f"ExprSolid({self._expr!r:.80}, bounds={self._bounds})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        node = {"type": "expression", "expr": repr(self.expr)}
        if self.bounds is not None:
            node["bounds"] = [list(self.bounds[0]), list(self.bounds[1])]
        return node


