"""Distance fields: measured against analytic distances, brute force and independent oracles."""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

import csg
import implicitvox as iv
from implicitvox import linf, x, y, z
from implicitvox.linf.box_tests import TIE_ULPS
from implicitvox.fields.bricks import band_bricks
from implicitvox.fields.distance_kernels import linf_by_box_test
from implicitvox.linf.euclidean import triangle_distance as triangle_euclidean
from implicitvox.triangles.inputs import as_triangles

CUBE = np.array([[a, b, c] for a in (0.0, 1.0) for b in (0.0, 1.0) for c in (0.0, 1.0)])


def _band(field):
    coords, values, errors = field.band_values()
    return field.grid.centers(coords), values, errors


def _box_euclidean(p, lo, hi):
    outside = np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0), axis=1)
    inside = -np.min(np.minimum(p - lo, hi - p), axis=1)
    return np.where(outside > 0, outside, inside)


def _linf_ball_oracle(p, centre, r, weights):
    """The weighted max-norm distance to a ball, by bisection on 'the cube meets the
    ball' (clamp the centre into the cube): independent of the contact equations."""
    lo, hi = np.zeros(len(p)), np.full(len(p), 10.0)
    inside = np.linalg.norm(p - centre, axis=1) < r
    for _ in range(80):
        t = 0.5 * (lo + hi)
        half = t[:, None] * weights
        near = np.clip(centre, p - half, p + half)
        meets = np.linalg.norm(near - centre, axis=1) <= r
        far = np.linalg.norm(np.abs(p - centre) + half, axis=1) > r  # leaves the ball
        hit = np.where(inside, far, meets)
        lo, hi = np.where(hit, lo, t), np.where(hit, t, hi)
    return np.where(inside, -hi, hi)


EXACT_CASES = {
    "sphere": (linf.Sphere((0.1, 0, 0), 0.8),
               lambda p: np.linalg.norm(p - [0.1, 0, 0], axis=1) - 0.8),
    "box": (linf.ConvexPolyhedron.from_points(CUBE * [1.0, 0.6, 0.4]),
            lambda p: _box_euclidean(p, np.zeros(3), np.array([1.0, 0.6, 0.4]))),
    "torus": (linf.Torus((0, 0, 0), (0, 0, 1), 0.7, 0.2),
              lambda p: np.hypot(np.hypot(p[:, 0], p[:, 1]) - 0.7, p[:, 2]) - 0.2),
    "cylinder": (linf.Cylinder((0, 0, -0.5), (0, 0, 1), 1.0, 0.4),
                 # the (rho, z) rectangle [0, 0.4] x [-0.5, 0.5]; the axis is no boundary
                 lambda p: _box_euclidean(np.c_[np.hypot(p[:, 0], p[:, 1]), p[:, 2],
                                                np.zeros(len(p))],
                                          np.array([-1.0, -0.5, -1.0]),
                                          np.array([0.4, 0.5, 1.0]))),
}


@pytest.mark.parametrize("name", sorted(EXACT_CASES))
def test_euclidean_fields_of_primitives_are_the_analytic_distances(name):
    shape, truth = EXACT_CASES[name]
    field = iv.distance_field(shape, 24, band=2, check_suitability=False)
    p, v, e = _band(field)
    assert field.kind == "exact" and field.count > 1000
    assert np.allclose(v, truth(p), rtol=0, atol=1e-12)
    assert field.max_error == 0.0


def test_linf_field_of_a_sphere_matches_an_independent_oracle_on_non_cubic_voxels():
    ball = linf.Sphere((0.05, 0, 0), 0.8)
    field = iv.distance_field(ball, (20, 28, 36), norm="linf", band=2)
    h = np.asarray(field.grid.voxel_size)
    assert len(set(h.tolist())) == 3
    p, v, _ = _band(field)
    oracle = _linf_ball_oracle(p, ball.center, ball.r, h / h.max())
    assert np.allclose(v, oracle, rtol=0, atol=1e-9)
    # Varadhan §5.1: the surface meets a voxel iff |D(centre)| <= its longest half-edge
    vox = iv.voxelize(ball, bounds=field.grid.bounds, voxel_size=field.grid.voxel_size)
    c = field.coords()
    meets = np.abs(v) <= h.max() / 2
    assert np.array_equal(np.sort(iv.octree.morton.encode(c[meets])),
                          np.sort(iv.octree.morton.encode(vox.coords())))


