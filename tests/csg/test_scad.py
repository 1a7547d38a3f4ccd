""".scad files through the installed OpenSCAD (issue 51): read as the .csg OpenSCAD
exports, OpenSCAD's warnings and errors passed on with file and line, a time limit,
and a clear error without OpenSCAD."""
from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

import csg
import implicitvox as iv
from csg.scad import OPENSCAD_VARIABLE, OpenSCADNotFound, export_csg
from implicitvox.io.cli import main

needs_openscad = pytest.mark.skipif(
    shutil.which("openscad") is None,
    reason="OpenSCAD is not installed (apt-get install openscad): .scad input runs it")

PEGS = ("module peg(h) { cylinder(h = h, r = 1, $fn = 8); }\n"
        "for (i = [0:2]) translate([3 * i, 0, 0]) peg(2 + i);\n")


def _write(folder, name, text):
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


@needs_openscad
def test_a_scad_program_reads_as_the_csg_openscad_exports(tmp_path):
    scad = _write(tmp_path, "pegs.scad", PEGS)
    subprocess.run(["openscad", "-o", str(tmp_path / "pegs.csg"), str(scad)], check=True,
                   capture_output=True)
    ours = csg.read_openscad(scad)
    theirs = csg.read_openscad(tmp_path / "pegs.csg")
    assert ours.bounds == theirs.bounds
    assert np.allclose(ours.bounds, ((-1, -1, 0), (7, 1, 4)), atol=1e-9)
    a = iv.voxelize(ours, 24, bounds=ours.bounds, workers=1)
    b = iv.voxelize(theirs, 24, bounds=ours.bounds, workers=1)
    assert a.count > 0 and np.array_equal(a.coords(), b.coords())


@needs_openscad
def test_openscads_warnings_name_their_file_and_line(tmp_path):
    _write(tmp_path, "lib/parts.scad", "module part() { cube(1); }\necho(unknown);\n")
    scad = _write(tmp_path, "main.scad", "include <lib/parts.scad>\npart();\nnothing();\n")
    with pytest.warns(csg.OpenSCADWarning) as said:
        solid = csg.read_openscad(scad)
    messages = [str(w.message) for w in said]
    assert any(m.startswith(f"{tmp_path / 'lib' / 'parts.scad'}:2: Ignoring unknown variable")
               for m in messages), messages
    assert any(m.startswith(f"{scad}:3: Ignoring unknown module 'nothing'")
               for m in messages), messages
    assert solid.bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))


@needs_openscad
@pytest.mark.parametrize("text, line, says", [
    ("cube(1);\nsphere(2;\n", 2, "syntax error"),
    # OpenSCAD exits with status 0 here, and exports nothing
    ("module m() { m(); }\ncube(1);\nm();\n", 1, "Recursion detected calling module 'm'"),
    ("assert(1 > 2, \"too small\");\ncube(1);\n", 1, "too small"),
])
def test_openscads_errors_are_raised_with_file_and_line(tmp_path, text, line, says):
    scad = _write(tmp_path, "bad.scad", text)
    with pytest.raises(csg.OpenSCADError, match=says) as err:
        csg.read_openscad(scad)
    assert (err.value.source, err.value.line, err.value.column) == (str(scad), line, None)
    assert str(err.value).startswith(f"{scad}:{line}: OpenSCAD: ")


@needs_openscad
def test_a_slow_program_is_stopped_at_the_time_limit(tmp_path):
    scad = _write(tmp_path, "slow.scad", "for (i = [0:999]) for (j = [0:999]) "
                                         "for (k = [0:999]) if (i < 0) cube(1);\ncube(1);\n")
    with pytest.raises(TimeoutError, match="did not finish exporting the .csg within 0.5 s"):
        export_csg(scad, seconds=0.5)


def test_without_openscad_the_error_says_how_to_go_on(tmp_path, monkeypatch):
    monkeypatch.setenv(OPENSCAD_VARIABLE, str(tmp_path / "no-openscad"))
    scad = _write(tmp_path, "pegs.scad", PEGS)
    says = r"Install OpenSCAD .*\(openscad -o part\.csg part\.scad\)"
    with pytest.raises(OpenSCADNotFound, match=says):
        csg.read_openscad(scad)


@needs_openscad
def test_the_command_line_reads_scad_and_says_warnings_in_one_line(tmp_path, capsys):
    scad = _write(tmp_path, "pegs.scad", PEGS + "nothing();\n")
    assert main(["voxelize", str(scad), "--resolution", "16"]) == 0
    err = capsys.readouterr().err
    assert f"implicitvox: warning: {scad}:3: Ignoring unknown module 'nothing'" in err
    bad = _write(tmp_path, "bad.scad", "cube(1)\nsphere(2;\n")
    assert main(["voxelize", str(bad), "--resolution", "16"]) == 2
    assert f"implicitvox: error: {bad}:2: OpenSCAD: Parser error" in capsys.readouterr().err
