"""Fuzzing the readers: every input loads or raises a documented error, in time, without a crash.

Seeds are real files of every format (the OpenSCAD fixtures, a JSON scene, an
``.npz``, a ``.binvox``, a ``.vti``, meshes as STL/PLY/OBJ/VTK in text and binary);
seeded mutations (bytes flipped, inserted, deleted, spans repeated, the file
truncated, numbers replaced by hostile ones: huge, negative, zero, NaN, inf)
are read in a separate process (:mod:`tests.support.fuzz_worker`) with a time
limit per input, so a hang or a native crash is caught as such. The documented
errors are ``ValueError`` (with its subclasses ``OpenSCADError`` and
``SceneError``), ``FileNotFoundError`` and ``MemoryError``.

``IMPLICITVOX_FUZZ_INPUTS`` sets how many mutants to try (CI: a few hundred);
run it with ``IMPLICITVOX_FUZZ_INPUTS=100000`` for a long session.
"""
from __future__ import annotations

import json
import os
import re
import selectors
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import implicitvox as ivx
from csg import Box, Cylinder, OpenSCADError, SceneError, Sphere, load_json, read_openscad

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "tests" / "openscad"
INPUTS = int(os.environ.get("IMPLICITVOX_FUZZ_INPUTS", "400"))
TIME_LIMIT = 20.0            # seconds per input
HOSTILE_NUMBERS = [b"1e999", b"-1e999", b"1e9", b"99999999999999999999", b"-1", b"0",
                   b"nan", b"-0", b"4294967295", b"1e-320", b"2147483648"]


def _seeds(folder: Path) -> list[Path]:
    import pyvista as pv
    seeds = sorted(FIXTURES.glob("*.csg"))[:4]
    scene = (Box((2, 1, 1)) - Cylinder(r=0.3, h=3, center=True)) | Sphere(0.4).translate((2, 0, 0))
    (folder / "scene.json").write_text(scene.to_json())
    seeds.append(folder / "scene.json")
    vox = ivx.voxelize(ivx.x ** 2 + ivx.y ** 2 + ivx.z ** 2 - 1, 12,
                       bounds=((-1.2,) * 3, (1.2,) * 3), interior=True, normals=True)
    for ext in (".npz", ".binvox", ".vti"):
        seeds.append(Path(vox.save(str(folder / f"ball{ext}"))))
    mesh = pv.Sphere(theta_resolution=8, phi_resolution=6)
    for name, kwargs in (("ascii.stl", {"binary": False}), ("binary.stl", {}),
                         ("ascii.ply", {"binary": False}), ("binary.ply", {}),
                         ("mesh.obj", {}), ("ascii.vtk", {"binary": False})):
        path = folder / name
        mesh.save(str(path), **kwargs)
        seeds.append(path)
    return seeds


def _mutate(data: bytes, rng: np.random.Generator) -> bytes:
    b = bytearray(data)
    for _ in range(int(rng.integers(1, 4))):
        kind = int(rng.integers(0, 6))
        n = len(b)
        if n == 0:
            b += bytes(rng.integers(0, 256, 8, dtype=np.uint8))
            continue
        i = int(rng.integers(0, n))
        if kind == 0:                                    # flip bytes
            for j in rng.integers(0, n, int(rng.integers(1, 8))):
                b[int(j)] = int(rng.integers(0, 256))
        elif kind == 1:                                  # insert random bytes
            b[i:i] = bytes(rng.integers(0, 256, int(rng.integers(1, 16)), dtype=np.uint8))
        elif kind == 2:                                  # delete a span
            del b[i:i + int(rng.integers(1, 64))]
        elif kind == 3:                                  # repeat a span
            span = b[i:i + int(rng.integers(1, 256))]
            b[i:i] = span * int(rng.integers(2, 50))
        elif kind == 4:                                  # truncate
            del b[i:]
        else:                                            # a number becomes a hostile one
            numbers = [m.span() for m in re.finditer(rb"-?\d+(\.\d+)?(e-?\d+)?", bytes(b[:1 << 16]))]
            if numbers:
                s, e = numbers[int(rng.integers(0, len(numbers)))]
                b[s:e] = HOSTILE_NUMBERS[int(rng.integers(0, len(HOSTILE_NUMBERS)))]
    return bytes(b)


class _Worker:
    def __init__(self):
        self.proc = subprocess.Popen([sys.executable, "-m", "tests.support.fuzz_worker"],
                                     cwd=ROOT, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1)
        self.sel = selectors.DefaultSelector()
        self.sel.register(self.proc.stdout, selectors.EVENT_READ)

    def ask(self, path: str) -> str:
        self.proc.stdin.write(path + "\n")
        self.proc.stdin.flush()
        if not self.sel.select(timeout=TIME_LIMIT + 30):     # +30: the first import
            self.close()
            return f"hang (over {TIME_LIMIT} s)"
        line = self.proc.stdout.readline()
        if not line:
            code = self.proc.wait()
            return f"crash (exit {code})"
        return line.strip()

    def close(self):
        self.proc.kill()
        self.proc.wait()


