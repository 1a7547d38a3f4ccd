"""OpenSCAD's polygonization rules (2021.01), for ``facets="openscad"``.

* fragments of a circle of radius ``r``: ``$fn`` if set (at least 3), else
  ``ceil(max(min(360 / $fa, 2 pi r / $fs), 5))``; 3 below ``r = 2**-20``;
* a circle's vertices at angles ``360 i / n``;
* a sphere: ``(n + 1) // 2`` rings at polar angles ``180 (i + 1/2) / rings``,
  each a circle of ``n`` vertices;
* a cylinder: the circles of ``r1`` and ``r2`` (a point where a radius is 0)
  with the fragments of ``max(r1, r2)``;
* ``rotate_extrude``: ``max(fragments(max x) * |angle| / 360, 1)`` sectors
  whose faces are planar trapezoids: the profile at the polygonal radius
  ``rho_n = (x cos phi_k + y sin phi_k) / cos(w / 2)`` of sector ``k``
  (width ``w``, mid-angle ``phi_k``) - an exact implicit form; the reader
  sweeps a flat profile into OpenSCAD's own mesh instead
  (:func:`rotation_mesh_outlines`), for the exact box test of a mesh;
* ``linear_extrude`` with twist or a non-uniform scale: ``slices`` layers
  with each side quad split into two triangles along its shorter diagonal,
  as OpenSCAD does (a mesh). Without ``slices`` in the file, the count is
  OpenSCAD 2021.01's (:func:`extrusion_slices`). A 2D boolean under such an
  extrusion is first evaluated as OpenSCAD evaluates it, with Clipper
  (:func:`csg.clipper2d.region_pieces`), and its outlines extruded as one mesh
  (:func:`extrusion_mesh_outlines`).

Examples
--------
>>> fragments(10, fn=0, fs=2, fa=12)
30
>>> fragments(1, fn=0, fs=2, fa=12)
5
>>> circle_points(1, 4).round(12).tolist()
[[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]
"""
from __future__ import annotations

import math

import numpy as np

import implicitvox as iv
from implicitvox import Expr, x, y


__all__ = ["fragments", "helix_slices", "conical_helix_slices", "diagonal_slices",
           "extrusion_slices", "circle_points", "sphere_points", "cylinder_points",
           "polygonal_radius", "FULL_SWEEP_START", "extrusion_mesh", "extrusion_mesh_outlines",
           "rotation_mesh_outlines", "cap_triangles",
           "MAX_FRAGMENTS", "MAX_SPHERE_POINTS"]

GRID_FINE = 0.00000095367431640625
#: side-quad diagonals are equal to OpenSCAD when their lengths differ by at most this
#: share of their mean (``sgn_vdiff``'s ``ratio_threshold`` of 1e5: 10 ppm)
DIAGONAL_TIE = 1e-5


#: fragments per circle at most ($fn = 10000 is far beyond what a model needs; an OpenSCAD
#: sphere of n fragments has n (n + 1) / 2 vertices)
MAX_FRAGMENTS = 10_000
#: vertices of one faceted sphere at most (n = 2828 fragments)
MAX_SPHERE_POINTS = 4_000_000


def fragments(r: float, fn: float = 0.0, fs: float = 2.0, fa: float = 12.0) -> int:
    """OpenSCAD's ``get_fragments_from_r``, refused above :data:`MAX_FRAGMENTS`.

    Raises
    ------
    ValueError
        If ``$fn``, ``$fa`` or ``$fs`` ask for more than :data:`MAX_FRAGMENTS`
        fragments (a real model stays far below; raise the limit to go further).
    """
    if r < GRID_FINE:
        return 3
    if fn > 0:
        n = float(fn) if fn >= 3 else 3.0
    else:
        n = math.ceil(max(min(360.0 / fa, r * 2 * math.pi / fs), 5))
    if not n <= MAX_FRAGMENTS:
        raise ValueError(f"$fn/$fa/$fs ask for {n:.4g} fragments per circle, over the limit "
                         f"of {MAX_FRAGMENTS} (csg.facets.MAX_FRAGMENTS)")
    return int(n)