def test_band_holds_every_sample_near_the_surface():
    shape, truth = EXACT_CASES["torus"]
    band = 3
    field = iv.distance_field(shape, 32, band=band)
    g = field.grid
    ijk = np.stack(np.meshgrid(*[np.arange(n) for n in g.shape], indexing="ij"), -1).reshape(-1, 3)
    near = np.abs(truth(g.centers(ijk))) <= (band + 0.5) * g.voxel_size[0]
    stored = field.at(ijk)
    assert np.allclose(stored[near], truth(g.centers(ijk[near])), atol=1e-12)
    # beyond the band: the background with the right sign
    far = np.abs(stored) == field.background
    assert np.all(np.sign(stored[far]) == np.sign(truth(g.centers(ijk[far]))))


def test_band_bricks_dilate_by_the_band_per_axis():
    keys, active = band_bricks(np.array([[5, 9, 14]]), 2, (32, 32, 32))
    coords = iv.fields.bricks.brick_coords(keys)[active]
    assert len(coords) == 125
    assert np.abs(coords - [5, 9, 14]).max() == 2


def test_mesh_fields_equal_brute_force_over_every_triangle():
    sphere = pv.Sphere(radius=1.0, theta_resolution=8, phi_resolution=8)
    v, f = as_triangles(sphere)
    tri = v[f]
    for norm in ("euclidean", "linf"):
        field = iv.distance_field((v, f), 16, norm=norm, band=2)
        p, d, _ = _band(field)
        rows = np.repeat(np.arange(len(p)), len(tri))
        tiled = np.tile(tri, (len(p), 1, 1))
        if norm == "euclidean":
            brute = triangle_euclidean(p[rows], tiled)
        else:
            brute = linf.triangle_distance(p[rows], tiled)
        brute = brute.reshape(len(p), -1).min(axis=1)
        assert field.kind == "exact"
        assert np.allclose(np.abs(d), brute, rtol=0, atol=1e-12)
        inside = np.linalg.norm(p, axis=1) < 0.9
        assert np.all(d[inside] < 0)
        # off the band: the background, with the side proved by the mesh's solid fill
        g = field.grid
        ijk = np.stack(np.meshgrid(*[np.arange(k) for k in g.shape], indexing="ij"),
                       -1).reshape(-1, 3)
        stored = field.at(ijk)
        far = np.abs(stored) == field.background
        radius = np.linalg.norm(g.centers(ijk[far]), axis=1)
        assert far.any() and np.all(np.sign(stored[far]) == np.sign(radius - 1))


@pytest.mark.parametrize("norm", ["euclidean", "linf"])
def test_certified_distances_of_an_expression_hold_the_truth_within_1e3_voxel(norm):
    # f = |p|^2 - 1 is not a distance: the field must certify one
    field = iv.distance_field(x * x + y * y + z * z - 1, 20, band=1, norm=norm,
                              bounds=((-1.3,) * 3, (1.3,) * 3))
    p, v, e = _band(field)
    truth = np.linalg.norm(p, axis=1) - 1 if norm == "euclidean" else \
        linf.Sphere((0, 0, 0), 1.0).distance(p)
    assert field.kind == "certified"
    assert np.all(np.abs(v - truth) <= e * (1 + 1e-9) + 1e-15)
    assert field.max_error <= 1e-3 * field.grid.voxel_size[0]


