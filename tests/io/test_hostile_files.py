"""Hostile files and parameters: each is refused with an error that names it, quickly.

The cases that used to hang (issue 22: a JSON constant ``9**9**9``, an ``.npz``
depth of 10**9, ``refine(30)``) run in a subprocess with a time limit, so a
regression fails the test instead of stalling the suite; the one that used to
abort the process (a PLY declaring a billion vertices) runs there too, so a
crash would show as a signal.
"""
from __future__ import annotations

import json
import re
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import implicitvox as ivx
from csg import OpenSCADError, SceneError, load_json, read_openscad
from implicitvox.io import files

ROOT = Path(__file__).resolve().parents[2]


def _run_isolated(code: str, timeout: float = 60.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=timeout, cwd=ROOT)


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    vox = ivx.voxelize(ivx.x ** 2 + ivx.y ** 2 + ivx.z ** 2 - 1, 16,
                       bounds=((-1.2,) * 3, (1.2,) * 3), interior=True, normals=True)
    path = tmp_path_factory.mktemp("npz") / "ball.npz"
    vox.save(str(path))
    return vox, dict(np.load(path))


def _npz(tmp_path, arrays: dict, name="bad.npz") -> str:
    path = tmp_path / name
    np.savez(path, **arrays)
    return str(path)


@pytest.mark.parametrize("change, field", [
    (lambda a: a.update(depth=np.array([10**9])), "depth"),
    (lambda a: a.update(shape=np.array([0, 16, 16])), "shape"),
    (lambda a: a.update(origin=np.array([np.nan, 0, 0])), "origin"),
    (lambda a: a.update(voxel_size=np.array([0.1, -0.1, 0.1])), "voxel_size"),
    (lambda a: a.update(voxel_size=np.array(["a", "b", "c"])), "voxel_size"),
    (lambda a: a.pop("masks_1"), "masks_1"),
    (lambda a: a.update(masks_2=a["masks_2"][:-1]), "inconsistent"),
    (lambda a: a.update(first_1=a["first_1"] + 1), "inconsistent"),
    (lambda a: a.update(payload_normals=a["payload_normals"][:-1]), "inconsistent"),
    (lambda a: a.update(interior_3=np.array([[99, 0, 0]])), "interior_3"),
    (lambda a: a.update(interior_77=np.array([[0, 0, 0]])), "interior_77"),
    (lambda a: a.update(metadata=np.array("[1, 2")), "metadata"),
])
def test_inconsistent_npz_files_are_refused_naming_the_field(saved, tmp_path, change, field):
    arrays = dict(saved[1])
    change(arrays)
    with pytest.raises(ValueError, match=field):
        ivx.load(_npz(tmp_path, arrays))


def test_a_good_npz_still_loads(saved, tmp_path):
    vox, arrays = saved
    back = ivx.load(_npz(tmp_path, arrays, "good.npz"))
    assert np.array_equal(back.coords(), vox.coords()) and back.interior_count == vox.interior_count


def test_an_npz_that_unpacks_too_far_is_refused_before_reading(saved, tmp_path, monkeypatch):
    monkeypatch.setattr(files, "NPZ_LIMIT", 1000)
    with pytest.raises(ValueError, match="unpacks to .* over the limit"):
        ivx.load(_npz(tmp_path, dict(saved[1])))


def test_a_huge_npz_depth_does_not_hang(saved, tmp_path):
    arrays = dict(saved[1], depth=np.array([10**9]))
    path = _npz(tmp_path, arrays)
    out = _run_isolated(f"""
        import implicitvox as iv
        try:
            iv.load({path!r})
        except ValueError as err:
            print("refused:", err)
        """)
    assert out.returncode == 0 and "refused:" in out.stdout and "depth" in out.stdout


def _binvox(tmp_path, header: bytes, data: bytes) -> str:
    path = tmp_path / "bad.binvox"
    path.write_bytes(b"#binvox 1\n" + header + b"data\n" + data)
    return str(path)


