"""Parallel runs (issue 21): bit-identical to the serial run for any number of workers,
any schedule and any executor; a dead worker is reported; Ctrl-C stops everything."""
from __future__ import annotations

import hashlib
import os
import random
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import csg
import implicitvox as iv
from implicitvox.expr import examples
from implicitvox.parallel import Job, WorkerError, farm, plan_workers, split_evenly
from implicitvox.octree.run import Run
from implicitvox.octree.subtrees import subdivide_in_parallel
from implicitvox.octree.surface import SurfaceOptions

HERE = os.path.dirname(__file__)
FIXTURES = os.path.join(HERE, "..", "openscad")


def _torus_mesh():
    """A closed mesh of about 20,000 triangles (a torus, from PyVista)."""
    import pyvista as pv
    knot = pv.ParametricTorus(ringradius=1.0, crosssectionradius=0.3, u_res=100, v_res=100,
                              w_res=2).triangulate().clean()
    return np.asarray(knot.points), knot.faces.reshape(-1, 4)[:, 1:]


MESH = _torus_mesh()


def digest(vox) -> str:
    """Voxels, interior octants (per level, in order) and normals, hashed."""
    h = hashlib.sha256(np.ascontiguousarray(vox.coords()).tobytes())
    for level in sorted(vox.interior):
        h.update(f"{level}:".encode() + np.ascontiguousarray(vox.interior[level]).tobytes())
    if vox.normals is not None:
        h.update(np.ascontiguousarray(vox.normals).tobytes())
    return h.hexdigest()


MODELS = {
    "sinsin34": (examples.example("sinsin34"), {"interior": True, "normals": True}),
    "menger": (examples.example("menger"), {"interior": True}),
    "torus-sweep": (examples.example("torus-sweep"), {"normals": True, "subvoxel": 1}),
    "gear": (examples.example("gear"), {"mean_value": True, "interior": True}),
    "csg": (csg.Box((2, 2, 1)) - csg.Cylinder(0.4, 2).translate((0.3, 0, -0.5)),
            {"interior": True, "normals": True}),
}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_workers_give_the_serial_voxels(name):
    shape, options = MODELS[name]
    serial = iv.voxelize(shape, 48, workers=1, **options)
    assert serial.metadata["workers"] == 1
    for n in (2, 3):
        vox = iv.voxelize(shape, 48, workers=n, **options)
        assert vox.metadata["workers"] == n
        assert digest(vox) == digest(serial), (name, n)
        assert vox.metadata["boxes_evaluated"] == serial.metadata["boxes_evaluated"]


class _Shuffled(ThreadPoolExecutor):
    """Threads that finish the pieces in a random order (each sleeps a random while)."""

    def __init__(self, seed: int):
        super().__init__(4)
        self.rng = random.Random(seed)

    def submit(self, fn, *args, **kwargs):
        delay = self.rng.random() * 0.02

        def late():
            time.sleep(delay)
            return fn(*args, **kwargs)
        return super().submit(late)


@pytest.mark.parametrize("seed", [1, 2])
def test_any_schedule_gives_the_serial_voxels(seed):
    shape = examples.example("blobby")
    serial = iv.voxelize(shape, 40, interior=True, normals=True, workers=1)
    with _Shuffled(seed) as pool:
        vox = iv.voxelize(shape, 40, interior=True, normals=True, executor=pool)
    assert digest(vox) == digest(serial)


@pytest.mark.parametrize("name", ["lobed-plate", "menger"])
def test_any_process_pool_as_executor(name):
    """An Executor of the user's (the job goes with each piece, prepared once per
    worker; on the compiled kernel, with the head's pool of pruned tapes)."""
    from concurrent.futures import ProcessPoolExecutor
    shape = examples.example(name)
    serial = iv.voxelize(shape, 40, interior=True, normals=True, workers=1)
    with ProcessPoolExecutor(2) as pool:
        vox = iv.voxelize(shape, 40, interior=True, normals=True, executor=pool, workers=2)
    assert digest(vox) == digest(serial)


def test_refine_in_parallel():
    """Voxels.refine reuses the run's workers, and matches the serial refine."""
    shape = examples.example("sinsin34")
    serial = iv.voxelize(shape, 32, interior=True, normals=True, workers=1).refine(1)
    refined = iv.voxelize(shape, 32, interior=True, normals=True, workers=2).refine(1)
    assert refined.metadata["workers"] == 2
    assert digest(refined) == digest(serial)