def test_certified_distances_to_a_kinked_surface_keep_its_edges_and_corners():
    # f = max(|x|, |y|, |z|)^2 - 1/4 is a cube with kinks on its edges and faces'
    # diagonals; outside points' nearest points lie on edges and corners, where only
    # Clarke's generalized gradient is parallel to p - q: the search may not prune
    # those boxes (certified_kernels.pair_bounds), nor the ones on the domain's faces
    m = iv.max(iv.max(iv.abs(x), iv.abs(y)), iv.abs(z))
    field = iv.distance_field(m * m - 0.25, 16, band=2, bounds=((-0.8,) * 3, (0.8,) * 3),
                              check_suitability=False)
    p, v, e = _band(field)
    a = np.abs(p) - 0.5
    truth = np.where(np.max(a, axis=1) > 0, np.linalg.norm(np.maximum(a, 0), axis=1),
                     np.max(a, axis=1))
    assert field.kind == "certified"
    assert np.all(np.abs(v - truth) <= e * (1 + 1e-9) + 1e-15)
    corner = np.all(a > 0, axis=1)
    assert corner.sum() > 20 and field.max_error <= 1e-3 * field.grid.voxel_size[0]


def test_certified_distances_to_a_ridge_on_the_voxels_faces():
    # z = 0.3 - |x|: a roof whose ridge lies on voxel faces (x = 0), nearest to the
    # samples above it; the boxes on either side see one face's gradient over their
    # open part, so the search must take the gradients on the closed box (both sides'
    # hull) to keep them (mean_value_kernels.tape_interval_gradients(closed=True))
    field = iv.distance_field(z + iv.abs(x) - 0.3, 16, band=2,
                              bounds=((-0.8,) * 3, (0.8,) * 3), check_suitability=False)
    p, v, e = _band(field)
    ax, pz = np.abs(p[:, 0]), p[:, 2]
    t = (ax + pz - 0.3) / 2                                   # the foot on the nearer face
    on_face = ax - t >= 0
    truth = np.sign(ax + pz - 0.3) * np.where(on_face, np.abs(ax + pz - 0.3) / np.sqrt(2),
                                              np.hypot(ax, pz - 0.3))
    inside = np.where(on_face, ax - t, 0.0) < 0.7             # nearest point in the domain
    assert field.kind == "certified" and (~on_face).sum() > 50
    assert np.all((np.abs(v - truth) <= e * (1 + 1e-9) + 1e-15)[inside])
    assert field.max_error <= 1e-3 * field.grid.voxel_size[0]


def test_certified_torus_as_a_product_of_quadrics():
    R, r = 0.6, 0.25
    q = x * x + y * y + z * z + R * R - r * r
    f = q * q - 4 * R * R * (x * x + y * y)           # the quartic: not a distance
    field = iv.distance_field(f, 12, band=1, bounds=((-0.9, -0.9, -0.3), (0.9, 0.9, 0.3)),
                              check_suitability=False)
    p, v, e = _band(field)
    truth = np.hypot(np.hypot(p[:, 0], p[:, 1]) - R, p[:, 2]) - r
    assert np.all(np.abs(v - truth) <= e * (1 + 1e-9) + 1e-15)
    assert field.max_error <= 1e-3 * field.grid.voxel_size[0]


def test_linf_of_a_csg_union_by_the_box_test_is_the_min_outside():
    box = csg.Box((1, 1, 1))
    ball = csg.Sphere(r=0.6).translate((1.0, 0.5, 0.5))
    union = box | ball
    field = iv.distance_field(union, 20, norm="linf", band=2, check_suitability=False)
    assert field.kind == "box test"
    p, v, e = _band(field)
    parts = np.minimum(box.linf_distance(p), ball.linf_distance(p))
    out = parts > 0
    assert np.all(np.abs(v[out] - parts[out]) <= e[out])      # within the stored bound
    assert np.all(v[~out] <= 0) and e.max() <= 1e-13


def test_box_test_bisection_is_within_its_stored_error():
    ball = linf.Sphere((0, 0, 0), 1.0)
    p = np.array([[1.5, 0.2, -0.1], [0.1, 0.2, 0.3]])
    d, err = linf_by_box_test(ball.classify_boxes, p, None)
    # the least float up to the box test's allowance for touching within rounding
    # (TIE_ULPS ulps of the centre): the error is stored, and holds
    assert np.all(np.abs(d - ball.distance(p)) <= err)
    assert np.all(err <= 4 * TIE_ULPS * np.finfo(float).eps * (np.abs(p).max(axis=1) + np.abs(d)))


