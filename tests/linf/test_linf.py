"""Max-norm distances against independent brute force, and exact voxel tests (Varadhan)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

import implicitvox as ivx
from implicitvox import linf
from implicitvox.expr.shape import AMBIGUOUS, EMPTY, FULL
from implicitvox.linf.euclidean import triangle_distance as euclidean_triangle_distance
from tests.support import sweeps
from tests.support.linf_oracle import (corner_depth, dual_distance, ellipsoid_support, frustum_support,
                                quadric_box_range, quadric_distance, torus_surface_distance)

CUBE = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q


#: HiGHS at its tightest (its defaults, 1e-7, are too loose for a 1e-9 comparison)
_TIGHT = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


def lp_distance(poly: linf.ConvexPolyhedron, p, w):
    """Brute force outside a polytope: min t s.t. A x <= b, |x - p| <= t w (a linear programme)."""
    A, b = poly.normals, poly.offsets
    # variables (x, t): minimise t
    rows = [np.c_[A, np.zeros(len(A))]]
    rhs = [b]
    for s in (1, -1):
        rows.append(np.c_[s * np.eye(3), -w[:, None]])
        rhs.append(s * p)
    res = linprog(np.r_[0, 0, 0, 1], A_ub=np.vstack(rows), b_ub=np.concatenate(rhs),
                  bounds=[(None, None)] * 3 + [(0, None)], method="highs", options=_TIGHT)
    return res.fun


def lp_depth(poly, p, w):
    """Brute force inside: the largest box around p inside the polytope (a linear programme)."""
    A, b = poly.normals, poly.offsets
    h = np.abs(A) @ w
    res = linprog([-1], A_ub=h[:, None], b_ub=b - A @ p, bounds=[(0, None)], method="highs",
                  options=_TIGHT)
    return -res.x[0]


@pytest.mark.parametrize("name", ["cube", "rotated box", "random hull", "octahedron"])
def test_polytope_matches_linear_programming(name):
    rng = np.random.default_rng(len(name))
    pts = {"cube": CUBE, "rotated box": (CUBE - 0.5) * [1, 2, 0.5] @ _rotation(rng).T,
           "random hull": rng.normal(size=(30, 3)),
           "octahedron": np.vstack([np.eye(3), -np.eye(3)])}[name]
    poly = linf.ConvexPolyhedron.from_points(pts)
    n = sweeps.size(10_000)
    p = rng.normal(size=(n, 3)) * 1.5
    # also points near vertices and edges, where the contact is a vertex or an edge
    v = poly.vertices[rng.integers(0, len(poly.vertices), n // 3)]
    p[: n // 3] = v + rng.normal(size=v.shape) * 1e-3
    w = rng.uniform(0.3, 2.0, size=(n, 3))
    d = poly.distance(p, w)
    for i in range(n):
        want = lp_distance(poly, p[i], w[i]) if d[i] > 0 else lp_depth(poly, p[i], w[i])
        assert d[i] == pytest.approx(want, rel=1e-9, abs=1e-12), (i, p[i])


def test_halfspace_both_sides():
    h = linf.HalfSpace((1, -2, 0.5), 0.3)
    rng = np.random.default_rng(1)
    p = rng.normal(size=(10_000, 3))
    w = rng.uniform(0.5, 2, (10_000, 3))
    d = h.distance(p, w)
    # the box of radius |d| around p touches the plane: its extreme corner lies on it
    corner = p - np.sign(d)[:, None] * np.sign(h.normal) * np.abs(d)[:, None] * w
    assert np.allclose(corner @ h.normal, h.offset, atol=1e-12)


def sphere_bisection(c, r, p, w):
    """Brute force, all points at once: bisection on t of 'the box B(p, t) meets the
    ball' (outside) or 'the box lies in the ball' (inside), each a Euclidean test."""
    a = np.abs(p - c)
    inside = np.einsum("ij,ij->i", a, a) < r * r
    lo, hi = np.zeros(len(p)), np.full(len(p), 10.0)
    for _ in range(200):
        t = 0.5 * (lo + hi)
        grown = np.linalg.norm(a + t[:, None] * w, axis=1) <= r
        apart = np.linalg.norm(np.maximum(a - t[:, None] * w, 0), axis=1) > r
        ok = np.where(inside, grown, apart)
        lo, hi = np.where(ok, t, lo), np.where(ok, hi, t)
    return np.where(inside, -lo, lo)


def test_sphere_matches_bisection_and_sampling():
    rng = np.random.default_rng(2)
    s = linf.Sphere((0.1, -0.2, 0.3), 0.8)
    n = 10_000
    p = rng.normal(size=(n, 3))
    p[:100] = s.center                                      # the centre itself
    p[100:200, 1:] = s.center[1:]                           # on an axis through the centre
    w = rng.uniform(0.5, 2, (n, 3))
    d = s.distance(p, w)
    assert np.allclose(d, sphere_bisection(s.center, s.r, p, w), rtol=1e-9, atol=1e-12)
    # no sampled surface point is nearer than the distance (an upper bound check)
    u = rng.normal(size=(20_000, 3))
    surf = s.center + s.r * u / np.linalg.norm(u, axis=1, keepdims=True)
    for i in range(0, 200, 7):
        nearest = np.min(np.max(np.abs(surf - p[i]) / w[i], axis=1))
        assert nearest >= abs(d[i]) * (1 - 1e-9)


def test_mesh_matches_brute_force():
    """10^4 points around PyVista's nut against the least distance over all its triangles
    (no hierarchy, no culling)."""
    import pyvista as pv
    from implicitvox.triangles.inputs import as_triangles
    v, f = as_triangles(pv.examples.load_nut())
    mesh = linf.TriangleMesh(v, f)
    rng = np.random.default_rng(3)
    lo, hi = v.min(0), v.max(0)
    p = rng.uniform(lo - 5, hi + 5, (10_000, 3))
    w = rng.uniform(0.5, 2, (10_000, 3))
    d = mesh.distance(p, w)
    tri = v[f]
    brute = np.empty(len(p))
    for s in range(0, len(p), 16):                  # every triangle, 16 points at a time
        k = len(p[s:s + 16])
        brute[s:s + k] = linf.triangle_distance(
            np.repeat(p[s:s + 16], len(tri), 0), np.tile(tri, (k, 1, 1)),
            np.repeat(w[s:s + 16], len(tri), 0)).reshape(k, len(tri)).min(axis=1)
    # the compiled walk computes each triangle's distance as the array kernel does
    np.testing.assert_array_equal(np.abs(d), brute)
    assert mesh.closed and (d < 0).any() and (d > 0).any()
    e = mesh.euclidean_distance(p[:2000])
    brute_e = np.array([euclidean_triangle_distance(np.repeat(q[None], len(tri), 0), tri).min()
                        for q in p[:2000]])
    np.testing.assert_allclose(np.abs(e), brute_e, rtol=1e-12, atol=1e-12)