def test_meshes_and_patches_give_the_serial_voxels():
    serial = iv.voxelize_mesh(MESH, 64, workers=1)
    for n in (2, 3):
        assert np.array_equal(iv.voxelize_mesh(MESH, 64, workers=n).coords(), serial.coords())
    teapot = iv.voxelize_bezier(iv.utah_teapot(), 48, workers=1)
    assert np.array_equal(iv.voxelize_bezier(iv.utah_teapot(), 48, workers=2).coords(),
                          teapot.coords())


def test_openscad_model_in_parallel():
    solid = csg.read_openscad(os.path.join(FIXTURES, "bracket.csg"), facets="true")
    serial = iv.voxelize(solid, 48, interior=True, workers=1)
    assert digest(iv.voxelize(solid, 48, interior=True, workers=2)) == digest(serial)


def test_dask_local_cluster_gives_the_serial_voxels():
    import distributed          # a test dependency (pyproject: the test and dask extras)
    shape = examples.example("sinsin34")
    serial = iv.voxelize(shape, 48, interior=True, normals=True, workers=1)
    mesh_serial = iv.voxelize_mesh(MESH, 48, workers=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        scattered = []                  # a small job goes with its tasks, a big one is scattered
        scatter = client.scatter
        client.scatter = lambda *args, **kwargs: scattered.append(1) or scatter(*args, **kwargs)
        vox = iv.voxelize(shape, 48, interior=True, normals=True, executor=client)
        assert vox.metadata["workers"] == 2
        assert digest(vox) == digest(serial)
        assert not scattered
        mesh_vox = iv.voxelize_mesh(MESH, 48, executor=client)
        assert np.array_equal(mesh_vox.coords(), mesh_serial.coords())
        assert scattered


def test_too_shallow_to_split_runs_serially():
    shape = examples.example("sphere")
    vox = iv.voxelize(shape, 4, workers=2)
    assert vox.metadata["workers"] == 1 and vox.count > 0


class Crash(Job):
    """Kills the worker process running piece 1."""

    def run(self, piece):
        if piece == 1:
            os._exit(3)
        time.sleep(0.05)
        return piece


def test_a_dead_worker_is_reported_not_waited_for():
    # the error itself is the check: a farm that waited for the dead worker would never
    # return (no time is asserted here)
    with pytest.raises(WorkerError, match=r"a worker died while testing \([0-3] of 4 pieces done"):
        list(farm(Crash(), [0, 1, 2, 3], workers=2, what="testing"))


class Fail(Job):
    def run(self, piece):
        raise ValueError(f"piece {piece} is bad")


def test_an_error_in_a_piece_is_raised_as_itself():
    with pytest.raises(ValueError, match="piece 0 is bad"):
        list(farm(Fail(), [0], workers=2))


def test_ctrl_c_stops_the_master_and_every_worker(tmp_path):
    """SIGINT to the master alone (the hard case: the workers do not get it): it
    stops at once and leaves no process of its group behind."""
    script = tmp_path / "run.py"
    script.write_text(textwrap.dedent("""
        import sys, implicitvox as iv
        from implicitvox.expr import examples
        def tell(share):
            print("progress", flush=True)
        iv.voxelize(examples.example("sinsin918"), 1024, workers=2, progress=tell)
    """))
    child = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        assert child.stdout.readline().strip() == "progress"
        time.sleep(0.5)
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=30)
    finally:
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGKILL)
    assert "KeyboardInterrupt" in err
    deadline = time.time() + 15
    while time.time() < deadline:
        try:
            os.killpg(child.pid, 0)          # anything left of the run's process group?
        except ProcessLookupError:
            break
        time.sleep(0.2)
    else:
        os.killpg(child.pid, signal.SIGKILL)
        pytest.fail("worker processes outlived the interrupted run")