def test_reconstruction_sample_gradient_and_isosurface():
    ball = linf.Sphere((0.03, -0.02, 0.01), 0.8)
    field = iv.distance_field(ball, 32, band=3, bounds=((-1.1,) * 3, (1.1,) * 3))
    coords, values, _ = field.band_values()
    assert np.array_equal(field.sample(field.grid.centers(coords[:50])), values[:50])
    dirs = iv.meshing.hausdorff.sphere_directions(40)
    on = ball.center + 0.8 * dirs
    grad = field.gradient(on)
    cos = np.sum(grad / np.linalg.norm(grad, axis=1, keepdims=True) * dirs, axis=1)
    assert cos.min() > 0.99
    mesh = field.isosurface()
    radius = np.linalg.norm(np.asarray(mesh.points) - ball.center, axis=1)
    h = field.grid.voxel_size[0]
    assert np.abs(radius - 0.8).max() <= iv.fields.analytic_error_bound(0.8 / h) * h
    assert mesh.n_cells > 1000 and mesh.point_data["Normals"].shape == (mesh.n_points, 3)


def test_bærentzen_fig8_errors_fall_below_the_analytic_bound_and_0_1_voxel_from_r3():
    for r in (2.0, 3.0, 5.0):
        stats = iv.fields.sphere_reconstruction_errors(r, offsets=2, rays=150)
        assert stats["max"] < iv.fields.analytic_error_bound(r)
        if r >= 3:
            assert stats["max"] < 0.1
        assert 0 < stats["mean"] <= stats["max"]
    assert iv.fields.analytic_error_bound(math.sqrt(3)) == math.inf
    assert math.isclose(iv.fields.analytic_error_bound(3.0), 3 / (8 * (3 - math.sqrt(3))))


def test_suitability_sphere_cube_and_two_close_spheres():
    # a sphere of radius 10 voxels: open up to ~10 (a ball of radius 10 rolls inside),
    # closed without limit (its complement is open for every ball): r ≈ 10, suitable
    s = iv.suitability(linf.Sphere((0, 0, 0), 1.0), 21, oversample=2, max_radius=12)
    assert 9 <= s.r_open <= 10.5 and s.r_closed == 12 and s.suitable
    assert s.predicted_error == iv.fields.analytic_error_bound(s.r)
    # a cube: no ball reaches into its corners, r = 0 up to the fine grid's voxel
    cube = linf.ConvexPolyhedron.from_points(CUBE)
    s = iv.suitability(cube, 16, oversample=4, max_radius=4)
    assert s.r_open < 1 and not s.suitable
    assert "no bound on the trilinear error" in str(s) and "inf" not in str(s)
    # two spheres 2 voxels apart: the gap closes for any ball wider than it, r ≈ 1
    pitch = 4.0 / 31
    pair = csg.Sphere(r=1.0) | csg.Sphere(r=1.0).translate((2 + 2 * pitch, 0, 0))
    s = iv.suitability(pair, 32, oversample=2, max_radius=4)
    assert 0.5 <= s.r_closed <= 1.5 and s.r_open > 3 and not s.suitable


def test_suitability_takes_the_finest_grid_memory_holds(monkeypatch):
    # by default the finest of 4, 2, 1 fine voxels per voxel whose padded grid has at
    # most SUITABILITY_FINE_CELLS voxels; coarser, the answer is still near r
    import importlib
    module = importlib.import_module("implicitvox.fields.suitability")
    sphere = linf.Sphere((0, 0, 0), 1.0)
    assert iv.suitability(sphere, 21, max_radius=12).oversample == 4
    monkeypatch.setattr(module, "SUITABILITY_FINE_CELLS", 100 ** 3)
    s = iv.suitability(sphere, 21, max_radius=12)
    assert s.oversample == 2 and 9 <= s.r_open <= 10.5 and s.suitable
    monkeypatch.setattr(module, "SUITABILITY_FINE_CELLS", 10)
    s = iv.suitability(sphere, 21, max_radius=12)
    assert s.oversample == 1 and 8.5 <= s.r_open <= 10.5 and "about 1 voxel" in str(s)


