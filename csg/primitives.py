"""Primitive solids with named parameters, each an implicit function negative inside.

The functions are chosen for exact signs (the surface is exactly where they
vanish) and cheap, tight intervals: Euclidean distances where they are
simple (sphere, torus), max-norm forms for boxes and polytopes.

Examples
--------
>>> from csg import Sphere, Box, Cylinder
>>> Sphere(2).bounds
((-2.0, -2.0, -2.0), (2.0, 2.0, 2.0))
>>> Box((1, 2, 3), center=True).bounds
((-0.5, -1.0, -1.5), (0.5, 1.0, 1.5))
>>> Cylinder(h=2, r1=1, r2=0).bounds      # a cone, from z = 0
((-1.0, -1.0, 0.0), (1.0, 1.0, 2.0))
"""
from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

import implicitvox as iv
from implicitvox import Expr, validate, linf, x, y, z
from implicitvox.triangles.closed import hull_mesh, is_convex_mesh
from implicitvox.triangles.inputs import as_triangles
from implicitvox.octree.morton import CORNERS

from .tree_classifier import MeshClassifier, similarity_scale
from .protocol import NotAPolytope
from .solid import Bounds, Solid, box_bound, vector

__all__ = ["Sphere", "Box", "Cylinder", "Torus", "Ellipsoid", "Capsule", "HalfSpace",
           "ConvexPolyhedron", "Polyhedron"]


_positive = validate.positive_number


def _nonneg(value: Any, name: str) -> float:
    return validate.number_in(value, name, 0.0, float(np.finfo(np.float64).max))


def _point(value: Any, name: str) -> np.ndarray:
    """3 finite floats (one number fills all three)."""
    return vector(value, name, planar=False, scalar=True)


def _similarity(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray, Optional[float]]:
    """The linear part, the offset and the scale of an affine map (None if it is not a
    rotation times a scale)."""
    m = matrix[:3, :3]
    return m, matrix[:3, 3], similarity_scale(m)


def _box(lo: Sequence[float], hi: Sequence[float]) -> Bounds:
    return tuple(float(v) for v in lo), tuple(float(v) for v in hi)


class Sphere(Solid):
    """Ball of radius ``r`` about ``center``: ``|p - c| - r``."""

    scene_type = "sphere"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``r``, ``center [3]`` (optional, the origin)."""
        return cls(read.num(node, path, "r"), read.array(node, path, "center", (3,), [0, 0, 0]))

    curved = True

    def __init__(self, r: float = 1.0, center: Sequence[float] = (0, 0, 0)):
        self.r = _positive(r, "r")
        self.center = _point(center, "center")

    @property
    def expr(self) -> Expr:
        cx, cy, cz = self.center
        return iv.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) - self.r

    @property
    def bounds(self) -> Bounds:
        return _box(self.center - self.r, self.center + self.r)

    exact = True

    def world_linf(self, matrix: np.ndarray) -> linf.Primitive:
        m, t = matrix[:3, :3], matrix[:3, 3]
        k = similarity_scale(m)
        if k is not None:
            return linf.Sphere(m @ self.center + t, self.r * k)
        return linf.Ellipsoid.from_affine(m * self.r, m @ self.center + t)

    def __repr__(self) -> str:
        return f"Sphere(r={self.r}, center={self.center.tolist()})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "sphere", "r": self.r, "center": self.center.tolist()}


class Box(Solid):
    """Axis-aligned box of ``size``, from the origin corner or centred (``center=True``);
    ``max_a(|p_a - c_a| - h_a)``."""

    scene_type = "box"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``size [3]``, ``center`` (optional)."""
        return cls(read.array(node, path, "size", (3,)), center=read.flag(node, path, "center"))

    def __init__(self, size: Any = (1, 1, 1), center: bool = False):
        s = _point(size, "size")
        if not np.all(s > 0):
            raise ValueError(f"size must be positive on every axis, got {s.tolist()}")
        self.size = s
        self.centered = bool(center)

    @property
    def _lo_hi(self):
        lo = -self.size / 2 if self.centered else np.zeros(3)
        return lo, lo + self.size

    @property
    def expr(self) -> Expr:
        lo, hi = self._lo_hi
        c, h = (lo + hi) / 2, (hi - lo) / 2
        return iv.max(abs(x - c[0]) - h[0], abs(y - c[1]) - h[1], abs(z - c[2]) - h[2])

    @property
    def bounds(self) -> Bounds:
        return _box(*self._lo_hi)

    exact = True

    def world_linf(self, matrix: np.ndarray) -> linf.Primitive:
        lo, hi = self._lo_hi
        corners = np.where(CORNERS.astype(bool), hi, lo)
        return linf.ConvexPolyhedron.from_points(corners @ matrix[:3, :3].T + matrix[:3, 3])

    def polytope_vertices(self, convex: bool, pieces: Any) -> np.ndarray:
        """Its 8 corners."""
        lo = -self.size / 2 if self.centered else np.zeros(3)
        corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
        return lo + corners * self.size

    def closed_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """The hull of its corners: 12 triangles."""
        return hull_mesh(self.polytope_vertices(True, None))

    def __repr__(self) -> str:
        return f"Box(size={self.size.tolist()}, center={self.centered})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "box", "size": self.size.tolist(), "center": self.centered}


