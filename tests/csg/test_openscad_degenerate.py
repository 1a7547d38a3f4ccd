"""Degenerate OpenSCAD input (issue 17, item 2): skipped with a warning naming line and
column, as OpenSCAD skips it, and the rest of the file read; a 2D design refused clearly."""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import csg
import implicitvox as iv
from tests.support.mesh_helpers import misses

REST = "sphere(r = 1);"
BOUNDS = ((-1.5,) * 3, (1.5,) * 3)


@pytest.mark.parametrize("degenerate, says", [
    ("cube(size = [0, 1, 1], center = false);", "cube: size [0.0, 1.0, 1.0] is not positive"),
    ("cube(size = [1, -2, 1]);", "cube: size [1.0, -2.0, 1.0] is not positive"),
    ("sphere(r = 0, $fn = 0, $fa = 12, $fs = 2);", "sphere: radius 0.0 is not positive"),
    ("cylinder(h = 0, r1 = 1, r2 = 1, center = false);", "cylinder: height 0.0 is not positive"),
    ("cylinder(h = 1, r1 = 0, r2 = 0, center = false);", "cylinder: both radii are 0"),
    ("multmatrix([[0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) "
     "{ cube(size = [1, 1, 1]); }", "multmatrix: the transform is singular"),
    ("multmatrix([[nan, nan, 0, 0], [nan, nan, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) "
     "{ cube(size = [1, 1, 1]); }", "multmatrix: the transform holds NaN or infinity"),
    ("rotate_extrude(angle = 0, convexity = 2) { square(size = [1, 1]); }",
     "rotate_extrude: angle 0 sweeps no volume"),
    ("polyhedron(points = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces = [[0, 1, 5]]);",
     "polyhedron: faces[0] [0.0, 1.0, 5.0] does not list 3 or more indices"),
    ("polyhedron(points = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces = [[0, 1]]);",
     "polyhedron: faces[0] [0.0, 1.0] does not list 3 or more indices"),
    # issue 51: the same rule for every primitive and extrusion
    ("linear_extrude(height = 0) square(size = [1, 1]);",
     "linear_extrude: height 0 is not positive"),
    ("polyhedron(points = [[0, -4, 1], [0, -5, 1], [0, -5, 2], [0, -4, 0]], "
     "faces = [[1, 2, 2, 1], [0, 0, 3, 3]]);",       # OpenSCAD's test model issue1325
     "polyhedron: every face repeats a corner next to itself"),
    ("polyhedron(points = undef, faces = [[0, 1, 2]], convexity = 1);",
     "polyhedron: its points are undef"),
])
def test_skipped_with_a_warning_and_the_rest_read(degenerate, says):
    text = f"group() {{\n  {REST}\n  {degenerate}\n}}\n"
    expected = rf"<csg>:3:3: {re.escape(says)}.*skipped, as OpenSCAD"
    with pytest.warns(csg.OpenSCADWarning, match=expected):
        solid = csg.read_openscad(text, facets="true")
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # the rest alone: no warning
        alone = csg.read_openscad(REST, facets="true")
    assert np.array_equal(iv.voxelize(solid, 24, bounds=BOUNDS, workers=1).coords(),
                          iv.voxelize(alone, 24, bounds=BOUNDS, workers=1).coords())


def test_a_3d_child_of_an_extrusion_is_skipped_and_the_2d_ones_extruded():
    text = ("linear_extrude(height = 1, center = false) {\n"
            "  square(size = [1, 1]);\n  cube(size = [2, 2, 2]);\n}\n")
    with pytest.warns(csg.OpenSCADWarning, match="<csg>:3:3: cube: a 3D child of "
                                                 "linear_extrude"):
        solid = csg.read_openscad(text, facets="true")
    assert solid.bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))


def test_a_file_of_only_degenerate_parts_holds_no_geometry():
    with pytest.warns(csg.OpenSCADWarning):
        with pytest.raises(csg.OpenSCADError, match="holds no geometry"):
            csg.read_openscad("sphere(r = 0);", facets="true")


@pytest.mark.parametrize("text", ["square(size = [1, 1], center = false);",
                                  "group() {\n  circle(r = 1);\n}"])
def test_a_2d_design_says_so_at_read_time(text):
    with pytest.raises(csg.OpenSCADError, match=r"<csg>:1:1: the design is 2D .*extrude it"):
        csg.read_openscad(text, facets="true")


def test_bad_values_are_still_errors():
    """Degenerate is not malformed: a radius that is no number is still refused."""
    with pytest.raises(csg.OpenSCADError, match="sphere: r must be a finite number"):
        csg.read_openscad('sphere(r = "one");', facets="true")


