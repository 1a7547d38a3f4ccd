"""JSON scenes: CSG trees as data, for other tools to hand to the voxelizer.

A scene is ``{"implicitvox_scene": 1, "root": NODE}``; a node is an object
with a ``"type"`` and its fields (numbers are JSON numbers, vectors are
arrays; every field shown is required unless marked optional)::

    sphere            r, center (optional, [0, 0, 0])
    box               size [3], center (bool, optional)
    cylinder          h, r1, r2, center (optional)
    torus             R, r
    ellipsoid         radii [3], center (optional)
    halfspace         normal [3], offset
    convex_polyhedron normals [[3]...], offsets [...]   (or points [[3]...])
    polyhedron        vertices [[3]...], faces [[3 ints]...]
    circle            r
    rectangle         size [2], center (optional)
    polygon           points [[2]...], paths (optional) [[ints]...]
    union, intersection, difference     children [NODE...]  (difference: first minus the rest)
    complement        child NODE
    transform         matrix [[4]x4], child NODE
    linear_extrude    height, twist, scale [2], center, child NODE
    rotate_extrude    angle, sectors (optional int), child NODE
    smooth            kind ("union", "intersection", "difference"), radius, children [2 NODEs]
    blobby            centers [[3]...], radius [...], threshold
    expression        expr (implicitvox syntax, e.g. "sqrt(x**2 + y**2) - 1"), bounds (optional)

Nothing in a scene runs as code: an ``expression`` is parsed by a whitelist
of numbers, ``x, y, z``, ``+ - * / **`` and the kernel's functions. Limits
guard against hostile input: text size, nesting depth, node count, array
lengths; each error names the offending path (``root.children[1].r``).
Round trips are exact (floats are written with ``repr``).

Examples
--------
>>> from csg import Box, Sphere, load_json
>>> s = Box((2, 2, 2), center=True) - Sphere(1.2).translate((0, 0, 1))
>>> again = load_json(s.to_json())
>>> again.expr.equals(s.expr)
True
"""
from __future__ import annotations

import ast
import json
import math
from typing import Any

import numpy as np

import implicitvox as iv

from .blends import Blobby, SmoothBoolean
from .planar import Circle, LinearExtrude, Polygon, Rectangle, RotateExtrude
from .primitives import (Box, ConvexPolyhedron, Cylinder, Ellipsoid, HalfSpace, Polyhedron,
                         Sphere, Torus)
from .solid import (Complement, Difference, ExprSolid, Intersection, Solid, Transformed,
                    Union)

__all__ = ["to_json", "load_json", "to_dict", "from_dict", "SceneError", "LIMITS"]

#: hostile-input limits
LIMITS = {"text_bytes": 200 << 20, "depth": 100, "nodes": 100_000, "array": 5_000_000,
          "expr_chars": 1 << 20}


#: the node types a scene may hold: the reader dispatches through this table only, so a
#: "type" string never reaches any other attribute of the reader
NODE_TYPES = frozenset({
    "sphere", "box", "cylinder", "torus", "ellipsoid", "halfspace", "convex_polyhedron",
    "polyhedron", "circle", "rectangle", "polygon", "union", "intersection", "difference",
    "complement", "transform", "linear_extrude", "rotate_extrude", "smooth", "blobby",
    "expression"})


#: the longest string taken as a file name (Linux's PATH_MAX); a longer one that is not
#: JSON is refused without echoing it
MAX_PATH_CHARS = 4096


class SceneError(ValueError):
    """A scene that cannot be read, with the JSON path of the problem."""


# -- writing -------------------------------------------------------------------------------
def to_dict(solid: Solid) -> dict:
    """The scene node of a solid (each solid writes its own: ``Solid.scene_node``)."""
    return solid.scene_node()


def to_json(solid: Solid, indent: Any = None) -> str:
    """The solid as a JSON scene string."""
    return solid.to_json(indent=indent)