def test_mutated_files_load_or_are_refused_in_time(tmp_path):
    seeds = _seeds(tmp_path)
    rng = np.random.default_rng(int(os.environ.get("IMPLICITVOX_FUZZ_SEED", "20261201")))
    worker = _Worker()
    failures, outcomes = [], {}
    try:
        for k in range(INPUTS):
            seed = seeds[k % len(seeds)]
            path = tmp_path / f"m{k % 64}{seed.suffix}"
            path.write_bytes(_mutate(seed.read_bytes(), rng))
            t0 = time.perf_counter()
            answer = worker.ask(str(path))
            if answer.startswith(("ok", "refused")) and time.perf_counter() - t0 <= TIME_LIMIT:
                outcomes[answer] = outcomes.get(answer, 0) + 1
                continue
            keep = tmp_path / f"failure{len(failures)}{seed.suffix}"
            keep.write_bytes(path.read_bytes())
            failures.append(f"{seed.name} mutant {k}: {answer} "
                            f"({time.perf_counter() - t0:.1f} s; kept as {keep})")
            if answer.startswith(("hang", "crash")):
                worker = _Worker()
    finally:
        worker.close()
    print(f"{INPUTS} mutants of {len(seeds)} seeds: {outcomes}")
    assert not failures, "\n".join(failures[:10])
    assert sum(outcomes.values()) == INPUTS and "ok" in outcomes


#: hostile-number mutants of the OpenSCAD fixtures read and voxelized in the suite
#: (``tests/benchmarks/bench_fuzz_csg.py`` runs thousands)
CSG_MUTANTS = int(os.environ.get("IMPLICITVOX_FUZZ_CSG", "150"))


def run_csg_mutants(folder: Path, count: int, seed: int) -> tuple[dict, list[str]]:
    """Read and voxelize ``count`` hostile-number mutants (:mod:`tests.support.hostile_csg`)
    in a watched worker: the outcomes counted, and the failures (a crash, a hang, an
    undocumented error) described."""
    from tests.support.hostile_csg import mutants
    worker = _Worker()
    failures, outcomes = [], {}
    try:
        for k, (label, text) in enumerate(mutants(count, seed)):
            path = folder / f"mutant{k % 16}.csg"
            path.write_text(text)
            t0 = time.perf_counter()
            answer = worker.ask(f"voxelize {path}")
            if answer.startswith(("ok", "refused")) and time.perf_counter() - t0 <= TIME_LIMIT:
                outcomes[answer] = outcomes.get(answer, 0) + 1
                continue
            failures.append(f"{label}: {answer} ({time.perf_counter() - t0:.1f} s)")
            if answer.startswith(("hang", "crash")):
                worker = _Worker()
    finally:
        worker.close()
    return outcomes, failures


def test_hostile_numbers_in_csg_files_are_read_and_voxelized_or_refused(tmp_path):
    """Every numeric field may be huge, tiny, subnormal, infinite or NaN: no crash (a
    signal from Clipper's C++), no hang, no error but the documented ones."""
    outcomes, failures = run_csg_mutants(tmp_path, CSG_MUTANTS, 20261206)
    print(f"{CSG_MUTANTS} hostile-number mutants: {outcomes}")
    assert not failures, "\n".join(failures[:10])
    assert sum(outcomes.values()) == CSG_MUTANTS and "ok" in outcomes


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-10**30, 10**30) | st.floats(allow_nan=False)
    | st.text(max_size=12) | st.sampled_from(["sphere", "box", "union", "transform", "expression",
                                             "x*x - 1", "9**9**9", "__init__"]),
    lambda inner: st.lists(inner, max_size=5) | st.dictionaries(
        st.sampled_from(["type", "r", "size", "center", "children", "child", "matrix", "expr",
                         "bounds", "h", "points", "faces", "kind"]), inner, max_size=5),
    max_leaves=30)


@settings(max_examples=150, deadline=2000, suppress_health_check=[HealthCheck.too_slow])
@given(root=JSON_VALUES)
def test_random_json_scenes_load_or_raise_a_scene_error(root):
    try:
        load_json(json.dumps({"implicitvox_scene": 1, "root": root}))
    except SceneError:
        pass


CSG_TOKENS = st.sampled_from(["cube(", "sphere(", "cylinder(", "union()", "difference()",
                              "multmatrix(", "polyhedron(", "linear_extrude(", "circle(",
                              "{", "}", "(", ")", "[", "]", ";", ",", "=", "r", "size", "$fn",
                              "1", "-2.5", "1e999", "1e9", "true", "\"s\"", "points", "faces",
                              "%", "#", "*", "!", "\n"])


@settings(max_examples=150, deadline=2000, suppress_health_check=[HealthCheck.too_slow])
@given(tokens=st.lists(CSG_TOKENS, max_size=40))
def test_random_csg_token_soups_load_or_raise_an_openscad_error(tokens):
    text = " ".join(tokens) + " cube(size = 1);"
    try:
        read_openscad(text, facets="openscad")
    except OpenSCADError:
        pass