def _triangles_and_points(rng, n):
    """Random triangles, with degenerate ones (a repeated vertex, collinear vertices,
    an axis-parallel edge), and points, some in a triangle's plane or on its vertex."""
    tri = rng.normal(size=(n, 3, 3))
    tri[0::7, 1] = tri[0::7, 0]                                  # a zero edge
    tri[1::7, 2] = 2 * tri[1::7, 1] - tri[1::7, 0]               # collinear
    tri[2::7, 1, 1:] = tri[2::7, 0, 1:]                          # an edge along x
    p = rng.normal(size=(n, 3)) * 2
    p[3::7] = tri[3::7].mean(axis=1)                              # in the plane
    p[4::7] = tri[4::7, 2]                                        # on a vertex
    return tri, p, rng.uniform(0.25, 4.0, (n, 3))


def test_compiled_triangle_distances_are_the_array_kernels():
    from implicitvox.linf.mesh_walk import triangle_euclidean, triangle_linf
    tri, p, w = _triangles_and_points(np.random.default_rng(8), 3000)
    ours = np.array([triangle_linf(*p[k], *w[k], tri[k]) for k in range(len(p))])
    np.testing.assert_array_equal(ours, linf.triangle_distance(p, tri, w))
    ours = np.array([triangle_euclidean(*p[k], tri[k]) for k in range(len(p))])
    # (the array kernel sums its dot products in numpy's order: equal up to rounding at
    # the coordinates' scale, which is 1 here)
    np.testing.assert_allclose(ours, euclidean_triangle_distance(p, tri), rtol=1e-13,
                               atol=1e-14)


def test_a_triangles_projected_axes_give_its_distance_below_any_bound():
    from implicitvox.linf.triangle_axes import axis_rows, box_gap, linf_below
    tri, p, w = _triangles_and_points(np.random.default_rng(9), 2000)
    rows = axis_rows(tri)
    truth = linf.triangle_distance(p, tri, w)
    bounds = truth * np.random.default_rng(1).uniform(0.5, 1.5, len(p))
    for k in range(len(p)):
        box = box_gap(*p[k], *w[k], rows[k])
        assert box <= truth[k]
        assert linf_below(*p[k], *w[k], rows[k], box, np.inf) == truth[k]
        got = linf_below(*p[k], *w[k], rows[k], box, bounds[k])
        assert got == truth[k] if truth[k] < bounds[k] else got >= bounds[k]


def test_the_compiled_convex_distance_is_the_array_paths_bit_for_bit():
    rng = np.random.default_rng(11)
    tiny = np.finfo(np.float64).tiny
    for _ in range(40):
        pts = rng.normal(size=(int(rng.integers(4, 40)), 3))
        solid = linf.ConvexPolyhedron.from_points(pts)
        p = rng.normal(size=(400, 3)) * 2
        p[::29] = pts[0]                                          # on a vertex
        w = rng.uniform(0.1, 3.0, (400, 3))
        w[::17] = tiny                                            # a flat box's weights
        w[::19, 1] = tiny
        with np.errstate(all="ignore"):
            got, truth = solid.distance(p, w), solid.distance_by_arrays(p, w)
        assert np.array_equal(got, truth, equal_nan=True)


def _brute_classify_sphere(c, r, lo, hi):
    """A box against a sphere's surface, Euclidean: the nearest and farthest box points."""
    near = np.linalg.norm(np.maximum(np.maximum(lo - c, c - hi), 0), axis=1)
    far = np.linalg.norm(np.maximum(np.abs(lo - c), np.abs(hi - c)), axis=1)
    out = np.full(len(lo), AMBIGUOUS)
    out[near > r] = EMPTY
    out[far < r] = FULL
    return out, np.minimum(np.abs(near - r), np.abs(far - r))


def voxel_boxes(vox):
    """Every voxel of ``vox``'s grid: integer coordinates ``(n, 3)`` and box corners."""
    g = vox.grid
    every = np.stack(np.meshgrid(*[np.arange(k) for k in g.shape], indexing="ij"),
                     -1).reshape(-1, 3)
    lo = np.stack([g.edge(a, every[:, a]) for a in range(3)], 1)
    hi = np.stack([g.edge(a, every[:, a] + 1) for a in range(3)], 1)
    return every, lo, hi


def test_sphere_classification_on_a_million_boxes():
    rng = np.random.default_rng(4)
    s = linf.Sphere((0, 0, 0), 1.0)
    lo = rng.uniform(-1.5, 1.5, (10**6, 3))
    hi = lo + rng.uniform(1e-3, 0.5, (10**6, 3))
    got = s.classify_boxes(lo, hi)
    want, margin = _brute_classify_sphere(s.center, s.r, lo, hi)
    bad = got != want
    assert np.all(margin[bad] < 1e-12)              # disagreements only at exact ties
    assert (want == AMBIGUOUS).sum() > 10**5


def test_voxelizing_a_sphere_gives_exactly_the_voxels_it_meets():
    s = linf.Sphere((0.013, -0.021, 0.007), 0.77)
    vox = ivx.voxelize(s, bounds=((-1, -1, -1), (1, 1, 1)), resolution=64)
    every, lo, hi = voxel_boxes(vox)
    want, margin = _brute_classify_sphere(s.center, s.r, lo, hi)
    got = vox.contains(every)
    assert np.all((got == (want == AMBIGUOUS)) | (margin < 1e-12))
    assert got.sum() > 0


def test_public_entry_point_and_errors():
    assert ivx.linf_distance(linf.HalfSpace((0, 0, 1), 0), [[0, 0, 2]]).tolist() == [2.0]
    with pytest.raises(TypeError, match="no max-norm distance"):
        ivx.linf_distance(object(), [[0, 0, 0]])
    with pytest.raises(ValueError, match="weights must be positive"):
        linf.Sphere((0, 0, 0), 1).distance([[1, 2, 3]], weights=(1, 0, 1))
    with pytest.raises(ValueError, match=r"points must have shape \(n, 3\)"):
        linf.Sphere((0, 0, 0), 1).distance([[1, 2]])


