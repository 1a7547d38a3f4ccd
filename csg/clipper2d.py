"""2D regions as OpenSCAD 2021.01 computes them, with Clipper: booleans and ``offset``.

OpenSCAD evaluates its 2D operations with Angus Johnson's Clipper on integer
coordinates (``ClipperUtils``: points times 2¹⁶, truncated); here the same
library does it, through `pyclipper <https://github.com/fonttools/pyclipper>`_,
on the same integers, so the outlines are OpenSCAD's:

* a leaf's outlines are sanitized with an even-odd union (``polygon`` is
  filled even-odd), a ``multmatrix`` moves the points before they are scaled;
* ``union``/``group`` is one non-zero union of the children, ``difference``
  the first child minus the others, ``intersection`` a chain of binary
  intersections (``ClipperUtils::apply``);
* ``offset`` unites its children, then offsets the outlines
  (``ClipperOffset``): ``r`` with round joins, whose arcs take the tolerance
  ``|r| (1 − cos(180° / n))`` for OpenSCAD's ``n`` fragments of a circle of
  radius ``|r|`` (so a full turn has ``n`` steps), ``delta`` with miter joins
  (a miter limit of 10⁶: corners stay sharp), ``chamfer`` with square joins.

The result is a :class:`~csg.planar.Polygon` of the outlines (filled
even-odd: Clipper's outlines do not cross), or None when nothing is left.

Examples
--------
>>> from csg import Rectangle
>>> rounded = offset(Rectangle((2, 2), center=True), 1.0, "round", fragments=8)
>>> len(rounded.points), rounded.bounds
(12, ((-2.0, -2.0, 0.0), (2.0, 2.0, 0.0)))
>>> offset(Rectangle((2, 2)), -1.5, "miter") is None        # shrunk away
True
"""
from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

from .planar import Polygon, pieces_polygon
from .protocol import NotFlat, fold
from .solid import Solid

__all__ = ["region_paths", "boolean_paths", "region_pieces", "simple_pieces", "offset",
           "minkowski",
           "to_polygon", "clip",
           "to_clipper", "check_range", "OutOfRange", "CLIPPER_SCALE", "CLIPPER_RANGE",
           "MITER_LIMIT", "NotFlat"]

#: OpenSCAD 2021.01's ``ClipperUtils::CLIPPER_SCALE``: points are times this, truncated
CLIPPER_SCALE = float(1 << 16)
#: Clipper's largest coordinate (its ``hiRange``, 2^62 - 1): a larger one throws from C++
CLIPPER_RANGE = float((1 << 62) - 1)
#: OpenSCAD's ``offset`` miter limit (``delta`` keeps every corner sharp)
MITER_LIMIT = 1_000_000.0
_JOINS = {"round": "JT_ROUND", "miter": "JT_MITER", "square": "JT_SQUARE"}


class OutOfRange(ValueError):
    """A 2D coordinate beyond what Clipper can hold (:data:`CLIPPER_RANGE`)."""


