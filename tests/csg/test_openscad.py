"""OpenSCAD .csg files: facets as OpenSCAD makes them, true curves, and bad input.

The fixtures under ``tests/openscad/`` are ``.scad`` models with the ``.csg`` and
``.stl`` files OpenSCAD 2021.01 exported from them (``regenerate.sh``).
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import implicitvox as ivx
from csg import read_openscad
from csg.facets import fragments
from csg.openscad import SUPPORTED
from csg.openscad_parser import OpenSCADError, parse
from implicitvox.triangles.inputs import as_triangles
from tests.support.clip_oracle import triangle_meets_box
from tests.support.facet_tolerance import facet_tolerance
from tests.support.mesh_helpers import sample_surface

FIXTURES = Path(__file__).resolve().parents[1] / "openscad"
MODELS = sorted(p.stem for p in FIXTURES.glob("*.csg"))
RES = 128


def _walk(nodes):
    for n in nodes:
        yield n
        yield from _walk(n.children)


def test_fixtures_use_every_supported_module():
    used = set()
    for m in MODELS:
        used |= {n.name for n in _walk(parse((FIXTURES / f"{m}.csg").read_text()))}
    assert set(SUPPORTED) <= used | {"union"} and "union" in used
    assert len(MODELS) >= 6


def _stl_voxels(model):
    return ivx.voxelize_mesh(str(FIXTURES / f"{model}.stl"), RES)


@pytest.mark.parametrize("model", MODELS)
def test_facets_contain_openscads_own_voxels(model):
    """The .csg with OpenSCAD's facets holds every voxel of the exact voxelization of
    OpenSCAD's .stl, and at most 2% more. The .stl is written with 6 significant
    digits: a voxel the .stl only grazes within that rounding may be absent."""
    stl = _stl_voxels(model)
    solid = read_openscad(FIXTURES / f"{model}.csg", facets="openscad")
    vox = solid.voxelize(bounds=stl.bounds, voxel_size=stl.voxel_size)
    assert vox.grid == stl.grid
    missing = stl.coords()[~vox.contains(stl.coords())]
    if len(missing):
        v, f = as_triangles(str(FIXTURES / f"{model}.stl"))
        tri = v[f]
        tol = 2e-6 * float(np.abs(v).max())
        g = stl.grid
        for c in missing:
            lo = np.array([g.edge(a, c[a]) for a in range(3)]) + tol
            hi = np.array([g.edge(a, c[a] + 1) for a in range(3)]) - tol
            near = np.flatnonzero(np.all((tri.min(1) <= hi) & (tri.max(1) >= lo), axis=1))
            assert not any(triangle_meets_box(tri[t], lo, hi) for t in near), c
    assert len(missing) <= 5
    assert vox.count <= 1.02 * stl.count


def _facet_tolerance(model) -> float:
    """The largest chordal deviation of the model's facets (tests.support.facet_tolerance)."""
    v, _ = as_triangles(str(FIXTURES / f"{model}.stl"))
    return facet_tolerance((FIXTURES / f"{model}.csg").read_text(),
                           float(np.hypot(v[:, 0], v[:, 1]).max()))


@pytest.mark.parametrize("model", MODELS)
def test_true_curves_within_facet_tolerance(model):
    """Every sampled point of OpenSCAD's faceted surface lies within the facets'
    chordal tolerance of a voxel of the true-curve voxelization."""
    stl = _stl_voxels(model)
    solid = read_openscad(FIXTURES / f"{model}.csg", facets="true")
    vox = solid.voxelize(bounds=stl.bounds, voxel_size=stl.voxel_size)
    v, f = as_triangles(str(FIXTURES / f"{model}.stl"))
    pts = sample_surface(v[f], 100_000, np.random.default_rng(0))
    idx = vox.grid.voxels_holding(pts)[0]
    away = np.flatnonzero(~vox.contains(idx))
    tol = _facet_tolerance(model) + 2e-6 * float(np.abs(v).max())
    h = np.asarray(vox.voxel_size)
    # distance of each such point to the nearest output voxel: the voxels whose centres
    # lie within tol + half a diagonal (a KD-tree), each box's distance exactly
    from scipy.spatial import cKDTree
    c = vox.coords()
    lo_all = np.stack([vox.grid.edge(a, c[:, a]) for a in range(3)], 1)
    tree = cKDTree(lo_all + h / 2)
    nearest = np.full(len(pts), np.inf)
    # in chunks of points: a point far from the surface of a coarse model has thousands
    # of voxels within reach, and all at once they took 3 GB (the helix)
    for start in range(0, len(away), 1024):
        part = away[start:start + 1024]
        near = tree.query_ball_point(pts[part], tol + np.linalg.norm(h) / 2)
        counts = np.array([len(n) for n in near], dtype=np.int64)
        assert counts.all(), (model, pts[part][counts == 0][:3], tol)
        point = np.repeat(part, counts)
        lo = lo_all[np.concatenate(near).astype(np.int64)]
        d = np.linalg.norm(np.maximum(np.maximum(lo - pts[point], pts[point] - (lo + h)), 0),
                           axis=1)
        np.minimum.at(nearest, point, d)
    if not len(away):
        return
    worst = int(np.argmax(np.where(np.isin(np.arange(len(pts)), away), nearest, 0)))
    assert nearest[away].max() <= tol, (model, pts[worst], nearest[worst], tol)