def test_voxelizing_a_rotated_box_gives_exactly_the_voxels_it_meets():
    """Oracle: the exact box-triangle test against the box's 12 faces (another algorithm)."""
    from implicitvox.triangles.tribox import Triangles
    rng = np.random.default_rng(5)
    corners = (CUBE - 0.5) * [1.3, 0.9, 0.6] @ _rotation(rng).T + 0.05
    poly = linf.ConvexPolyhedron.from_points(corners)
    vox = ivx.voxelize(poly, bounds=((-1, -1, -1), (1, 1, 1)), resolution=48)
    from scipy.spatial import ConvexHull
    faces = ConvexHull(corners).simplices
    tris = Triangles(corners[faces])
    every, lo, hi = voxel_boxes(vox)
    want = np.zeros(len(every), dtype=bool)
    for t in range(len(faces)):
        want |= tris.meet_boxes(np.full(len(every), t), lo, hi)
    got = vox.contains(every)
    assert want.sum() > 1000
    assert np.array_equal(got, want)


def near_surface(rng, surface_points, n, spread):
    """Points scattered around given surface points (edges, rims, apexes): ``spread`` wide."""
    base = surface_points[rng.integers(0, len(surface_points), n)]
    return base + rng.normal(size=(n, 3)) * spread * rng.choice([1e-9, 1e-4, 1e-1], (n, 1))


def check_against_oracle(d, p, w, support, inside):
    """D matches the dual brute force outside and the corner bisection inside, to 1e-9
    relative, or 1e-12 absolute for the points within 1e-3 of the surface (the
    coordinates, about 1, are themselves rounded at 1e-16). The duality bound holds
    from below to the same 1e-12 absolute: the kernels accept a contact up to their
    tolerance (``cylinder._TOL``, 1e-12) past an edge or rim, which can only make the
    distance smaller (a voxel test that errs, errs towards keeping the voxel)."""
    out = d > 0
    lower = dual_distance(support, p[out], w[out])
    depth = corner_depth(inside, p[~out], w[~out])
    assert np.all(lower <= d[out] * (1 + 1e-12) + 1e-12)         # a bound on the true value
    np.testing.assert_allclose(d[out], lower, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(d[~out], depth, rtol=1e-9, atol=1e-12)
    return out.sum(), (~out).sum()


def test_ellipsoid_matches_brute_force():
    """10^4 points (a quarter in the suite: tests/support/sweeps.py): spread around, near
    the surface, near the axis ends (the vertices of the support function); against
    duality (outside) and corner bisection (inside)."""
    rng = np.random.default_rng(6)
    e = linf.Ellipsoid((0.1, -0.2, 0.3), (1.5, 0.7, 0.4), _rotation(rng))
    ends = e.center + (e.rotation * e.radii).T
    ends = np.concatenate([ends, 2 * e.center - ends])
    on_surface = e.center + rng.normal(size=(sweeps.size(2000), 3))
    y = on_surface - e.center
    on_surface = e.center + y / np.sqrt(np.einsum("ni,ij,nj->n", y, e.Q, y))[:, None]
    p = np.concatenate([rng.normal(size=(sweeps.size(5000), 3)) * 1.5,
                        near_surface(rng, ends, sweeps.size(1000), 1.0),
                        near_surface(rng, on_surface, sweeps.size(4000), 1.0)])
    w = rng.uniform(0.5, 2, (len(p), 3))
    d = e.distance(p, w)
    inside = lambda X: np.einsum("...i,ij,...j->...", X - e.center, e.Q, X - e.center) <= 1
    n_out, n_in = check_against_oracle(d, p, w, ellipsoid_support(e.center, e.Qinv), inside)
    assert n_out > 0.3 * len(p) and n_in > 0.1 * len(p)
    sphere = linf.Sphere((0.1, 0.2, 0.3), 0.8)
    as_ellipsoid = linf.Ellipsoid((0.1, 0.2, 0.3), (0.8, 0.8, 0.8))
    q = rng.normal(size=(10_000, 3))
    ww = rng.uniform(0.5, 2, (10_000, 3))
    assert np.allclose(as_ellipsoid.distance(q, ww), sphere.distance(q, ww), rtol=1e-12,
                       atol=1e-14)


def test_voxelizing_a_rotated_ellipsoid_gives_exactly_the_voxels_it_meets():
    """Oracle: a voxel meets the surface iff the quadric's minimum over the box is <= 1
    and its maximum (at a corner: the quadric is convex) is >= 1; the minimum over the
    box by a bounded QP (L-BFGS-B), checked only away from ties."""
    from scipy.optimize import minimize
    rng = np.random.default_rng(7)
    e = linf.Ellipsoid((0.05, -0.03, 0.02), (0.9, 0.5, 0.3), _rotation(rng))
    vox = ivx.voxelize(e, bounds=((-1, -1, -1), (1, 1, 1)), resolution=32)
    every, lo, hi = voxel_boxes(vox)
    corners = lo[:, None, :] + signs_box()[None] * (hi - lo)[:, None, :]
    y = corners - e.center
    qmax = np.einsum("nci,ij,ncj->nc", y, e.Q, y).max(axis=1)
    got = vox.contains(every)
    checked = 0
    for k in np.flatnonzero(qmax >= 1):
        f = lambda v: (v - e.center) @ e.Q @ (v - e.center)
        r = minimize(f, 0.5 * (lo[k] + hi[k]), bounds=list(zip(lo[k], hi[k])), method="L-BFGS-B",
                     jac=lambda v: 2 * e.Q @ (v - e.center), options={"ftol": 1e-15, "gtol": 1e-12})
        qmin = r.fun
        if abs(qmin - 1) > 1e-6 and abs(qmax[k] - 1) > 1e-9:
            assert got[k] == (qmin <= 1), k
            checked += 1
    assert not got[qmax < 1 - 1e-9].any()              # voxels inside: never output
    assert checked > 1000


def signs_box():
    return np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)], dtype=float)


def _cylinder_constraints(cyl):
    """K as concave constraints: 0 <= s <= h and R(s) - rho >= 0 (a convex set)."""
    def g(v):
        y = v[:3] - cyl.c
        s = y @ cyl.a
        perp = y - s * cyl.a               # not |y|^2 - s^2: that cancels near the axis
        return np.array([s, cyl.h - s, cyl.radius(s) - np.sqrt(perp @ perp)])
    return g


