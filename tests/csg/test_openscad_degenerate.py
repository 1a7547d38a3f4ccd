"""Degenerate OpenSCAD input (issue 17, item 2): skipped with a warning naming line and
column, as OpenSCAD skips it, and the rest of the file read; a 2D design refused clearly."""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import csg
import implicitvox as iv

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
    ("rotate_extrude(angle = 0, convexity = 2) { square(size = [1, 1]); }",
     "rotate_extrude: angle 0 sweeps no volume"),
    ("polyhedron(points = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces = [[0, 1, 5]]);",
     "polyhedron: faces[0] [0.0, 1.0, 5.0] does not list 3 or more indices"),
    ("polyhedron(points = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces = [[0, 1]]);",
     "polyhedron: faces[0] [0.0, 1.0] does not list 3 or more indices"),
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