def test_a_float32_field_keeps_the_truth_within_its_bounds_in_half_the_memory(tmp_path):
    shape, truth = EXACT_CASES["torus"]
    wide = iv.distance_field(shape, 32, band=3, check_suitability=False)
    field = iv.distance_field(shape, 32, band=3, check_suitability=False, dtype=np.float32)
    p, v, e = _band(field)
    assert v.dtype == e.dtype == np.float32 and field.kind == "exact"
    assert np.array_equal(field.active, wide.active)
    _, v64, e64 = _band(wide)
    off = np.abs(v.astype(np.float64) - v64)              # the rounding, within the bound
    assert np.all(off <= e - e64) and np.any(off > 0)
    assert np.all(e <= 2.0 ** -24 * np.abs(v64) + 1e-300)  # and no more than it
    # the truth (the analytic formula's own rounding is 1e-12, as for float64 fields)
    assert np.all(np.abs(v - truth(p)) <= e + 1e-12)
    assert field.max_error == float(e.max()) > 0
    assert field.nbytes < 0.55 * wide.nbytes + wide.keys.nbytes + wide.active.nbytes
    assert field.to_dense().dtype == np.float32
    back = iv.load_field(field.save(str(tmp_path / "f32.npz")))
    assert back.values.dtype == np.float32 and np.array_equal(back.errors, field.errors)
    image = pv.read(field.save(str(tmp_path / "f32.vti")))
    assert image.point_data["distance"].dtype == np.float32
    mixed = dict(np.load(tmp_path / "f32.npz"))
    mixed["errors"] = mixed["errors"].astype(np.float64)
    np.savez(tmp_path / "mixed.npz", **mixed)
    with pytest.raises(ValueError, match="field 'errors': must be float32"):
        iv.load_field(str(tmp_path / "mixed.npz"))
    with pytest.raises(ValueError, match="dtype must be one of 'float64', 'float32'"):
        iv.distance_field(shape, 8, dtype="float16")


def test_files_round_trip_and_refuse_bad_input(tmp_path):
    field = iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 16, band=1)
    back = iv.load_field(field.save(str(tmp_path / "f.npz")))
    assert np.array_equal(back.values, field.values) and back.norm == field.norm
    image = pv.read(field.save(str(tmp_path / "f.vti")))
    assert image.n_points == int(np.prod(field.grid.shape))
    bad = tmp_path / "bad.npz"
    np.savez(bad, format=np.array([1]))
    with pytest.raises(ValueError, match="field 'origin': missing"):
        iv.load_field(str(bad))
    with pytest.raises(ValueError, match="norm must be one of"):
        iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 8, norm="l2")
    with pytest.raises(ValueError, match="band must be"):
        iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 8, band=0)
    with pytest.raises(MemoryError, match="a distance field of .* bricks"):
        # the voxelization fits in 80 MB (about 71 MB), its 8-voxel band does not
        iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 128, band=8, max_memory=80 << 20)


def test_progress_is_monotone_and_ends_at_one():
    seen = []
    iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 16, band=1, progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == 1.0


def test_prefiltered_isosurface_moves_with_curvature_and_the_distance_field_does_not():
    from implicitvox.fields.prefilter import prefilter_comparison
    rows = prefilter_comparison((2, 4, 8), rays=60)
    for kind, mean_curvature in (("sphere", 2.0), ("cylinder", 1.0)):
        mine = [r for r in rows if r["shape"] == kind]
        moved = np.array([r["prefilter"] for r in mine])
        radius = np.array([r["radius"] for r in mine])
        # intrinsic (no sampling): inward, shrinking with the curvature, about c * kappa
        assert np.all(moved < -0.03) and np.all(np.diff(moved) > 0)
        scaled = -moved * radius / mean_curvature
        assert scaled.max() / scaled.min() < 1.5
        # the sampled distance field's only error is reconstruction: several times smaller
        assert all(abs(r["distance_sampled"]) < abs(r["prefilter"]) / 2.5 for r in mine)


def test_distance_field_warns_when_the_solid_is_unsuitable_at_the_resolution():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        field = iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 21, band=1)   # r = 10 voxels
    assert field.metadata["suitable"] is True
    with pytest.warns(UserWarning, match="not suitable for voxelization at"):
        field = iv.distance_field(linf.ConvexPolyhedron.from_points(CUBE), 16, band=1)
    assert field.metadata["suitable"] is False
    with pytest.warns(UserWarning, match="not suitable"):                    # r = 2 voxels
        iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 5, band=1)


