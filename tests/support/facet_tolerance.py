"""How far OpenSCAD's facets of a ``.csg`` model may lie from its true curves.

:func:`facet_tolerance` walks the tree and takes the largest chordal deviation
(sagitta ``r (1 - cos(pi / n))`` of a circle in ``n`` fragments, a sphere's in
longitude and latitude), of a twisted extrusion's slices (an arc becomes a chord
and each side quad two triangles, off the ruled surface by ``L alpha / 4``), and of
a non-uniformly scaled extrusion's bilinear side patches, each times the largest
scale of the transforms above it. The true-curve checks allow that much
(``tests/csg/test_openscad.py``, ``bench_openscad.py``).
"""
from __future__ import annotations

import math

import numpy as np

from csg.facets import extrusion_slices, fragments
from csg.openscad_parser import parse

__all__ = ["facet_tolerance", "outline_size"]


def facet_tolerance(text: str, reach: float) -> float:
    """The largest deviation of a ``.csg`` text's facets from its true curves; a sweep's
    (``rotate_extrude``) with the model's ``reach`` from the z axis as its radius
    (its profile may be moved and imported: that bounds it)."""
    worst = 0.0

    def visit(node, scale):
        nonlocal worst
        a = node.args
        if node.name == "multmatrix":
            m = np.array(a.get("m", node.positional[0] if node.positional else None), float)
            if not np.all(np.isfinite(m)):
                return                               # OpenSCAD removes what it holds
            scale = scale * float(np.linalg.norm(m[:3, :3], 2))
        res = (a.get("$fn", 0.0), a.get("$fs", 2.0), a.get("$fa", 12.0))
        r = None
        if node.name in ("sphere", "circle"):
            r = a.get("r", 1.0)
        elif node.name == "cylinder":
            r = max(a.get("r1", 1.0), a.get("r2", 1.0))
        elif node.name == "rotate_extrude":
            r = reach / scale                          # in the sweep's own frame
        elif node.name == "linear_extrude" and a.get("twist", 0.0) != 0 and node.children:
            length, radius = outline_size(node.children[0])
            alpha = math.radians(abs(a["twist"]) / _slices(node, radius))
            k = max(1.0, *np.atleast_1d(a.get("scale", 1.0)))
            worst = max(worst, scale * k * (length * alpha / 4 + radius * (1 - math.cos(alpha / 2))))
        if node.name == "linear_extrude" and node.children:
            # a scale unequal on the axes makes each side quad a bilinear patch, which
            # its two triangles leave by a quarter of its twist vector's part off the
            # patch: the unequal half of a slice's scale step dS times an edge p - q
            step = 1.0 - np.broadcast_to(np.asarray(a.get("scale", 1.0), float), (2,))
            if step[0] != step[1]:
                length, _ = outline_size(node.children[0])
                worst = max(worst, scale * abs(step[0] - step[1]) / 2
                            / _slices(node, outline_size(node.children[0])[1]) * length / 4)
        if r is not None:
            n = fragments(r, *res)
            cos_lat = 1.0
            if node.name == "sphere":
                # OpenSCAD's sphere has (n + 1) // 2 rings of n-gons, none on the
                # equator: a facet is off by a chord in longitude and in latitude
                cos_lat = math.cos(math.pi / (2 * ((n + 1) // 2)))
            worst = max(worst, scale * r * (1 - math.cos(math.pi / n) * cos_lat))
        for c in node.children:
            visit(c, scale)

    for n in parse(text):
        visit(n, 1.0)
    return worst


def _slices(node, radius: float) -> float:
    """An extrusion's slices: the file's, else as OpenSCAD computes them for a section
    reaching ``radius`` (:func:`csg.facets.extrusion_slices`)."""
    a = node.args
    if a.get("slices") is not None:
        return max(float(a["slices"]), 1.0)
    square = radius * np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    scale = np.broadcast_to(np.asarray(a.get("scale", 1.0), float), (2,))
    return max(float(extrusion_slices(square, a.get("height", 100.0), a.get("twist", 0.0),
                                      scale, a.get("$fn", 0.0), a.get("$fs", 2.0),
                                      a.get("$fa", 12.0), twisted="twist" in a)), 1.0)


def outline_size(node) -> tuple[float, float]:
    """Longest edge and farthest point of a 2D tree's leaves (square, circle, polygon)."""
    if node.children:
        sizes = [outline_size(c) for c in node.children]
        return max(s[0] for s in sizes), max(s[1] for s in sizes)
    a = node.args
    if node.name == "square":
        size = np.broadcast_to(np.asarray(a.get("size", 1.0), dtype=float), (2,))
        return float(size.max()), float(np.hypot(*size))
    if node.name == "circle":
        r = a.get("r", 1.0)
        n = fragments(r, a.get("$fn", 0.0), a.get("$fs", 2.0), a.get("$fa", 12.0))
        return 2 * r * math.sin(math.pi / n), r
    if node.name == "polygon" and isinstance(a.get("points"), list):
        pts = np.asarray(a["points"], dtype=float)
        edges = np.linalg.norm(np.roll(pts, -1, 0) - pts, axis=1)
        return float(edges.max()), float(np.linalg.norm(pts, axis=1).max())
    return 0.0, 0.0