# -- reading -------------------------------------------------------------------------------
def load_json(text_or_path: Any) -> Solid:
    """Read a JSON scene (text, or a path to a ``.json`` file)."""
    import os
    text = text_or_path
    if isinstance(text, bytes):
        raise SceneError("load_json takes JSON text (a str) or a path, got bytes: decode them")
    if not isinstance(text, (str, os.PathLike)):
        raise SceneError(f"load_json takes JSON text or a path to a .json file, got "
                         f"{type(text).__name__} {text!r:.60}")
    if not (isinstance(text, str) and text.lstrip()[:1] in ("{", "[")):
        path = os.fspath(text_or_path)
        if len(path) > MAX_PATH_CHARS or "\0" in path:
            raise SceneError(f"load_json: {path[:60]!r}... ({len(path):,} characters) is "
                             "neither JSON text (it does not start with '{' or '[') nor a "
                             "file name")
        if not os.path.isfile(path):
            raise FileNotFoundError(f"no such scene file: {path}")
        if os.path.getsize(path) > LIMITS["text_bytes"]:
            raise SceneError(f"{path}: larger than {LIMITS['text_bytes']} bytes")
        try:
            with open(path, encoding="utf-8") as fh:
                text = fh.read()
        except UnicodeDecodeError as err:
            raise SceneError(f"{path}: not UTF-8 text ({err.reason} at byte {err.start})") \
                from None
    if len(text) > LIMITS["text_bytes"]:
        raise SceneError(f"scene larger than {LIMITS['text_bytes']} bytes")
    try:
        data = json.loads(text, parse_constant=_no_constant)
    except RecursionError:
        raise SceneError("scene nested too deeply for the JSON reader") from None
    except json.JSONDecodeError as err:
        raise SceneError(f"not JSON: {err.msg} at line {err.lineno}, column {err.colno}") \
            from None
    if not isinstance(data, dict) or data.get("implicitvox_scene") != 1 or "root" not in data:
        raise SceneError('a scene is {"implicitvox_scene": 1, "root": {...}}')
    return from_dict(data["root"])


def _no_constant(name: str):
    raise SceneError(f"{name} is not a number a scene may hold")


def from_dict(node: Any, path: str = "root") -> Solid:
    """The solid of a scene node (see the module docstring)."""
    try:
        return _Reader().read(node, path, 0)
    except RecursionError:      # a deep stack beneath us: refuse rather than crash
        raise SceneError(f"{path}: nested too deeply for the reader") from None