BAD = [
    ("cube(size = [1, 2, 3])", "expected ';' or '{'", (1, 23)),
    ("frobnicate(r = 1);", "module 'frobnicate' is unknown", (1, 1)),
    ("cube(size = [1, 2, 3x]);", "expected ',' or ']'", (1, 21)),
    ("cube(size = 1.2.3);", "expected ',' or ')'", (1, 16)),
    ("difference() {\n  cube(size = 1);\n", "never closed", (3, 1)),
    ("cube(size = 1); }", "unbalanced '}'", (1, 17)),
    ("union() { sphere(r = 1); cyl", "expected '('", (1, 29)),
    ("sphere(r = \"big\");", "r must be a finite number", (1, 1)),
    ("cube(size = [1, 2]);", "size must be 3 finite numbers", (1, 1)),
    ("cube(size = 1, size = 2);", "given twice", (1, 16)),
    ("cube(size = 1) @ ;", "unexpected character", (1, 16)),
    ("cube(size = 1) # ;", "expected a module name, got ';'", (1, 18)),
    ("multmatrix(m = [[1, 0], [0, 1]]) cube(size = 1);", "4 x 4", (1, 1)),
]


@pytest.mark.parametrize("text, message, where", BAD)
def test_malformed_csg(text, message, where):
    with pytest.raises(OpenSCADError, match=re.escape(message)) as err:
        read_openscad(text, facets="true")
    assert (err.value.line, err.value.column) == where


@pytest.mark.parametrize("module", ["roof", "mirror"])
def test_unsupported_modules_are_named(module):
    text = f"group() {{\n  {module}() {{ cube(size = 1); }}\n}}"
    with pytest.raises(OpenSCADError, match=f"module '{module}' is not supported") as err:
        read_openscad(text, facets="true")
    assert (err.value.line, err.value.column) == (2, 3)


def test_hostile_nesting_and_size_fail_fast():
    deep = "group() {" * 5000 + "cube(size = 1);" + "}" * 5000
    with pytest.raises(OpenSCADError, match="nesting deeper|nesting too deep"):
        read_openscad(deep, facets="true")
    vec = "cube(size = " + "[" * 5000 + "1" + "]" * 5000 + ");"
    with pytest.raises(OpenSCADError, match="nesting deeper|nesting too deep"):
        read_openscad(vec, facets="true")
    ok = "group() {" * 150 + "cube(size = 1);" + "}" * 150       # deep but allowed
    assert read_openscad(ok, facets="true").bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    with pytest.raises(OpenSCADError, match="holds no geometry"):
        read_openscad("group();", facets="true")