@pytest.mark.parametrize("header, data, match", [
    (b"dim 100000 100000 100000\ntranslate 0 0 0\nscale 1\n", b"\x00\xff", "over the limit"),
    (b"dim 0 4 4\ntranslate 0 0 0\nscale 1\n", b"", "'dim' must be 3 counts"),
    (b"dim 4 4 4\ntranslate 0 nan 0\nscale 1\n", b"\x00\x40", "'translate' must be"),
    (b"dim 4 4 4\ntranslate 0 0 0\nscale -1\n", b"\x00\x40", "'scale' must be"),
    (b"dim 4 4 4\ntranslate 0 0 0\nscale 1\n", b"\x00\x40\x01", "odd number of bytes"),
    (b"dim 4 4 4\ntranslate 0 0 0\nscale 1\n", b"\x00\xff\x01\xff", "header says"),
    (b"comment\n" * 100, b"", "no 'data' line"),
])
def test_inconsistent_binvox_files_are_refused(tmp_path, header, data, match):
    with pytest.raises(ValueError, match=match):
        ivx.load(_binvox(tmp_path, header, data))


PLY_LIE = (b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n"
           b"property float x\nproperty float y\nproperty float z\nelement face 1\n"
           b"property list uchar int vertex_indices\nend_header\n" + b"\0" * 100)


@pytest.mark.parametrize("name, content, match", [
    ("lie.ply", PLY_LIE, "declares 1,000,000,000 vertex"),
    ("lie.stl", b"\0" * 80 + struct.pack("<I", 10**9) + b"\0" * 50, "declares 1,000,000,000 "
                                                                        "triangles"),
    ("lie.vtk", b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n"
                b"POINTS 1000000000 float\n0 0 0\n", "POINTS 1,000,000,000"),
    ("lie.vtp", b'<VTKFile type="PolyData"><PolyData><Piece NumberOfPoints="999999999999">'
                b"</Piece></PolyData></VTKFile>", "NumberOfPoints"),
])
def test_mesh_files_that_declare_more_than_they_hold_are_refused(tmp_path, name, content, match):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(ValueError, match=match):
        ivx.voxelize_mesh(str(path), 16)


def test_the_billion_vertex_ply_no_longer_takes_the_process_down(tmp_path):
    path = tmp_path / "lie.ply"
    path.write_bytes(PLY_LIE)
    out = subprocess.run([sys.executable, "-m", "implicitvox.io.cli", "voxelize", str(path),
                          "--resolution", "16", "--quiet"], capture_output=True, text=True,
                         timeout=120, cwd=ROOT)
    assert out.returncode == 2, (out.returncode, out.stderr[-500:])
    assert "declares 1,000,000,000 vertex" in out.stderr and "Traceback" not in out.stderr


def _scene(expr: str) -> str:
    return json.dumps({"implicitvox_scene": 1, "root": {
        "type": "expression", "expr": expr, "bounds": [[-1, -1, -1], [1, 1, 1]]}})


@pytest.mark.parametrize("expr, match", [
    ("1/0 + x", "division by zero"),
    ("10**400 + x", "overflows"),
    ("1e999 * x", "overflows"),
    ("(-8)**0.5 + x", "not a real number"),
    ("x.__class__", "Attribute"),
])
def test_json_constants_fold_in_floats_and_refuse_what_is_not_a_number(expr, match):
    with pytest.raises(SceneError, match=match):
        load_json(_scene(expr))


def test_json_constant_power_towers_do_not_hang():
    out = _run_isolated(f"""
        from csg import load_json
        try:
            load_json({_scene("9**9**9*x")!r})
        except ValueError as err:
            print("refused:", err)
        """, timeout=60)
    assert out.returncode == 0 and "refused:" in out.stdout and "overflows" in out.stdout


def test_json_types_dispatch_through_the_table_only():
    for kind in ("__init__", "_build", "read", "num"):
        with pytest.raises(SceneError, match="unknown node type"):
            load_json(json.dumps({"implicitvox_scene": 1, "root": {"type": kind}}))


