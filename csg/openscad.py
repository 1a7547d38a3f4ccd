"""``read_openscad``: OpenSCAD's ``.csg`` files as :class:`~csg.solid.Solid` trees.

Supported modules: ``group, union, difference, intersection, multmatrix,
cube, sphere, cylinder, polyhedron, circle, square, polygon, linear_extrude,
rotate_extrude, color, render, import`` (triangle meshes: STL, PLY, OBJ, VTK;
DXF drawings as OpenSCAD reads them),
``hull``, ``minkowski`` and ``resize`` (exact on polytopes,
:mod:`csg.polytopes`: the operands must be booleans of boxes, polyhedra,
polygons, faceted primitives and straight extrusions; a 2D Minkowski sum
with a piece that is not convex is OpenSCAD's own, by Clipper,
:func:`csg.clipper2d.minkowski`; with
``facets="true"`` their curved children are taken as OpenSCAD's facets, with
a warning, since the hull of curved solids is no polytope and OpenSCAD itself
builds it on its facets; ``resize`` scales by the bounding box of those
facets, as OpenSCAD does), ``surface`` (heightmaps, ``.dat`` or PNG, as
OpenSCAD's mesh: :mod:`csg.heightmap`), ``offset`` (``r``, ``delta``,
``chamfer``: with Clipper, as OpenSCAD computes it, :mod:`csg.clipper2d`),
``projection`` (the section by z = 0 through any boolean, or the shadow of
meshes and polytopes: :mod:`csg.projection`), ``text`` (the glyph outlines
OpenSCAD 2021.01 draws, with fontconfig, HarfBuzz and FreeType:
:mod:`csg.text`), with ``$fn, $fa, $fs``, and OpenSCAD's
modifiers as its ``.csg`` export writes them: ``%`` (background) and ``*``
(disabled) drop their subtree, ``#`` (highlight) keeps it, ``!`` (root) makes
its subtree the whole design. Any other module
(``roof``, ...) is
refused with its name, line and column. Nothing is evaluated.

Degenerate input is skipped, as OpenSCAD skips it, with an
:class:`~csg.openscad_parser.OpenSCADWarning` naming line and column: a cube
with a size of 0, a sphere or cylinder of radius or height 0 (or below), a
singular ``multmatrix`` (a scale of 0), ``rotate_extrude(angle = 0)``, a 3D
child of an extrusion, an invalid polyhedron. The rest of the file is read.
A file whose design is 2D (OpenSCAD would export DXF or SVG) is refused at
read time, saying so.

``facets="openscad"`` (default) reproduces OpenSCAD's own polygonization
(:mod:`csg.facets`): spheres and cylinders become the convex polyhedra
OpenSCAD builds, circles its polygons, ``rotate_extrude`` its sectors, and a
twisted or unevenly scaled ``linear_extrude`` its sliced mesh, so a ``$fn = 6``
cylinder is the hexagonal prism OpenSCAD renders and exports.
``facets="true"`` voxelizes the true curved primitives the file's ``$fn, $fa,
$fs`` only approximate.

Examples
--------
>>> s = read_openscad('difference() { cube(size = [2, 2, 2], center = true); '
...                   'sphere($fn = 0, $fa = 12, $fs = 2, r = 1.2); }')
>>> s.bounds
((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0))
>>> read_openscad('roof() square(size = [2, 2]);')  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
csg.openscad_parser.OpenSCADError: <csg>:1:1: module 'roof' is not supported (supported: ...)
"""
from __future__ import annotations

import functools
import math
import os
import warnings
from typing import Any, Optional

import numpy as np

from . import facets as fx
from .facet_modes import FACET_MODES, FacetMode
from .clipper2d import NotFlat, offset as clipped_offset, region_pieces
from .dxf import read_dxf
from .prism import Prism, bound_functions
from .projection import NotAMesh, projection as project
from .text import text_polygon
from .tessellation import openscad_vertex_ids, quad_diagonals
from .heightmap import heightmap_mesh
from .openscad_parser import Node, OpenSCADError, OpenSCADWarning, parse
from .scad import CSG_BYTES, export_csg
from .planar import LinearExtrude, Polygon, Rectangle, RotateExtrude
from implicitvox.triangles.closed import is_closed_mesh
from implicitvox.triangles.inputs import MESH_SUFFIXES

from .polytopes import NotAPolytope, hull, minkowski, vertices
from .primitives import Box, Polyhedron
from .solid import Difference, Intersection, Solid, Transformed, Union

__all__ = ["read_openscad", "SUPPORTED", "UNSUPPORTED", "MAX_SLICES", "IMPORT_SUFFIXES"]

#: slices of a twisted or scaled extrusion at most (OpenSCAD's own default is 1 per
#: few degrees of twist: real models stay in the hundreds)
MAX_SLICES = 10_000

SUPPORTED = ("group", "union", "difference", "intersection", "multmatrix", "cube", "sphere",
             "cylinder", "polyhedron", "circle", "square", "polygon", "linear_extrude",
             "rotate_extrude", "color", "render", "import", "hull", "minkowski", "resize",
             "surface", "offset", "projection", "text")
