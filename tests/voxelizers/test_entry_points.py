"""One model, one grid: every entry point gives the same voxels.

The CLI, ``implicitvox.voxelize(solid)`` and ``solid.voxelize()`` use the one
default-bounds rule (:func:`implicitvox.octree.grid.padded_bounds`) and cubic
voxels; meshes take trimesh objects as well as PyVista ones and arrays.
"""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from csg import Box, Cylinder
from implicitvox.io.cli import main
from implicitvox.octree.grid import padded_bounds

BRACKET = Box((4, 2, 1)) - Cylinder(r=0.4, h=3, center=True).translate((1, 1, 0))


def test_cli_python_and_solid_give_the_same_voxels(tmp_path, capsys):
    scene = tmp_path / "bracket.json"
    scene.write_text(BRACKET.to_json())
    out = tmp_path / "cli.npz"
    assert main(["voxelize", str(scene), "--resolution", "48", "--out", str(out),
                 "--quiet"]) == 0
    from_cli = ivx.load(str(out))
    from_function = ivx.voxelize(BRACKET, 48)
    from_method = BRACKET.voxelize(48)
    for vox in (from_function, from_method):
        assert vox.grid == from_cli.grid
        assert np.array_equal(vox.coords(), from_cli.coords())
    # the grid is the documented one: cubes, the bounds grown by half a voxel
    assert from_cli.grid.cubic
    lo, _ = padded_bounds(BRACKET.bounds, 48)
    assert from_cli.grid.origin == lo


def test_example_from_cli_and_python_agree(tmp_path, capsys):
    from implicitvox.expr.examples import example
    out = tmp_path / "gear.npz"
    assert main(["voxelize", "--example", "gear", "--resolution", "40", "--out", str(out),
                 "--quiet"]) == 0
    direct = ivx.voxelize(example("gear"), 40)
    back = ivx.load(str(out))
    assert back.grid == direct.grid and np.array_equal(back.coords(), direct.coords())


def test_voxel_size_and_resolution_name_the_same_grid():
    a = ivx.voxelize(BRACKET, bounds=((0, 0, 0), (4, 2, 1)), resolution=32)
    b = ivx.voxelize(BRACKET, bounds=((0, 0, 0), (4, 2, 1)), voxel_size=4 / 32)
    assert a.grid == b.grid and a.grid.shape == (32, 16, 8)
    assert np.array_equal(a.coords(), b.coords())
    with pytest.raises(ValueError, match="not both"):
        ivx.voxelize(BRACKET, 32, voxel_size=0.1)


def test_voxelize_mesh_takes_trimesh_meshes():
    trimesh = pytest.importorskip("trimesh")
    m = trimesh.creation.box(extents=(2.0, 1.0, 0.5))
    a = ivx.voxelize_mesh(m, 24, interior=True)
    b = ivx.voxelize_mesh((np.asarray(m.vertices), np.asarray(m.faces)), 24, interior=True)
    assert a.grid == b.grid and a.grid.cubic
    assert np.array_equal(a.coords(), b.coords()) and a.interior_count == b.interior_count > 0


def test_every_voxelizer_takes_the_same_arguments():
    import inspect
    common = ["resolution", "bounds", "voxel_size"]
    for f in (ivx.voxelize, ivx.voxelize_mesh, ivx.voxelize_bezier):
        params = list(inspect.signature(f).parameters)
        assert params[1:4] == common, (f.__name__, params)
        assert inspect.signature(f).parameters["bounds"].kind is inspect.Parameter.KEYWORD_ONLY
    for f in (ivx.voxelize, ivx.voxelize_mesh):
        assert "interior" in inspect.signature(f).parameters