def test_import_of_a_mesh_relative_to_the_csg_file(tmp_path):
    """``import`` reads the mesh the path names, relative to the .csg file's folder (or
    ``base``); its voxels are exactly the mesh's."""
    import pyvista as pv
    mesh = pv.Icosphere(radius=1.0, nsub=2).translate((0.1, 0.2, 0.3))
    models = tmp_path / "models"
    models.mkdir()
    mesh.save(str(models / "ball.stl"))
    text = 'multmatrix([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) {\n' \
           '  import(file = "ball.stl", layer = "", origin = [0, 0], scale = 1, ' \
           'convexity = 1, $fn = 0, $fa = 12, $fs = 2, timestamp = 1);\n}\n'
    (models / "model.csg").write_text(text)
    solid = csg.read_openscad(str(models / "model.csg"), facets="true")
    elsewhere = csg.read_openscad(text, base=models, facets="true")
    exact = iv.voxelize_mesh(str(models / "ball.stl"), 32, workers=1)
    for s in (solid, elsewhere):
        vox = s.voxelize(bounds=exact.bounds, voxel_size=exact.voxel_size, workers=1)
        assert np.array_equal(vox.coords(), exact.coords())


def test_import_of_a_missing_or_unread_file(tmp_path):
    with pytest.warns(csg.OpenSCADWarning, match=r"<csg>:2:3: import: cannot open .*gone.stl"):
        solid = csg.read_openscad('union() {\n  import(file = "gone.stl");\n  cube(size = 1);\n}',
                                  base=tmp_path, facets="true")
    assert solid.bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    with pytest.raises(csg.OpenSCADError, match=r"import: \.svg files are not read"):
        csg.read_openscad('import(file = "part.svg");', base=tmp_path, facets="true")
    with pytest.warns(csg.OpenSCADWarning, match=r"<csg>:1:19: import: cannot open .*gone.dxf"):
        assert csg.read_openscad('linear_extrude(1) import(file = "gone.dxf"); cube(1);',
                                 base=tmp_path, facets="true").bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))