#: OpenSCAD modules we know but do not voxelize
UNSUPPORTED = ("roof", "mirror", "rotate", "translate", "scale")
#: the files ``import`` reads: triangle meshes (:func:`implicitvox.triangles.inputs.as_triangles`)
#: and DXF drawings (:func:`csg.dxf.read_dxf`)
IMPORT_SUFFIXES = (*MESH_SUFFIXES, ".dxf")


def read_openscad(path_or_text: Any, facets: str = "openscad", base: Any = None) -> Solid:
    """Read a ``.csg`` file (path) or its text into a solid; or a ``.scad`` file,
    through the installed OpenSCAD.

    Parameters
    ----------
    path_or_text : str or os.PathLike
        A path to a ``.csg`` file, or ``.csg`` text (anything containing ``(``).
        A path ending in ``.scad`` is first evaluated by OpenSCAD
        (:func:`csg.scad.export_csg`: a temporary ``.csg``, OpenSCAD's warnings
        passed on as :class:`OpenSCADWarning` s with their file and line, its
        errors raised as :class:`OpenSCADError`, a time limit); the reader's
        own messages on the export name it ``<path> (as .csg)``, with the line
        and column of what ``openscad -o part.csg part.scad`` writes.
    facets : {"openscad", "true"}
        OpenSCAD's own facets (the solid OpenSCAD renders and exports), or the
        true curves they approximate.
    base : str or os.PathLike, optional
        The folder ``import(file = ...)`` paths are relative to: by default the
        ``.csg`` file's own (OpenSCAD writes them relative to the ``.scad``
        file's folder; pass that when the ``.csg`` was written elsewhere), or
        the working directory for text.

    Raises
    ------
    OpenSCADError
        Malformed or unsupported input (a ``ValueError`` with line and column).
    csg.scad.OpenSCADNotFound
        A ``.scad`` file, and no OpenSCAD to evaluate it.
    TimeoutError
        OpenSCAD took longer than :data:`csg.scad.OPENSCAD_SECONDS` on a ``.scad`` file.
    """
    if facets not in ("true", "openscad"):
        raise ValueError(f"facets must be 'true' or 'openscad', got {facets!r}")
    if isinstance(path_or_text, os.PathLike) or (isinstance(path_or_text, str)
                                                  and "(" not in path_or_text):
        path = os.fspath(path_or_text)
        if not os.path.isfile(path):
            raise FileNotFoundError(f"no such file: {path}")
        if path.lower().endswith(".scad"):
            text, source = export_csg(path), f"{path} (as .csg)"
            base = os.path.dirname(os.path.abspath(path)) if base is None else base
        elif os.path.getsize(path) > CSG_BYTES:
            raise OpenSCADError(f"the file is larger than {CSG_BYTES} bytes (csg.scad.CSG_BYTES)",
                                1, None, path)
        else:
            with open(path, encoding="utf-8", errors="replace") as fh:
                text, source = fh.read(), path
    elif isinstance(path_or_text, str):
        text, source = path_or_text, "<csg>"
    else:
        raise TypeError(f"expected a path or .csg text, got {type(path_or_text).__name__}")
    nodes = parse(text, source)
    root = _root_node(nodes)
    if root is not None:                 # "!": this subtree alone is the design
        nodes = [root]
        root.modifiers = root.modifiers.replace("!", "")
    if base is None:
        base = os.path.dirname(os.path.abspath(source)) if source != "<csg>" else os.getcwd()
    builder = _Builder(source, FACET_MODES[facets], os.fspath(base))
    builder.build_from_leaves(nodes)
    built = builder.closed_operands([(n, s) for n, s in ((n, builder.build(n)) for n in nodes)
                                     if s is not None])
    if not built:
        raise OpenSCADError("the file holds no geometry", 1, 1, source)
    solids = [s for _, s in built]
    solid = solids[0] if len(solids) == 1 else Union(*solids)
    if solid.dim == 2:
        first = built[0][0]
        raise OpenSCADError("the design is 2D (OpenSCAD exports it as DXF or SVG, not as a "
                            "solid): implicitvox voxelizes 3D solids; extrude it "
                            "(linear_extrude, rotate_extrude) first", first.line, first.column,
                            source)
    bound_functions(solid)      # many prisms: their exact tests, not their functions
    return solid