@pytest.mark.parametrize("text, match", [
    ("sphere($fn = 1e9, r = 1);", "over the limit of 10000"),
    ("linear_extrude(height = 1, twist = 90, slices = 1e9) square(1);", "slices = 1e\\+09"),
    ("polyhedron(points = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]], "
     "faces = [[0,1,2],[0,1,1e999],[0,2,3],[1,2,3]]);", "faces\\[1\\]"),
])
def test_openscad_resource_limits(text, match):
    with pytest.raises(OpenSCADError, match=match):
        read_openscad(text, facets="openscad")


def test_refine_beyond_the_octree_is_refused_at_once():
    out = _run_isolated("""
        import implicitvox as iv
        vox = iv.voxelize(iv.x ** 2 + iv.y ** 2 + iv.z ** 2 - 1, 8, bounds=((-2,) * 3, (2,) * 3))
        try:
            vox.refine(30)
        except ValueError as err:
            print("refused:", err)
        """)
    assert out.returncode == 0 and "exceeds the octree's 21 levels" in out.stdout


def test_polygons_are_bounded():
    pts = ",".join(f"[{i},{(i * 7) % 13}]" for i in range(5000))
    with pytest.raises(OpenSCADError, match="over the limit of 4,000"):
        read_openscad(f"linear_extrude(height = 1) polygon(points = [{pts}]);", facets="true")


@pytest.mark.parametrize("option", [{"mean_value": "no"}, {"interior": 1}, {"normals": "yes"},
                                    {"recheck": True}, {"subvoxel": 1.0}])
def test_option_types_are_strict(option):
    with pytest.raises(ValueError, match=next(iter(option))):
        ivx.voxelize(ivx.x ** 2 + ivx.y ** 2 + ivx.z ** 2 - 1, 8, bounds=((-2,) * 3, (2,) * 3),
                     **option)


def test_the_command_line_says_which_files_run_code(capsys):
    from implicitvox.io.cli import main
    with pytest.raises(SystemExit):
        main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "A .py model file is Python and is executed" in out
    assert "read as data" in out


def test_a_vti_whose_arrays_lie_is_refused_not_a_crash(saved, tmp_path):
    """A corrupt data array that makes VTK's XML reader allocate without end (the long
    fuzz run found such mutants: std::bad_alloc, SIGABRT) ends in a ValueError."""
    vox = saved[0]
    path = tmp_path / "v.vti"
    vox.save(str(path))
    data = path.read_bytes()
    m = re.search(rb'NumberOfComponents="1"', data)
    bad = data.replace(b'NumberOfComponents="1"', b'NumberOfComponents="999999999"', 1) \
        if m else data[:len(data) // 2]
    path.write_bytes(bad)
    out = _run_isolated(f"""
        import implicitvox as iv
        try:
            iv.load({str(path)!r})
            print("loaded")
        except ValueError as err:
            print("refused:", str(err)[:200])
        """, timeout=120)
    assert out.returncode == 0 and ("refused:" in out.stdout), (out.stdout, out.stderr[-300:])



@pytest.mark.parametrize("text", [
    "cylinder($fn = 24, $fa = 12, $fs = 2, h = 20, r1 = 99999999999999999999, r2 = 3);",
    "sphere($fn = 0, $fa = 12, $fs = 2, r = 1e-320);",
])
def test_degenerate_facets_are_refused_with_their_location(text):
    """Found by the long fuzz run: Qhull's error escaped as a QhullError."""
    with pytest.raises(OpenSCADError, match="1:1: .*: the points span no volume"):
        read_openscad(text, facets="openscad")


def test_an_npz_larger_than_the_memory_left_says_which_file_and_how_much(saved, tmp_path,
                                                                            monkeypatch):
    monkeypatch.setattr(files, "available_memory", lambda: 100)
    path = _npz(tmp_path, dict(saved[1]))
    with pytest.raises(MemoryError, match=r"bad\.npz. unpacks to .* MiB, more than the 0\.0 "
                                          r"MiB this process may still use"):
        ivx.load(path)