def to_clipper(points: np.ndarray, *, rounding: Any = np.trunc) -> list:
    """Points as Clipper's integers: times :data:`CLIPPER_SCALE`, truncated toward zero
    (C++'s conversion of a double to ``IntPoint``), or rounded by ``rounding``.

    Raises
    ------
    OutOfRange
        A coordinate beyond :data:`CLIPPER_RANGE` once scaled (Clipper would throw
        from C++, which ends the process), or not finite.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        scaled = rounding(np.asarray(points, dtype=np.float64) * CLIPPER_SCALE)
    check_range(scaled)
    return scaled.astype(np.int64).tolist()


def check_range(scaled: Any, reach: float = 0.0) -> None:
    """``OutOfRange`` unless every scaled coordinate, grown by ``reach`` (scaled too:
    an offset's distance), lies within Clipper's :data:`CLIPPER_RANGE`."""
    scaled = np.asarray(scaled, dtype=np.float64)
    largest = float(np.max(np.abs(scaled), initial=0.0)) if scaled.size else 0.0
    if not (math.isfinite(largest) and math.isfinite(reach)) or \
            largest + abs(reach) > CLIPPER_RANGE:
        worst = (largest + abs(reach)) / CLIPPER_SCALE
        raise OutOfRange(f"a 2D coordinate of magnitude {worst:.4g} is beyond the "
                         f"±{CLIPPER_RANGE / CLIPPER_SCALE:.4g} that Clipper (OpenSCAD's 2D "
                         "geometry library) can hold at OpenSCAD's scale of 2^16 per unit "
                         "(csg.clipper2d.CLIPPER_RANGE)")


def clip(subjects: list, clips: list, operation: str, fill: str = "PFT_NONZERO") -> list:
    """One Clipper operation (``"CT_UNION"``, ``"CT_DIFFERENCE"``, ``"CT_INTERSECTION"``)
    on integer paths, both sides filled by ``fill`` (``"PFT_NONZERO"`` as OpenSCAD's
    booleans, ``"PFT_EVENODD"`` as its sanitize)."""
    import pyclipper
    if not subjects:
        return []                                 # nothing to unite, cut or keep
    clipper = pyclipper.Pyclipper()
    if not _add_paths(clipper, subjects, pyclipper.PT_SUBJECT):
        return []                                 # every subject vanished on the grid
    if clips:
        _add_paths(clipper, clips, pyclipper.PT_CLIP)    # none: nothing cuts or is kept
    fill_type = getattr(pyclipper, fill)
    return clipper.Execute(getattr(pyclipper, operation), fill_type, fill_type)


def _add_paths(clipper: Any, paths: list, kind: Any) -> bool:
    """Add closed paths to a Clipper; False when every one is degenerate on Clipper's
    grid (a part smaller than 2^-16, its points truncated together). Clipper's C++
    ``AddPaths`` then adds nothing and says so, as it does in OpenSCAD, which goes on
    with what is left; pyclipper raises instead, and that is caught here."""
    import pyclipper
    try:
        clipper.AddPaths(paths, kind, True)
    except pyclipper.ClipperException:
        return False
    return True


def _usable(paths: list) -> list:
    return [p for p in paths if len(p) >= 3]


def region_paths(solid: Solid, matrix: Optional[np.ndarray] = None) -> list:
    """The outlines (Clipper integer paths) of a 2D tree, as OpenSCAD evaluates it.

    Raises
    ------
    NotFlat
        A leaf with no outline (a true :class:`~csg.planar.Circle`).
    """
    def leaf(node: Solid, moved: np.ndarray) -> list:
        outlines = [o @ moved[:2, :2].T + moved[:2, 3] for o in node.outlines()]
        paths = _usable([to_clipper(o) for o in outlines])
        return clip(paths, [], "CT_UNION", "PFT_EVENODD")      # OpenSCAD's sanitize

    return fold(solid, leaf, boolean_paths, matrix)


def boolean_paths(operation: str, parts: list) -> list:
    """Clipper's result of a boolean (``"union"``, ``"difference"``,
    ``"intersection"``) of its operands' integer paths, as OpenSCAD computes it."""
    if operation == "union":
        return clip([p for part in parts for p in part], [], "CT_UNION")
    if operation == "difference":
        return clip(parts[0], [p for part in parts[1:] for p in part], "CT_DIFFERENCE")
    out = parts[0]
    for part in parts[1:]:
        out = clip(out, part, "CT_INTERSECTION")
    return out


def region_pieces(solid: Solid) -> list[tuple[np.ndarray, list[np.ndarray]]]:
    """A 2D tree's region as OpenSCAD computes it, in parts ``(outer, [holes])``
    (float points; outer outlines counter-clockwise, holes clockwise: Clipper's
    tree of outlines, islands in holes as parts of their own).

    Raises
    ------
    NotFlat
        As :func:`region_paths`.
    """
    return _tree_pieces(region_paths(solid))