def test_a_field_everywhere_holds_every_sample():
    shape, truth = EXACT_CASES["sphere"]
    field = iv.distance_field(shape, 12, band=None)
    g = field.grid
    assert field.count == int(np.prod(g.shape)) and field.band is None
    p, v, _ = _band(field)
    assert np.allclose(v, truth(p), atol=1e-12)


def test_box_slab_lower_bounds_never_exceed_the_distance_to_box_and_slab():
    # the bounds the certified search prunes with, against dense samples of box ∩ slab,
    # including points on the slab's normal through the box (a direction of rounding)
    from implicitvox.fields.certified_kernels import euclidean_box_slab, linf_box_slab
    room = np.empty(9)
    rng = np.random.default_rng(3)
    for trial in range(300):
        lo = rng.uniform(-1, 0, (1, 3))
        hi = lo + rng.uniform(0.05, 1, (1, 3))
        g = rng.normal(size=(1, 3)) if trial % 3 else np.full((1, 3), rng.uniform(0.5, 2))
        mid = float(g[0] @ (0.5 * (lo + hi))[0])
        s_lo = np.array([mid + rng.uniform(-0.3, 0.1)])
        s_hi = s_lo + rng.uniform(0, 0.2)
        n = g[0] / np.linalg.norm(g[0])
        p = (0.5 * (lo + hi)) + rng.uniform(-2, 2) * n if trial % 2 else rng.uniform(-3, 3, (1, 3))
        gp = float(g[0] @ p[0])
        to_slab = np.array([max(s_lo[0] - gp, gp - s_hi[0], 0.0) / np.linalg.norm(g)])
        q = rng.uniform(lo[0], hi[0], (40000, 3))
        q = q[(q @ g[0] >= s_lo[0]) & (q @ g[0] <= s_hi[0])]
        if not len(q):
            continue
        euclid = euclidean_box_slab(p[0], lo[0], hi[0], g[0], s_lo[0], s_hi[0], room)
        assert euclid <= np.linalg.norm(q - p, axis=1).min() + 1e-12
        if trial < 20:      # and exact: a quadratic programme's optimum, found by scipy
            from scipy.optimize import Bounds, LinearConstraint, minimize
            best = minimize(lambda v: np.sum((v - p[0]) ** 2), 0.5 * (lo[0] + hi[0]),
                            jac=lambda v: 2 * (v - p[0]), method="SLSQP",
                            bounds=Bounds(lo[0], hi[0]),
                            constraints=[LinearConstraint(g, s_lo, s_hi)],
                            options={"ftol": 1e-14, "maxiter": 500})
            assert abs(euclid - np.sqrt(best.fun)) <= 1e-5
        cheb = linf_box_slab(p[0], np.ones(3), lo[0], hi[0], g[0], s_lo[0], s_hi[0], room)
        assert cheb <= np.abs(q - p).max(axis=1).min() + 1e-12


def _box_linf(p, lo, hi):
    outside = np.max(np.maximum(np.maximum(lo - p, p - hi), 0), axis=1)
    inside = -np.min(np.minimum(p - lo, hi - p), axis=1)
    return np.where(outside > 0, outside, inside)


@pytest.mark.parametrize("name", sorted(EXACT_CASES))
def test_max_norm_fields_of_primitives(name):
    shape, _ = EXACT_CASES[name]
    field = iv.distance_field(shape, 20, norm="linf", band=2, check_suitability=False)
    p, v, _ = _band(field)
    assert field.kind == "exact"
    # the primitives' own max-norm distances are checked against independent oracles in
    # tests/linf; here the field must hold them, and the box its analytic one
    assert np.array_equal(v, iv.linf_distance(shape, p))
    if name == "box":
        assert np.allclose(v, _box_linf(p, np.zeros(3), np.array([1.0, 0.6, 0.4])), atol=1e-12)


