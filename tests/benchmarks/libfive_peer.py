"""libfive (https://libfive.com), the meshing benchmark's peer, driven by its Python
bindings (ctypes over ``libfive.so``).

``sh tests/benchmarks/build_libfive.sh`` builds it outside the repository, into
``$LIBFIVE_HOME`` (default ``~/.cache/implicitvox/libfive``); :func:`load` finds it
there, or returns None. :func:`tree` writes an implicitvox expression as a libfive
tree, operation for operation (``radius``, ``elevation`` and ``hypot`` by their
formulas; libfive computes in float32), and :func:`render` meshes it with
``libfive_tree_render_mesh_st`` (libfive's dual contouring on one thread; its
8-thread default is no faster on 2 cores) over a region at a resolution in
cells per unit, returning numpy arrays (the C mesh is copied out whole, not
triangle by triangle).
"""
from __future__ import annotations

import ctypes
import os
import sys
from pathlib import Path
from typing import Any, Optional

import numpy as np

__all__ = ["load", "tree", "render", "home"]


def home() -> Path:
    """Where :file:`build_libfive.sh` puts libfive."""
    return Path(os.environ.get("LIBFIVE_HOME",
                               Path.home() / ".cache" / "implicitvox" / "libfive"))


def load() -> Optional[Any]:
    """libfive's Python bindings (the ``libfive.shape`` module), or None where libfive is
    not built."""
    where = home()
    if not (where / "lib" / "libfive.so").exists():
        return None
    os.environ["LIBFIVE_FRAMEWORK_DIR"] = str(where / "lib")
    if str(where / "python") not in sys.path:
        sys.path.insert(0, str(where / "python"))
    from libfive import ffi, shape
    ffi.lib.libfive_tree_render_mesh_st.argtypes = [ffi.libfive_tree, ffi.libfive_region_t,
                                                   ctypes.c_float]
    ffi.lib.libfive_tree_render_mesh_st.restype = ctypes.POINTER(ffi.libfive_mesh_t)
    return shape


def tree(lib: Any, expr: Any) -> Any:
    """The libfive ``Shape`` of an implicitvox :class:`~implicitvox.expr.nodes.Expr`."""
    Shape = lib.Shape
    made: dict[int, Any] = {}

    def build(node):
        key = id(node)
        if key in made:
            return made[key]
        a = [build(arg) for arg in node.args]
        op, p = node.op, node.param
        if op == "const":
            out = Shape.wrap(float(p))
        elif op == "var":
            out = {"x": Shape.X, "y": Shape.Y, "z": Shape.Z}[p]()
        elif op in ("add", "sub", "mul", "div"):
            out = {"add": lambda u, v: u + v, "sub": lambda u, v: u - v,
                   "mul": lambda u, v: u * v, "div": lambda u, v: u / v}[op](*a)
        elif op == "neg":
            out = -a[0]
        elif op == "square":
            out = a[0].square()
        elif op in ("sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "abs"):
            out = getattr(a[0], op)()
        elif op in ("min", "max", "atan2"):
            out = getattr(a[0], op)(a[1])
        elif op == "hypot":
            out = (a[0].square() + a[1].square()).sqrt()
        elif op == "radius":
            out = (a[0].square() + a[1].square() + a[2].square()).sqrt()
        elif op == "elevation":
            out = a[2].atan2((a[0].square() + a[1].square()).sqrt())
        elif op == "powi":
            out = a[0]
            for _ in range(int(p) - 1):
                out = out * a[0]
        elif op == "powr":
            out = a[0].pow(float(p))
        else:
            raise ValueError(f"no libfive form for {op!r}")
        made[key] = out
        return out

    stack = [expr]
    order = []
    seen = set()
    while stack:                              # children first, without deep recursion
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        order.append(node)
        stack.extend(node.args)
    for node in reversed(order):
        build(node)
    return made[id(expr)]


def render(lib: Any, shape: Any, bounds: Any, resolution: float
           ) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (n, 3) float64, triangles (m, 3) int64)``: libfive's mesh of ``shape``
    over ``bounds`` at ``resolution`` cells per unit, on one thread."""
    from libfive import ffi
    (x0, y0, z0), (x1, y1, z1) = bounds
    region = ffi.libfive_region_t(ffi.libfive_interval_t(x0, x1),
                                  ffi.libfive_interval_t(y0, y1),
                                  ffi.libfive_interval_t(z0, z1))
    pointer = ffi.lib.libfive_tree_render_mesh_st(shape.ptr, region, float(resolution))
    mesh = pointer[0]
    verts = np.ctypeslib.as_array(ctypes.cast(mesh.verts, ctypes.POINTER(ctypes.c_float)),
                                  shape=(mesh.vert_count * 3,)).reshape(-1, 3).astype(np.float64)
    tris = np.ctypeslib.as_array(ctypes.cast(mesh.tris, ctypes.POINTER(ctypes.c_uint32)),
                                 shape=(mesh.tri_count * 3,)).reshape(-1, 3).astype(np.int64)
    ffi.lib.libfive_mesh_delete(pointer)
    return verts, tris