class _Reader:
    def __init__(self) -> None:
        self.count = 0

    def read(self, node: Any, path: str, depth: int) -> Solid:
        if depth > LIMITS["depth"]:
            raise SceneError(f"{path}: nested deeper than {LIMITS['depth']} levels")
        self.count += 1
        if self.count > LIMITS["nodes"]:
            raise SceneError(f"{path}: more than {LIMITS['nodes']} nodes")
        if not isinstance(node, dict):
            raise SceneError(f"{path}: a node must be an object, got {type(node).__name__}")
        kind = node.get("type")
        reader = getattr(self, f"_{kind}") if isinstance(kind, str) and kind in NODE_TYPES \
            else None
        if reader is None:
            raise SceneError(f"{path}.type: unknown node type {kind!r}")
        try:
            return reader(node, path, depth)
        except SceneError:
            raise
        except (ValueError, TypeError, ArithmeticError) as err:
            raise SceneError(f"{path}: {err}") from None

    # field readers
    def num(self, node, path, key, default=None):
        v = node.get(key, default)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise SceneError(f"{path}.{key}: must be a finite number, got {_short(v)}")
        return float(v)

    def flag(self, node, path, key, default=False):
        v = node.get(key, default)
        if not isinstance(v, bool):
            raise SceneError(f"{path}.{key}: must be true or false, got {_short(v)}")
        return v

    def array(self, node, path, key, shape, default=None, integer=False):
        v = node.get(key, default)
        if v is None:
            raise SceneError(f"{path}.{key}: required")
        size = _count(v, LIMITS["array"])
        if size > LIMITS["array"]:
            raise SceneError(f"{path}.{key}: more than {LIMITS['array']} numbers")
        try:
            a = np.array(v, dtype=np.float64)
        except (TypeError, ValueError):
            raise SceneError(f"{path}.{key}: must be a numeric array of shape {shape}") from None
        if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
            raise SceneError(f"{path}.{key}: must have shape {shape}, got {a.shape}")
        if not np.all(np.isfinite(a)) or _has_bool(v):
            raise SceneError(f"{path}.{key}: must hold finite numbers")
        if integer:
            if not np.all(a == np.round(a)):
                raise SceneError(f"{path}.{key}: must hold integers")
            return a.astype(np.int64)
        return a

    def child(self, node, path, depth, key="child"):
        if key not in node:
            raise SceneError(f"{path}.{key}: required")
        return self.read(node[key], f"{path}.{key}", depth + 1)

    def kids(self, node, path, depth):
        v = node.get("children")
        if not isinstance(v, list) or not v:
            raise SceneError(f"{path}.children: must be a non-empty list of nodes")
        return [self.read(c, f"{path}.children[{i}]", depth + 1) for i, c in enumerate(v)]

    # node readers
    def _sphere(self, n, p, d):
        return Sphere(self.num(n, p, "r"), self.array(n, p, "center", (3,), [0, 0, 0]))

    def _box(self, n, p, d):
        return Box(self.array(n, p, "size", (3,)), center=self.flag(n, p, "center"))

    def _cylinder(self, n, p, d):
        return Cylinder(h=self.num(n, p, "h"), r1=self.num(n, p, "r1"), r2=self.num(n, p, "r2"),
                        center=self.flag(n, p, "center"))

    def _torus(self, n, p, d):
        return Torus(self.num(n, p, "R"), self.num(n, p, "r"))

    def _ellipsoid(self, n, p, d):
        return Ellipsoid(self.array(n, p, "radii", (3,)), self.array(n, p, "center", (3,),
                                                                     [0, 0, 0]))

    def _halfspace(self, n, p, d):
        return HalfSpace(self.array(n, p, "normal", (3,)), self.num(n, p, "offset"))

    def _convex_polyhedron(self, n, p, d):
        if "points" in n:
            return ConvexPolyhedron(points=self.array(n, p, "points", (None, 3)))
        return ConvexPolyhedron(planes=(self.array(n, p, "normals", (None, 3)),
                                        self.array(n, p, "offsets", (None,))))

    def _polyhedron(self, n, p, d):
        return Polyhedron(self.array(n, p, "vertices", (None, 3)),
                          self.array(n, p, "faces", (None, 3), integer=True))

    def _circle(self, n, p, d):
        return Circle(self.num(n, p, "r"))

    def _rectangle(self, n, p, d):
        return Rectangle(self.array(n, p, "size", (2,)), center=self.flag(n, p, "center"))

    def _polygon(self, n, p, d):
        paths = n.get("paths")
        if paths is not None:
            if not isinstance(paths, list) or not all(
                    isinstance(q, list) and all(isinstance(i, int) and not isinstance(i, bool)
                                                for i in q) for q in paths):
                raise SceneError(f"{p}.paths: must be lists of integer indices")
            if sum(len(q) for q in paths) > LIMITS["array"]:
                raise SceneError(f"{p}.paths: more than {LIMITS['array']} indices")
        return Polygon(self.array(n, p, "points", (None, 2)), paths)

    def _union(self, n, p, d):
        return Union(*self.kids(n, p, d))

    def _intersection(self, n, p, d):
        return Intersection(*self.kids(n, p, d))

    def _difference(self, n, p, d):
        return Difference(*self.kids(n, p, d))

    def _complement(self, n, p, d):
        return Complement(self.child(n, p, d))

    def _transform(self, n, p, d):
        return Transformed(self.child(n, p, d), self.array(n, p, "matrix", (4, 4)))

    def _linear_extrude(self, n, p, d):
        return LinearExtrude(self.child(n, p, d), self.num(n, p, "height"),
                             self.num(n, p, "twist", 0.0), self.array(n, p, "scale", (2,),
                                                                        [1.0, 1.0]),
                             self.flag(n, p, "center"))

    def _rotate_extrude(self, n, p, d):
        sectors = n.get("sectors")
        if sectors is not None and (isinstance(sectors, bool) or not isinstance(sectors, int)):
            raise SceneError(f"{p}.sectors: must be an integer")
        return RotateExtrude(self.child(n, p, d), self.num(n, p, "angle", 360.0), sectors)

    def _smooth(self, n, p, d):
        kids = self.kids(n, p, d)
        if len(kids) != 2:
            raise SceneError(f"{p}.children: a smooth boolean takes exactly 2 children")
        kind = n.get("kind")
        if not isinstance(kind, str):
            raise SceneError(f"{p}.kind: must be 'union', 'intersection' or 'difference'")
        return SmoothBoolean(kind, kids[0], kids[1], self.num(n, p, "radius"))

    def _blobby(self, n, p, d):
        return Blobby(self.array(n, p, "centers", (None, 3)),
                      self.array(n, p, "radius", (None,)), self.num(n, p, "threshold"))

    def _expression(self, n, p, d):
        text = n.get("expr")
        if not isinstance(text, str):
            raise SceneError(f"{p}.expr: must be a string")
        if len(text) > LIMITS["expr_chars"]:
            raise SceneError(f"{p}.expr: longer than {LIMITS['expr_chars']} characters")
        bounds = n.get("bounds")
        if bounds is not None:
            bounds = self.array(n, p, "bounds", (2, 3))
        return ExprSolid(parse_expression(text, f"{p}.expr"), bounds)