def test_a_file_nested_as_deep_as_allowed_reads_and_runs_in_parallel():
    """Every level keeps a cube and a transform, so the solid is as deep as the file; the
    builder, the compiler and the parallel run's pickling must all take it."""
    from csg.openscad_parser import MAX_DEPTH
    level = ("multmatrix([[1, 0, 0, 0.05], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) "
             "{ union() { cube(0.02); ")
    text = level * (MAX_DEPTH // 2) + "sphere(1);" + "} }" * (MAX_DEPTH // 2)
    solid = read_openscad(text, facets="true")
    depth, node = 0, solid
    while node.children:
        depth, node = depth + 1, node.children[-1]
    assert depth == MAX_DEPTH
    serial = ivx.voxelize(solid, 16, workers=1)
    parallel = ivx.voxelize(solid, 16, workers=2)
    assert parallel.metadata["workers"] == 2
    assert np.array_equal(np.unique(parallel.coords(), axis=0), np.unique(serial.coords(), axis=0))
    with pytest.raises(OpenSCADError, match="nesting deeper"):
        read_openscad(level + text + "} }", facets="true")


def test_truncated_file(tmp_path):
    text = (FIXTURES / "knob.csg").read_text()
    path = tmp_path / "cut.csg"
    path.write_text(text[: len(text) // 2])
    with pytest.raises(OpenSCADError, match=str(path)):
        read_openscad(path, facets="true")
    with pytest.raises(FileNotFoundError):
        read_openscad(tmp_path / "missing.csg", facets="true")


@pytest.mark.parametrize("text, bounds", [
    ("union() { cube(size = 1); %sphere(r = 5); }", ((0, 0, 0), (1, 1, 1))),       # background
    ("union() { cube(size = 1); *sphere(r = 5); }", ((0, 0, 0), (1, 1, 1))),       # disabled
    ("union() { cube(size = 1); #sphere(r = 5); }", ((-5, -5, -5), (5, 5, 5))),    # highlight
    ("union() { cube(size = 1); multmatrix([[1, 0, 0, 9], [0, 1, 0, 0], [0, 0, 1, 0], "
     "[0, 0, 0, 1]]) !sphere(r = 0.5); }", ((-0.5,) * 3, (0.5,) * 3)),             # root
    ("group() %#cube(size = 2); cube(size = 1);", ((0, 0, 0), (1, 1, 1))),         # combined
])
def test_modifiers_as_openscad_writes_them(text, bounds):
    for facets, atol in (("true", 1e-9), ("openscad", 0.1)):     # facets: polygons inside
        solid = read_openscad(text, facets=facets)
        np.testing.assert_allclose(solid.bounds, bounds, atol=atol)


def test_a_file_of_background_parts_only_has_no_geometry():
    with pytest.raises(OpenSCADError, match="holds no geometry"):
        read_openscad("%cube(size = 1);", facets="true")


def test_openscads_facets_are_the_default():
    # a $fn = 6 cylinder is the hexagonal prism OpenSCAD renders, unless true curves
    # are asked for
    text = "cylinder($fn = 6, $fa = 12, $fs = 2, h = 1, r1 = 1, r2 = 1, center = false);"
    hexagon = np.array(read_openscad(text).bounds)
    circle = np.array(read_openscad(text, facets="true").bounds)
    assert np.allclose(hexagon, [[-1, -np.sqrt(3) / 2, 0], [1, np.sqrt(3) / 2, 1]])
    assert np.allclose(circle, [[-1, -1, 0], [1, 1, 1]])


@pytest.mark.parametrize("model, facets", [("bracket", "openscad"), ("bracket", "true"),
                                           ("knob", "openscad"), ("pyramid", "true"),
                                           ("primitives", "true"), ("imported", "true")])
def test_an_ordinary_run_prints_no_numpy_warning(model, facets):
    """The max-norm box tests divide by tiny half-widths (to an infinity, the right
    distance) and meet inf - inf (NaN: the box stays AMBIGUOUS): no RuntimeWarning
    reaches the user (they were printed once per worker, into the progress bar)."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        solid = read_openscad(FIXTURES / f"{model}.csg", facets=facets)
        warnings.simplefilter("error", RuntimeWarning)
        solid.voxelize(48, workers=1)


def test_faceted_solids_take_their_normals_from_their_facets():
    """OpenSCAD's facets are bounded by a box function whose gradient says nothing of
    the surface (70% of the knob's voxels got zero normals and rendered black): the
    normals come from the nearest facet instead, stored and rendered alike."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        knob = read_openscad(FIXTURES / "knob.csg")
        vox = knob.voxelize(48, workers=1, normals=True)
    assert not knob.expression_is_exact
    shading = vox.source.normals_at(vox.centers())
    assert np.allclose(np.linalg.norm(shading, axis=1), 1, atol=1e-6)
    assert np.array_equal(shading, vox.normals)
    # a pyramid of four sloped faces (a polyhedron): every voxel's normal is a face's
    pyramid = read_openscad("polyhedron(points = [[0, 0, 0], [10, 0, 0], [10, 10, 0], "
                            "[0, 10, 0], [5, 5, 6]], faces = [[0, 1, 4], [1, 2, 4], "
                            "[2, 3, 4], [3, 0, 4], [1, 0, 3], [2, 1, 3]]);")
    normals = pyramid.voxelize(32, workers=1).source.normals_at(
        pyramid.voxelize(32, workers=1).centers())
    faces = np.array([[0, -6, 5], [6, 0, 5], [0, 6, 5], [-6, 0, 5], [0, 0, -1]], float)
    faces /= np.linalg.norm(faces, axis=1, keepdims=True)
    assert np.abs(normals @ faces.T).max(axis=1).min() > 1 - 1e-6