def _read(text: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", csg.OpenSCADWarning)
        return csg.read_openscad(text)


def test_a_2d_child_of_a_3d_boolean_is_ignored_with_a_warning():
    """OpenSCAD does not mix 2D and 3D operands: the circle bores no endless hole."""
    text = "difference() {\n  cube(size = 10);\n  circle(r = 6);\n}\n"
    with pytest.warns(csg.OpenSCADWarning, match=r"<csg>:3:3: circle: a 2D child of a 3D "
                                                 r"difference"):
        solid = csg.read_openscad(text)
    cube = _read("cube(size = 10);")
    assert np.array_equal(solid.voxelize(24).coords(), cube.voxelize(24).coords())


def test_an_intersection_with_an_empty_extrusion_is_empty():
    with pytest.raises(csg.OpenSCADError, match="holds no geometry"):
        _read("intersection() { cube(size = 10); linear_extrude(height = 0) "
              "square(size = 5); }")


TOUCHING = ("intersection() {\n  cube(size = 10);\n"
            "  multmatrix([[1, 0, 0, 10], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) "
            "cube(size = 10);\n}\n")
TURNED = ("multmatrix([[0.866025, -0.5, 0, 0], [0.5, 0.866025, 0, 0], [0, 0, 1, 0], "
          "[0, 0, 0, 1]]) {\n" + TOUCHING + "}\n")
FAR_CUBE = "multmatrix([[1, 0, 0, 40], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) cube(size = 6);"


@pytest.mark.parametrize("text", [TOUCHING, TURNED, TOUCHING + FAR_CUBE, TURNED + FAR_CUBE],
                         ids=["alone", "turned", "beside-a-cube", "turned-beside-a-cube"])
def test_cubes_that_only_touch_intersect_in_nothing(text):
    """The intersection of two cubes sharing a face has no volume: no voxel, alone or
    beside another part (it used to leave the shared face, a one-voxel layer, where
    it stood alone). OpenSCAD 2021.01 exports that face as a sheet of volume 0,
    warning that the object "may not be a valid 2-manifold and may need repair";
    the regularized solid, which this voxelizes, has no surface there."""
    solid = _read(text)
    bounds = ((-10.0, -10.0, -10.0), (50.0, 30.0, 20.0))
    vox = iv.voxelize(solid, 60, bounds=bounds, workers=1)
    alone = iv.voxelize(_read(FAR_CUBE), 60, bounds=bounds, workers=1) \
        if FAR_CUBE in text else None
    if alone is None:
        assert vox.count == 0
    else:
        assert alone.count > 0 and np.array_equal(vox.coords(), alone.coords())


def test_a_hull_skips_an_empty_child_and_hulls_the_rest():
    text = ("hull() {\n  intersection() { cube(size = 1); multmatrix([[1, 0, 0, 5], [0, 1, 0, 0], "
            "[0, 0, 1, 0], [0, 0, 0, 1]]) cube(size = 1); }\n"
            "  multmatrix([[1, 0, 0, 2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) "
            "cube(size = 1);\n  cube(size = 1);\n}\n")
    with pytest.warns(csg.OpenSCADWarning, match=r"<csg>:2:3: intersection: the intersection "
                                                 r"is empty"):
        solid = csg.read_openscad(text)
    assert np.allclose(solid.bounds, ((0, 0, 0), (3, 1, 1)), atol=1e-9)


@pytest.mark.parametrize("newsize, auto, size", [
    ("[6, 0, 0]", "[1, 1, 1]", (6, 6, 6)),        # shrinking: auto axes take x's factor
    ("[18, 0, 0]", "[1, 1, 1]", (18, 18, 18)),    # growing
    ("[6, 0, 0]", "[0, 0, 0]", (6, 9, 9)),        # no auto: the others stay
    ("[6, 27, 0]", "[1, 1, 1]", (6, 27, 27)),     # auto takes the largest new size's factor
])
def test_resize_autoscales_as_openscad_does(newsize, auto, size):
    solid = _read(f"resize(newsize = {newsize}, auto = {auto}) cube(size = 9);")
    lo, hi = np.asarray(solid.bounds)
    assert np.allclose(hi - lo, size, atol=1e-6)


def test_a_circle_of_radius_0_is_skipped_and_its_extrusion_with_it():
    text = "group() {\n  sphere(r = 1);\n  linear_extrude(height = 1) circle(r = 0);\n}\n"
    with pytest.warns(csg.OpenSCADWarning, match=r"<csg>:3:30: circle: radius 0 is not "
                                                 r"positive; skipped, as OpenSCAD does"):
        solid = csg.read_openscad(text, facets="true")
    assert np.allclose(solid.bounds, ((-1,) * 3, (1,) * 3))


def test_a_profile_touching_the_axis_is_revolved():
    """OpenSCAD's test model horn-torus.scad: a circle touching the axis (its bounds
    a rounding hair across x = 0) makes a horn torus, not an error."""
    text = ("rotate_extrude(angle = 360, convexity = 2, $fn = 24) {\n"
            "  multmatrix([[1, 0, 0, 1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) {\n"
            "    circle(r = 1, $fn = 24);\n  }\n}\n")
    assert csg.read_openscad(text).bounds is not None          # OpenSCAD's facets
    solid = csg.read_openscad(text, facets="true")
    vox = iv.voxelize(solid, 32, workers=1)
    u, v = np.random.default_rng(5).uniform(0, 2 * np.pi, (2, 500))
    points = np.stack([(1 + np.cos(u)) * np.cos(v), (1 + np.cos(u)) * np.sin(v), np.sin(u)], 1)
    assert misses(vox, points) == 0


OPEN_TET = ("polyhedron(points = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], "
            "faces = [[0, 1, 2], [0, 3, 1], [0, 2, 3]]);")       # one face missing


def test_an_open_mesh_is_dropped_from_a_boolean_and_kept_alone():
    """OpenSCAD cannot make a CGAL Nef polyhedron of a mesh that is not closed: beside
    another part it drops it ("The given mesh is not closed!"; its STL holds the cube
    alone, checked with OpenSCAD 2021.01, as in its test model bugs/issue802); alone
    it exports it as it is."""
    moved = "multmatrix([[1, 0, 0, 3], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) " + OPEN_TET
    with pytest.warns(csg.OpenSCADWarning, match=r"<csg>:2:1: multmatrix: its mesh is not "
                                                 r"closed"):
        solid = csg.read_openscad("cube(size = 0.5);\n" + moved)
    assert solid.bounds == ((0.0, 0.0, 0.0), (0.5, 0.5, 0.5))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        alone = csg.read_openscad(OPEN_TET)
    assert alone.bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    # and in the booleans (each as OpenSCAD 2021.01 exports it): nothing left to cut
    # from, nothing cut, nothing shared
    with pytest.warns(csg.OpenSCADWarning, match="not closed"):
        assert _read_raw("difference() { " + OPEN_TET + " cube(size = 0.5); }") is None
    with pytest.warns(csg.OpenSCADWarning, match="not closed"):
        cut = _read_raw("difference() { cube(size = 2); " + OPEN_TET + " }")
    assert cut.bounds == ((0.0, 0.0, 0.0), (2.0, 2.0, 2.0)) and not cut.children
    with pytest.warns(csg.OpenSCADWarning, match="not closed"):
        assert _read_raw("intersection() { cube(size = 2); " + OPEN_TET + " }") is None


def _read_raw(text: str):
    try:
        return csg.read_openscad(text)
    except csg.OpenSCADError as err:
        assert "holds no geometry" in str(err)
        return None
