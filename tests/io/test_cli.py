"""The implicitvox command: examples, model files, errors with locations."""
from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox.io.cli import main


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_examples_lists_stolte_models(capsys):
    code, out, _ = run(["examples"], capsys)
    assert code == 0 and "sinsin34" in out and "gear" in out and "torus-sweep" in out


def test_model_file_with_progress_and_output(tmp_path, capsys):
    model = tmp_path / "ball.py"
    model.write_text("from implicitvox import x, y, z, sqrt\nshape = sqrt(x*x + y*y + z*z) - 1\n")
    out_file = tmp_path / "ball.npz"
    code, out, err = run(["voxelize", str(model), "--resolution", "24", "--bounds", "-1.2",
                          "-1.2", "-1.2", "1.2", "1.2", "1.2", "--out", str(out_file)], capsys)
    assert code == 0, err
    assert "100.0%" in err and "surface voxels" in out
    direct = ivx.voxelize(ivx.sqrt(ivx.x**2 + ivx.y**2 + ivx.z**2) - 1,
                          24, bounds=((-1.2,) * 3, (1.2,) * 3))
    assert np.array_equal(ivx.load(str(out_file)).coords(), direct.coords())


@pytest.mark.parametrize("source, match", [
    ("x = 1\n", "defines no `shape`"),
    ("from implicitvox import x\n\nshape = x / undefined_name\n", r"model\.py:3: NameError"),
    ("shape = (\n", "syntax error"),
])
def test_model_errors_name_the_model_line(tmp_path, capsys, source, match):
    model = tmp_path / "model.py"
    model.write_text(source)
    code, _, err = run(["voxelize", str(model), "--bounds", "0", "0", "0", "1", "1", "1"], capsys)
    assert code == 2 and "Traceback" not in err
    import re
    assert re.search(match, err), err


@pytest.mark.parametrize("argv, match", [
    (["voxelize"], "model file or --example"),
    (["voxelize", "--example", "nope"], "unknown example"),
    (["voxelize", "missing.py"], "no such model file"),
    (["voxelize", "--example", "sphere", "--resolution", "0"], "resolution must be an int from 1 to"),
    (["voxelize", "--example", "sphere", "--out", "/no/such/dir/v.npz"], "cannot write --out"),
    (["voxelize", "--example", "sphere", "--bounds", "0", "0", "0", "0", "1", "1"], "extent"),
    (["voxelize", "--example", "sinsin918", "--resolution", "8192", "--max-memory", "0.1"],
     "over the budget"),
    (["voxelize", "--example", "sphere", "--max-memory", "inf"], "--max-memory must be a positive"),
    (["voxelize", "--example", "sphere", "--voxel-size", "-1"], "voxel_size must be a positive"),
    (["voxelize", "--example", "sphere", "--workers", "0"], "--workers must be an int from 1"),
])
def test_bad_input_is_refused_clearly(argv, match, capsys):
    code, _, err = run(argv, capsys)
    assert code == 2 and match in err and "Traceback" not in err


