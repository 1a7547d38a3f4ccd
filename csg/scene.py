"""JSON scenes: CSG trees as data, for other tools to hand to the voxelizer.

A scene is ``{"implicitvox_scene": 1, "root": NODE}``; a node is an object
with a ``"type"`` and its fields (numbers are JSON numbers, vectors are
arrays; every field shown is required unless marked optional). The type names
the solid class that reads the node (:data:`csg.solid.SCENE_TYPES`: each class
registers its ``scene_type`` and reads its fields in ``from_scene``, so a new
solid needs no line here); the built-in types::

    sphere            r, center (optional, [0, 0, 0])
    box               size [3], center (bool, optional)
    cylinder          h, r1, r2, center (optional)
    torus             R, r
    ellipsoid         radii [3], center (optional)
    capsule           a [3], b [3], r
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

from . import blends, planar, primitives  # noqa: F401 - their solids register their types
from .solid import SCENE_TYPES, Solid

__all__ = ["to_json", "load_json", "to_dict", "from_dict", "SceneReader", "SceneError",
           "LIMITS"]

#: hostile-input limits
LIMITS = {"text_bytes": 200 << 20, "depth": 100, "nodes": 100_000, "array": 5_000_000,
          "expr_chars": 1 << 20}


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
        return SceneReader().read(node, path, 0)
    except RecursionError:      # a deep stack beneath us: refuse rather than crash
        raise SceneError(f"{path}: nested too deeply for the reader") from None


class SceneReader:
    """Reads scene nodes: each through the class its ``"type"`` names
    (:data:`csg.solid.SCENE_TYPES`, :meth:`csg.solid.Solid.from_scene`: only
    registered solid classes, so a ``"type"`` string never reaches anything else),
    under :data:`LIMITS`; the field readers check a field and name it in their error."""

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
        solid = SCENE_TYPES.get(kind) if isinstance(kind, str) else None
        if solid is None:
            raise SceneError(f"{path}.type: unknown node type {_short(kind)}")
        try:
            return solid.from_scene(self, node, path, depth)
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

    def integer(self, node, path, key, default=None):
        v = node.get(key, default)
        if v is None or (isinstance(v, int) and not isinstance(v, bool)):
            return v
        raise SceneError(f"{path}.{key}: must be an integer")

    def choice(self, node, path, key, options):
        v = node.get(key)
        if not isinstance(v, str) or v not in options:
            raise SceneError(f"{path}.{key}: must be "
                             + ", ".join(repr(o) for o in options[:-1])
                             + f" or {options[-1]!r}")
        return v

    def index_lists(self, node, path, key):
        v = node.get(key)
        if v is None:
            return None
        if not isinstance(v, list) or not all(
                isinstance(q, list) and all(isinstance(i, int) and not isinstance(i, bool)
                                            for i in q) for q in v):
            raise SceneError(f"{path}.{key}: must be lists of integer indices")
        if sum(len(q) for q in v) > LIMITS["array"]:
            raise SceneError(f"{path}.{key}: more than {LIMITS['array']} indices")
        return v

    def expression(self, node, path, key):
        text = node.get(key)
        if not isinstance(text, str):
            raise SceneError(f"{path}.{key}: must be a string")
        if len(text) > LIMITS["expr_chars"]:
            raise SceneError(f"{path}.{key}: longer than {LIMITS['expr_chars']} characters")
        return parse_expression(text, f"{path}.{key}")


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