def _quad_triangles(v: np.ndarray, quads: np.ndarray, corner_ids: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """A polyhedron's quad faces ``a, b, c, d`` (clockwise seen from outside) as the two
    triangles OpenSCAD 2021.01 cuts them into (:func:`csg.tessellation.quad_diagonals`,
    with OpenSCAD's vertex numbers ``corner_ids``), and the alternative faces of the
    quads whose diagonal is not known there (a degenerate projection): their other
    diagonal's triangles and the first
    pair reversed, which cancel in the winding number, so that either diagonal's
    voxels are kept (:attr:`csg.primitives.Polyhedron.alternative_faces`)."""
    if not len(quads):
        return np.zeros((0, 3), dtype=np.int64), np.zeros((0, 3), dtype=np.int64)
    a, b, c, d = quads.T
    along_ac = np.stack([np.stack([a, c, b], 1), np.stack([a, d, c], 1)], 1)
    along_bd = np.stack([np.stack([b, d, c], 1), np.stack([b, a, d], 1)], 1)
    diagonal = quad_diagonals(v[quads], corner_ids)
    chosen = np.where((diagonal == 1)[:, None, None], along_bd, along_ac)
    unknown = diagonal == -1
    alternatives = np.concatenate([along_bd[unknown], along_ac[unknown][:, :, ::-1]], axis=1)
    return chosen.reshape(-1, 3), alternatives.reshape(-1, 3)


def _holds_text(node: Node) -> bool:
    """Whether a ``text`` node is below ``node``."""
    stack = list(node.children)
    while stack:
        child = stack.pop()
        if child.name == "text":
            return True
        stack.extend(child.children)
    return False


def _root_node(nodes: list[Node]) -> Optional[Node]:
    """The first node marked with OpenSCAD's root modifier ``!``, depth first, or None."""
    stack = list(reversed(nodes))
    while stack:
        node = stack.pop()
        if "!" in node.modifiers:
            return node
        stack.extend(reversed(node.children))
    return None


class _Builder:
    """Builds the solids of a file's nodes, each once, in a facet mode
    (:mod:`csg.facet_modes`: everything that differs between the modes)."""

    def __init__(self, source: str, facets: FacetMode, base: str = "."):
        self.source, self.facets, self.base = source, facets, base
        self._built: dict[int, tuple[Node, Optional[Solid]]] = {}
        #: the solids that are meshes OpenSCAD could not make a CGAL Nef polyhedron of
        #: (not closed), and their transforms: dropped from booleans (closed_operands)
        self._open: set[int] = set()

    @functools.cached_property
    def faceted_twin(self) -> "_Builder":
        """The builder of the same file with OpenSCAD's facets (one, reused: each node
        it builds is built once), for the operations only defined on them."""
        openscad = FACET_MODES["openscad"]
        return self if self.facets is openscad else _Builder(self.source, openscad, self.base)

    def error(self, node: Node, message: str) -> OpenSCADError:
        return OpenSCADError(message, node.line, node.column, self.source)

    def skip(self, node: Node, message: str) -> None:
        """Degenerate input OpenSCAD skips (with a warning): skipped here too, named."""
        warnings.warn(f"{self.source}:{node.line}:{node.column}: {node.name}: {message}; "
                      "skipped, as OpenSCAD does", OpenSCADWarning, stacklevel=4)
        return None

    # -- arguments -------------------------------------------------------------------
    def arg(self, node: Node, name: str, default: Any = None, index: Optional[int] = None):
        if name in node.args:
            return node.args[name]
        if index is not None and index < len(node.positional):
            return node.positional[index]
        return default

    def number(self, node: Node, name: str, default: Any = None, index: Optional[int] = None,
               positive: bool = False) -> float:
        v = self.arg(node, name, default, index)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise self.error(node, f"{node.name}: {name} must be a finite number, got {v!r}")
        if positive and not v > 0:
            raise self.error(node, f"{node.name}: {name} must be positive, got {v!r}")
        return float(v)

    def vector(self, node: Node, name: str, n: int, default: Any = None,
               index: Optional[int] = None) -> np.ndarray:
        v = self.arg(node, name, default, index)
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            v = [v] * n
        if not isinstance(v, list) or len(v) != n or not all(
                isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c)
                for c in v):
            raise self.error(node, f"{node.name}: {name} must be {n} finite numbers, got {v!r}")
        return np.array(v, dtype=np.float64)

    def flag(self, node: Node, name: str, default: bool = False) -> bool:
        v = self.arg(node, name, default)
        if v is None:
            return default
        if not isinstance(v, bool):
            raise self.error(node, f"{node.name}: {name} must be true or false, got {v!r}")
        return v

    def resolution(self, node: Node) -> tuple[float, float, float]:
        fn = self.number(node, "$fn", 0.0)
        fa = self.number(node, "$fa", 12.0)
        fs = self.number(node, "$fs", 2.0)
        if fa <= 0 or fs <= 0:
            raise self.error(node, f"{node.name}: $fa and $fs must be positive")
        return fn, fs, fa

    # -- nodes -----------------------------------------------------------------------------
    def build_from_leaves(self, nodes: list[Node]) -> None:
        """Build every node below ``nodes``, children before parents, without
        recursion: a parent's :meth:`build` then finds its children built, so a
        file nested :data:`~csg.openscad_parser.MAX_DEPTH` deep costs no deeper a
        Python stack than a flat one. Background and disabled subtrees are not
        entered (they are no geometry, and are not read further)."""
        stack = [(n, False) for n in reversed(nodes)]
        while stack:
            node, expanded = stack.pop()
            if id(node) in self._built or "%" in node.modifiers or "*" in node.modifiers:
                continue
            if expanded:
                self.build(node)
            else:
                stack.append((node, True))
                stack.extend((c, False) for c in reversed(node.children))

    def build(self, node: Node) -> Optional[Solid]:
        """The solid of ``node`` (None: no geometry), built once."""
        if id(node) not in self._built:
            self._built[id(node)] = (node, self._build(node))   # (the node kept: ids stay unique)
        return self._built[id(node)][1]

    def _build(self, node: Node) -> Optional[Solid]:
        if "%" in node.modifiers or "*" in node.modifiers:
            return None                  # background and disabled subtrees are no geometry
        handler = getattr(self, "_" + node.name, None)
        if node.name not in SUPPORTED or handler is None:
            known = "not supported" if node.name in UNSUPPORTED else "unknown"
            raise self.error(node, f"module {node.name!r} is {known} (supported: "
                                   f"{', '.join(SUPPORTED)})")
        try:
            return handler(node)
        except OpenSCADError:
            raise
        except (ValueError, TypeError, ArithmeticError) as err:   # refused parameters
            raise self.error(node, f"{node.name}: {err}") from None

    def children(self, node: Node) -> list[Solid]:
        return [s for s in (self.build(c) for c in node.children) if s is not None]

    def _group(self, node: Node) -> Optional[Solid]:
        built = [(c, s) for c, s in ((c, self.build(c)) for c in node.children)
                 if s is not None]
        kids = [s for _, s in self.closed_operands(built)]
        if not kids:
            return None
        return kids[0] if len(kids) == 1 else Union(*kids)

    def closed_operands(self, built: list) -> list:
        """The operands ``(child node, solid)`` of a boolean of two or more that OpenSCAD
        keeps: it makes each a CGAL Nef polyhedron, which a mesh that is not closed
        cannot be ("The given mesh is not closed!"), and drops that one with an error;
        so does this, with a warning. A lone mesh is no boolean: it stays (OpenSCAD
        exports it as it is)."""
        if len(built) < 2:
            return built
        kept = []
        for child, solid in built:
            if id(solid) in self._open:
                self.skip(child, "its mesh is not closed, so OpenSCAD cannot take it into "
                                 "a boolean (\"The given mesh is not closed!\")")
            else:
                kept.append((child, solid))
        return kept

    def _open_if(self, solid: Optional[Solid], body: Solid) -> Optional[Solid]:
        """``solid`` (a transform of ``body``), remembered as open where ``body`` is."""
        if solid is not None and id(body) in self._open:
            self._open.add(id(solid))
        return solid

    def _mesh(self, solid: Polyhedron) -> Polyhedron:
        """A polyhedron or imported mesh, remembered as open where it is not closed."""
        if not is_closed_mesh(solid.vertices, solid.faces):
            self._open.add(id(solid))
        return solid

    _union = _render = _color = _group

    def group(self, node: Node) -> Optional[Solid]:
        """The union of ``node``'s children's solids (None: no geometry)."""
        return self._group(node)

    def _one_dimension(self, node: Node, built: list) -> list:
        """The operands of a boolean ``(child node, solid)`` of the first one's dimension:
        OpenSCAD ignores the others, with a warning ("mixing 2D and 3D objects is not
        supported"), and so does this: a circle is no drill through a cube."""
        if not built:
            return built
        dim = built[0][1].dim
        for child, solid in built[1:]:
            if solid.dim != dim:
                self.skip(child, f"a {solid.dim}D child of a {dim}D {node.name} (OpenSCAD "
                                 "does not mix 2D and 3D objects)")
        return [(child, solid) for child, solid in built if solid.dim == dim]

    def _difference(self, node: Node) -> Optional[Solid]:
        if not node.children:
            return None
        first = self.build(node.children[0])
        if first is None:
            return None
        built = [(c, s) for c, s in ((c, self.build(c)) for c in node.children[1:])
                 if s is not None]
        operands = self.closed_operands(self._one_dimension(node, [(node.children[0], first)]
                                                            + built))
        if not operands or operands[0][1] is not first:
            return None                       # the first operand dropped: nothing is left
        rest = [s for _, s in operands[1:]]
        return Difference(first, *rest) if rest else first

    def _intersection(self, node: Node) -> Optional[Solid]:
        built = [(c, self.build(c)) for c in node.children]
        if not built or any(s is None for _, s in built):
            return None                       # an empty operand empties the intersection
        operands = self._one_dimension(node, built)
        kids = [s for _, s in self.closed_operands(operands)]
        if len(kids) < len(operands):
            return None                       # a dropped operand empties it, as in OpenSCAD
        return kids[0] if len(kids) == 1 else Intersection(*kids)

    def _multmatrix(self, node: Node) -> Optional[Solid]:
        m = self.arg(node, "m", None, 0)
        try:
            mat = np.array(m, dtype=np.float64)
        except (TypeError, ValueError):
            mat = None
        if mat is None or mat.shape not in ((4, 4), (3, 4), (3, 3)):
            raise self.error(node, f"multmatrix: expected a 4 x 4 matrix, got {m!r:.80}")
        if not np.all(np.isfinite(mat)):
            return self.skip(node, "the transform holds NaN or infinity: its children are "
                                   "removed")
        if mat.shape == (3, 4):
            mat = np.vstack([mat, [0, 0, 0, 1]])
        body = self._group(node)
        if body is None:
            return None
        if mat.shape == (4, 4) and body.dim == 2:
            mat = mat.copy()
            mat[2], mat[:2, 2] = [0, 0, 1, 0], 0        # 2D: only the in-plane part acts
        linear = mat[:3, :3] if mat.shape[0] == 4 else mat
        if body.dim == 2:
            linear = linear[:2, :2]
        if abs(float(np.linalg.det(linear))) <= 1e-12 * max(1.0, float(np.abs(linear).max())) \
                ** len(linear):
            return self.skip(node, "the transform is singular (a scale of 0): its children "
                                   "collapse to a plane, line or point")
        return self._open_if(Transformed(body, mat), body)

    def _cube(self, node: Node) -> Optional[Solid]:
        size = self.vector(node, "size", 3, 1.0, 0)
        if not np.all(size > 0):
            return self.skip(node, f"size {size.tolist()} is not positive on every axis")
        return Box(size, center=self.flag(node, "center"))

    def _sphere(self, node: Node) -> Optional[Solid]:
        r = self._radius(node, "r", "d", 1.0, empty_ok=True)
        if not r > 0:
            return self.skip(node, f"radius {r} is not positive")
        return self.facets.sphere(r, lambda: fx.fragments(r, *self.resolution(node)))

    def _radius(self, node: Node, rname: str, dname: str, default: float,
                empty_ok: bool = False) -> float:
        """The radius from ``r`` or ``d``; with ``empty_ok`` 0 or below passes (the
        caller skips the primitive)."""
        if dname in node.args and node.args[dname] is not None:
            return self.number(node, dname, positive=not empty_ok) / 2
        return self.number(node, rname, default, positive=not empty_ok)

    def _cylinder(self, node: Node) -> Optional[Solid]:
        h = self.number(node, "h", 1.0)
        r = self.arg(node, "r", None)
        r1 = self.number(node, "r1", r if r is not None else 1.0)
        r2 = self.number(node, "r2", r if r is not None else 1.0)
        if not h > 0:
            return self.skip(node, f"height {h} is not positive")
        if r1 < 0 or r2 < 0:
            return self.skip(node, f"a radius is negative (r1={r1}, r2={r2})")
        if r1 == 0 and r2 == 0:
            return self.skip(node, "both radii are 0")
        center = self.flag(node, "center")
        return self.facets.cylinder(h, r1, r2, center,
                                    lambda: fx.fragments(max(r1, r2), *self.resolution(node)))

    def _polyhedron(self, node: Node) -> Optional[Solid]:
        pts = self.arg(node, "points", None, 0)
        faces = self.arg(node, "faces", None, 1)
        if faces is None:
            faces = self.arg(node, "triangles", None)
        if pts is None:
            return self.skip(node, "its points are undef")
        try:
            v = np.array(pts, dtype=np.float64)
        except (TypeError, ValueError):
            raise self.error(node, "polyhedron: points must be a list of [x, y, z]") from None
        if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)):
            raise self.error(node, "polyhedron: points must be a list of finite [x, y, z]")
        if not isinstance(faces, list) or not faces:
            return self.skip(node, "it has no faces")
        tris, quads, degenerate = [], [], 0
        for k, face in enumerate(faces):
            if not isinstance(face, list) or not all(isinstance(i, float) and math.isfinite(i)
                                                     for i in face):
                raise self.error(node, f"polyhedron: faces[{k}] must be a list of finite "
                                       "indices")
            if len(face) < 3 or not all(0 <= i < len(v) and i == int(i) for i in face):
                return self.skip(node, f"faces[{k}] {face!r:.60} does not list 3 or more "
                                       f"indices into points (0..{len(v) - 1}): the "
                                       "polyhedron is invalid")
            # a corner repeated next to itself is one corner, as OpenSCAD cleans faces
            idx = [int(i) for n, i in enumerate(face) if i != face[n - 1]] \
                if len(set(face)) > 1 else []
            if len(idx) < 3:
                degenerate += 1
                continue
            if len(idx) == 4:
                quads.append(idx)
            else:     # clockwise seen from outside, as OpenSCAD lists them: fanned reversed
                tris += [(idx[0], idx[j + 1], idx[j]) for j in range(1, len(idx) - 1)]
        if degenerate == len(faces):
            return self.skip(node, "every face repeats a corner next to itself (fewer than "
                                   "3 corners): no surface")
        quads = np.array(quads, dtype=np.int64).reshape(-1, 4)
        numbers = openscad_vertex_ids(v, [[int(i) for i in face] for face in faces])
        quad_tris, alternatives = _quad_triangles(v, quads, numbers[quads])
        return self._mesh(Polyhedron(v, np.concatenate([np.array(tris, dtype=np.int64)
                                                        .reshape(-1, 3), quad_tris]),
                                     alternatives))

    def _import(self, node: Node) -> Optional[Solid]:
        """A triangle mesh file, as OpenSCAD imports it: the same solid in both facet
        modes (a closed mesh, classified exactly); or a DXF drawing's region, as
        OpenSCAD 2021.01 makes it (:func:`csg.dxf.read_dxf`: ``layer``, ``origin``,
        ``scale``, arcs in OpenSCAD's fragments in both modes). A missing file is
        skipped with a warning, as OpenSCAD skips it."""
        name = self.arg(node, "file", None, 0)
        if not isinstance(name, str) or not name:
            raise self.error(node, f"import: file must be a file name, got {name!r:.60}")
        path = name if os.path.isabs(name) else os.path.join(self.base, name)
        suffix = os.path.splitext(name)[1].lower()
        if suffix not in IMPORT_SUFFIXES:
            raise self.error(node, f"import: {suffix or 'this'} files are not read (meshes: "
                                   f"{', '.join(MESH_SUFFIXES)}; drawings: .dxf)")
        if not os.path.isfile(path):
            return self.skip(node, f"cannot open {path!r}")
        if suffix != ".dxf":
            return self._mesh(Polyhedron(path))
        layer = self.arg(node, "layer", None)
        if layer is not None and not isinstance(layer, str):
            raise self.error(node, f"import: layer must be a string, got {layer!r:.60}")
        fn, fs, fa = self.resolution(node)
        region = read_dxf(path, layer=layer, origin=self.vector(node, "origin", 2, 0.0),
                          scale=self.number(node, "scale", 1.0), fn=fn, fs=fs, fa=fa)
        if region is None:
            return self.skip(node, f"{path!r}{f' layer {layer!r}' if layer else ''} holds no "
                                   "closed outline")
        return region

    def _surface(self, node: Node) -> Optional[Solid]:
        """A heightmap (``.dat`` or PNG) as the closed mesh OpenSCAD 2021.01 builds
        (:func:`csg.heightmap.heightmap_mesh`), the same in both facet modes; a
        missing file is skipped with a warning, as OpenSCAD skips it."""
        name = self.arg(node, "file", None, 0)
        if not isinstance(name, str) or not name:
            raise self.error(node, f"surface: file must be a file name, got {name!r:.60}")
        path = name if os.path.isabs(name) else os.path.join(self.base, name)
        if not os.path.isfile(path):
            return self.skip(node, f"cannot open {path!r}")
        return Polyhedron(*heightmap_mesh(path, center=self.flag(node, "center"),
                                          invert=self.flag(node, "invert")))

    def _circle(self, node: Node) -> Optional[Solid]:
        r = self._radius(node, "r", "d", 1.0, empty_ok=True)
        if not r > 0:
            return self.skip(node, f"radius {r:g} is not positive")
        return self.facets.circle(r, lambda: fx.fragments(r, *self.resolution(node)))

    def _square(self, node: Node) -> Solid:
        return Rectangle(self.vector(node, "size", 2, 1.0, 0), center=self.flag(node, "center"))

    def _polygon(self, node: Node) -> Solid:
        pts = self.arg(node, "points", None, 0)
        paths = self.arg(node, "paths", None, 1)
        try:
            p = np.array(pts, dtype=np.float64)
        except (TypeError, ValueError):
            raise self.error(node, "polygon: points must be a list of [x, y]") from None
        if p.ndim != 2 or p.shape[1] != 2:
            raise self.error(node, "polygon: points must be a list of [x, y]")
        if paths is not None and not (isinstance(paths, list) and all(
                isinstance(q, list) and all(isinstance(i, float) and i == int(i) for i in q)
                for q in paths)):
            raise self.error(node, "polygon: paths must be lists of point indices")
        return Polygon(p, None if paths is None else [[int(i) for i in q] for q in paths])

    def _text(self, node: Node) -> Optional[Solid]:
        """OpenSCAD's ``text``: the polygon of its glyph outlines as OpenSCAD 2021.01
        draws them (:func:`csg.text.text_polygon`), the same in both facet modes
        (OpenSCAD's curves are part of the model: its outlines are sampled by its
        own rule); a text that draws nothing (spaces) is skipped with a warning."""
        words = self.arg(node, "text", None, 0)
        if not isinstance(words, str):
            raise self.error(node, f"text: text must be a string, got {words!r:.40}")
        options = {}
        for name in ("font", "halign", "valign", "direction", "language", "script"):
            value = self.arg(node, name, None)
            if value is not None and not isinstance(value, str):
                raise self.error(node, f"text: {name} must be a string, got {value!r:.40}")
            if value is not None:
                options[name] = value
        fn, fs, fa = self.resolution(node)
        polygon = text_polygon(words, self.number(node, "size", 10.0, 1, positive=True),
                               spacing=self.number(node, "spacing", 1.0), fn=fn, fs=fs,
                               fa=fa, **options)
        if polygon is None:
            return self.skip(node, f"{words!r:.40} draws no glyph outline")
        return polygon

    def _section(self, node: Node) -> Optional[Solid]:
        """The 2D children of an extrusion, united (None when there are none); 3D
        children are skipped with a warning, as OpenSCAD does."""
        kids = []
        for child in node.children:
            built = self.build(child)
            if built is not None and built.dim != 2:
                self.skip(child, f"a 3D child of {node.name} (only 2D children are extruded)")
            elif built is not None:
                kids.append(built)
        if not kids:
            return None
        return kids[0] if len(kids) == 1 else Union(*kids)

    def _linear_extrude(self, node: Node) -> Optional[Solid]:
        body = self._section(node)
        if body is None:
            return None
        h = self.number(node, "height", 100.0, 0)
        if not h > 0:
            return self.skip(node, f"height {h:g} is not positive")
        twist = self.number(node, "twist", 0.0)
        scale = self.vector(node, "scale", 2, 1.0)
        center = self.flag(node, "center")
        straight = twist == 0 and scale[0] == scale[1]
        # OpenSCAD extrudes the result of its 2D booleans (Clipper): so does this. A
        # straight one is a Prism (an exact box test: a polygon's function encloses
        # loosely near concave corners, a glyph's most of all); true circles
        # (facets="true") keep their function
        try:
            pieces = region_pieces(body)
        except NotFlat as err:
            return self.facets.unflat(self, node, err,
                                      lambda: LinearExtrude(body, h, twist, scale, center))
        if not pieces:
            return self.skip(node, "its 2D children leave no area")
        if twist == 0 and scale[0] == scale[1] == 1:
            return Prism(pieces, h, center)
        if self.facets.extrusion(straight, _holds_text(node)):
            return LinearExtrude(body, h, twist, scale, center)
        if straight:
            slices = 1.0
        elif node.args.get("slices") is not None:
            slices = self.number(node, "slices", 1.0)
        else:                                  # OpenSCAD computes them (calc.cc)
            fn, fs, fa = self.resolution(node)
            points = np.concatenate([r for outer, holes in pieces for r in (outer, *holes)])
            slices = fx.extrusion_slices(points, h, twist, scale, fn, fs, fa,
                                         twisted="twist" in node.args)
        if not slices <= MAX_SLICES:
            raise self.error(node, f"linear_extrude: slices = {slices:.4g}, over the limit of "
                                   f"{MAX_SLICES} (csg.openscad.MAX_SLICES)")
        slices = max(int(slices), 1)
        v, f = fx.extrusion_mesh_outlines(pieces, h, twist, scale, slices,
                                          -h / 2 if center else 0.0)
        return Polyhedron(v, f)

    def _rotate_extrude(self, node: Node) -> Optional[Solid]:
        body = self._section(node)
        if body is None:
            return None
        angle = self.number(node, "angle", 360.0)
        if angle == 0:
            return self.skip(node, "angle 0 sweeps no volume")
        return self.facets.sweep(self, node, body, angle)

    def faceted_sweep(self, node: Node, body: Solid, angle: float) -> Optional[Solid]:
        """``rotate_extrude`` as OpenSCAD 2021.01 sweeps it: its sectors, as a mesh."""
        b = body.bounds
        max_x = max(abs(b[0][0]), abs(b[1][0])) if b is not None else 1.0
        n = max(int(fx.fragments(max_x, *self.resolution(node)) * abs(angle) / 360), 1)
        swept = RotateExtrude(body, angle, sectors=n)
        # OpenSCAD sweeps the result of its 2D booleans (Clipper) into a mesh: so does
        # this, for an exact box test (the sweep's function has many sectors' terms)
        try:
            pieces = region_pieces(body)
        except NotFlat:
            return swept
        if not pieces:
            return self.skip(node, "its 2D children leave no area")
        return Polyhedron(*fx.rotation_mesh_outlines(pieces, angle, n))

    # -- hull, minkowski, resize: exact on polytopes (csg.polytopes) ----------------------
    def _polytope_children(self, node: Node, what: str) -> list[Solid]:
        """The children as polytope trees of one dimension (children of the other
        dimension skipped with a warning, as OpenSCAD ignores them). In
        ``facets="true"``, curved children are taken as OpenSCAD's facets (with a
        warning): the hull or sum of curved solids is no polytope, and this is the
        solid OpenSCAD itself makes."""
        pairs, failure = self._polytope_operands(node, what)
        if failure is not None:
            pairs = self.facets.facet(self, node, what, failure,
                                      lambda faceted: faceted._polytope_operands(node, what)[0])
        if pairs and any(kid.dim != pairs[0][1].dim for _, kid in pairs):
            dim = pairs[0][1].dim
            for child, kid in pairs:
                if kid.dim != dim:
                    self.skip(child, f"a {kid.dim}D child of a {dim}D {what}")
            pairs = [(child, kid) for child, kid in pairs if kid.dim == dim]
        return [kid for _, kid in pairs]

    def _polytope_operands(self, node: Node, what: str
                           ) -> tuple[list[tuple[Node, Solid]], Optional[NotAPolytope]]:
        """The children ``(node, solid)`` with geometry, an empty boolean among them
        skipped with a warning (OpenSCAD's is no geometry), and the first reason one of
        the others has no vertex set (None: they all have one)."""
        pairs, failure = [], None
        for child in node.children:
            kid = self.build(child)
            if kid is None:
                continue
            try:
                vertices(kid)
            except NotAPolytope as err:
                if err.empty:
                    self.skip(child, f"{err} (its {what} takes the others)")
                    continue
                failure = failure or err
            pairs.append((child, kid))
        return pairs, failure

    def _hull(self, node: Node) -> Optional[Solid]:
        kids = self._polytope_children(node, "hull")
        return hull(*kids) if kids else None

    def _minkowski(self, node: Node) -> Optional[Solid]:
        kids = self._polytope_children(node, "minkowski")
        if len(kids) == 1:
            return kids[0]
        return minkowski(*kids) if kids else None

    def _offset(self, node: Node) -> Optional[Solid]:
        """OpenSCAD's 2D ``offset`` (``r``: round joins in OpenSCAD's fragments of a
        circle of radius ``|r|``; ``delta``: sharp corners, or cut with ``chamfer``),
        computed with Clipper as OpenSCAD computes it (:func:`csg.clipper2d.offset`).
        With ``facets="true"`` a true circle below it is taken as OpenSCAD's
        polygon, with a warning (an offset outline is OpenSCAD's Clipper result)."""
        body = self._group(node)
        if body is None:
            return None
        if body.dim != 2:
            return self.skip(node, "a 3D child (offset works on 2D shapes)")
        if self.arg(node, "r", None) is not None:
            value, join = self.number(node, "r"), "round"
        else:
            value = self.number(node, "delta", 1.0)
            join = "square" if self.flag(node, "chamfer") else "miter"
        fn, fs, fa = self.resolution(node)
        n = fx.fragments(abs(value), fn, fs, fa)
        try:
            region = clipped_offset(body, value, join, n)
        except NotFlat as err:
            region = self.facets.facet(
                self, node, "offset", err,
                lambda faceted: clipped_offset(faceted.group(node), value, join, n))
        if region is None:
            return self.skip(node, f"the offset by {value:g} leaves nothing")
        return region

    def _projection(self, node: Node) -> Optional[Solid]:
        """OpenSCAD's ``projection``: the section by z = 0 (``cut = true``, exact, through
        any boolean) or the shadow on z = 0 of meshes and polytopes
        (:func:`csg.projection.projection`). With ``facets="true"`` curved children
        are taken as OpenSCAD's facets, with a warning."""
        body = self._group(node)
        if body is None:
            return None
        if body.dim != 3:
            return self.skip(node, "a 2D child (projection flattens 3D solids)")
        cut = self.flag(node, "cut")
        try:
            region = project(body, cut=cut)
        except NotAMesh as err:
            region = self.facets.facet(self, node, "projection", err,
                                       lambda faceted: project(faceted.group(node), cut=cut))
        if region is None:
            return self.skip(node, "the projection is empty" + (" (nothing meets z = 0)"
                                                                 if cut else ""))
        return region

    def _resize(self, node: Node) -> Optional[Solid]:
        """OpenSCAD's ``resize``: a scale about the origin taking the bounding box
        of the children's facets to ``newsize`` on every axis where it is not 0;
        ``auto`` axes (given 0) take the largest of those factors."""
        body = self._group(node)
        if body is None:
            return None
        dim = body.dim
        newsize = self.vector(node, "newsize", 3, 0.0, 0)
        auto = self.vector(node, "auto", 3, 0.0, 1) != 0
        faceted = self.facets.faceted_body(self, node, body)
        try:
            points = vertices(faceted)
        except NotAPolytope as err:
            raise self.error(node, f"resize: the bounding box of its children is not known "
                                   f"exactly here: {err}") from None
        size = np.zeros(3)
        size[:dim] = points.max(axis=0) - points.min(axis=0)
        scale = np.ones(3)
        for axis in range(dim):
            if newsize[axis] > 0:
                if size[axis] == 0:
                    raise self.error(node, "resize: a flat child cannot be resized across "
                                           "its plane")
                scale[axis] = newsize[axis] / size[axis]
        # OpenSCAD's autoscale: the factor of the axis given the largest new size
        automatic = scale[int(np.argmax(newsize[:dim]))]
        for axis in range(dim):
            if auto[axis] and newsize[axis] <= 0:
                scale[axis] = automatic
        if np.all(scale == 1):
            return body
        return self._open_if(Transformed(body, np.diag([*scale, 1.0])), body)
