"""csg solids: volumes bracketed, surfaces never missed, transforms, classification, JSON."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import pyvista as pv

import csg
import implicitvox as ivx
from csg import (Blobby, Box, Circle, ConvexPolyhedron, Cylinder, Ellipsoid, HalfSpace,
                 Polygon, Polyhedron, Rectangle, SceneError, Sphere, Torus, load_json,
                 linear_extrude, rotate_extrude, smooth_union)
from implicitvox.expr.shape import AMBIGUOUS, EMPTY, FULL
from tests.support.surface import found, surface_brackets

SPHERE_MESH = pv.Sphere(radius=1.0, theta_resolution=24, phi_resolution=24)

VOLUMES = [
    ("sphere", Sphere(1), 4 / 3 * math.pi),
    ("rotated box", Box((1, 2, 3)).rotate("x", 30).rotate((1, 1, 0), 17), 6.0),
    ("cylinder", Cylinder(h=2, r=1, center=True), 2 * math.pi),
    ("cone", Cylinder(h=2, r1=1, r2=0), 2 * math.pi / 3),
    ("torus", Torus(1, 0.3), 2 * math.pi ** 2 * 0.09),
    ("ellipsoid", Ellipsoid((1, 2, 0.5)), 4 / 3 * math.pi),
    ("box - sphere", Box((2, 2, 2), center=True) - Sphere(0.5), 8 - math.pi / 6),
    # two unit spheres 1 apart: the lens is pi (4 r + d) (2 r - d)^2 / 12 = 5 pi / 12
    ("two spheres", Sphere(1) | Sphere(1, center=(1, 0, 0)), 8 / 3 * math.pi - 5 * math.pi / 12),
    ("lens", Sphere(1) & Sphere(1, center=(1, 0, 0)), 5 * math.pi / 12),
    ("scaled sphere", Sphere(1).scale((2, 1, 0.5)), 4 / 3 * math.pi),
    ("mirrored cone", Cylinder(h=2, r1=1, r2=0).mirror((0, 0, 1)), 2 * math.pi / 3),
    ("revolved disc", rotate_extrude(Circle(0.3).translate((1, 0))), 2 * math.pi ** 2 * 0.09),
    ("270 degrees", rotate_extrude(Circle(0.3).translate((1, 0)), 270),
     1.5 * math.pi ** 2 * 0.09),
    ("twisted prism", linear_extrude(Rectangle((1, 1), center=True), 2, twist=120), 2.0),
    ("frustum prism", linear_extrude(Rectangle((1, 1), center=True), 2, scale=0.5), 7 / 6),
    ("concave prism", linear_extrude(Polygon([(0, 0), (2, 0), (2, 2), (1, 0.5), (0, 2)]), 1),
     2.5),
    ("holed prism", linear_extrude(Polygon([(0, 0), (3, 0), (3, 3), (0, 3), (1, 1), (2, 1),
                                            (2, 2), (1, 2)], [[0, 1, 2, 3], [4, 5, 6, 7]]), 1),
     8.0),
    ("octahedron", ConvexPolyhedron(points=[(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0),
                                            (0, 0, 1), (0, 0, -1)]), 4 / 3),
    ("polyhedron", Polyhedron(SPHERE_MESH), SPHERE_MESH.volume),
    ("polyhedron - cylinder", Polyhedron(SPHERE_MESH).scale((1, 1, 2))
     - Cylinder(h=5, r=0.4, center=True), None),
]


@pytest.mark.parametrize("name, solid, volume", VOLUMES, ids=[v[0] for v in VOLUMES])
def test_interior_and_surface_bracket_the_volume(name, solid, volume):
    vox = solid.voxelize(48, interior=True)
    cell = float(np.prod(vox.voxel_size))
    inner = vox.interior_count * cell
    outer = (vox.interior_count + vox.count) * cell
    if volume is None:       # polyhedron minus a cylinder: Monte Carlo with exact winding
        from implicitvox.triangles.crossings import RayWinding
        from implicitvox.triangles.inputs import as_triangles
        v, f = as_triangles(SPHERE_MESH.scale((1, 1, 2), inplace=False))
        rng = np.random.default_rng(0)
        (lo, hi), n = solid.bounds, 400_000
        p = rng.uniform(lo, hi, (n, 3))
        hit = (RayWinding(v[f])(p) != 0) & (np.hypot(p[:, 0], p[:, 1]) > 0.4)
        box = float(np.prod(np.subtract(hi, lo)))
        volume, sigma = hit.mean() * box, box * math.sqrt(hit.mean() * (1 - hit.mean()) / n)
        assert inner <= volume + 4 * sigma and volume - 4 * sigma <= outer
        return
    assert inner <= volume <= outer
    assert outer - inner < 0.6 * volume        # and the bracket is not vacuous


NEVER_MISS = [
    Box((1, 2, 3)).rotate("x", 30),
    Cylinder(h=2, r1=1, r2=0.3).rotate("y", 45),
    Torus(1, 0.25).rotate((1, 1, 1), 33),
    (Box((2, 2, 1), center=True) | Sphere(0.8).translate((0, 0, 0.5))) - Cylinder(r=0.3, h=4,
                                                                                   center=True),
    linear_extrude(Rectangle((1, 1), center=True), 2, twist=90, scale=0.5),
    rotate_extrude(Polygon([(0.5, 0), (1, 0), (0.8, 0.6)]), 200),
    smooth_union(Sphere(0.6), Sphere(0.6, center=(0.8, 0, 0)), 0.3),
    Blobby([(0, 0, 0), (0.8, 0, 0), (0.4, 0.6, 0)], radius=0.5),
]


@pytest.mark.parametrize("k", range(len(NEVER_MISS)))
def test_never_misses_a_surface_point(k):
    solid = NEVER_MISS[k]
    vox = solid.voxelize(64)
    func = ivx.compile(solid.expr)
    a, b = surface_brackets(func, vox.bounds, min(vox.voxel_size), 20_000,
                            np.random.default_rng(k))
    assert len(a) >= 5_000
    assert found(vox.contains, vox.grid, a, b).all()


def test_polyhedron_classification_is_exact():
    """Boxes against a mesh: AMBIGUOUS iff a triangle meets them (checked by the kernel's
    mesh voxelizer on the same grid), FULL/EMPTY agree with the winding number."""
    solid = Polyhedron(SPHERE_MESH)
    vox = solid.voxelize(32, bounds=((-1.2,) * 3, (1.2,) * 3), interior=True)
    mesh_vox = ivx.voxelize_mesh(SPHERE_MESH, 32, bounds=((-1.2,) * 3, (1.2,) * 3), interior=True)
    assert np.array_equal(vox.coords(), mesh_vox.coords())
    assert np.array_equal(vox.to_dense(), mesh_vox.to_dense())
    classify = solid.classify_boxes
    lo = np.array([[-0.1, -0.1, -0.1], [2, 2, 2], [0.9, -0.1, -0.1]])
    assert classify(lo, lo + 0.2).tolist() == [FULL, EMPTY, AMBIGUOUS]


def test_which_solids_have_an_exact_test():
    assert csg.ExprSolid(ivx.x ** 2 - 1).classify_boxes is None
    assert Blobby([(0, 0, 0), (1, 0, 0)], radius=0.5).classify_boxes is None
    assert Sphere(1).classify_boxes is not None               # max-norm distance
    assert Torus(1, 0.2).rotate((0, 1, 0), 90).classify_boxes is not None
    assert (csg.ExprSolid(ivx.x ** 2 - 1) - Polyhedron(SPHERE_MESH)).classify_boxes is not None
    from csg.tree_classifier import world_primitive as world_linf
    assert world_linf(Torus(1, 0.2).rotate((1, 1, 0), 30)).axis is None  # general orientation
    assert world_linf(Torus(0.2, 0.3).rotate((1, 1, 0), 30)) is None  # tilted spindle torus
    assert world_linf(Torus(0.2, 0.3).rotate((1, 0, 0), 90)) is not None  # upright: exact


def test_exact_leaves_settle_boxes_intervals_cannot():
    """A rotated box: intervals of its max-of-abs function stay AMBIGUOUS on boxes near a
    rotated corner that the max-norm test settles; both never drop a surface voxel."""
    box = Box((1, 2, 3)).rotate((1, 1, 0), 37).translate((0.1, 0.2, 0.3))
    exact = box.voxelize(48)
    loose = ivx.voxelize(box.expr, 48, bounds=exact.bounds)
    assert np.all(loose.contains(exact.coords()))
    assert exact.count < loose.count


def test_transforms_compose_and_invert():
    s = Box((1, 2, 3)).translate((1, 2, 3)).rotate("z", 90).scale(2).mirror((1, 0, 0))
    f = ivx.compile(s.expr)
    # the box's corner (1, 2, 3) goes to: rotate z 90 -> (-2, 1, 3); scale 2 -> (-4, 2, 6);
    # mirror x -> (4, 2, 6); the opposite corner (2, 4, 6) -> (8, 4, 12)
    centre = np.array([[6.0, 3.0, 9.0]])
    assert f(*centre.T)[0] < 0
    assert s.bounds[0] == pytest.approx((4, 2, 6)) and s.bounds[1] == pytest.approx((8, 4, 12))


@pytest.mark.parametrize("make, match", [
    (lambda: Sphere(-1), "r must be a positive finite number"),
    (lambda: Box((1, 0, 1)), "size must be positive"),
    (lambda: Cylinder(h=1, r=1, r1=2), "give r, or r1 and r2"),
    (lambda: Sphere(1).scale(0), "non-zero"),
    (lambda: Sphere(1).transform(np.zeros((4, 4))), "affine"),
    (lambda: Sphere(1).rotate("w", 10), "axis must be"),
    (lambda: HalfSpace((0, 0, 0)), "normal must not be zero"),
    (lambda: ConvexPolyhedron(points=[(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]), "no volume"),
    (lambda: Polygon([(0, 0), (1, 1), (2, 2)]), "zero area"),
    (lambda: rotate_extrude(Circle(1)), "one side of the axis"),
    (lambda: linear_extrude(Sphere(1), 1), "2D shape"),
    (lambda: Sphere(1) | 3, "cannot combine"),
])
def test_bad_solids(make, match):
    with pytest.raises((ValueError, TypeError), match=match):
        make()


def test_truth_value_refused():
    with pytest.raises(TypeError, match="no truth value"):
        bool(Sphere(1))


def test_json_round_trip_exact():
    s = (Box((2, 2, 2), center=True) - Sphere(1.2).translate((0, 0, 1))) | \
        linear_extrude(Polygon([(0, 0), (2, 0), (1, 1)]), 1, twist=30, scale=(0.5, 1))
    s = s | csg.ExprSolid(ivx.sqrt(ivx.x ** 2 + ivx.y ** 2) - 0.1 * ivx.sin(ivx.z))
    text = s.to_json()
    again = load_json(text)
    assert again.to_json() == text and again.expr.equals(s.expr)


HOSTILE = [
    ('{"implicitvox_scene": 1, "root": ' + '{"type": "complement", "child": ' * 300
     + '{"type": "sphere", "r": 1}' + "}" * 301, "nested deeper|nested too deeply"),
    ('[' * 100000 + ']' * 100000, "nested too deeply|a scene is"),
    ('{"implicitvox_scene": 1, "root": {"type": "polyhedron", "vertices": [' +
     ",".join(["[0,0,0]"] * 2_000_000) + '], "faces": [[0,1,2]]}}', "more than"),
    ('{"implicitvox_scene": 1, "root": {"type": "sphere", "r": true}}', r"root\.r"),
    ('{"implicitvox_scene": 1, "root": {"type": "box", "size": [1, 2]}}', r"root\.size"),
    ('{"implicitvox_scene": 1, "root": {"type": "union", "children": [{"type": "sphere", '
     '"r": 1}, {"type": "teapot"}]}}', r"root\.children\[1\]\.type"),
    ('{"implicitvox_scene": 1, "root": {"type": "sphere", "r": NaN}}', "NaN"),
    ('{"implicitvox_scene": 1, "root": {"type": "expression", "expr": '
     '"__import__(\'os\').system(\'echo hi\')"}}', "not allowed"),
    ('{"implicitvox_scene": 1, "root": {"type": "expression", "expr": "x.real"}}',
     "not allowed"),
    ('{"implicitvox_scene": 1, "root": {"type": "expression", "expr": "' + "(" * 5000 + "x"
     + ")" * 5000 + '"}}', "nested too deeply|syntax error"),
    ('{"implicitvox_scene": 2, "root": {}}', "a scene is"),
    ('{"implicitvox_scene": 1, "root": ', "not JSON"),
]


@pytest.mark.parametrize("scene, match", HOSTILE, ids=[f"hostile-{i}" for i in range(len(HOSTILE))])
def test_hostile_scenes(scene, match):
    with pytest.raises(SceneError, match=match):
        load_json(scene)


def test_what_is_neither_json_nor_a_path_is_refused_without_echoing_it():
    with pytest.raises(SceneError, match="got NoneType None"):
        load_json(None)
    with pytest.raises(SceneError, match="got bytes"):
        load_json(b'{"implicitvox_scene": 1}')
    with pytest.raises(SceneError, match=r"\(300,000,000 characters\) is neither JSON") as info:
        load_json("x" * 300_000_000)
    assert len(str(info.value)) < 300
    with pytest.raises(FileNotFoundError, match="no such scene file"):
        load_json("no/such/scene.json")


def test_linf_distance_of_transformed_primitives():
    rng = np.random.default_rng(9)
    p = rng.normal(size=(2000, 3)) * 2
    # a sphere under a non-uniform scale is an ellipsoid: compare with the kernel's
    d = Sphere(1).scale((2, 1, 0.5)).linf_distance(p)
    assert np.allclose(d, ivx.linf.Ellipsoid((0, 0, 0), (2, 1, 0.5)).distance(p), rtol=1e-12,
                       atol=1e-14)
    # a translated polyhedron (a closed mesh): signed, and 0 on its vertices
    mesh = Polyhedron(SPHERE_MESH).translate((1, 0, 0))
    v = np.asarray(SPHERE_MESH.points) + [1, 0, 0]
    assert np.allclose(mesh.linf_distance(v), 0, atol=1e-12)
    assert mesh.linf_distance([[1.0, 0.0, 0.0]])[0] < 0 < mesh.linf_distance([[3.0, 0, 0]])[0]
    with pytest.raises(TypeError, match="only single primitives"):
        (Sphere(1) | Box()).linf_distance(p)


# -- box minus two cylinders: exactly the voxels its surface meets ---------------------
#: the box [-1, 1] x [-0.65, 0.65] x [-0.55, 0.55] moved off the grid lines, minus a
#: cylinder along z and one along x, both longer than the box
BOX_LO, BOX_HI = np.array([-0.997, -0.651, -0.553]), np.array([1.003, 0.649, 0.547])
CYL_Z = (0.21, 0.05, 0.43)          # axis (x, y) = (0.21, 0.05), radius
CYL_X = (-0.07, 0.13, 0.31)         # axis (y, z) = (-0.07, 0.13), radius


def box_minus_two_cylinders():
    return (Box(tuple(BOX_HI - BOX_LO)).translate(tuple(BOX_LO))
            - Cylinder(h=3.0, r=CYL_Z[2], center=True).translate((CYL_Z[0], CYL_Z[1], 0))
            - Cylinder(h=3.0, r=CYL_X[2], center=True).rotate((0, 1, 0), 90)
            .translate((0, CYL_X[0], CYL_X[1])))


def _far(lo, hi, c):
    return np.maximum(np.abs(lo - c), np.abs(hi - c))


def _near(lo, hi, c):
    return np.maximum(np.maximum(lo - c, c - hi), 0.0)


def surface_meets(lo, hi):
    """Independent oracle: does the surface of B - C1 - C2 meet the closed boxes [lo, hi]?

    It does iff the box meets the solid S and the closure of its complement.
    * Closure of the complement: outside the open box B, or in a closed cylinder.
    * S = B minus the open cylinders: W = box & B must hold a point outside both open
      cylinders. For a fixed y the conditions part: (x - a)^2 + (y - b)^2 >= r1^2 for
      some x of W iff far_x^2 + (y - b)^2 >= r1^2 (far_x: W's farthest x from a), and
      likewise in z. Each is y outside an open interval around b (around the other
      cylinder's y): W's y range minus two open intervals, in closed form.
    """
    a, b, r1 = CYL_Z
    c, d, r2 = CYL_X
    in_box = np.all((lo > BOX_LO) & (hi < BOX_HI), axis=1)
    meets_c1 = np.hypot(_near(lo[:, 0], hi[:, 0], a), _near(lo[:, 1], hi[:, 1], b)) <= r1
    meets_c2 = np.hypot(_near(lo[:, 1], hi[:, 1], c), _near(lo[:, 2], hi[:, 2], d)) <= r2
    meets_outside = ~in_box | meets_c1 | meets_c2
    wlo, whi = np.maximum(lo, BOX_LO), np.minimum(hi, BOX_HI)
    nonempty = np.all(wlo <= whi, axis=1)
    with np.errstate(invalid="ignore"):
        # y is removed by C1 iff |y - b| < s1, s1 = sqrt(r1^2 - far_x^2) (none if far_x >= r1)
        s1 = np.sqrt(r1 ** 2 - _far(wlo[:, 0], whi[:, 0], a) ** 2)
        s2 = np.sqrt(r2 ** 2 - _far(wlo[:, 2], whi[:, 2], d) ** 2)
    s1, s2 = np.nan_to_num(s1, nan=-1.0), np.nan_to_num(s2, nan=-1.0)
    y0, y1 = wlo[:, 1], whi[:, 1]
    # candidates for a surviving y: the ends of W's range and of the two open intervals
    cands = np.stack([y0, y1, b - s1, b + s1, c - s2, c + s2], axis=1)
    ok = (cands >= y0[:, None]) & (cands <= y1[:, None]) \
        & ~(np.abs(cands - b) < s1[:, None]) & ~(np.abs(cands - c) < s2[:, None])
    meets_solid = nonempty & ok.any(axis=1)
    return meets_solid & meets_outside


def test_box_minus_two_cylinders_gives_exactly_the_voxels_its_surface_meets():
    """Every voxel of the grid against the oracle, away from ties (the answer for the
    voxel grown and shrunk by 1e-9 agrees); the ties are few."""
    solid = box_minus_two_cylinders()
    vox = solid.voxelize(48, bounds=((-1.1, -0.7, -0.6), (1.1, 0.7, 0.6)))
    n = vox.grid.shape
    every = np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), -1).reshape(-1, 3)
    lo = np.stack([vox.grid.edge(a, every[:, a]) for a in range(3)], 1)
    hi = np.stack([vox.grid.edge(a, every[:, a] + 1) for a in range(3)], 1)
    grown, shrunk = surface_meets(lo - 1e-9, hi + 1e-9), surface_meets(lo + 1e-9, hi - 1e-9)
    sure = grown == shrunk
    got = vox.contains(every)
    assert np.array_equal(got[sure], shrunk[sure])
    assert (~sure).sum() <= 0.001 * len(every) and shrunk.sum() > 5000
    assert not (got & ~grown).any() and not (~got & shrunk).any()   # ties: either is right


def test_settling_drops_voxels_where_two_surfaces_cancel():
    """Two overlapping balls: next to their crease, inside the union, a voxel can cut
    both spheres and miss the union's surface. Settling (halving such voxels) drops
    them, and only them: every dropped voxel is wholly inside the union (17^3 samples)
    and the rest of the output is unchanged."""
    from csg import tree_classifier
    centres, radii = np.array([[-0.3, 0.01, 0.02], [0.35, -0.02, 0.0]]), np.array([0.6, 0.5])
    union = Sphere(radii[0]).translate(tuple(centres[0])) | \
        Sphere(radii[1]).translate(tuple(centres[1]))
    settled = union.voxelize(64)
    depth = tree_classifier.SETTLE_DEPTH
    try:
        tree_classifier.SETTLE_DEPTH = 0
        union.__dict__.pop("_classifier_cache", None)
        conservative = union.voxelize(64, bounds=settled.bounds)
    finally:
        tree_classifier.SETTLE_DEPTH = depth
    assert settled.grid == conservative.grid
    kept = conservative.contains(settled.coords())
    assert kept.all()
    dropped = conservative.coords()[~settled.contains(conservative.coords())]
    assert len(dropped) > 0
    t = np.linspace(0.0, 1.0, 17)
    offsets = np.stack(np.meshgrid(t, t, t, indexing="ij"), -1).reshape(-1, 3)
    g = settled.grid
    lo = np.stack([g.edge(a, dropped[:, a]) for a in range(3)], 1)
    pts = lo[:, None, :] + offsets[None] * np.array(g.voxel_size)
    dist = np.linalg.norm(pts[:, :, None, :] - centres[None, None], axis=-1) - radii
    assert np.all(dist.min(axis=2) < 0)                 # every sample inside a ball


def _unculled(node):
    """The same plan with every child's support unbounded: each child tested on every box."""
    if node[0] in ("union", "intersection"):
        kids = [_unculled(k) for k in node[1]]
        n = len(kids)
        return (node[0], kids, (np.full((n, 3), -np.inf), np.full((n, 3), np.inf), node[2][2]))
    if node[0] == "complement":
        return ("complement", _unculled(node[1]))
    return node


def test_culling_children_by_their_support_changes_no_state():
    from csg.tree_classifier import exact_classifier, plan
    rng = np.random.default_rng(11)
    for _ in range(12):
        parts = []
        for _ in range(rng.integers(2, 10)):
            kind = rng.integers(0, 3)
            p = Box(tuple(rng.choice([0.25, 0.5, 0.75], 3)), center=bool(rng.integers(0, 2))) \
                if kind == 0 else Sphere(float(rng.choice([0.2, 0.4]))) if kind == 1 else \
                Cylinder(h=0.8, r=0.25).rotate("x", 90)
            parts.append(p.translate(tuple(np.round(rng.uniform(-0.6, 0.6, 3) * 8) / 8)))
        tree = parts[0]
        for p in parts[1:]:
            tree = [tree | p, tree & p, tree - p][rng.integers(0, 3)]
        whole = plan(tree)
        # boxes of several sizes, on a 1/16 lattice (faces of the parts lie on it: ties)
        lo = np.round(rng.uniform(-1, 1, (3000, 3)) * 16) / 16
        hi = lo + rng.choice([1 / 16, 1 / 8, 1 / 2], (3000, 1))
        culled = exact_classifier(whole, settle=True)(lo, hi)
        assert np.array_equal(culled, exact_classifier(_unculled(whole), settle=True)(lo, hi))


def test_corner_witnesses_settle_as_halving_does(monkeypatch):
    """Boxes that two exact surfaces meet are first decided by their corners and centre
    (a point inside and one outside: the box meets the surface); the states are those
    of halving alone: on near-coincident meshes (a sphere and the same sphere turned,
    as OpenSCAD's example010 intersects a heightmap with its turned copy), across the
    gap between two meshes (where halving finds the boxes EMPTY, and no witness may
    say otherwise), and with interval leaves."""
    from csg import tree_classifier as classify
    turned = Polyhedron(SPHERE_MESH) & Polyhedron(SPHERE_MESH).rotate((1, 2, 3), 7)
    apart = Polyhedron(SPHERE_MESH) & Polyhedron(SPHERE_MESH).translate((2.02, 0, 0))
    blend = Polyhedron(SPHERE_MESH) - smooth_union(Sphere(0.4), Sphere(0.4, center=(0.5, 0, 0)),
                                                   0.2)
    rng = np.random.default_rng(3)
    on_sphere = rng.normal(size=(4000, 3))
    on_sphere /= np.linalg.norm(on_sphere, axis=1, keepdims=True)
    on_gap = rng.uniform((0.9, -0.1, -0.1), (1.1, 0.1, 0.1), (4000, 3))
    settled = []
    for tree, near in ((turned, on_sphere), (apart, on_gap), (blend, on_sphere)):
        whole = classify.plan(tree)
        size = rng.choice([1 / 32, 1 / 16, 1 / 8], (4000, 1))
        lo = near - size * rng.uniform(0.2, 0.8, (4000, 1))
        hi = lo + size
        raw = classify._run(whole, lo, hi)
        unsure = (raw == classify.UNKNOWN) | (raw == classify.MAYBE)
        assert unsure.sum() > 100
        fast = classify.exact_classifier(whole, settle=True)(lo, hi)
        with monkeypatch.context() as m:
            m.setattr(classify, "_witnessed", lambda plan, a, b: np.zeros(len(a), dtype=bool))
            slow = classify.exact_classifier(whole, settle=True)(lo, hi)
        assert np.array_equal(fast, slow)
        settled.append((classify._witnessed(whole, lo[unsure], hi[unsure]).mean(),
                        (slow[unsure] == EMPTY).mean()))
    assert settled[0][0] > 0.9 and settled[2][0] > 0.5      # the witnesses do the work
    assert settled[1][1] > 0.5                               # halving finds EMPTY boxes


def _every_child(plan: tuple, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The states of a plan by its rules, every child asked about every box (the
    reference for the classifier, which skips children where another decided)."""
    from csg import tree_classifier as classify
    kind = plan[0]
    if kind in ("union", "intersection"):
        states = np.array([_every_child(k, lo, hi) for k in plan[1]])
        absorbing, neutral = (FULL, EMPTY) if kind == "union" else (EMPTY, FULL)
        active = states != neutral
        out = np.full(len(lo), classify.UNKNOWN, dtype=np.int8)
        one = active.sum(axis=0) == 1
        out[one] = states[active.argmax(axis=0)[one], np.flatnonzero(one)]
        out[(active.sum(axis=0) > 1) & (states == classify.MAYBE).any(axis=0)] = classify.MAYBE
        out[~active.any(axis=0)] = neutral
        out[(states == absorbing).any(axis=0)] = absorbing
        return out
    if kind == "complement":
        s = _every_child(plan[1], lo, hi)
        return np.where(s == FULL, EMPTY, np.where(s == EMPTY, FULL, s)).astype(np.int8)
    return classify._run(plan, lo, hi)


def test_children_decided_by_another_are_skipped_and_change_no_state(monkeypatch):
    """A box one child makes absorbing (EMPTY in an intersection, FULL in a union)
    asks no other child, the interval leaves last; the states are those of asking
    every child, in both orders of the operands."""
    from csg import tree_classifier as classify
    blend = smooth_union(Sphere(0.4), Sphere(0.4, center=(0.5, 0, 0)), 0.2)
    slab = Box((2, 0.4, 2), center=True)
    trees = [Polyhedron(SPHERE_MESH) - blend, blend - Polyhedron(SPHERE_MESH),
             blend & slab, slab & blend,
             (Polyhedron(SPHERE_MESH) | blend) - Sphere(0.3, center=(0, 0.5, 0))]
    rng = np.random.default_rng(11)
    lo = rng.uniform(-1.2, 1.1, (3000, 3))
    hi = lo + rng.choice([1 / 64, 1 / 16, 1 / 4], (3000, 1))
    asked, exact_open = [], []
    for tree in trees:
        plan = classify.plan(tree)
        exact_open.append((classify._run(plan[1][0], lo, hi) != EMPTY).sum())
        assert np.array_equal(classify._run(plan, lo, hi), _every_child(plan, lo, hi))
        seen = []
        with monkeypatch.context() as m:
            original = classify._run
            m.setattr(classify, "_run", lambda p, a, b, asked=None: (
                seen.append(len(a)) if p[0] == "function" else None) or original(p, a, b, asked))
            classify._run(plan, lo, hi)
        asked.append(sum(seen))
    # the exact child goes first, in either order written; the blend is asked only
    # where it left the box open
    for tree in trees[2:4]:
        assert [kid[0] for kid in classify.plan(tree)[1]] == ["exact", "function"]
    for k in (0, 2, 3):
        assert 0 < asked[k] <= exact_open[k] < len(lo)


@pytest.mark.parametrize("turn", [0.0, 17.0])
def test_faces_shared_inside_a_union_are_no_surface(turn):
    """Two boxes touching on a face, and a box minus one sharing its top face, voxelize
    as the one box they make: the shared face is inside the regularized solid (the
    tree's mesh decides the voxels that halving leaves tied), on a lattice the face
    lies on and, turned, across voxels."""
    def placed(s):
        return s.rotate((1, 2, 3), turn)
    halves = placed(Box((1, 1, 1)) | Box((1, 1, 1)).translate((1, 0, 0)))
    cut = placed(Box((2, 1, 1.5)) - Box((2, 1, 0.5)).translate((0, 0, 1)))
    whole = placed(Box((2, 1, 1)))
    bounds = ((-1.5, -1.5, -1.5), (2.5, 2.5, 2.5))
    expected = whole.voxelize(64, bounds=bounds)
    for solid in (halves, cut):
        vox = solid.voxelize(64, bounds=bounds)
        assert vox.count == expected.count
        assert np.array_equal(vox.coords(), expected.coords())
    assert halves.regularized_boundary is not None


def test_chained_operators_make_one_boolean_and_run_in_parallel():
    """``a | b | c ...`` (a loop ``u = u | part``) is one n-ary union, as OpenSCAD's
    union() of many children: the same function, a shallow tree, so a model of
    thousands of parts compiles and pickles for the workers."""
    parts = [Sphere(0.02).translate((0.01 * i, 0.0, 0.0)) for i in range(600)]
    chain = parts[0]
    for part in parts[1:]:
        chain = chain | part
    assert type(chain) is csg.Union and len(chain.children) == 600
    assert chain.expr == ivx.min(*[p.expr for p in parts])
    assert len((parts[0] & parts[1] & parts[2]).children) == 3
    cut = Box(2) - parts[0] - parts[1] - parts[2]
    assert type(cut) is csg.Difference and cut.children[1:] == tuple(parts[:3])
    inner = parts[1] - parts[2]                      # a - (b - c) stays nested
    assert (parts[0] - inner).children == (parts[0], inner)
    serial = ivx.voxelize(chain, 24, workers=1)
    parallel = ivx.voxelize(chain, 24, workers=2)
    assert parallel.metadata["workers"] == 2
    assert np.array_equal(np.unique(parallel.coords(), axis=0), np.unique(serial.coords(), axis=0))


def test_a_tree_too_deep_to_compile_is_refused_by_name():
    solid = Sphere(1.0)
    for _ in range(3000):
        solid = solid.translate((0.001, 0.0, 0.0))
    with pytest.raises(ValueError, match="Transformed is nested too deeply to compile"):
        ivx.voxelize(solid, 16)


def test_a_twisted_extrusion_to_a_point_keeps_no_voxel_off_its_cone():
    """OpenSCAD's Basics/linear_extrude cone: a 20 x 10 rectangle turned -360 degrees and
    scaled to 0 over 40. Undoing a scale near 0 is unbounded, so the turned section
    alone keeps every box at the top; the solid lies in the cone of the section's
    reach (rho <= R (1 - t)), and every voxel kept must meet that cone."""
    solid = linear_extrude(Rectangle((20, 10), center=True), 40, twist=-360, scale=0,
                           center=True)
    vox = ivx.voxelize(solid, 64, bounds=((-12, -12, -21), (12, 12, 21)))
    lo, h = np.asarray(vox.bounds[0]), np.asarray(vox.voxel_size)
    box_lo = lo + vox.coords() * h
    box_hi = box_lo + h
    nearest = np.hypot(*np.maximum(np.maximum(box_lo[:, :2], -box_hi[:, :2]), 0.0).T)
    widest = math.hypot(10, 5) * (1 - (box_lo[:, 2] + 20) / 40)   # the cone at the box's bottom
    assert vox.count > 1000 and np.all(nearest <= widest + 1e-9)


def test_a_twisted_extrusion_off_the_axis_keeps_no_voxel_inside_its_annulus():
    """A section 5 to 7 from the axis, turned 720 degrees: its points stay 5 to 7 from
    the axis, and so must the voxels kept (each meets the annulus)."""
    section = Rectangle((2, 2), center=True).translate((6, 0))
    solid = linear_extrude(section, 10, twist=720)
    vox = ivx.voxelize(solid, 64, bounds=((-8, -8, -0.5), (8, 8, 10.5)))
    lo, h = np.asarray(vox.bounds[0]), np.asarray(vox.voxel_size)
    box_lo = lo + vox.coords() * h
    box_hi = box_lo + h
    corners = np.stack([np.where(np.abs(box_lo[:, :2]) > np.abs(box_hi[:, :2]), box_lo[:, :2],
                                 box_hi[:, :2])], 0)[0]
    farthest = np.hypot(*corners.T)
    assert vox.count > 1000 and np.all(farthest >= 5.0 - 1e-9)


def _capsule_surface(a, b, r, n, rng):
    """Points on a capsule's surface: its side and its two half-spheres."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    axis = d / np.linalg.norm(d)
    u = np.cross(axis, [1.0, 0, 0] if abs(axis[0]) < 0.9 else [0, 1.0, 0])
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    ang, t = rng.uniform(0, 2 * np.pi, n), rng.uniform(0, 1, n)
    side = a + t[:, None] * d + r * (np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v)
    ball = rng.normal(size=(n, 3))
    ball = r * ball / np.linalg.norm(ball, axis=1, keepdims=True)
    ends = np.where((ball @ axis)[:, None] < 0, a + ball, b + ball)   # the outer halves
    return np.concatenate([side, ends])


def test_a_capsule_is_one_class_and_every_surface_voxel_is_found():
    """The leaf protocol's example: Capsule is defined in csg.primitives alone, and the
    voxelizer, scenes, hulls and the protocol check take it from there."""
    from csg import Capsule
    from csg.solid import SCENE_TYPES
    cap = Capsule((0.1, -0.2, 0.3), (1.3, 0.6, -0.4), 0.35)
    vox = cap.voxelize(48)
    pts = _capsule_surface(cap.a, cap.b, cap.r, 20_000, np.random.default_rng(5))
    idx, below = vox.grid.voxels_holding(pts)
    assert (idx >= 0).all() and (vox.contains(idx) | vox.contains(below)).all()
    # and no stray voxels: the intervals keep near misses only. The exact signed distance
    # (in numpy, from the segment) of a voxel the surface meets is at most half its
    # diagonal at its centre; every kept voxel is within a whole diagonal, nearly all
    # within half of one
    centres = vox.grid.centers(vox.coords())
    d = cap.b - cap.a
    t = np.clip((centres - cap.a) @ d / (d @ d), 0, 1)
    f = np.abs(np.linalg.norm(centres - cap.a - t[:, None] * d, axis=1) - cap.r)
    h = vox.voxel_size[0]
    assert f.max() <= np.sqrt(3) * h and np.mean(f <= np.sqrt(3) / 2 * h) > 0.95
    assert SCENE_TYPES["capsule"] is Capsule
    again = load_json(cap.translate((1, 0, 0)).to_json())
    assert again.expr.equals(cap.translate((1, 0, 0)).expr)
    with pytest.raises(csg.NotAPolytope, match="Capsule is curved"):
        csg.hull(cap, Box((1, 1, 1)))
    with pytest.raises(ValueError, match="ends a and b must differ"):
        Capsule((1, 1, 1), (1, 1, 1), 0.5)