def test_ellipsoid_euclidean_distance_agrees_with_the_certified_bounds():
    rng = np.random.default_rng(5)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    ell = linf.Ellipsoid((0.1, -0.1, 0.05), (0.9, 0.6, 0.35), q)
    exact = iv.distance_field(ell, 16, band=1, check_suitability=False)
    assert exact.kind == "exact"
    # the same solid as a bare expression: certified bounds, found independently
    certified = iv.distance_field(ell.expr, 16, band=1, bounds=exact.grid.bounds,
                                  check_suitability=False)
    assert certified.kind == "certified"
    c1, v1, _ = exact.band_values()
    c2, v2, e2 = certified.band_values()
    common, i1, i2 = np.intersect1d(iv.octree.morton.encode(c1), iv.octree.morton.encode(c2),
                                    return_indices=True)
    assert len(common) > 500
    assert np.all(np.abs(v1[i1] - v2[i2]) <= e2[i2] + 1e-12)
    # points on the medial disc (zero along the shortest axis): against dense samples
    loc = rng.uniform(-0.25, 0.25, (200, 3))
    loc[:, 2] = 0
    p = ell.center + loc @ ell.rotation.T
    u = rng.normal(size=(300000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    surface = ell.center + (u * ell.radii) @ ell.rotation.T
    from scipy.spatial import cKDTree
    sampled, _ = cKDTree(surface).query(p)
    d = -ell.euclidean_distance(p)
    assert np.all(d <= sampled + 1e-9) and np.all(d >= sampled - 1e-3)


def test_the_default_grid_reaches_past_the_surface_by_the_band_and_the_isosurface_closes():
    """OpenSCAD's bracket has faces on its bounding box (x = 0, x = 40, y = 0): the
    default grid puts `band` voxels of samples beyond them on every side, so the
    0-isosurface is closed (no boundary edge)."""
    from csg import read_openscad
    bracket = read_openscad(str(Path(__file__).resolve().parents[1] / "openscad" / "bracket.csg"))
    band = 2
    field = iv.distance_field(bracket, 40, norm="linf", band=band, check_suitability=False)
    lo, hi = (np.asarray(b) for b in bracket.bounds)
    h = np.asarray(field.grid.voxel_size)
    origin = np.asarray(field.grid.origin)
    top = origin + h * np.asarray(field.grid.shape)
    assert max(field.grid.shape) == 40
    assert np.all(lo - origin >= band * h) and np.all(top - hi >= band * h)
    surface = field.isosurface()
    assert surface.n_cells > 0
    edges = surface.extract_feature_edges(boundary_edges=True, non_manifold_edges=False,
                                          feature_edges=False, manifold_edges=False)
    assert edges.n_cells == 0, f"{edges.n_cells} boundary edges"


def test_centre_grid_finds_the_boxes_a_kd_tree_finds():
    """The certified search's initial pairs (certified_kernels.CentreGrid): every box
    whose centre is within each point's radius, as scipy's cKDTree finds them (the
    grid's slack of 1e-12 may only add boxes at the rim), point by point."""
    from scipy.spatial import cKDTree
    from implicitvox.fields.certified_kernels import CentreGrid
    rng = np.random.default_rng(11)
    centres = np.round(rng.uniform(-2, 2, (5000, 3)) * 16) / 16        # voxel centres
    points = rng.uniform(-2.5, 2.5, (400, 3))
    radius = rng.uniform(0.0, 0.6, 400)
    radius[:5] = [0.0, -1.0, np.inf * 0, 10.0, 0.3]       # none, none, NaN: none, all, some
    grid = CentreGrid(centres, 1 / 16)
    counts = grid.pairs(points, radius)
    pt, box = grid.pairs(points, radius, counts)
    tree = cKDTree(centres)
    for i in range(len(points)):
        want = set(tree.query_ball_point(points[i], radius[i])) if radius[i] >= 0 else set()
        got = set(box[pt == i].tolist())
        assert got >= want and counts[i] == len(got)
        extra = got - want
        d = np.linalg.norm(centres[list(extra)] - points[i], axis=1) if extra else np.zeros(0)
        assert np.all(d <= radius[i] * (1 + 1e-12))
    assert np.all(np.diff(pt) >= 0) and counts[3] == len(centres)