def helix_slices(r_sqr: float, height: float, twist: float, fn: float, fs: float,
                 fa: float) -> int:
    """OpenSCAD 2021.01's slices of a twisted ``linear_extrude`` without ``slices``
    (``Calc::get_helix_slices``): 3 per turn at least; ``$fn`` per turn; else the
    fewer of ``twist / $fa`` and the helix's length over ``$fs``, for the vertex
    ``sqrt(r_sqr)`` from the axis.

    >>> helix_slices(89.0, 10.0, 90.0, 0.0, 2.0, 12.0), helix_slices(89.0, 10.0, 90.0, 16, 2, 12)
    (8, 4)
    """
    twist = abs(twist)
    least = max(int(math.ceil(twist / 120.0)), 1)
    if math.sqrt(r_sqr) < GRID_FINE or not math.isfinite(fn):
        return least
    if fn > 0:
        return max(int(math.ceil(twist / 360.0 * fn)), least)
    turn = math.radians(twist)
    length = turn * math.sqrt(r_sqr + (height / turn) ** 2) if turn > 0 else height
    return max(min(int(math.ceil(twist / fa)), int(math.ceil(length / fs))), least)


def conical_helix_slices(r_sqr: float, height: float, twist: float, scale: float, fn: float,
                         fs: float, fa: float) -> int:
    """``Calc::get_conical_helix_slices``: a twist with a uniform scale; the vertex
    runs on a section of an Archimedes spiral, whose length (with the height)
    over ``$fs`` bounds the slices.

    >>> conical_helix_slices(89.0, 10.0, 720.0, 0.5, 0.0, 2.0, 12.0)
    45
    """
    twist = abs(twist)
    r = math.sqrt(r_sqr)
    least = max(int(math.ceil(twist / 120.0)), 1)
    if r < GRID_FINE or not math.isfinite(fn):
        return least
    if fn > 0:
        return max(int(math.ceil(twist * fn / 360)), least)
    turn = math.radians(twist)
    end = turn * scale / (scale - 1) if scale > 1 else turn / (1 - scale)
    start = end - turn
    a = r / end

    def spiral(theta: float) -> float:
        return 0.5 * a * (theta * math.sqrt(1 + theta * theta) + math.asinh(theta))

    length = math.hypot(spiral(end) - spiral(start), height)
    return max(min(int(math.ceil(twist / fa)), int(math.ceil(length / fs))), least)


def diagonal_slices(delta_sqr: float, height: float, fn: float, fs: float) -> int:
    """``Calc::get_diagonal_slices``: a non-uniform scale without twist; ``$fn``
    slices, else the longest vertex path over ``$fs``."""
    if math.sqrt(delta_sqr) < GRID_FINE or not math.isfinite(fn):
        return 1
    if fn > 0:
        return max(int(fn), 1)
    return max(int(math.ceil(math.sqrt(delta_sqr + height * height) / fs)), 1)


def extrusion_slices(points: np.ndarray, height: float, twist: float, scale: np.ndarray,
                     fn: float, fs: float, fa: float, twisted: bool) -> int:
    """The slices OpenSCAD 2021.01 cuts a ``linear_extrude`` into when the file gives
    none, from the section's vertices ``points (n, 2)`` (``twisted``: the file
    gives ``twist``): the helix (no scale, or an uneven one), the conical helix
    (a uniform scale), the diagonal (an uneven scale without twist), or one.

    >>> square = np.array([[3.0, 0], [8, 0], [8, 5], [3, 5]])
    >>> extrusion_slices(square, 10.0, 90.0, np.array([1.0, 1.0]), 0.0, 2.0, 12.0, True)
    8
    """
    sx, sy = float(scale[0]), float(scale[1])
    if twisted:
        r_sqr = float(np.max(np.einsum("ij,ij->i", points, points))) if len(points) else 0.0
        if (sx == 1.0 and sy == 1.0) or sx != sy:
            return helix_slices(r_sqr, height, twist, fn, fs, fa)
        return conical_helix_slices(r_sqr, height, twist, sx, fn, fs, fa)
    if sx != sy:
        delta = points - points * np.array([sx, sy])
        delta_sqr = float(np.max(np.einsum("ij,ij->i", delta, delta))) if len(points) else 0.0
        return diagonal_slices(delta_sqr, height, fn, fs)
    return 1