class Cylinder(Solid):
    """Cylinder, cone or frustum along z: radius ``r1`` at the bottom, ``r2`` at the top
    (or ``r`` for both), height ``h``, from ``z = 0`` or centred."""

    scene_type = "cylinder"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``h``, ``r1``, ``r2``, ``center`` (optional)."""
        return cls(h=read.num(node, path, "h"), r1=read.num(node, path, "r1"),
                   r2=read.num(node, path, "r2"), center=read.flag(node, path, "center"))

    curved = True

    def __init__(self, h: float = 1.0, r: Optional[float] = None, r1: Optional[float] = None,
                 r2: Optional[float] = None, center: bool = False):
        self.h = _positive(h, "h")
        if r is not None:
            if r1 is not None or r2 is not None:
                raise ValueError("give r, or r1 and r2, not both")
            r1 = r2 = r
        r1 = 1.0 if r1 is None else r1
        r2 = r1 if r2 is None else r2
        self.r1, self.r2 = _nonneg(r1, "r1"), _nonneg(r2, "r2")
        if self.r1 == 0 and self.r2 == 0:
            raise ValueError("r1 and r2 are both 0: the cylinder has no volume")
        self.centered = bool(center)

    @property
    def _z(self) -> tuple[float, float]:
        return (-self.h / 2, self.h / 2) if self.centered else (0.0, self.h)

    @property
    def expr(self) -> Expr:
        z0, z1 = self._z
        rho = iv.hypot(x, y)
        if self.r1 == self.r2:
            side = rho - self.r1
        else:
            # rho - R(z) scaled by the slant so the side is a distance-like function
            slope = (self.r2 - self.r1) / self.h
            side = (rho - (self.r1 + slope * (z - z0))) / float(np.hypot(1.0, slope))
        return iv.max(side, z0 - z, z - z1)

    @property
    def bounds(self) -> Bounds:
        r = max(self.r1, self.r2)
        z0, z1 = self._z
        return _box((-r, -r, z0), (r, r, z1))

    exact = True

    def world_linf(self, matrix: np.ndarray) -> Optional[linf.Primitive]:
        """Exact under similarities (a frustum); None under other maps."""
        m, t, k = _similarity(matrix)
        if k is None:
            return None
        z0, _ = self._z
        return linf.Frustum(m @ np.array([0.0, 0.0, z0]) + t, m[:, 2], self.h * k,
                            self.r1 * k, self.r2 * k)

    def __repr__(self) -> str:
        return f"Cylinder(h={self.h}, r1={self.r1}, r2={self.r2}, center={self.centered})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "cylinder", "h": self.h, "r1": self.r1, "r2": self.r2,
                "center": self.centered}


class Torus(Solid):
    """Torus about the z axis: major radius ``R``, minor radius ``r``."""

    scene_type = "torus"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``R``, ``r``."""
        return cls(read.num(node, path, "R"), read.num(node, path, "r"))

    curved = True

    def __init__(self, R: float = 1.0, r: float = 0.25):
        self.R, self.r = _positive(R, "R"), _positive(r, "r")

    @property
    def expr(self) -> Expr:
        return iv.hypot(iv.hypot(x, y) - self.R, z) - self.r

    @property
    def bounds(self) -> Bounds:
        e = self.R + self.r
        return _box((-e, -e, -self.r), (e, e, self.r))

    exact = True

    def world_linf(self, matrix: np.ndarray) -> Optional[linf.Primitive]:
        """Exact under similarities; turned off the axes, for ring tori only."""
        m, t, k = _similarity(matrix)
        if k is None:
            return None
        axis = m[:, 2] / np.linalg.norm(m[:, 2])
        aligned = np.allclose(np.abs(axis), np.eye(3)[np.argmax(np.abs(axis))], rtol=0,
                              atol=1e-12)
        if aligned or self.R > self.r:
            return linf.Torus(t, axis, self.R * k, self.r * k)
        return None

    def __repr__(self) -> str:
        return f"Torus(R={self.R}, r={self.r})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "torus", "R": self.R, "r": self.r}


