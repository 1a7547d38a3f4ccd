"""Smooth booleans and Stolte's blobby spheres.

The smooth booleans use the polynomial smooth minimum (Quilez): with
``h = clip(1/2 + (b - a) / (2 k), 0, 1)``, ``smin(a, b) = b (1 - h) + a h - k h (1 - h)``.
Where ``|a - b| >= k`` it is exactly ``min(a, b)``; in between it rounds the
crease with a fillet of size about ``k`` (``radius``).

Examples
--------
>>> from csg import Sphere, smooth_union, Blobby
>>> s = smooth_union(Sphere(1), Sphere(1, center=(1.5, 0, 0)), radius=0.3)
>>> s.bounds
((-1.3, -1.3, -1.3), (2.8, 1.3, 1.3))
>>> Blobby([(0, 0, 0), (1, 0, 0)], radius=0.6).bounds[1][0] > 1
True
"""
from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

import implicitvox as iv
from implicitvox import Expr, validate, x, y, z

from .solid import Bounds, Solid

__all__ = ["smooth_union", "smooth_intersection", "smooth_difference", "SmoothBoolean",
           "Blobby"]


def _smin(a: Expr, b: Expr, k: float) -> Expr:
    h = iv.clip(0.5 + (b - a) / (2 * k), 0.0, 1.0)
    return b * (1 - h) + a * h - k * h * (1 - h)


class SmoothBoolean(Solid):
    """Smooth union, intersection or difference of two solids with a fillet ``radius``."""

    scene_type = "smooth"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``kind`` (``"union"``, ``"intersection"``, ``"difference"``), ``radius``, ``children [2 NODEs]``."""
        kids = read.kids(node, path, depth)
        if len(kids) != 2:
            raise ValueError("children: a smooth boolean takes exactly 2 children")
        kind = read.choice(node, path, "kind", ("union", "intersection", "difference"))
        return cls(kind, kids[0], kids[1], read.num(node, path, "radius"))

    def __init__(self, kind: str, a: Solid, b: Solid, radius: float):
        if kind not in ("union", "intersection", "difference"):
            raise ValueError(f"kind must be union, intersection or difference, got {kind!r}")
        self.kind, self._children, self.radius = kind, (a, b), validate.positive_number(radius, "radius")

    @property
    def children(self):
        return self._children

    @property
    def expr(self) -> Expr:
        a, b = (c.expr for c in self._children)
        k = self.radius
        if self.kind == "union":
            return _smin(a, b, k)
        if self.kind == "intersection":
            return -_smin(-a, -b, k)
        return -_smin(-a, b, k)

    @property
    def bounds(self) -> Bounds:
        a, b = (c.bounds for c in self._children)
        if self.kind == "difference" or self.kind == "intersection":
            base = a if self.kind == "difference" or b is None else b
            return base
        if a is None or b is None:
            return None
        # the fillet adds at most k/4 of material where the two are within k of each other
        pad = self.radius
        return (tuple((np.minimum(a[0], b[0]) - pad).tolist()),
                tuple((np.maximum(a[1], b[1]) + pad).tolist()))

    def __repr__(self) -> str:
        return f"smooth_{self.kind}({self._children[0]!r}, {self._children[1]!r}, {self.radius})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "smooth", "kind": self.kind, "radius": self.radius,
                "children": [c.scene_node() for c in self.children]}


def smooth_union(a: Solid, b: Solid, radius: float) -> Solid:
    return SmoothBoolean("union", a, b, radius)


def smooth_intersection(a: Solid, b: Solid, radius: float) -> Solid:
    return SmoothBoolean("intersection", a, b, radius)


def smooth_difference(a: Solid, b: Solid, radius: float) -> Solid:
    return SmoothBoolean("difference", a, b, radius)


class Blobby(Solid):
    """Stolte's blobby spheres: inside where ``sum_i exp(-|p - c_i|^2 / s_i^2)`` reaches
    ``threshold``; ``radius`` (one or per centre) is where a lone blob's surface lies."""

    scene_type = "blobby"

    @classmethod
    def from_scene(cls, read: Any, node: dict, path: str, depth: int) -> Solid:
        """``centers [[3]...]``, ``radius [...]``, ``threshold``."""
        return cls(read.array(node, path, "centers", (None, 3)),
                   read.array(node, path, "radius", (None,)), read.num(node, path, "threshold"))

    def __init__(self, centers: Sequence[Sequence[float]], radius: Any = 1.0,
                 threshold: float = 0.5):
        c = np.asarray(centers, dtype=np.float64)
        if c.ndim != 2 or c.shape[1] != 3 or not len(c) or not np.all(np.isfinite(c)):
            raise ValueError("centers must be a non-empty (n, 3) array of finite numbers")
        r = np.broadcast_to(np.asarray(radius, dtype=np.float64), (len(c),)).copy()
        if not np.all(r > 0):
            raise ValueError("radius must be positive")
        t = float(threshold)
        if not 0 < t < 1:
            raise ValueError(f"threshold must be in (0, 1), got {threshold!r}")
        self.centers, self.radius, self.threshold = c, r, t
        # exp(-r^2 / s^2) = t for a lone blob: s = r / sqrt(-ln t)
        self.spread = r / math.sqrt(-math.log(t))

    @property
    def expr(self) -> Expr:
        field = None
        for (cx, cy, cz), s in zip(self.centers, self.spread):
            term = iv.exp(-((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (s * s))
            field = term if field is None else field + term
        return self.threshold - field

    @property
    def bounds(self) -> Bounds:
        # beyond distance d of every centre the field is below n exp(-d^2/s^2) <= threshold
        n = len(self.centers)
        d = self.spread.max() * math.sqrt(math.log(n / self.threshold)) if n > self.threshold \
            else self.spread.max()
        d = max(d, float(self.radius.max()))
        return (tuple((self.centers.min(0) - d).tolist()),
                tuple((self.centers.max(0) + d).tolist()))

    def __repr__(self) -> str:
        return f"Blobby({len(self.centers)} centres, threshold={self.threshold})"

    def scene_node(self) -> dict:
        """This node of a JSON scene (:mod:`csg.scene`)."""
        return {"type": "blobby", "centers": self.centers.tolist(),
                "radius": self.radius.tolist(), "threshold": self.threshold}