CYLINDERS = {"cylinder z": ((0, 0, 1), 0.5, 0.5), "cylinder x": ((1, 0, 0), 0.5, 0.5),
             "cylinder rotated": (None, 0.5, 0.5), "frustum rotated": (None, 0.5, 0.2),
             "cone x, apex at the base": ((1, 0, 0), 0.0, 0.5),
             "cone rotated": (None, 0.6, 0.0)}


def _rims(cyl, n, rng):
    """Points on the two rim circles (an apex where a radius is 0)."""
    u = np.cross(cyl.a, [1.0, 0, 0] if abs(cyl.a[0]) < 0.9 else [0, 1.0, 0])
    u /= np.linalg.norm(u)
    v = np.cross(cyl.a, u)
    ang = rng.uniform(0, 2 * np.pi, (n, 1))
    ring = np.cos(ang) * u + np.sin(ang) * v
    end = rng.integers(0, 2, (n, 1))
    return cyl.c + end * cyl.h * cyl.a + np.where(end, cyl.r2, cyl.r1) * ring


@pytest.mark.parametrize("name", list(CYLINDERS))
def test_cylinder_matches_brute_force(name):
    """10^4 points (a quarter in the suite: tests/support/sweeps.py): spread around, on
    and near the axis line (the degenerate case of the side's quadratic), near the rims
    and apexes; duality outside, corner bisection inside."""
    rng = np.random.default_rng(len(name))
    axis, r1, r2 = CYLINDERS[name]
    a = _rotation(rng)[:, 0] if axis is None else axis
    cyl = linf.Frustum((0.1, 0.2, -0.3), a, 1.2, r1, r2)
    p = np.concatenate([rng.normal(size=(sweeps.size(5000), 3)) * 1.2,
                        cyl.c + rng.uniform(-0.5, 1.7, (sweeps.size(2000), 1)) * cyl.a,
                        near_surface(rng, _rims(cyl, sweeps.size(1000), rng), sweeps.size(3000),
                                     1.0)])
    w = rng.uniform(0.5, 2, (len(p), 3))
    d = cyl.distance(p, w)

    def inside(X):
        y = X - cyl.c
        s = y @ cyl.a
        perp = y - s[..., None] * cyl.a
        return (s >= 0) & (s <= cyl.h) & (np.sqrt(np.sum(perp * perp, -1)) <= cyl.radius(s))

    support = frustum_support(cyl.c, cyl.a, cyl.h, cyl.r1, cyl.r2)
    n_out, n_in = check_against_oracle(d, p, w, support, inside)
    assert n_out > 0.3 * len(p) and n_in > 0.05 * len(p)


def test_voxelizing_a_rotated_cylinder_gives_exactly_the_voxels_it_meets():
    """Oracle, away from ties: a voxel meets the surface iff it meets K (a feasibility
    problem, SLSQP over the box) and not all 8 corners are in K (K is convex)."""
    from scipy.optimize import minimize
    rng = np.random.default_rng(13)
    cyl = linf.Cylinder((-0.3, -0.2, -0.4), _rotation(rng)[:, 0], 1.1, 0.35)
    assert isinstance(cyl, linf.Frustum) and cyl.r1 == cyl.r2 == 0.35
    vox = ivx.voxelize(cyl, bounds=((-1, -1, -1), (1, 1, 1)), resolution=32)
    g = _cylinder_constraints(cyl)
    every, lo, hi = voxel_boxes(vox)
    got = vox.contains(every)
    corners = lo[:, None, :] + signs_box()[None] * (hi - lo)[:, None, :]
    all_in = np.array([all(g(c).min() >= 0 for c in cs) for cs in corners])
    assert not got[all_in].any()
    centre = 0.5 * (lo + hi)
    near = np.flatnonzero(~all_in & (np.linalg.norm(centre - (cyl.c + 0.55 * cyl.a), axis=1)
                                     < 1.2))
    checked = 0
    for k in rng.choice(near, min(len(near), 1500), replace=False):
        s_corners = (corners[k] - cyl.c) @ cyl.a
        if s_corners.max() < 0 or s_corners.min() > cyl.h:      # the box misses the slab
            assert not got[k]
            checked += 1
            continue

        def rho2(x):
            perp = (x - cyl.c) - ((x - cyl.c) @ cyl.a) * cyl.a
            return perp @ perp
        # min of the (convex) squared distance to the axis over box and slab: a QP
        cons = [{"type": "ineq", "fun": lambda x: (x - cyl.c) @ cyl.a},
                {"type": "ineq", "fun": lambda x: cyl.h - (x - cyl.c) @ cyl.a}]
        r = minimize(rho2, centre[k], bounds=list(zip(lo[k], hi[k])), constraints=cons,
                     method="SLSQP", options={"ftol": 1e-15, "maxiter": 500})
        if abs(r.fun - cyl.r1 ** 2) > 1e-7:
            assert got[k] == (r.fun <= cyl.r1 ** 2), (k, r.fun)
            checked += 1
    assert checked > 500


# -- the torus ------------------------------------------------------------------------------
TORUS_AXES = {"y": "y", "x": "x", "z": "z",
              "random": (0.48, -0.62, 0.62),
              "in the xy plane (a_z = 0)": (1.0, -1.0, 0.0),
              "1e-9 off the xy plane": (0.6, 0.8, 1e-9),
              "3e-8 off the xy plane": (0.6, 0.8, 3e-8),
              "1e-7 off the z axis": (1e-7, 0.0, 1.0),
              "rotation round-off (a_z = 1e-17)": (0.8, 0.6, 1e-17)}