def _tree_pieces(paths: list) -> list[tuple[np.ndarray, list[np.ndarray]]]:
    """Clipper's outlines (integer paths, not crossing) as parts ``(outer, [holes])``,
    from Clipper's own tree of outlines, every ring simple."""
    import pyclipper
    paths = _usable(paths)
    if not paths:
        return []
    clipper = pyclipper.Pyclipper()
    # rings that touch themselves at a vertex (Clipper's "weakly simple" output, as in
    # GEB's shadows) are split into simple rings: the same region, and outlines whose
    # triangulation and crossing number need no special case
    clipper.StrictlySimple = True
    if not _add_paths(clipper, paths, pyclipper.PT_SUBJECT):
        return []
    tree = clipper.Execute2(pyclipper.CT_UNION, pyclipper.PFT_NONZERO, pyclipper.PFT_NONZERO)
    pieces = []
    stack = list(tree.Childs)
    while stack:
        node = stack.pop(0)
        outer = np.asarray(node.Contour, dtype=np.float64) / CLIPPER_SCALE
        holes = [np.asarray(h.Contour, dtype=np.float64) / CLIPPER_SCALE for h in node.Childs]
        pieces.append((outer, [h for h in holes if len(h) >= 3]))
        for hole in node.Childs:
            stack.extend(hole.Childs)                 # islands inside the holes
    return [(o, hs) for o, hs in pieces if len(o) >= 3]


def simple_pieces(pieces: list) -> list[tuple[np.ndarray, list[np.ndarray]]]:
    """Region parts ``(outer, [holes])`` with every ring simple: parts whose rings
    touch themselves at a vertex are split by Clipper (StrictlySimple) into simple
    rings of the same region; the rest are returned as they are. Points are on
    Clipper's grid already when they came from Clipper, so they are kept exactly.

    >>> import numpy as np
    >>> eight = np.array([[1, 1], [3, 1], [3, 3], [5, 3], [5, 5], [3, 5], [3, 3], [1, 3.0]])
    >>> [(len(o), [len(h) for h in hs]) for o, hs in simple_pieces([(eight, [])])]
    [(4, []), (4, [])]
    """
    def touching(ring: np.ndarray) -> bool:
        return len(np.unique(ring, axis=0)) < len(ring)

    plain, split = [], []
    for outer, holes in pieces:
        rings = [np.asarray(r, dtype=np.float64) for r in (outer, *holes)]
        (split if any(touching(r) for r in rings) else plain).append((rings[0], rings[1:]))
    if not split:
        return plain
    paths = [to_clipper(r, rounding=np.round) for outer, holes in split for r in (outer, *holes)]
    return plain + _tree_pieces(paths)


def to_polygon(paths: list) -> Optional[Polygon]:
    """Clipper's outlines as a :class:`~csg.planar.Polygon` (its nesting from Clipper's
    tree of outlines: rings touching at a vertex stay apart), or None."""
    pieces = _tree_pieces(paths)
    return pieces_polygon(pieces) if pieces else None


def minkowski(solids: Sequence[Solid]) -> Optional[Polygon]:
    """OpenSCAD's 2D ``minkowski()`` of 2D trees (``ClipperUtils::applyMinkowski``), on
    its integers: per pair of outlines, the quads that sum each edge of one with each
    edge of the other (``minkowski_outline``), then each operand moved to the first
    point of every positive outline of the other (``fill_minkowski_insides``: the
    sums of the interiors), united non-zero; from the third operand on, the sum so far
    is the first. Exact for outlines of any shape, holes and separate parts included
    (a sum point ``a + b`` lies on an edge sum where both ``a`` and ``b`` can be moved
    to their outlines, else in one operand moved by a point of the other's part).

    >>> from csg import Rectangle, Union
    >>> ell = Union(Rectangle((4, 1)), Rectangle((1, 4)))         # not convex
    >>> minkowski([ell, Rectangle((1, 1))]).bounds
    ((0.0, 0.0, 0.0), (5.0, 5.0, 0.0))
    """
    lhs = region_paths(solids[0])
    for solid in solids[1:]:
        rhs = region_paths(solid)
        terms = []
        for r in rhs:
            for path in lhs:
                terms.extend(_edge_sums(path, r))
        terms.extend(_moved_into(lhs, rhs))
        terms.extend(_moved_into(rhs, lhs))
        lhs = clip(terms, [], "CT_UNION")
    return to_polygon(lhs)