_FUNCTIONS = {name: getattr(iv, name) for name in (
    "sqrt", "square", "abs", "exp", "log", "sin", "cos", "tan", "atan", "atan2", "asin",
    "acos", "hypot", "min", "max", "floor", "clip", "constant")}
_VARIABLES = {"x": iv.x, "y": iv.y, "z": iv.z}


def parse_expression(text: str, where: str = "expr") -> iv.Expr:
    """An implicitvox expression from its text, by a whitelist (nothing is ``eval``ed)."""
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as err:
        raise SceneError(f"{where}: syntax error at column {err.offset}: {err.msg}") from None
    except (RecursionError, MemoryError):
        raise SceneError(f"{where}: expression nested too deeply") from None
    try:
        return _build(tree.body, where)
    except RecursionError:
        raise SceneError(f"{where}: expression nested too deeply") from None


_BINARY = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
           ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b,
           ast.Pow: lambda a, b: a ** b}


def _refuse(node: ast.AST, where: str, why: str) -> SceneError:
    return SceneError(f"{where}: column {getattr(node, 'col_offset', 0) + 1}: {why}")


def _folded(node: ast.AST, where: str, op, *args) -> Any:
    """``op`` on the arguments; on numbers alone it is folded in floats, and a fold
    that overflows, divides by zero or leaves the reals is refused (Python's own
    integer arithmetic is never used: ``9**9**9`` is one float overflow, not a hang)."""
    numbers = all(isinstance(a, float) for a in args)
    try:
        result = op(*args)
    except ZeroDivisionError:
        raise _refuse(node, where, "division by zero in a constant") from None
    except OverflowError:
        raise _refuse(node, where, "a constant overflows (beyond 1.8e308)") from None
    except (TypeError, ValueError) as err:
        raise _refuse(node, where, f"{err}") from None
    if numbers and isinstance(result, (float, complex)):
        if isinstance(result, complex):
            raise _refuse(node, where, "a constant is not a real number (a negative base "
                                       "to a fractional power)")
        if not math.isfinite(result) and all(math.isfinite(a) for a in args):
            raise _refuse(node, where, "a constant overflows (beyond 1.8e308)")
    return result


def _build(node: ast.AST, where: str) -> Any:
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and \
            not isinstance(node.value, bool):
        try:
            value = float(node.value)
        except OverflowError:
            value = math.inf
        if not math.isfinite(value):
            raise _refuse(node, where, "a number overflows (beyond 1.8e308; write inf for "
                                       "infinity)")
        return value
    if isinstance(node, ast.Name) and node.id in _VARIABLES:
        return _VARIABLES[node.id]
    if isinstance(node, ast.Name) and node.id in ("inf", "pi"):
        return {"inf": math.inf, "pi": math.pi}[node.id]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return _folded(node, where, _BINARY[type(node.op)], _build(node.left, where),
                       _build(node.right, where))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        v = _build(node.operand, where)
        return -v if isinstance(node.op, ast.USub) else v
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
            node.func.id in _FUNCTIONS and not node.keywords:
        args = [_build(a, where) for a in node.args]
        return _folded(node, where, _FUNCTIONS[node.func.id], *args)
    what = type(node).__name__
    name = getattr(node, "id", None) or getattr(getattr(node, "func", None), "id", None)
    raise SceneError(f"{where}: column {getattr(node, 'col_offset', 0) + 1}: {what}"
                     f"{' ' + repr(name) if name else ''} is not allowed in an expression "
                     "(numbers, x, y, z, + - * / **, and the kernel's functions)")


def _count(v: Any, limit: int) -> int:
    """Numbers in a nested list, stopping past ``limit`` (no deep recursion)."""
    total, stack = 0, [v]
    while stack and total <= limit:
        item = stack.pop()
        if isinstance(item, list):
            if len(stack) > limit:
                return limit + 1
            stack.extend(item)
        else:
            total += 1
    return total


def _has_bool(v: Any) -> bool:
    stack = [v]
    while stack:
        item = stack.pop()
        if isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, bool):
            return True
    return False


def _short(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 40 else text[:37] + "..."