def test_quartic_real_roots_against_numpy():
    """The vertex contacts' quartic solver: four real roots, symmetric ones (the
    biquadratic case) and double roots, against the roots they were built from; random
    quartics (two real roots, or none) against numpy.roots. Every real root is found
    (a double root to about sqrt(eps)), none is invented."""
    from implicitvox.linf.torus_frame import _quartic_real_roots
    rng = np.random.default_rng(11)
    n = 4000
    real = rng.normal(size=(n, 4)) * rng.uniform(0.1, 3, (n, 1))
    real[: n // 4, 2:] = -real[: n // 4, :2]                      # +-a, +-b: biquadratic
    real[n // 4: n // 2, 1] = real[n // 4: n // 2, 0]               # a double root
    polys = np.array([np.poly(r) for r in real])
    mixed = rng.normal(size=(n, 5))
    mixed[:, 0] = 1.0
    mixed_roots = [np.roots(m) for m in mixed]

    def close(values, targets):
        # a root within 1e-2 of another is ill-conditioned (a double root moves by
        # sqrt(eps), a near-triple one by eps^(1/3)): 1e-3 there
        def tol(v):
            crowd = np.sort(np.abs(np.concatenate([values, targets]) - v))
            return 1e-6 * (1 + abs(v)) if len(crowd) < 3 or crowd[2] > 1e-2 else 1e-3
        return all(np.min(np.abs(targets - v), initial=np.inf) <= tol(v) for v in values)
    for coeffs, truth in ((polys, list(real)), (mixed, mixed_roots)):
        got = _quartic_real_roots(*coeffs[:, 1:].T)
        for i in range(n):
            mine = got[i][np.isfinite(got[i])]
            t = np.asarray(truth[i])
            assert close(t.real[np.abs(t.imag) <= 1e-9], mine), (coeffs[i], mine, t)
            assert close(mine, t.real[np.abs(t.imag) <= 1e-6]), (coeffs[i], mine, t)


def _torus_frame(tor):
    """An orthonormal pair across the torus axis."""
    a = tor.unit_axis
    e1 = np.eye(3)[int(np.argmin(np.abs(a)))]
    e1 = e1 - (e1 @ a) * a
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1)


@pytest.mark.parametrize("axis, n", [("y", sweeps.size(10_000)), ("x", 2000), ("z", 2000),
                                     ("random", sweeps.size(10_000)),
                                     ("in the xy plane (a_z = 0)", 2000),
                                     ("1e-9 off the xy plane", 2000),
                                     ("3e-8 off the xy plane", 2000),
                                     ("1e-7 off the z axis", 2000),
                                     ("rotation round-off (a_z = 1e-17)", 2000)])
def test_torus_matches_brute_force(axis, n):
    """Points spread around, near the surface (1e-9 to 1e-1 away), on the axis, in the
    equatorial plane, near the inner and outer equators and the top and bottom circles
    (where the surface's normal is along the axis: degenerate contacts), with weights;
    the axis along x, y, z (the exact rectangle method), and in general orientation (the
    contact equations) - random, exactly in a coordinate plane (the degenerate
    silhouette), and within 1e-17, 1e-9 and 1e-7 of the degenerate cases.
    Brute force: the max-norm distance to a dense sampling of the surface parameters,
    refined by nested golden sections (tests.support.linf_oracle). Any surface point bounds the
    distance from above, so the distance may never exceed the oracle; where the oracle
    is larger (its refinement can stall where the norm has a kink), SLSQP from 72 starts
    over the surface parameters must agree to 1e-9."""
    rng = np.random.default_rng(sum(map(ord, axis)))
    tor = linf.Torus((0.1, -0.2, 0.3), TORUS_AXES[axis], 1.0, 0.3)
    assert (tor.axis is None) == (len(axis) > 1)          # which method is under test
    along = tor.unit_axis
    e1, e2 = _torus_frame(tor)
    ang = rng.uniform(0, 2 * np.pi, (n, 1))
    ring = np.cos(ang) * e1 + np.sin(ang) * e2
    circles = np.concatenate([tor.center + 1.3 * ring[: n // 5], tor.center + 0.7 * ring[: n // 5],
                              tor.center + ring[: n // 5] + 0.3 * along,
                              tor.center + ring[: n // 5] - 0.3 * along])
    p = np.concatenate([tor.center + rng.uniform(-1.5, 1.5, (n // 2, 3)),
                        tor.center + rng.uniform(-0.5, 0.5, (n // 10, 1)) * along,
                        tor.center + rng.uniform(0.0, 1.5, (n // 10, 1)) * ring[: n // 10],
                        near_surface(rng, circles, n // 5, 1.0)])
    p = np.concatenate([p, tor.center + rng.uniform(-1.5, 1.5, (n - len(p), 3))])
    w = rng.uniform(0.5, 2, (n, 3))
    d = tor.distance(p, w)
    q = p - tor.center
    height = q @ along
    rho = np.linalg.norm(q - height[:, None] * along, axis=1)
    inside = np.hypot(rho - 1.0, height) < 0.3
    assert np.array_equal(d < 0, inside)                  # the sign
    oracle = torus_surface_distance(tor.center, along, tor.R, tor.r, p, w)
    tol = 1e-9 * np.abs(d) + 1e-12
    assert np.all(np.abs(d) <= oracle + tol)               # never above a surface point
    again = np.flatnonzero(oracle - np.abs(d) > tol)
    assert len(again) <= 0.01 * n
    for i in again:
        assert abs(d[i]) == pytest.approx(_torus_slsqp(tor, p[i], w[i]), rel=1e-9, abs=1e-12)


def _torus_slsqp(tor, p, w):
    """min s over (u, v, s) with |p - q(u, v)| <= s w, from 72 starts; feasible ends only
    (the Jacobians analytic: SLSQP's finite differences cost three times as many calls)."""
    from scipy.optimize import minimize
    e1, e2 = _torus_frame(tor)
    q = p - tor.center
    a = tor.unit_axis

    def surface(uv):
        ring = tor.R + tor.r * np.cos(uv[1])
        return ring * (np.cos(uv[0]) * e1 + np.sin(uv[0]) * e2) + tor.r * np.sin(uv[1]) * a

    def tangents(x):                      # columns: dq/du, dq/dv, and w for s
        u, v = x[0], x[1]
        radial = np.cos(u) * e1 + np.sin(u) * e2
        du = (tor.R + tor.r * np.cos(v)) * (np.cos(u) * e2 - np.sin(u) * e1)
        dv = -tor.r * np.sin(v) * radial + tor.r * np.cos(v) * a
        return du, dv
    cons = [{"type": "ineq", "fun": lambda x: x[2] * w - (q - surface(x[:2])),
             "jac": lambda x: np.column_stack([*tangents(x), w])},
            {"type": "ineq", "fun": lambda x: x[2] * w + (q - surface(x[:2])),
             "jac": lambda x: np.column_stack([*(-t for t in tangents(x)), w])}]
    best = np.inf
    for u0 in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        for v0 in np.linspace(0, 2 * np.pi, 6, endpoint=False):
            r = minimize(lambda x: x[2], np.r_[u0, v0, 3.0], jac=lambda x: np.array([0, 0, 1.0]),
                         constraints=cons, method="SLSQP",
                         options={"ftol": 1e-16, "maxiter": 500})
            if np.max(np.abs(q - surface(r.x[:2])) - r.x[2] * w) < 1e-13:
                best = min(best, r.x[2])
    return best


def test_torus_errors_and_voxels():
    with pytest.raises(ValueError, match="ring torus"):
        linf.Torus((0, 0, 0), (1, 1, 0), 0.2, 0.3)          # a spindle torus, tilted
    with pytest.raises(ValueError, match="non-zero"):
        linf.Torus((0, 0, 0), (0, 0, 0), 1.0, 0.2)
    with pytest.raises(ValueError, match="positive"):
        linf.Torus((0, 0, 0), "z", 1.0, -0.2)
    with pytest.raises(ValueError, match="axis"):
        linf.Torus((0, 0, 0), "w", 1.0, 0.2)


def _circle_box_distance(R, lo, hi, n=2048, basins=3, chunk=2048):
    """Euclidean distance from the circle of radius R about the z axis (z = 0) to boxes:
    a dense sweep of the circle, refined by golden sections around its best minima
    (``chunk`` boxes at a time: the sweep holds ``n`` points per box)."""
    if len(lo) > chunk:
        return np.concatenate([_circle_box_distance(R, lo[s:s + chunk], hi[s:s + chunk], n,
                                                    basins, chunk)
                               for s in range(0, len(lo), chunk)])
    u = np.arange(n) * (2 * np.pi / n)

    def dist(uu):
        c = np.stack([R * np.cos(uu), R * np.sin(uu), np.zeros_like(uu)], -1)
        return np.linalg.norm(c - np.clip(c, lo[:, None] if np.ndim(uu) == 2 else lo,
                                          hi[:, None] if np.ndim(uu) == 2 else hi), axis=-1)
    f = dist(np.broadcast_to(u, (len(lo), n)))
    local = (f <= np.roll(f, 1, axis=1)) & (f <= np.roll(f, -1, axis=1))
    picks = np.argsort(np.where(local, f, np.inf), axis=1)[:, :basins]
    best = f.min(axis=1)
    from tests.support.linf_oracle import _golden_max
    for b in range(basins):
        u0 = u[picks[:, b]]
        best = np.minimum(best, -_golden_max(lambda t: -dist(t), u0 - 2 * np.pi / n,
                                             u0 + 2 * np.pi / n, 60))
    return best


def test_voxelizing_a_torus_gives_exactly_the_voxels_it_meets():
    """A torus turned onto the y axis, at 48^3: a voxel meets the surface iff its distance
    to the core circle is at most r (sweep of the circle, tests above) and its farthest
    point is beyond r (its 8 corners and the point nearest the axis: the distance to the
    circle grows away from the circle's plane and is largest at the box's extremes in
    rho). Checked where neither quantity is within 1e-9 of r (ties)."""
    import csg
    solid = csg.Torus(0.8, 0.25).rotate((1, 0, 0), 90).translate((0.013, -0.021, 0.017))
    vox = solid.voxelize(48)
    every, lo, hi = voxel_boxes(vox)
    c = np.array([0.013, -0.021, 0.017])
    perm = [0, 2, 1]                       # the torus axis (y) last: local (x, z, y)
    llo, lhi = (lo - c)[:, perm], (hi - c)[:, perm]
    near = _circle_box_distance(0.8, llo, lhi)
    corners = llo[:, None, :] + CUBE[None] * (lhi - llo)[:, None, :]
    rho_c = np.hypot(corners[..., 0], corners[..., 1])
    far_sq = np.max((rho_c - 0.8) ** 2, axis=1)
    nearest = np.clip(0.0, llo[:, :2], lhi[:, :2])
    rho_n = np.hypot(nearest[:, 0], nearest[:, 1])
    far_sq = np.maximum(far_sq, (rho_n - 0.8) ** 2)
    far = np.sqrt(far_sq + np.max(np.abs(np.stack([llo[:, 2], lhi[:, 2]], 1)), axis=1) ** 2)
    truth = (near <= 0.25) & (far >= 0.25)
    sure = (np.abs(near - 0.25) > 1e-9) & (np.abs(far - 0.25) > 1e-9)
    got = vox.contains(every)
    assert np.array_equal(got[sure], truth[sure])
    assert sure.mean() > 0.999 and truth.sum() > 5000


def _tilted_circle_box_range(c, e1, e2, a, R, lo, hi, n=256, edge_samples=64):
    """Least and greatest distance from the circle ``c + R (cos e1 + sin e2)`` to points of
    boxes ``[lo, hi]``, by brute force. Least: a sweep of the circle (distance to the
    clipped point), refined by golden sections around its best minima. Greatest: the
    squared distance ``|y|^2 + R^2 - 2 R rho`` has no interior maximum on a face or in
    the box except on the axis (where ``rho`` has its kink), and along the axis it is
    convex; so the greatest is at a corner, where the axis crosses a face, or on an
    edge (a dense sweep of each edge refined by golden sections)."""
    from tests.support.linf_oracle import _golden_max

    def to_circle(x):
        y = x - c
        h = y @ a
        rho = np.linalg.norm(y - h[..., None] * a, axis=-1)
        return np.sqrt((rho - R) ** 2 + h ** 2)

    u = np.arange(n) * (2 * np.pi / n)

    def near_at(t):
        q = c + R * (np.cos(t)[..., None] * e1 + np.sin(t)[..., None] * e2)
        lo_, hi_ = (lo[:, None], hi[:, None]) if np.ndim(t) == 2 else (lo, hi)
        return np.linalg.norm(q - np.clip(q, lo_, hi_), axis=-1)
    f = near_at(np.broadcast_to(u, (len(lo), n)))
    local = (f <= np.roll(f, 1, axis=1)) & (f <= np.roll(f, -1, axis=1))
    picks = np.argsort(np.where(local, f, np.inf), axis=1)[:, :3]
    near = f.min(axis=1)
    for b in range(3):
        u0 = u[picks[:, b]]
        near = np.minimum(near, -_golden_max(lambda t: -near_at(t), u0 - 2 * np.pi / n,
                                             u0 + 2 * np.pi / n, 60))
    corners = lo[:, None, :] + CUBE[None] * (hi - lo)[:, None, :]
    far = to_circle(corners).max(axis=1)
    for axis_k in range(3):                      # the axis line through each face plane
        for side in (lo, hi):
            with np.errstate(divide="ignore", invalid="ignore"):   # axis along the face
                t = (side[:, axis_k] - c[axis_k]) / a[axis_k]
                x = c + t[:, None] * a
                ok = np.all((x >= lo - 1e-12) & (x <= hi + 1e-12), axis=1)
            far = np.where(ok, np.maximum(far, to_circle(np.where(ok[:, None], x, lo))), far)
    s = np.linspace(0.0, 1.0, edge_samples)
    for k in range(3):                           # the 12 edges along each axis
        for corner in CUBE[CUBE[:, k] == 0]:
            start = lo + corner * (hi - lo)

            def along(t):
                x = np.array(start, dtype=float)
                x = np.broadcast_to(x[:, None, :] if np.ndim(t) == 2 else x,
                                    (len(lo),) + np.shape(t)[1:] + (3,)).copy()
                x[..., k] = (lo[:, k:k + 1] if np.ndim(t) == 2 else lo[:, k]) + t * (
                    (hi - lo)[:, k:k + 1] if np.ndim(t) == 2 else (hi - lo)[:, k])
                return to_circle(x)
            g = along(np.broadcast_to(s, (len(lo), edge_samples)))
            far = np.maximum(far, g.max(axis=1))
            top = np.argmax(g, axis=1)
            ds = s[1]
            t0 = s[top]
            far = np.maximum(far, _golden_max(along, np.clip(t0 - ds, 0, 1), np.clip(t0 + ds, 0, 1),
                                              60))
    return near, far


def test_voxelizing_a_tilted_torus_gives_exactly_the_voxels_it_meets():
    """A torus turned about a skew axis (general orientation: the contact equations), at
    40^3: a voxel meets the surface iff its least distance to the core circle is at most
    r and its greatest is at least r (brute force above). Boxes farther than half their
    diagonal from the surface are settled by the Euclidean distance of their centre;
    the rest are checked wherever neither distance is within 1e-9 of r (ties)."""
    import csg
    R, r = 0.8, 0.25
    solid = csg.Torus(R, r).rotate((1.0, 2.0, 0.5), 37).translate((0.013, -0.021, 0.017))
    vox = solid.voxelize(40)
    every, lo, hi = voxel_boxes(vox)
    m = csg.rotation_matrix((1.0, 2.0, 0.5), 37)
    e1, e2, a = m[:, 0], m[:, 1], m[:, 2]
    c = np.array([0.013, -0.021, 0.017])
    assert linf.Torus(c, a, R, r).axis is None               # general orientation
    centre, half = 0.5 * (lo + hi), 0.5 * np.linalg.norm(hi - lo, axis=1)
    y = centre - c
    h = y @ a
    rho = np.linalg.norm(y - h[:, None] * a, axis=1)
    gap = np.sqrt((rho - R) ** 2 + h ** 2) - r
    unsure = np.abs(gap) <= half + 1e-9
    near, far = _tilted_circle_box_range(c, e1, e2, a, R, lo[unsure], hi[unsure])
    truth = np.zeros(len(every), dtype=bool)
    truth[unsure] = (near <= r) & (far >= r)
    sure = np.ones(len(every), dtype=bool)
    sure[unsure] = (np.abs(near - r) > 1e-9) & (np.abs(far - r) > 1e-9)
    got = vox.contains(every)
    assert np.array_equal(got[sure], truth[sure])
    assert sure.mean() > 0.999 and truth.sum() > 2500


@pytest.mark.parametrize("turned", [True, False])
def test_torus_classification_on_random_boxes(turned):
    """classify_boxes of a torus in general orientation (and with its axis along y) on
    10^6 boxes (a quarter in the suite: tests/support/sweeps.py; sides 1e-3 to 0.3)
    against the brute-force least and greatest distance to its core circle; boxes whose
    centre is farther from the surface than half their diagonal are settled by that
    alone. A disagreement only where a distance is within 1e-9 of r (a tie)."""
    rng = np.random.default_rng(8)
    R, r = 1.0, 0.3
    c = np.array([0.1, -0.2, 0.05])
    a = _rotation(rng)[:, 2] if turned else np.array([0.0, 1.0, 0.0])
    tor = linf.Torus(c, a, R, r)
    assert (tor.axis is None) == turned
    lo = rng.uniform(-1.5, 1.5, (sweeps.size(10**6), 3))
    hi = lo + rng.uniform(1e-3, 0.3, (len(lo), 3))
    got = tor.classify_boxes(lo, hi)
    y = 0.5 * (lo + hi) - c
    h = y @ a
    gap = np.hypot(np.linalg.norm(y - h[:, None] * a, axis=1) - R, h) - r
    half = 0.5 * np.linalg.norm(hi - lo, axis=1)
    want = np.where(gap > 0, EMPTY, FULL).astype(got.dtype)
    tie = np.zeros(len(lo), dtype=bool)
    unsure = np.flatnonzero(np.abs(gap) <= half + 1e-9)
    e1, e2 = _torus_frame(tor)
    for part in np.array_split(unsure, max(1, len(unsure) // 50_000)):
        near, far = _tilted_circle_box_range(c, e1, e2, a, R, lo[part], hi[part], n=128,
                                             edge_samples=32)
        want[part] = np.where(near > r, EMPTY, np.where(far < r, FULL, AMBIGUOUS))
        tie[part] = (np.abs(near - r) <= 1e-9) | (np.abs(far - r) <= 1e-9)
    bad = got != want
    assert np.all(tie[bad])
    assert (want == AMBIGUOUS).sum() > 0.09 * len(lo)


# -- general quadrics ----------------------------------------------------------------------
QUADRICS = {"hyperboloid of one sheet": (np.diag([1.0, 2.0, -0.5]), np.zeros(3), -0.3),
            "hyperboloid of two sheets": (np.diag([-1.0, 2.0, -0.5]), np.zeros(3), 0.3),
            "elliptic paraboloid": (np.diag([1.0, 0.5, 0.0]), np.array([0, 0, -1.0]), 0.0),
            "cone": (np.diag([1.0, 1.0, -0.7]), np.zeros(3), 0.0),
            "infinite cylinder": (np.diag([1.0, 1.0, 0.0]), np.zeros(3), -0.4),
            "two planes": (np.diag([1.0, 0.0, 0.0]), np.zeros(3), -0.2),
            "saddle": (np.array([[0, 1.0, 0], [1.0, 0, 0], [0, 0, 0]]), np.array([0, 0, -1.0]),
                       0.0)}


def _on_quadric(Q, p, steps=60):
    """Points moved onto Q = 0 by Newton steps along the gradient (those that converge)."""
    for _ in range(steps):
        g = 2 * p @ Q.A + Q.b
        gg = np.sum(g * g, axis=1)
        p = p - (Q.value(p) / np.where(gg > 0, gg, 1.0))[:, None] * g
    return p[np.abs(Q.value(p)) < 1e-12]


@pytest.mark.parametrize("name", list(QUADRICS))
@pytest.mark.parametrize("turned", [False, True])
def test_quadric_matches_brute_force_on_ten_thousand_points(name, turned):
    """Points spread around, near the surface (1e-9 to 1e-1 away), on the local axes (the
    degenerate cases: cone apex, axis of a cylinder, the saddle's lines), against an
    independent brute force: bisection on the box size with the exact least and
    greatest value of Q over a box (all 27 faces' stationary points)."""
    rng = np.random.default_rng(len(name) + 7 * turned)
    A, b, c = QUADRICS[name]
    rotation = _rotation(rng) if turned else None
    Q = linf.Quadric.from_local(A, b, c, rotation, (0.1, -0.2, 0.05))
    local_axes = rng.uniform(-1.5, 1.5, (1000, 1)) * np.eye(3)[rng.integers(0, 3, 1000)]
    axes = local_axes @ (np.eye(3) if rotation is None else rotation).T + [0.1, -0.2, 0.05]
    surface = _on_quadric(Q, rng.normal(size=(6000, 3)))
    p = np.concatenate([rng.normal(size=(5000, 3)) * 1.2, axes,
                        near_surface(rng, surface, 4000, 1.0)])
    w = rng.uniform(0.5, 2, (len(p), 3))
    d = Q.distance(p, w)
    assert np.array_equal(d < 0, Q.value(p) < 0)
    brute = quadric_distance(Q.A, Q.b, Q.c, p, w)
    np.testing.assert_allclose(np.abs(d), brute, rtol=1e-9, atol=1e-12)


def test_voxelizing_a_turned_hyperboloid_gives_exactly_the_voxels_it_meets():
    """Oracle: a voxel meets Q = 0 iff Q's least value over it is <= 0 <= its greatest
    (exact, by the 27 faces); checked away from ties (both ends farther than 1e-12)."""
    rng = np.random.default_rng(11)
    Q = linf.Quadric.from_local(np.diag([1.0, 2.0, -0.5]), np.zeros(3), -0.3, _rotation(rng),
                                (0.03, -0.02, 0.01))
    vox = ivx.voxelize(Q, bounds=((-1, -1, -1), (1, 1, 1)), resolution=40)
    every, lo, hi = voxel_boxes(vox)
    vmin, vmax = quadric_box_range(Q.A, Q.b, Q.c, lo, hi)
    truth = (vmin <= 0) & (vmax >= 0)
    sure = (np.abs(vmin) > 1e-12) & (np.abs(vmax) > 1e-12)
    got = vox.contains(every)
    assert np.array_equal(got[sure], truth[sure])
    assert sure.mean() > 0.999 and truth.sum() > 2500


def test_quadric_errors():
    with pytest.raises(ValueError, match="symmetric"):
        linf.Quadric([[1, 2, 0], [0, 1, 0], [0, 0, 1]], [0, 0, 0], -1)
    with pytest.raises(ValueError, match="no surface"):
        linf.Quadric(np.zeros((3, 3)), [0, 0, 0], 1)
    with pytest.raises(ValueError, match="orthonormal"):
        linf.Quadric.from_local(np.eye(3), [0, 0, 0], -1, rotation=2 * np.eye(3))


@pytest.mark.parametrize("name", ["hyperboloid of one sheet", "cone", "saddle", "ellipsoid"])
def test_quadric_classification_on_random_boxes(name):
    """classify_boxes against the exact range of Q over each box (10^6 boxes, a quarter
    in the suite: tests/support/sweeps.py); a disagreement only
    where an end of the range is within 1e-12 of 0 (a tie). The ellipsoid is
    linf.Ellipsoid's own test, checked against its quadric."""
    rng = np.random.default_rng(5)
    rotation = _rotation(rng)
    if name == "ellipsoid":
        radii = np.array([1.2, 0.7, 0.4])
        prim = linf.Ellipsoid((0.1, -0.2, 0.05), radii, rotation)
        Q = linf.Quadric.from_local(np.diag(radii ** -2.0), np.zeros(3), -1.0, rotation,
                                    (0.1, -0.2, 0.05))
    else:
        A, b, c = QUADRICS[name]
        prim = Q = linf.Quadric.from_local(A, b, c, rotation, (0.1, -0.2, 0.05))
    lo = rng.uniform(-1.5, 1.5, (sweeps.size(10**6), 3))
    hi = lo + rng.uniform(1e-3, 0.5, (len(lo), 3))
    got = prim.classify_boxes(lo, hi)
    vmin, vmax = quadric_box_range(Q.A, Q.b, Q.c, lo, hi)
    want = np.where(vmin > 0, EMPTY, np.where(vmax < 0, FULL, AMBIGUOUS))
    bad = got != want
    assert np.all(np.minimum(np.abs(vmin), np.abs(vmax))[bad] < 1e-12)
    assert (want == AMBIGUOUS).sum() > 0.1 * len(lo)


def test_a_box_along_the_axes_takes_the_columns_and_the_same_bits():
    """A box along the axes (OpenSCAD's cube) is measured by columns, not by (n, F)
    products: the same operations on the same numbers, so bit for bit the general
    polytope's distance, on points inside, outside, on faces and at corners, with
    per-point and shared weights."""
    import copy
    from implicitvox.linf.polyhedron import ConvexPolyhedron
    rng = np.random.default_rng(7)
    corners = np.array([[x, y, z] for x in (-1.5, 2.0) for y in (0.0, 3.0) for z in (-0.25, 0.5)])
    box = ConvexPolyhedron.from_points(corners)
    general = copy.copy(box)
    general._axis_aligned = None
    assert box._axis_aligned is not None
    p = rng.uniform(-3, 4, (4000, 3))
    p[:500] = corners[rng.integers(0, 8, 500)]              # corners and faces: ties
    p[500:1000, 0] = rng.choice([-1.5, 2.0], 500)
    p[1000:1100] = 0.0
    for w in (rng.uniform(0.5, 2.0, (len(p), 3)), np.tile([0.25, 0.5, 2.0], (len(p), 1))):
        a, b = box.distance(p, w), general.distance(p, w)
        assert np.array_equal(a.view(np.uint64), b.view(np.uint64))
    tilted = ConvexPolyhedron.from_points(corners @ np.array([[0.8, 0.6, 0], [-0.6, 0.8, 0],
                                                               [0, 0, 1.0]]))
    assert tilted._axis_aligned is None