def _edge_sums(poly: list, path: list) -> list:
    """``minkowski_outline(poly, path, sum, closed)``: the quads
    ``path[i] + poly[j], path[i + 1] + poly[j], path[i + 1] + poly[j + 1],
    path[i] + poly[j + 1]``, each turned counter-clockwise (Clipper's
    ``Orientation``: area at least 0)."""
    a = np.asarray(poly, dtype=np.int64)
    b = np.asarray(path, dtype=np.int64)
    pp = b[:, None, :] + a[None, :, :]                        # (path, poly, 2)
    nxt_i = np.roll(np.arange(len(b)), -1)
    nxt_j = np.roll(np.arange(len(a)), -1)
    quads = np.stack([pp, pp[nxt_i], pp[nxt_i][:, nxt_j], pp[:, nxt_j]], axis=2).reshape(-1, 4, 2)
    if np.abs(quads).max(initial=0) >= 1 << 29:               # exact areas as Python ints
        quads = quads.astype(object)
    x, y = quads[:, :, 0], quads[:, :, 1]
    twice_area = (x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y).sum(axis=1)
    backward = np.asarray(twice_area < 0, dtype=bool)
    quads[backward] = quads[backward][:, ::-1]
    return quads.astype(np.int64).tolist()


def _moved_into(a: list, b: list) -> list:
    """``fill_minkowski_insides(a, b)``: every outline of ``a`` moved to the first point
    of each positive (counter-clockwise) outline of ``b``."""
    import pyclipper
    out = []
    for path in b:
        if path and pyclipper.Orientation(path):
            dx, dy = path[0]
            out.extend([[(x + dx, y + dy) for x, y in outline] for outline in a])
    return out


def offset(solid: Solid, delta: float, join: str = "round", fragments: Optional[int] = None
           ) -> Optional[Polygon]:
    """OpenSCAD's ``offset`` of a 2D tree: ``join`` is ``"round"`` (``r``, arcs of
    ``fragments`` steps per full turn), ``"miter"`` (``delta``) or ``"square"``
    (``delta`` with ``chamfer``). None when the offset leaves nothing.

    Raises
    ------
    NotFlat
        As :func:`region_paths`.
    ValueError
        An unknown ``join``, or a round join without ``fragments``.
    """
    import pyclipper
    if join not in _JOINS:
        raise ValueError(f"join must be one of {sorted(_JOINS)}, got {join!r}")
    if join == "round" and not fragments:
        raise ValueError("a round offset needs fragments (OpenSCAD's n for a circle of |r|)")
    n = fragments or 3
    arc_tolerance = abs(delta) * (1 - math.cos(math.radians(180.0 / n)))
    united = clip(region_paths(solid), [], "CT_UNION")
    check_range([c for path in united for point in path for c in point], delta * CLIPPER_SCALE)
    co = pyclipper.PyclipperOffset(MITER_LIMIT, arc_tolerance * CLIPPER_SCALE)
    if united:
        co.AddPaths(united, getattr(pyclipper, _JOINS[join]), pyclipper.ET_CLOSEDPOLYGON)
    return to_polygon(co.Execute(delta * CLIPPER_SCALE) if united else [])