def _alive(pid: int) -> bool:
    """Whether a process runs (a zombie, dead but not yet reaped, does not)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not hasattr(os, "fork") or not os.path.isdir("/proc"),
                    reason="forks and reads /proc (Linux)")
def test_a_forked_child_has_its_own_pool_and_its_workers_die_with_it(tmp_path):
    """A child forked from a process that already has a pool starts its own (the
    parent's is not its to use), and its workers exit with it when it leaves by
    ``os._exit`` (no atexit: as a test runner's or multiprocessing's children do)."""
    script = tmp_path / "fork.py"
    script.write_text(textwrap.dedent("""
        import os, sys, time
        import implicitvox as iv
        from implicitvox import x, y, z
        import importlib
        farm = importlib.import_module("implicitvox.parallel.farm")
        sphere = x * x + y * y + z * z - 1
        box = ((-1.2,) * 3, (1.2,) * 3)
        first = iv.voxelize(sphere, 64, bounds=box, workers=2)     # the parent's pool
        parents = [p.pid for p in farm._POOLS[2]._processes.values()]
        read, write = os.pipe()
        child = os.fork()
        if child == 0:
            again = iv.voxelize(sphere, 64, bounds=box, workers=2)
            mine = [p.pid for p in farm._POOLS[2]._processes.values()]
            os.write(write, (" ".join(map(str, mine)) + "\\n").encode())
            os._exit(0 if again.count == first.count else 3)
        os.close(write)
        pids = [int(p) for p in os.fdopen(read).read().split()]
        _, status = os.waitpid(child, 0)
        print("child", os.waitstatus_to_exitcode(status), flush=True)
        print("pids", *pids, flush=True)
        print("shared", sorted(set(pids) & set(parents)), flush=True)
        # the parent's pool is untouched and still runs
        print("parent", iv.voxelize(sphere, 64, bounds=box, workers=2).count == first.count,
              flush=True)
    """))
    run = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, start_new_session=True,
                           env=dict(os.environ, IMPLICITVOX_WORKERS="2"))
    try:
        out, err = run.communicate(timeout=60)
        lines = dict(line.split(" ", 1) for line in out.splitlines())
        assert run.returncode == 0, err
        assert lines["child"] == "0" and lines["shared"] == "[]" and lines["parent"] == "True"
        pids = [int(p) for p in lines["pids"].split()]
        assert len(pids) == 2
        time.sleep(1.0)
        assert not [pid for pid in pids if _alive(pid)], "the child's workers outlived it"
    finally:
        try:
            os.killpg(run.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def test_a_model_on_the_compiled_kernel_subdivides_on_threads(monkeypatch):
    """By default, a model the compiled kernel takes is voxelized on threads of this
    process (no process pool starts), each piece on the head's pruned tapes, with
    the voxels, interior, normals and boxes evaluated of one thread. Meshing it
    stays in one worker by default (Run.workers_for); a count is obeyed."""
    import threading
    from implicitvox.octree.subtrees import SubtreeJob
    from implicitvox.parallel import plan
    farms = sys.modules["implicitvox.parallel.farm"]      # (the package exports the function)
    monkeypatch.setattr(plan, "MIN_PARALLEL_WORK", 1)
    monkeypatch.setattr(plan, "available_cores", lambda: 2)
    monkeypatch.delenv("IMPLICITVOX_WORKERS", raising=False)

    def no_processes(*args, **kwargs):
        raise AssertionError("a process pool was started")
    monkeypatch.setattr(farms, "_OwnPool", no_processes)
    seen = []
    run = SubtreeJob.run

    def watched(self, piece):
        seen.append((threading.current_thread().name, self.pool.base is not None
                     and bool((piece[1] > 0).any())))
        return run(self, piece)
    monkeypatch.setattr(SubtreeJob, "run", watched)
    shape = examples.menger(2)
    threaded = iv.voxelize(shape, 64, interior=True, normals=True)
    serial = iv.voxelize(shape, 64, interior=True, normals=True, workers=1)
    assert threaded.metadata["workers"] == 2 and threaded.metadata["parallel"] == "threads"
    assert seen and all(name.startswith("implicitvox") for name, _ in seen)
    assert any(pruned for _, pruned in seen), "no piece started on a pruned tape"
    assert digest(threaded) == digest(serial)
    assert threaded.metadata["boxes_evaluated"] == serial.metadata["boxes_evaluated"]
    gear = examples.example("gear")
    assert iv.mesh(gear, resolution=12).field_data["workers"][0] == 1
    assert iv.mesh(gear, resolution=12, workers=2).field_data["workers"][0] == 2


def test_the_default_uses_every_core_when_it_pays(monkeypatch):
    from implicitvox.parallel import plan
    monkeypatch.setattr(plan, "MIN_PARALLEL_WORK", 1)
    monkeypatch.setenv("IMPLICITVOX_WORKERS", "2")
    assert iv.voxelize(examples.example("gear"), 48).metadata["workers"] == 2
    monkeypatch.setattr(plan, "MIN_PARALLEL_WORK", 1 << 40)
    assert iv.voxelize(examples.example("gear"), 48).metadata["workers"] == 1
    monkeypatch.setattr(plan, "MIN_PARALLEL_WORK", 1)
    monkeypatch.setenv("IMPLICITVOX_WORKERS", "none")
    with pytest.raises(ValueError, match="IMPLICITVOX_WORKERS must be a positive int"):
        iv.voxelize(examples.example("gear"), 48)
    monkeypatch.delenv("IMPLICITVOX_WORKERS")
    assert plan.available_cores() == len(os.sched_getaffinity(0))


def test_plan_and_split():
    assert plan_workers(None, None, work=1, cores=4) == 1
    assert plan_workers(None, None, work=1e9, cores=4) == 4
    assert plan_workers(2, None, work=1) == 2
    assert split_evenly(7, 3) == [(0, 3), (3, 5), (5, 7)]
    assert split_evenly(2, 5) == [(0, 1), (1, 2)]
    assert split_evenly(0, 5) == []


@pytest.mark.parametrize("bad, error, match", [
    ({"workers": 0}, ValueError, "workers must be an int from 1 to 1024, got int 0"),
    ({"workers": 2.5}, ValueError, "workers must be an int"),
    ({"executor": "dask"}, TypeError, "executor must be a concurrent.futures.Executor"),
])
def test_bad_parallel_options_are_named(bad, error, match):
    with pytest.raises(error, match=match):
        iv.voxelize(examples.example("sphere"), 8, **bad)
    with pytest.raises(error, match=match):
        iv.voxelize_mesh(MESH, 8, **bad)


def test_head_and_pieces_cover_the_serial_run():
    """The split level's octants, subdivided apart, give the serial octree, joined
    from the workers' parts; and the serial voxels as codes with their tapes."""
    from implicitvox.eval.function import Function
    from implicitvox.octree.grid import Grid
    shape = examples.example("gear")
    grid = Grid.from_bounds(shape.bounds, 64)
    options = SurfaceOptions(interior=True)
    serial = iv.voxelize(shape, bounds=grid.bounds, voxel_size=grid.voxel_size[0],
                         interior=True, workers=1)
    with ThreadPoolExecutor(2) as pool:
        run = Run.of(max_memory=1 << 30, executor=pool)
        joined = subdivide_in_parallel(shape, Function(shape.expr), grid, options, run,
                                       workers=3, per_voxel=48)
        codes = subdivide_in_parallel(shape, Function(shape.expr), grid, options, run,
                                      workers=3, per_voxel=48, tapes=True)
    assert joined.count == serial.count == sum(n for n, _ in codes.result.tapes)
    assert np.array_equal(joined.tree.coords(), serial.coords())
    assert all(np.array_equal(a, b) for a, b in zip(joined.tree.first, serial.octree.first))
    assert np.array_equal(np.sort(codes.result.codes),
                          iv.octree.morton.encode(serial.coords()))


def test_forkserver_when_other_threads_run():
    """With another thread alive a fork could deadlock: the pool starts its processes
    through the forkserver instead, with the same result."""
    import threading
    from implicitvox.parallel.farm import pool_context
    stop = threading.Event()
    thread = threading.Thread(target=stop.wait)
    thread.start()
    try:
        assert pool_context().get_start_method() in ("forkserver", "spawn")
        shape = examples.example("gear")
        assert digest(iv.voxelize(shape, 40, interior=True, workers=2)) == \
            digest(iv.voxelize(shape, 40, interior=True, workers=1))
    finally:
        stop.set()
        thread.join()


def test_mesh_and_distance_field_in_parallel():
    """mesh: the subdivision on workers, the same triangles; distance_field: the
    band's chunks on workers, the same values and errors (certified and mesh kernels)."""
    from implicitvox import hypot, x, y, z
    gear = examples.example("gear")
    one, two = (iv.mesh(gear, resolution=48, workers=n) for n in (1, 2))
    assert int(two.field_data["workers"][0]) == 2
    assert np.array_equal(one.points, two.points) and np.array_equal(one.faces, two.faces)
    torus = (hypot(x, y) - 0.6) ** 2 + z ** 2 - 0.1 ** 2
    cube = ((-1,) * 3, (1,) * 3)
    serial = iv.distance_field(torus, 32, band=1, bounds=cube, workers=1,
                               check_suitability=False)
    farmed = iv.distance_field(torus, 32, band=1, bounds=cube, workers=2,
                               check_suitability=False)
    assert farmed.metadata["workers"] == 2 and serial.kind == "certified"
    assert np.array_equal(serial.values, farmed.values, equal_nan=True)   # NaN: off the grid
    assert np.array_equal(serial.errors, farmed.errors, equal_nan=True)
    bunny = [iv.distance_field(MESH, 56, band=1, norm="linf", workers=n) for n in (1, 2)]
    assert bunny[1].metadata["workers"] == 2
    assert np.array_equal(bunny[0].values, bunny[1].values, equal_nan=True)