def test_console_entry_point_renders_an_example(tmp_path):
    png = tmp_path / "gear.png"
    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    proc = subprocess.run([sys.executable, "-m", "implicitvox.io.cli", "voxelize", "--example", "gear",
                           "--resolution", "64", "--render", str(png)],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert png.stat().st_size > 10_000


FIXTURES = os.path.join(os.path.dirname(os.path.dirname(__file__)), "openscad")


def test_openscad_and_json_models(tmp_path, capsys):
    csg_file = os.path.join(FIXTURES, "bracket.csg")
    for facets in ("true", "openscad"):
        out_file = tmp_path / f"bracket-{facets}.npz"
        code, out, err = run(["voxelize", csg_file, "--resolution", "32", "--facets", facets,
                              "--out", str(out_file)], capsys)
        assert code == 0, err
        assert ivx.load(str(out_file)).count > 0
    import csg
    scene = tmp_path / "part.json"
    scene.write_text((csg.Box((2, 2, 2), center=True) - csg.Sphere(1.2)).to_json())
    code, out, err = run(["voxelize", str(scene), "--resolution", "16", "--quiet"], capsys)
    assert code == 0 and "surface voxels" in out


@pytest.mark.parametrize("content, suffix, match", [
    ("cube(size = 1)", ".csg", r":1:15: expected ';'"),
    ('roof() square(size = [1, 1]);', ".csg", "module 'roof' is not supported"),
    ('{"implicitvox_scene": 1, "root": {"type": "sphere"}}', ".json", r"root\.r"),
    ("solid x", ".step", "unsupported model type '.step'"),
])
def test_bad_csg_and_json_models(tmp_path, capsys, content, suffix, match):
    path = tmp_path / f"model{suffix}"
    path.write_text(content)
    code, _, err = run(["voxelize", str(path), "--resolution", "8", "--quiet"], capsys)
    assert code == 2 and re.search(match, err), err


def test_mesh_model(tmp_path, capsys):
    import pyvista as pv
    path = tmp_path / "nut.stl"
    pv.examples.load_nut().save(str(path))
    code, out, err = run(["voxelize", str(path), "--resolution", "32", "--interior", "--quiet"],
                         capsys)
    assert code == 0 and "interior voxels" in out, err
    code, _, err = run(["voxelize", str(path), "--normals"], capsys)
    assert code == 2 and "implicit models" in err


def test_an_unexpected_error_is_one_line_unless_debug(monkeypatch, capsys):
    from implicitvox.io import cli

    def broken(args):
        raise RuntimeError("a bug")
    monkeypatch.setattr(cli, "_voxelize", broken)
    assert cli.main(["voxelize", "--example", "sphere"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error: RuntimeError: a bug" in err
    assert cli.main(["--debug", "voxelize", "--example", "sphere"]) == 1
    assert "Traceback" in capsys.readouterr().err


def test_an_unreachable_scheduler_is_named(monkeypatch, capsys):
    from implicitvox.io import cli
    monkeypatch.setattr(cli, "SCHEDULER_TIMEOUT", 1)
    code, _, err = run(["mesh", "--example", "sphere", "--resolution", "8", "--scheduler",
                        "tcp://127.0.0.1:9"], capsys)
    assert code == 2 and "--scheduler tcp://127.0.0.1:9: cannot reach it" in err


def test_workers_give_the_same_voxels(tmp_path, capsys):
    files = []
    for workers in ("1", "2"):
        out_file = tmp_path / f"gear{workers}.npz"
        code, _, err = run(["voxelize", "--example", "gear", "--resolution", "48", "--quiet",
                            "--interior", "--workers", workers, "--out", str(out_file)], capsys)
        assert code == 0, err
        files.append(ivx.load(str(out_file)))
    assert files[1].metadata["workers"] == 2
    assert np.array_equal(files[0].coords(), files[1].coords())


def test_no_prune_gives_the_same_voxels(tmp_path, capsys):
    files = []
    for flag in ([], ["--no-prune"]):
        out_file = tmp_path / f"plate{len(flag)}.npz"
        code, _, err = run(["voxelize", "--example", "drilled-plate", "--resolution", "64",
                            "--quiet", "--out", str(out_file)] + flag, capsys)
        assert code == 0, err
        files.append(ivx.load(str(out_file)))
    assert files[0].metadata["tapes_built"] > 0 and files[1].metadata["tapes_built"] == 0
    assert np.array_equal(files[0].coords(), files[1].coords())


def test_mesh_command_writes_a_mesh_and_voxelize_says_to_use_it(tmp_path, capsys):
    import pyvista as pv
    out = tmp_path / "ball.stl"
    assert main(["mesh", "--example", "sphere", "--resolution", "16", "--out", str(out),
                 "--quiet"]) == 0
    said = capsys.readouterr().out
    assert "triangles" in said and "Hausdorff distance <=" in said
    assert pv.read(str(out)).n_cells > 100
    assert main(["voxelize", "--example", "sphere", "--resolution", "16", "--out",
                 str(tmp_path / "v.stl"), "--quiet"]) == 2
    assert "implicitvox mesh" in capsys.readouterr().err
    assert main(["mesh", "--example", "sphere", "--resolution", "16", "--out",
                 str(tmp_path / "v.npz")]) == 2
    assert "a mesh is written as one of" in capsys.readouterr().err


def test_field_command_writes_a_field_and_checks_suitability(tmp_path, capsys):
    model = tmp_path / "ball.py"
    model.write_text("from implicitvox import linf\nshape = linf.Sphere((0, 0, 0), 1.0)\n")
    out = tmp_path / "ball.npz"
    assert main(["field", str(model), "--resolution", "24", "--band", "2", "--out", str(out),
                 "--check-suitability", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "suitability: S_r-open up to r = " in text and ": suitable" in text
    assert "(euclidean, exact)" in text
    back = ivx.load_field(str(out))
    p = back.grid.centers(back.coords())
    assert np.allclose(back.values[back.active], np.linalg.norm(p, axis=1) - 1, atol=1e-12)
    assert main(["field", str(model), "--resolution", "8", "--out", "x.stl"]) == 2
    assert "a distance field is written as one of .npz, .vti" in capsys.readouterr().err
    assert main(["field", str(model), "--resolution", "24", "--band", "2", "--out", str(out),
                 "--dtype", "float32", "--quiet"]) == 0
    small = ivx.load_field(str(out))
    assert small.values.dtype == np.float32 and np.array_equal(small.active, back.active)
    assert np.all(np.abs(small.values[small.active] - back.values[back.active])
                  <= small.errors[small.active])
