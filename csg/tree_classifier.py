"""Exact box classification of CSG trees with polyhedral leaves.

A CSG tree is flattened to world space: transforms are pushed into the
leaves (a :class:`~csg.primitives.Polyhedron`'s vertices are moved, a box's
or convex polyhedron's corners, a half-space's plane, a sphere under a
similarity; any other subtree becomes one compiled implicit function). Each
leaf classifies boxes as EMPTY, FULL or AMBIGUOUS:

* a polyhedron exactly - AMBIGUOUS iff a triangle meets the closed box
  (:class:`implicitvox.triangles.tribox.Triangles`), else FULL or EMPTY by the winding
  number at the box's centre;
* boxes, convex polyhedra, half-spaces, spheres and ellipsoids (under any
  affine map), capped cylinders and cones (under similarities), tori (under
  similarities that keep their axis along x, y or z) by their max-norm
  distance (Varadhan §5.1, :mod:`implicitvox.linf`): AMBIGUOUS iff the
  surface meets the box (up to rounding at exact ties);
* a straight prism (:class:`csg.prism.Prism`, OpenSCAD's extrusion of a 2D
  region) exactly, by its outlines' edges (:class:`implicitvox.triangles.prism_classifier.PrismClassifier`)
  or its mesh;
* a function by its interval enclosure (sound; AMBIGUOUS may be a near miss).

The booleans combine the states: a union is FULL if a child is, EMPTY if all
are, AMBIGUOUS if exactly one child is and the others are EMPTY (the union's
surface in the box is that child's); an intersection dually; a complement
swaps FULL and EMPTY. Where two children are AMBIGUOUS the state is
*unknown* - the surfaces may cancel inside the box - and the box is settled
by subdivision (:func:`_settle`; at the voxel level, so is an interval
leaf's AMBIGUOUS, as the voxelizer rechecks a voxel with no exact test on its
sub-voxels): its surface is met iff a sub-box is
AMBIGUOUS by the rules above, or one sub-box is FULL and another EMPTY (the
box is connected); EMPTY or FULL iff every sub-box is. A box still unknown
after :data:`SETTLE_DEPTH` halvings (two surfaces touching at a tangency)
counts as AMBIGUOUS: conservative, never a missed voxel. So a union,
intersection or difference of exact leaves voxelizes exactly, ties aside.
An interval leaf's AMBIGUOUS is not exact (it may be a near miss): combined
with another AMBIGUOUS child it stays AMBIGUOUS, and a sub-box that is such
counts as met (never a missed voxel).
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

import implicitvox as iv
from implicitvox import batches
from implicitvox.expr.shape import AMBIGUOUS, EMPTY, FULL, Octants
from implicitvox.octree.morton import CORNERS
from implicitvox.triangles.mesh_classifier import MeshClassifier, forget_decided

__all__ = ["plan", "exact_classifier", "world_primitive", "similarity_scale", "MeshClassifier",
           "SETTLE_DEPTH", "SUPPORT_PAD"]

#: internal states: two or more exact children AMBIGUOUS (settled by subdivision), and
#: an interval (not exact) AMBIGUOUS, which stays AMBIGUOUS through the booleans
UNKNOWN, MAYBE = 3, 4
#: relative outward padding of a leaf's bounding box, off which its state is taken
#: without its test (far beyond the rounding its tests allow for)
SUPPORT_PAD = 1e-9
#: halvings of a box whose state is unknown before it counts as AMBIGUOUS
SETTLE_DEPTH = 2
#: unknown boxes settled at once (each may have up to 4**SETTLE_DEPTH sub-boxes in play)
SETTLE_CHUNK = batches.SETTLE_BOXES
_HALF = CORNERS.astype(bool)
#: the witness points of a box (its corners in :data:`CORNERS` order, then its centre),
#: in the order :func:`_witnessed` tries them: two opposite corners, then the rest
_WITNESS_STAGES = (np.array([0, 7]), np.array([1, 2, 3, 4, 5, 6, 8]))
_BOOLEANS = ("union", "intersection", "difference", "complement")


def _has_exact_leaf(solid) -> bool:
    """Whether a leaf of the tree has an exact test (a polyhedron or a max-norm primitive)."""
    return solid.exact or any(_has_exact_leaf(c) for c in solid.children)


def similarity_scale(m: np.ndarray) -> Optional[float]:
    """The scale of ``m`` if it is a rotation (or reflection) times a scale, else None."""
    gram = m.T @ m
    scale2 = gram[0, 0]
    if np.allclose(gram, scale2 * np.eye(3), rtol=0, atol=1e-12 * scale2):
        return float(np.sqrt(scale2))
    return None


def world_primitive(solid, matrix: Optional[np.ndarray] = None):
    """A single (transformed) primitive as a world-space max-norm primitive
    (:mod:`implicitvox.linf`), or None."""
    matrix = np.eye(4) if matrix is None else matrix
    while solid.operation == "transform":
        solid, matrix = solid.children[0], matrix @ solid.matrix
    return solid.world_linf(matrix) if solid.exact else None


def _leaves(solid):
    if not solid.children:
        yield solid
    for c in solid.children:
        yield from _leaves(c)


def exact_classifier(tree_plan: Optional[tuple], settle: bool = False,
                     regularized: Optional[Callable[[], Any]] = None
                     ) -> Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """The box classifier of a tree's :func:`plan`, or None when it has none.

    With ``settle``, boxes whose state is unknown (two exact surfaces meet
    them) are decided by subdivision (:func:`_settle`); without, they are
    AMBIGUOUS - right for an octant the voxelizer will subdivide anyway, and
    much cheaper. The voxelizer settles at the voxel level only.

    A box that halving leaves unknown holds a tie: two surfaces touching along
    a face or an edge inside it (solids touching on a face, common in OpenSCAD
    models). ``regularized`` gives, when called, a classifier of the
    regularized solid's boundary (the tree's mesh, whose booleans drop faces
    shared inside the solid: :func:`csg.tree_mesh.tree_mesh`), or None where the
    tree has none (a curved leaf); it decides those boxes, so a face shared by
    two parts of a union is no surface. Without one they count as AMBIGUOUS.
    """
    if tree_plan is None:
        return None

    def classify(lo: np.ndarray, hi: np.ndarray, octants: Optional[Octants] = None
                 ) -> np.ndarray:
        lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        # boxes the voxelizer will subdivide (all but the voxels, which ``settle``):
        # their mesh leaves remember what they found for the children
        state = _run(tree_plan, lo, hi, None if octants is None else (octants, not settle))
        # at the voxel level an interval leaf's AMBIGUOUS (perhaps a near miss) is
        # halved too, as the voxelizer rechecks voxels with no exact test
        unsure = (state == UNKNOWN) | (state == MAYBE)
        unknown = np.flatnonzero(unsure) if settle else np.zeros(0, dtype=np.int64)
        for start in range(0, len(unknown), SETTLE_CHUNK):
            part = unknown[start:start + SETTLE_CHUNK]
            seen = _witnessed(tree_plan, lo[part], hi[part])
            state[part[seen]] = AMBIGUOUS
            part = part[~seen]
            state[part] = _settle(tree_plan, lo[part], hi[part])
        tied = np.flatnonzero(state == UNKNOWN) if settle else np.zeros(0, dtype=np.int64)
        if len(tied) and regularized is not None:
            boundary = regularized()
            if boundary is not None:
                state[tied] = boundary.classify(lo[tied], hi[tied])
        state[(state == MAYBE) | (state == UNKNOWN)] = AMBIGUOUS
        if octants is not None and not settle:
            # the boxes the tree decided will not be subdivided: their leaves' memory goes
            forget_decided(octants.run, octants, np.flatnonzero(state != AMBIGUOUS))
        return state
    classify.takes_octants = True
    return classify


def _function(solid, matrix: np.ndarray) -> tuple:
    identity = np.array_equal(matrix, np.eye(4))
    return ("function", iv.compile(solid.expr if identity else solid.transform(matrix).expr))


def plan(solid, matrix: Optional[np.ndarray] = None) -> Optional[tuple]:
    """The tree flattened to world space for classification, or None when no
    leaf has an exact test. Each node says what it is through its
    ``operation`` (a boolean, ``"transform"``, or None), ``exact`` and
    ``exact_leaf(matrix)``; nothing here names a primitive."""
    if not _has_exact_leaf(solid):
        return None
    return _plan(solid, np.eye(4) if matrix is None else matrix)


def _plan(solid, matrix: np.ndarray) -> tuple:
    if not _has_exact_leaf(solid):
        return _function(solid, matrix)
    if solid.operation == "transform":
        return _plan(solid.children[0], matrix @ solid.matrix)
    if solid.exact:
        leaf = solid.exact_leaf(matrix)
        return leaf if leaf is not None else _function(solid, matrix)
    if solid.operation not in _BOOLEANS:
        if any(leaf.needs_exact_test for leaf in _leaves(solid)):
            raise TypeError(f"{type(solid).__name__} with a polyhedron inside has no exact "
                            "test (only booleans and transforms combine them)")
        # another node (a blend, an extrusion): its own function, by intervals
        return _function(solid, matrix)
    kids = [_plan(c, matrix) for c in solid.children]
    if solid.operation == "union":
        return _boolean("union", kids)
    if solid.operation == "intersection":
        return _boolean("intersection", kids)
    if solid.operation == "difference":
        return _boolean("intersection", [kids[0]] + [("complement", k) for k in kids[1:]])
    return ("complement", kids[0])


def _boolean(kind: str, kids: list) -> tuple:
    """A union or intersection node: its children and their supports (stacked:
    ``lo`` (k, 3), ``hi`` (k, 3), the state off the box (k,)), so that a box
    evaluates only the children whose support box it touches."""
    # the cheap children first: a box one child makes absorbing (EMPTY for an
    # intersection, FULL for a union) skips the rest (:func:`_run`), and the
    # combination is symmetric in the children, so the order changes no state
    kids = sorted(kids, key=_interval_cost)
    supports = [_support(k) for k in kids]
    lo = np.array([sp[0] for sp in supports], dtype=np.float64).reshape(-1, 3)
    hi = np.array([sp[1] for sp in supports], dtype=np.float64).reshape(-1, 3)
    return (kind, kids, (lo, hi, np.array([sp[2] for sp in supports], dtype=np.int8)))


def _interval_cost(node: tuple) -> int:
    """The instructions of a node's interval leaves: the part of its cost that
    grows with its tapes (an exact leaf's test costs about one instruction)."""
    kind = node[0]
    if kind == "function":
        return len(node[1].tape)
    if kind == "complement":
        return _interval_cost(node[1])
    if kind in ("union", "intersection"):
        return sum(_interval_cost(k) for k in node[1])
    return 1


def _support(node: tuple) -> tuple[np.ndarray, np.ndarray, int]:
    """A box ``[lo, hi]`` off which the node's state is the same everywhere, and
    that state: EMPTY off a leaf's bounding box; a complement swaps it. Unbounded
    (infinite) where nothing is known: a function (its interval decides, even off
    its solid), a half-space. Padded outward (:data:`SUPPORT_PAD`) beyond every
    rounding of the leaves' tests, so culling a child changes no state."""
    everywhere = (np.full(3, -np.inf), np.full(3, np.inf), EMPTY)
    kind = node[0]
    if kind in ("mesh", "prism"):
        lo, hi = node[1].lo, node[1].hi
    elif kind == "exact":
        bounds = getattr(node[1], "bounds", None)
        if bounds is None:
            return everywhere
        lo, hi = np.asarray(bounds[0], dtype=np.float64), np.asarray(bounds[1], dtype=np.float64)
    elif kind == "complement":
        lo, hi, off = _support(node[1])
        return lo, hi, (FULL if off == EMPTY else EMPTY)
    elif kind in ("union", "intersection"):
        klo, khi, koff = node[2]
        absorbing = FULL if kind == "union" else EMPTY
        # children absorbing off their boxes: an intersection lies in each such
        # child, so in their boxes' intersection, and is EMPTY off it; dually a
        # union's complement (De Morgan). Else every child is neutral off its box,
        # and so is the node off their hull.
        pick = koff == absorbing
        if pick.any():
            return klo[pick].max(axis=0), khi[pick].min(axis=0), absorbing
        return klo.min(axis=0), khi.max(axis=0), (EMPTY if kind == "union" else FULL)
    else:
        return everywhere
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        return everywhere
    pad = SUPPORT_PAD * (np.abs(lo).max() + np.abs(hi).max() + (hi - lo).max())
    return lo - pad, hi + pad, EMPTY


def _run(plan: tuple, lo: np.ndarray, hi: np.ndarray, asked: Optional[tuple] = None
         ) -> np.ndarray:
    """The states of boxes ``[lo, hi]`` under a plan node. ``asked``: the octants the
    boxes are and whether they will be subdivided (``(Octants, bool)``), for the mesh
    leaves (:meth:`MeshClassifier.classify`), or None."""
    kind = plan[0]
    if kind == "function":
        flo, fhi = plan[1].interval(lo, hi)
        state = np.full(len(lo), MAYBE, dtype=np.int8)
        state[flo > 0] = EMPTY
        state[fhi < 0] = FULL
        return state
    if kind == "mesh" and asked is not None:
        return plan[1].classify(lo, hi, *asked)
    if kind in ("mesh", "prism"):
        return plan[1].classify(lo, hi)
    if kind == "exact":
        return plan[1].classify_boxes(lo, hi)
    if kind == "complement":
        s = _run(plan[1], lo, hi, asked)
        return np.where(s == FULL, EMPTY, np.where(s == EMPTY, FULL, s)).astype(np.int8)
    klo, khi, koff = plan[2]
    touches = np.all((lo[None] <= khi[:, None]) & (hi[None] >= klo[:, None]), axis=2)
    states = np.repeat(koff[:, None], len(lo), axis=1)
    # a union is an intersection of complements: one rule, with the roles swapped
    absorbing, neutral = (FULL, EMPTY) if kind == "union" else (EMPTY, FULL)
    open_ = koff != absorbing       # boxes no child has made absorbing yet
    open_ = np.ones(len(lo), dtype=bool) if open_.all() else \
        ~((~touches) & (koff == absorbing)[:, None]).any(axis=0)
    for k, kid in enumerate(plan[1]):        # each child only where its support reaches
        ask = touches[k] & open_             # and where no child decided the box already
        if ask.all():
            states[k] = _run(kid, lo, hi, asked)
        elif ask.any():
            near = np.flatnonzero(ask)
            states[k, near] = _run(kid, lo[near], hi[near],
                                   None if asked is None else (asked[0].subset(near), asked[1]))
        open_ &= states[k] != absorbing
    out = np.full(len(lo), UNKNOWN, dtype=np.int8)
    active = states != neutral
    n_active = active.sum(axis=0)
    single = n_active == 1
    if single.any():               # exactly one child decides: its state (AMBIGUOUS or unknown)
        out[single] = states[active.argmax(axis=0)[single], np.flatnonzero(single)]
    out[(n_active > 1) & (states == MAYBE).any(axis=0)] = MAYBE
    out[n_active == 0] = neutral
    out[(states == absorbing).any(axis=0)] = absorbing
    return out


def _witnessed(plan: tuple, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Which boxes hold a point inside the solid and a point outside it, among
    their corners and centres: a box is connected, so such a box meets the
    surface (AMBIGUOUS, as :func:`_settle` would find it, at a ninth of the
    cost of its first halving). A point is classified as the degenerate box
    ``[p, p]``, by the same exact tests: FULL or EMPTY only off every surface.

    Two opposite corners go first; only boxes they leave unwitnessed have their
    other seven points classified (the answer is that of all nine at once)."""
    mid = 0.5 * (lo + hi)                                   # rounded, but inside the box
    points = np.concatenate([np.where(_HALF[None], hi[:, None], lo[:, None]),
                             mid[:, None]], axis=1)         # (n, 9, 3)
    seen_full = np.zeros(len(lo), dtype=bool)
    seen_empty = np.zeros(len(lo), dtype=bool)
    boxes = np.arange(len(lo))
    for stage in _WITNESS_STAGES:
        p = points[boxes][:, stage].reshape(-1, 3)
        s = _run(plan, p, p).reshape(len(boxes), len(stage))
        seen_full[boxes] |= (s == FULL).any(axis=1)
        seen_empty[boxes] |= (s == EMPTY).any(axis=1)
        boxes = boxes[~(seen_full[boxes] & seen_empty[boxes])]
        if not len(boxes):
            break
    return seen_full & seen_empty


def _settle(plan: tuple, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Decide boxes of UNKNOWN state by halving them, level by level, all at once.

    A box meets the surface iff a sub-box does (an AMBIGUOUS sub-box), or it
    holds an inside and an outside sub-box (FULL and EMPTY: the box is
    connected); it is EMPTY (FULL) iff all its sub-boxes are. Unknown after
    :data:`SETTLE_DEPTH` levels: UNKNOWN (a tie: :func:`exact_classifier`).
    """
    state = np.full(len(lo), UNKNOWN, dtype=np.int8)
    owner = np.arange(len(lo))
    seen_full = np.zeros(len(state), dtype=bool)
    seen_empty = np.zeros(len(state), dtype=bool)
    blo, bhi = lo[owner], hi[owner]
    for _ in range(SETTLE_DEPTH):
        if not len(owner):
            break
        mid = 0.5 * (blo + bhi)
        clo = np.where(_HALF[None], mid[:, None], blo[:, None]).reshape(-1, 3)
        chi = np.where(_HALF[None], bhi[:, None], mid[:, None]).reshape(-1, 3)
        cowner = np.repeat(owner, 8)
        s = _run(plan, clo, chi)
        seen_full[cowner[s == FULL]] = True
        seen_empty[cowner[s == EMPTY]] = True
        surface = np.zeros(len(state), dtype=bool)
        surface[cowner[(s == AMBIGUOUS) | (s == MAYBE)]] = True
        surface |= seen_full & seen_empty
        pending = np.zeros(len(state), dtype=bool)
        pending[cowner[s == UNKNOWN]] = True
        decided_owner = np.unique(owner)
        state[decided_owner[surface[decided_owner]]] = AMBIGUOUS
        settled = decided_owner[~surface[decided_owner] & ~pending[decided_owner]]
        state[settled] = np.where(seen_full[settled], FULL, EMPTY)
        keep = (s == UNKNOWN) & ~surface[cowner]
        owner, blo, bhi = cowner[keep], clo[keep], chi[keep]
    return state