class Ellipsoid(Solid):
    """Ellipsoid with semi-axes ``radii`` about ``center``."""

    scene_type = "ellipsoid"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``radii [3]``, ``center [3]`` (optional)."""
        return cls(read.array(node, path, "radii", (3,)),
                   read.array(node, path, "center", (3,), [0, 0, 0]))

    curved = True

    def __init__(self, radii: Sequence[float] = (1, 1, 1), center: Sequence[float] = (0, 0, 0)):
        r = _point(radii, "radii")
        if not np.all(r > 0):
            raise ValueError(f"radii must be positive, got {r.tolist()}")
        self.radii, self.center = r, _point(center, "center")

    @property
    def expr(self) -> Expr:
        (a, b, c), (cx, cy, cz) = self.radii, self.center
        # scaled by the smallest radius: a distance-like function near the surface
        k = float(self.radii.min())
        return k * (iv.sqrt(((x - cx) / a) ** 2 + ((y - cy) / b) ** 2 + ((z - cz) / c) ** 2) - 1)

    @property
    def bounds(self) -> Bounds:
        return _box(self.center - self.radii, self.center + self.radii)

    exact = True

    def world_linf(self, matrix: np.ndarray) -> linf.Primitive:
        m, t = matrix[:3, :3], matrix[:3, 3]
        return linf.Ellipsoid.from_affine(m @ np.diag(self.radii), m @ self.center + t)

    def __repr__(self) -> str:
        return f"Ellipsoid(radii={self.radii.tolist()}, center={self.center.tolist()})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "ellipsoid", "radii": self.radii.tolist(),
                "center": self.center.tolist()}


class Capsule(Solid):
    """The points within ``r`` of the segment from ``a`` to ``b``: the union of the balls
    about its ends and the cylinder between them, ``min(|p - a| - r, |p - b| - r,
    max(rho - r, -w, w - |b - a|))`` with ``w`` the coordinate along the axis from ``a``
    and ``rho`` the distance from it (each affine in ``p``, so its intervals are tight: a
    sixth fewer voxels at 48³, 5,268 against 6,347, than the clipped-projection form
    ``|p - a - t (b - a)| - r``). Its scene node is ``capsule``: ``a [3]``, ``b [3]``,
    ``r``.

    >>> Capsule((0, 0, 0), (2, 0, 0), 0.5).bounds
    ((-0.5, -0.5, -0.5), (2.5, 0.5, 0.5))
    """

    curved = True
    scene_type = "capsule"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``a [3]``, ``b [3]``, ``r``."""
        return cls(read.array(node, path, "a", (3,)), read.array(node, path, "b", (3,)),
                   read.num(node, path, "r"))

    def __init__(self, a: Sequence[float] = (0, 0, 0), b: Sequence[float] = (0, 0, 1),
                 r: float = 0.5):
        self.a, self.b = _point(a, "a"), _point(b, "b")
        self.r = _positive(r, "r")
        if np.array_equal(self.a, self.b):
            raise ValueError("a capsule's ends a and b must differ (a ball is a Sphere)")

    @property
    def expr(self) -> Expr:
        d = self.b - self.a
        length = float(np.linalg.norm(d))
        w = d / length
        u = np.cross(w, [1.0, 0.0, 0.0] if abs(w[0]) < 0.9 else [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        v = np.cross(w, u)
        rel = [x - self.a[0], y - self.a[1], z - self.a[2]]
        along = iv.affine(w.tolist(), rel)
        rho = iv.hypot(iv.affine(u.tolist(), rel), iv.affine(v.tolist(), rel))

        def ball(c: np.ndarray) -> Expr:
            return iv.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) - self.r
        return iv.min(ball(self.a), ball(self.b),
                      iv.max(rho - self.r, -along, along - length))

    @property
    def bounds(self) -> Bounds:
        return _box(np.minimum(self.a, self.b) - self.r, np.maximum(self.a, self.b) + self.r)

    def __repr__(self) -> str:
        return f"Capsule(a={self.a.tolist()}, b={self.b.tolist()}, r={self.r})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "capsule", "a": self.a.tolist(), "b": self.b.tolist(), "r": self.r}


class HalfSpace(Solid):
    """``{p : n . p <= offset}`` (unbounded)."""

    scene_type = "halfspace"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``normal [3]``, ``offset``."""
        return cls(read.array(node, path, "normal", (3,)), read.num(node, path, "offset"))

    def __init__(self, normal: Sequence[float] = (0, 0, 1), offset: float = 0.0):
        n = _point(normal, "normal")
        length = float(np.linalg.norm(n))
        if length == 0:
            raise ValueError("normal must not be zero")
        self.normal, self.offset = n / length, float(offset) / length

    @property
    def expr(self) -> Expr:
        n = self.normal
        return iv.affine(n, (x, y, z), -self.offset)

    @property
    def bounds(self) -> Bounds:
        return None

    exact = True

    def world_linf(self, matrix: np.ndarray) -> linf.Primitive:
        m, t = matrix[:3, :3], matrix[:3, 3]
        n = np.linalg.solve(m.T, self.normal)          # M^-T n
        return linf.HalfSpace(n, self.offset + n @ t)

    def __repr__(self) -> str:
        return f"HalfSpace(normal={self.normal.tolist()}, offset={self.offset})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "halfspace", "normal": self.normal.tolist(), "offset": self.offset}


class ConvexPolyhedron(Solid):
    """Intersection of half-spaces ``n_i . p <= d_i``: from ``planes=(normals, offsets)``
    or as the convex hull of ``points``. ``max_i (n_i . p - d_i)`` (unit normals)."""

    scene_type = "convex_polyhedron"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``normals [[3]...]``, ``offsets [...]`` (or ``points [[3]...]``)."""
        if "points" in node:
            return cls(points=read.array(node, path, "points", (None, 3)))
        return cls(planes=(read.array(node, path, "normals", (None, 3)),
                           read.array(node, path, "offsets", (None,))))

    def __init__(self, planes: Optional[tuple[Any, Any]] = None, points: Any = None):
        if (planes is None) == (points is None):
            raise ValueError("give planes=(normals, offsets) or points, one of them")
        if points is not None:
            pts = np.asarray(points, dtype=np.float64)
            if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 4 or \
                    not np.all(np.isfinite(pts)):
                raise ValueError("points must be an (n, 3) array of at least 4 finite points")
            try:
                faces = linf.convex_hull_faces(pts)
            except ValueError as err:
                raise ValueError(f"the points span no volume (flat or degenerate): "
                                 f"{str(err).split(': ', 1)[-1]}") from None
            normals, offsets, self.points = faces.normals, faces.offsets, faces.vertices
        else:
            normals = np.asarray(planes[0], dtype=np.float64)
            offsets = np.asarray(planes[1], dtype=np.float64)
            if normals.ndim != 2 or normals.shape[1] != 3 or offsets.shape != (len(normals),):
                raise ValueError("planes must be (normals (k, 3), offsets (k,))")
            self.points = None
        length = np.linalg.norm(normals, axis=1)
        if np.any(length == 0) or not np.all(np.isfinite(normals)) or \
                not np.all(np.isfinite(offsets)):
            raise ValueError("plane normals must be finite and non-zero, offsets finite")
        self.normals, self.offsets = normals / length[:, None], offsets / length

    @property
    def expr(self) -> Expr:
        terms = [iv.affine(n, (x, y, z), -d) for n, d in zip(self.normals, self.offsets)]
        return iv.max(*terms) if len(terms) > 1 else terms[0]

    @property
    def bounds(self) -> Bounds:
        if self.points is not None:
            return _box(self.points.min(0), self.points.max(0))
        from scipy.optimize import linprog
        lo, hi = np.empty(3), np.empty(3)
        for a in range(3):
            for sign, out in ((1, lo), (-1, hi)):
                c = np.zeros(3)
                c[a] = sign
                res = linprog(c, A_ub=self.normals, b_ub=self.offsets, bounds=[(None, None)] * 3)
                if res.status == 3:
                    return None               # unbounded
                if res.status != 0:
                    raise ValueError(f"the planes bound no volume ({res.message})")
                out[a] = sign * res.fun
        pad = 1e-9 * (np.abs(np.concatenate([lo, hi])).max() + 1)
        return _box(lo - pad, hi + pad)

    exact = True

    def polytope_vertices(self, convex: bool, pieces: Any) -> np.ndarray:
        """The points it was given (a polytope given by planes has none)."""
        if self.points is None:
            raise NotAPolytope("a ConvexPolyhedron given by planes has no vertex list "
                               "(give points=)")
        return self.points

    def closed_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """The hull of its points (a polytope given by planes has no mesh)."""
        if self.points is None:
            return super().closed_mesh()
        return hull_mesh(np.asarray(self.points, dtype=np.float64))

    def world_linf(self, matrix: np.ndarray) -> linf.Primitive:
        if self.points is not None:
            return linf.ConvexPolyhedron.from_points(self.points @ matrix[:3, :3].T + matrix[:3, 3])
        return linf.ConvexPolyhedron.from_planes(self.normals, self.offsets).transformed(matrix)

    def __repr__(self) -> str:
        return f"ConvexPolyhedron({len(self.normals)} planes)"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "convex_polyhedron", "normals": self.normals.tolist(),
                "offsets": self.offsets.tolist()}