def _cos_sin_degrees(deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of degrees, exact at multiples of 90 (as OpenSCAD's are)."""
    deg = np.asarray(deg, dtype=np.float64)
    rad = np.radians(deg)
    c, s = np.cos(rad), np.sin(rad)
    q = deg / 90.0
    exact = q == np.round(q)
    k = np.round(q).astype(np.int64) % 4
    c = np.where(exact, np.array([1.0, 0.0, -1.0, 0.0])[k], c)
    s = np.where(exact, np.array([0.0, 1.0, 0.0, -1.0])[k], s)
    return c, s


def circle_points(r: float, n: int) -> np.ndarray:
    """``(n, 2)`` vertices of OpenSCAD's circle."""
    c, s = _cos_sin_degrees(360.0 * np.arange(n) / n)
    return np.stack([r * c, r * s], axis=1)


def sphere_points(r: float, n: int) -> np.ndarray:
    """Vertices of OpenSCAD's sphere with ``n`` fragments (at most
    :data:`MAX_SPHERE_POINTS` of them, else ``ValueError``)."""
    rings = (n + 1) // 2
    if rings * n > MAX_SPHERE_POINTS:
        raise ValueError(f"a sphere of {n} fragments has {rings * n:,} vertices, over the limit "
                         f"of {MAX_SPHERE_POINTS:,} (csg.facets.MAX_SPHERE_POINTS)")
    phi = 180.0 * (np.arange(rings) + 0.5) / rings
    c, s = _cos_sin_degrees(phi)
    pts = []
    for ring_r, ring_z in zip(r * s, r * c):
        circle = circle_points(ring_r, n)
        pts.append(np.column_stack([circle, np.full(n, ring_z)]))
    return np.concatenate(pts)


def cylinder_points(r1: float, r2: float, z1: float, z2: float, n: int) -> np.ndarray:
    """Vertices of OpenSCAD's cylinder (cone where a radius is 0)."""
    pts = []
    for r, zz in ((r1, z1), (r2, z2)):
        if r > 0:
            pts.append(np.column_stack([circle_points(r, n), np.full(n, zz)]))
        else:
            pts.append(np.array([[0.0, 0.0, zz]]))
    return np.concatenate(pts)


#: where OpenSCAD 2021.01 starts the sectors of a full ``rotate_extrude``: on the -x
#: axis ("for legacy support", its ``rotateextrude.cc``); a partial one starts on +x
FULL_SWEEP_START = 180.0


def polygonal_radius(n_sectors: int, angle: float, start: float = 0.0) -> Expr:
    """``rho_n(x, y)``: the circumradius of the ``n_sectors``-sided sweep through ``(x, y)``
    (sectors of ``angle / n_sectors`` degrees from ``start`` degrees: OpenSCAD 2021.01
    starts a partial sweep on the +x axis, 0, and a full one on the -x axis, 180
    (:data:`FULL_SWEEP_START`), which only an odd count of sectors tells apart).

    Within sector ``k`` it is the projection on the sector's mid-direction
    ``phi_k`` over ``cos(w / 2)``; the nearest mid-direction gives the largest
    projection, so ``rho_n`` is the maximum over the sectors - a max of linear
    functions, whose intervals are tight (no angle, no floor).
    """
    w = angle / n_sectors
    c, s = _cos_sin_degrees(start + w * (np.arange(n_sectors) + 0.5))
    scale = 1.0 / math.cos(math.radians(w / 2))
    if abs(w) >= 180:
        raise ValueError(f"{n_sectors} sector(s) over {angle} degrees: each must be < 180")
    terms = [iv.affine((ci * scale, si * scale), (x, y)) for ci, si in zip(c, s)]
    return iv.max(*terms) if len(terms) > 1 else terms[0]


def extrusion_mesh(outline: np.ndarray, height: float, twist: float, scale: np.ndarray,
                   slices: int, z0: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of OpenSCAD's linear extrusion of one polygon outline.

    Layer ``i`` is the outline turned by ``-twist i / slices`` degrees, then scaled by
    ``1 + (scale - 1) i / slices``, at ``z0 + height i / slices``
    (:func:`extrusion_mesh_outlines` of the outline alone).
    """
    poly = np.asarray(outline, dtype=np.float64)
    area = 0.5 * np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
    return extrusion_mesh_outlines([(poly if area > 0 else poly[::-1], [])], height, twist,
                                   scale, slices, z0)


def extrusion_mesh_outlines(pieces: list, height: float, twist: float, scale: np.ndarray,
                            slices: int, z0: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of OpenSCAD's linear extrusion of a 2D region, one closed
    mesh, as OpenSCAD extrudes the result of its 2D booleans. ``pieces``: the
    region's parts ``(outer, [holes])``, outer outlines counter-clockwise and holes
    clockwise (as Clipper returns them: :func:`csg.clipper2d.region_pieces`).

    Each side quad between two layers is split as OpenSCAD 2021.01's ``add_slice``
    splits it: along the diagonal shorter in the plane (within :data:`DIAGONAL_TIE`
    a tie, split by the twist's direction and whether the outline is a hole), except
    in the top slice of an extrusion scaled to 0 along an axis, where the choice is
    reversed (the shorter diagonal there would leave ears of no thickness) and the
    top cap is left out (it has no area); the caps are each part triangulated with its holes
    (`mapbox_earcut <https://github.com/skogler/mapbox_earcut_python>`_, Mapbox's
    ear clipping for polygons with holes: a cap is planar, so any triangulation
    of it is the same surface). Nothing is cut by a boolean afterwards, so where
    two outlines of the 2D tree cross, the walls run through the crossing point as
    OpenSCAD's do.
    """
    steps = np.arange(slices + 1) / slices
    sx, sy = 1 + (scale[0] - 1) * steps, 1 + (scale[1] - 1) * steps
    # the slices whose upper layer is scaled to 0 along an axis (OpenSCAD's any_zero)
    zero_top = (sx[1:] == 0) | (sy[1:] == 0)
    turns = [_cos_sin_degrees(-twist * t) for t in steps]
    c, s = np.array([t[0] for t in turns]), np.array([t[1] for t in turns])
    verts, faces = [], []
    base = 0
    for outer, holes in pieces:
        rings = [np.asarray(r, dtype=np.float64) for r in (outer, *holes)]
        starts = []
        for ring in rings:
            k = len(ring)
            # layer i: the section turned, then scaled (v = S R p), at z0 + height t_i
            rx = c[:, None] * ring[None, :, 0] - s[:, None] * ring[None, :, 1]
            ry = s[:, None] * ring[None, :, 0] + c[:, None] * ring[None, :, 1]
            layer = np.stack([rx * sx[:, None], ry * sy[:, None],
                              np.broadcast_to((z0 + height * steps)[:, None], rx.shape)],
                             axis=-1).reshape(-1, 3)
            i, j = np.meshgrid(np.arange(slices), np.arange(k), indexing="ij")
            j1 = (j + 1) % k
            a_j, a_j1 = i * k + j, i * k + j1
            b_j, b_j1 = (i + 1) * k + j, (i + 1) * k + j1
            # OpenSCAD's add_slice: the diagonal shorter in the plane, a tie by the twist's
            # direction and the outline's kind, reversed at a top scaled to 0 on an axis
            l1 = np.hypot(*(layer[a_j] - layer[b_j1])[..., :2].transpose(2, 0, 1))
            l2 = np.hypot(*(layer[a_j1] - layer[b_j])[..., :2].transpose(2, 0, 1))
            tie = 2 * np.abs(l1 - l2) <= DIAGONAL_TIE * (l1 + l2)
            flip = (ring is not rings[0]) != (twist <= 0)
            first = np.where(tie, not flip, l1 < l2) != zero_top[:, None]
            first = first[..., None, None]
            split1 = np.stack([np.stack([a_j, a_j1, b_j1], -1), np.stack([a_j, b_j1, b_j], -1)], -2)
            split2 = np.stack([np.stack([a_j, a_j1, b_j], -1), np.stack([a_j1, b_j1, b_j], -1)], -2)
            faces.append(base + np.where(first, split1, split2).reshape(-1, 3))
            verts.append(layer)
            starts.append(base)
            base += len(layer)
        bottom, upper = _end_caps(rings, starts, slices)
        faces.append(bottom[:, ::-1])                              # bottom, facing down
        faces.append(upper)                                        # top, facing up
    return np.concatenate(verts), np.concatenate(faces).astype(np.int64)


def _end_caps(rings: list, starts: list, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """The region's triangles (:func:`cap_triangles`, counter-clockwise) as vertex
    indices of the first and the last layer of a mesh whose ring ``r`` has its
    ``steps + 1`` layers of ``len(rings[r])`` points from ``starts[r]`` on."""
    tri = cap_triangles(rings)
    owner = np.repeat(np.arange(len(rings)), [len(r) for r in rings])
    local = np.concatenate([np.arange(len(r)) for r in rings])
    first = np.asarray(starts)[owner] + local
    last = first + steps * np.array([len(r) for r in rings])[owner]
    return first[tri], last[tri]


def cap_triangles(rings: list) -> np.ndarray:
    """Triangles ``(m, 3)``, counter-clockwise, of a planar region given by its outlines
    (an outer one counter-clockwise, then its holes): indices into the outlines' points
    concatenated. `mapbox_earcut <https://github.com/skogler/mapbox_earcut_python>`_,
    Mapbox's ear clipping for polygons with holes; a cap is planar, so any
    triangulation of it is the same surface."""
    import mapbox_earcut
    flat = np.concatenate(rings)
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    tri = mapbox_earcut.triangulate_float64(flat, ends).reshape(-1, 3).astype(np.int64)
    a, b, c = flat[tri[:, 0]], flat[tri[:, 1]], flat[tri[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tri[area < 0] = tri[area < 0][:, ::-1]
    return tri


def rotation_mesh_outlines(pieces: list, angle: float, sectors: int
                           ) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of OpenSCAD 2021.01's ``rotate_extrude`` of a 2D region
    (its ``rotatePolygon``): one closed mesh, oriented outward. ``pieces``: the
    region's parts ``(outer, [holes])`` in the ``(x, z)`` plane of the profile, as
    :func:`extrusion_mesh_outlines` takes them, all on one side of the axis.

    Ring ``j`` of a full sweep is the profile turned to OpenSCAD's angle
    ``a_j = -90 + 360 j / sectors`` (a partial one: ``a_j = 90 - angle j / sectors``,
    ``j = 0 .. sectors``), a profile point ``(px, pz)`` going to
    ``(px sin a_j, px cos a_j, pz)`` - :data:`FULL_SWEEP_START` in the usual angle.
    Each quad between two rings is planar (a trapezoid symmetric about its
    sector's mid-plane), so the solid is the same as :func:`polygonal_radius`
    describes; a partial sweep is closed by the profile, triangulated
    (:func:`cap_triangles`), at both ends. Profile points on the axis collapse
    their rings to a point: the triangles that degenerate there are dropped, so
    an edge of the profile on the axis leaves no face inside the solid.
    """
    full = abs(angle) >= 360
    j = np.arange(sectors if full else sectors + 1)
    a = -90.0 + 360.0 * j / sectors if full else 90.0 - angle * j / sectors
    cos_a, sin_a = _cos_sin_degrees(a)
    verts, faces = [], []
    base = 0
    for outer, holes in pieces:
        rings = [np.asarray(r, dtype=np.float64) for r in (outer, *holes)]
        starts = []
        for ring in rings:
            k = len(ring)
            layer = np.stack([sin_a[:, None] * ring[None, :, 0],
                              cos_a[:, None] * ring[None, :, 0],
                              np.broadcast_to(ring[None, :, 1], (len(j), k))],
                             axis=-1).reshape(-1, 3)
            jj, ii = np.meshgrid(np.arange(sectors), np.arange(k), indexing="ij")
            jn, i1 = (jj + 1) % len(j), (ii + 1) % k
            p, q = base + jj * k + ii, base + jj * k + i1            # ring j: i, i + 1
            r, t = base + jn * k + ii, base + jn * k + i1            # ring j + 1: i, i + 1
            faces.append(np.stack([np.stack([p, t, q], -1), np.stack([p, r, t], -1)],
                                  -2).reshape(-1, 3))
            verts.append(layer)
            starts.append(base)
            base += len(layer)
        if not full:
            first, last = _end_caps(rings, starts, sectors)
            faces.append(first)                                        # at a_0
            faces.append(last[:, ::-1])                                # at a_sectors
    v, f = np.concatenate(verts), np.concatenate(faces).astype(np.int64)
    tv = v[f]
    collapsed = (np.all(tv[:, 0] == tv[:, 1], axis=1) | np.all(tv[:, 1] == tv[:, 2], axis=1)
                 | np.all(tv[:, 0] == tv[:, 2], axis=1))
    f, tv = f[~collapsed], tv[~collapsed]
    volume = np.sum(np.einsum("ij,ij->i", tv[:, 0], np.cross(tv[:, 1], tv[:, 2])))
    # the rings' copies of a point on the axis are one vertex: a closed manifold mesh
    on_axis = np.flatnonzero((v[:, 0] == 0) & (v[:, 1] == 0))
    if len(on_axis):
        _, first = np.unique(v[on_axis, 2], return_inverse=True)
        _, lead = np.unique(first, return_index=True)
        renumber = np.arange(len(v))
        renumber[on_axis] = on_axis[lead][first]
        f = renumber[f]
    return v, (f if volume > 0 else f[:, ::-1])