class Polyhedron(Solid):
    """Any closed triangle mesh (``vertices``, ``faces``, or a mesh file / PyVista mesh).

    Its geometry lives in an exact box classification (:mod:`csg.tree_classifier`:
    the exact box-triangle test of :mod:`implicitvox.triangles.tribox`, and the
    winding number for boxes off the surface). Its expression is only a
    bound - positive outside the bounding box, zero inside - which
    intervals read as "ask the exact test".
    """

    scene_type = "polyhedron"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``vertices [[3]...]``, ``faces [[3 ints]...]``."""
        return cls(read.array(node, path, "vertices", (None, 3)),
                   read.array(node, path, "faces", (None, 3), integer=True))

    def __init__(self, vertices: Any, faces: Any = None, alternative_faces: Any = None):
        mesh = vertices if faces is None else (vertices, faces)
        v, f = as_triangles(mesh)
        if not len(f):
            raise ValueError("a Polyhedron needs at least one triangle")
        used = np.zeros(len(v), dtype=bool)
        used[f.ravel()] = True
        self.vertices, self.faces = v, f
        #: triangles that may be its surface as well (``(k, 3)`` indices, in pairs that
        #: cancel in the winding number): the other triangulation of a bent face, whose
        #: diagonal OpenSCAD's tessellator chooses (:meth:`csg.openscad` ``polyhedron``);
        #: the exact test counts them as surface, nothing else sees them
        self.alternative_faces = np.zeros((0, 3), dtype=np.int64) if alternative_faces is None \
            else np.asarray(alternative_faces, dtype=np.int64).reshape(-1, 3)
        if self.alternative_faces.size and (self.alternative_faces.min() < 0 or
                                            self.alternative_faces.max() >= len(v)):
            raise ValueError("alternative_faces index past the vertices")
        self._lo, self._hi = v[used].min(axis=0), v[used].max(axis=0)

    def _surface_faces(self) -> np.ndarray:
        """Its faces and its :attr:`alternative_faces`: every triangle that may be surface."""
        if not len(self.alternative_faces):
            return self.faces
        return np.concatenate([self.faces, self.alternative_faces])

    @property
    def expr(self) -> Expr:
        return box_bound(self._lo, self._hi)

    @property
    def bounds(self) -> Bounds:
        return _box(self._lo, self._hi)

    exact = True
    #: its expression is only a bound: it must be classified exactly
    needs_exact_test = True

    def _world_vertices(self, matrix: np.ndarray) -> np.ndarray:
        return self.vertices @ matrix[:3, :3].T + matrix[:3, 3]

    def world_linf(self, matrix: np.ndarray) -> linf.Primitive:
        return linf.TriangleMesh(self._world_vertices(matrix), self._surface_faces())

    def polytope_vertices(self, convex: bool, pieces: Any) -> np.ndarray:
        """The vertices its faces use; with ``convex``, only of a convex mesh."""
        used = np.unique(self.faces.ravel())
        if convex and not is_convex_mesh(self.vertices, self.faces):
            raise NotAPolytope("a non-convex Polyhedron in a Minkowski sum (its convex "
                               "decomposition is not built: split it into convex parts)")
        return self.vertices[used]

    def closed_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """Its own vertices and faces."""
        return self.vertices, np.asarray(self.faces)

    def exact_leaf(self, matrix: np.ndarray) -> tuple[str, Any]:
        flip = np.linalg.det(matrix[:3, :3]) < 0      # mirrored: the winding sign flips
        return ("mesh", MeshClassifier(self._world_vertices(matrix), self._surface_faces(),
                                       flip))

    def __repr__(self) -> str:
        return f"Polyhedron({len(self.vertices)} vertices, {len(self.faces)} triangles)"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "polyhedron", "vertices": self.vertices.tolist(),
                "faces": self.faces.tolist()}


