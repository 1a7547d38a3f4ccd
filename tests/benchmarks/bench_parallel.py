"""Benchmark: parallel subdivision (issue 21, Stolte §5.2): 1 worker against 2, in one run.

Run: ``python tests/benchmarks/bench_parallel.py [--cases ...] [--repeat 2] [--quick]
[--no-dask] [--threads] [--huge]``

For each case, in one process, alternately (best of ``--repeat`` each):

* ``serial``: ``workers=1``, in this process;
* ``workers=2``: what ``voxelize`` picks for two workers: threads of this
  process for a model on the compiled kernel (the CSG models here; its
  subdivision releases the GIL, and the pieces start on the head's pruned
  tapes), a pool of processes of this machine for the others; the row says
  which (``2 threads``, ``2 processes``);
* ``ThreadPoolExecutor(2)`` as the executor (``--threads``): on
  the array path the kernels are numpy calls that hold the GIL between them,
  so this measures what processes buy over threads there;
* ``LocalCluster``: a Dask ``LocalCluster(n_workers=2, processes=True)``
  as the executor. The cluster runs in a child process, started after the
  runs above (as a user's cluster runs apart from their script); a
  ``Client`` connects to it just before each of these runs and closes after
  it, outside the timing. A cluster or client inside this process would slow
  the serial baseline by 10–15% (their event-loop threads take the GIL;
  measured with the gear), which flatters every yield.

The cluster's yield is against serial runs made beside the same idle cluster
(``serial, cluster idle beside``, alternated with the cluster's runs); the
process pool's against serial runs with no cluster on the machine. An idle
2-worker cluster is not idle: its scheduler and workers wake for heartbeats
and system monitoring, and on a 2-core machine that alone took the gear's
2-process yield from 0.98-1.01 to 0.82-0.90 (measured, best of 3 each way).

It prints seconds, the yield ``t1 / (n tn)`` (Stolte's Table 1; 1 is perfect)
and checks that every run gives the serial run's voxels (a digest of the
sorted codes and the interior). Cases: sin(9θ)sin(18φ) − r and the gear at
1024³, the Stanford bunny (mesh) at 512³, the level-2 and level-3 Menger
sponges and the union of 100 spheres at 512³.

``--huge``: sin(3θ)sin(4φ) − r at 2048³ through the 2-worker LocalCluster and
serially, the voxels compared, the time and octree size of each (the table
``parallel-huge``).
"""
from __future__ import annotations

import argparse
import contextlib
import hashlib
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import implicitvox as iv
from implicitvox.expr import examples
from implicitvox.triangles.inputs import as_triangles

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables

from tests.support.mesh_helpers import BUNNY     # noqa: E402 (the shared data's bunny)
#: name -> (model, resolution, quick resolution)
CASES = {
    "sinsin918": ("sinsin918", 1024, 128),
    "gear": ("gear", 1024, 128),
    "bunny": ("bunny", 512, 128),
    "menger": ("menger", 512, 128),
    "menger3": ("menger3", 512, 128),
    "100 spheres": ("100 spheres", 512, 128),
}


def _digest(vox) -> str:
    h = hashlib.sha256(np.ascontiguousarray(vox.coords()).tobytes())
    for level in sorted(vox.interior):
        h.update(np.ascontiguousarray(vox.interior[level]).tobytes())
    return h.hexdigest()[:12]


def _model(name: str):
    if name == "bunny":
        return as_triangles(BUNNY)       # read once: the runs time the voxelization
    if name == "menger3":
        return examples.menger(3)
    if name == "100 spheres":
        return examples.sphere_union(100)
    return examples.example(name)


def _voxelize(model, res: int, **parallel):
    if isinstance(model, tuple):
        return iv.voxelize_mesh(model, res, **parallel)
    return iv.voxelize(model, res, **parallel)


def _time(model, res: int, **parallel) -> tuple[float, object]:
    t = time.perf_counter()
    vox = _voxelize(model, res, **parallel)
    return time.perf_counter() - t, vox


#: the child process holding the LocalCluster: prints its address, stops at EOF
_CLUSTER_PROCESS = """
import sys
from distributed import LocalCluster
if __name__ == "__main__":
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    print(cluster.scheduler_address, flush=True)
    sys.stdin.read()
    cluster.close()
"""


@contextlib.contextmanager
def _cluster():
    """A 2-worker ``LocalCluster(processes=True)`` in a child process; yields its address."""
    child = subprocess.Popen([sys.executable, "-c", _CLUSTER_PROCESS], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        address = child.stdout.readline().strip()
        if not address:
            raise RuntimeError("the LocalCluster did not start")
        yield address
    finally:
        child.stdin.close()
        try:
            child.wait(timeout=30)
        except subprocess.TimeoutExpired:
            child.kill()


def _time_on(address: str, model, res: int) -> tuple[float, object]:
    """One run through the cluster at ``address``, the client connected outside the timing."""
    from distributed import Client
    with Client(address) as client:
        return _time(model, res, executor=client)


def _fmt(seconds: float) -> str:
    return f"{seconds:.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="small resolutions (a smoke run)")
    parser.add_argument("--no-dask", action="store_true", help="skip the LocalCluster runs")
    parser.add_argument("--threads", action="store_true", help="also a 2-thread executor")
    parser.add_argument("--huge", action="store_true",
                        help="only sin(3θ)sin(4φ) − r at 2048³ through the LocalCluster")
    args = parser.parse_args()
    load = tables.load_average()
    print(f"load average before: {load}; {tables.machine()}")
    if args.huge:
        return huge(load, args.quick)
    local = {"workers=2": {"workers": 2}}
    if args.threads:
        local["ThreadPoolExecutor(2)"] = "threads"
    rows = timings(args, local)                      # no cluster on the machine
    if not args.no_dask:
        with _cluster() as address:                  # then beside the cluster
            rows += timings(args, {"LocalCluster (2)": address}, baseline="serial, "
                            "cluster idle beside")
    rows.sort(key=lambda row: list(CASES).index(row[0]))
    header = ["model", "N", "surface voxels", "run", "seconds (best of "
              f"{args.repeat})", "yield t1/(n·tn)", "same voxels"]
    if not args.quick:
        tables.write("parallel", header, rows,
                     "python tests/benchmarks/bench_parallel.py " + " ".join(sys.argv[1:]),
                     load)


def timings(args, parallel_modes: dict, baseline: str = "serial") -> list[list[str]]:
    """Every case, serially and in each of ``parallel_modes`` (name -> keyword
    arguments, ``"threads"``, or a cluster's address), alternated A B A B; the
    table's rows, each yield against the serial run of the same call (so the
    cluster's yield is against a serial run beside the same idle cluster)."""
    modes = {baseline: {"workers": 1}, **parallel_modes}
    rows = []
    for name in args.cases:
        model_name, res, quick = CASES[name]
        res = quick if args.quick else res
        model = _model(model_name)
        _voxelize(model, 64, workers=1)     # (the compiled kernel loaded, caches warm)
        best = {mode: np.inf for mode in modes}
        digests, label = {}, dict(zip(modes, modes))
        for _ in range(args.repeat):
            for mode, parallel in modes.items():          # alternated, A B C A B C
                if parallel == "threads":
                    with ThreadPoolExecutor(2) as pool:
                        seconds, vox = _time(model, res, executor=pool, workers=2)
                elif isinstance(parallel, str):
                    seconds, vox = _time_on(parallel, model, res)
                else:
                    seconds, vox = _time(model, res, **parallel)
                best[mode] = min(best[mode], seconds)
                digests.setdefault(mode, _digest(vox))
                if mode == "workers=2":       # threads or processes, as voxelize chose
                    label[mode] = f"2 {vox.metadata.get('parallel', 'processes')}"
                count = vox.count
                del vox
        t1 = best[baseline]
        for mode in modes:
            n = 1 if mode == baseline else 2
            same = "yes" if digests[mode] == digests[baseline] else "NO"
            row = [name, f"{res}³", f"{count:,}", label[mode], _fmt(best[mode]),
                   f"{t1 / (n * best[mode]):.2f}", same]
            print(" | ".join(row), flush=True)
            rows.append(row)
    return rows


def huge(load: str, quick: bool) -> None:
    """sin(3θ)sin(4φ) − r at 2048³: a 2-worker LocalCluster, then serially."""
    shape = examples.example("sinsin34")
    res = 256 if quick else 2048
    with _cluster() as address:
        t_farmed, farmed = _time_on(address, shape, res)
        count_farmed, bytes_farmed = farmed.count, farmed.octree.nbytes
        digest_farmed = _digest(farmed)
        del farmed
    print(f"LocalCluster: {count_farmed:,} voxels in {t_farmed:.1f} s", flush=True)
    t = time.perf_counter()
    serial = iv.voxelize(shape, res, workers=1)
    t_serial = time.perf_counter() - t
    same = "yes" if _digest(serial) == digest_farmed else "NO"
    print(f"serial: {serial.count:,} voxels in {t_serial:.1f} s; same voxels: {same}")
    rows = [["sinsin34", f"{res}³", "LocalCluster (2)", f"{count_farmed:,}",
             f"{bytes_farmed / 2**20:,.0f}", f"{t_farmed:.1f}", same],
            ["sinsin34", f"{res}³", "serial", f"{serial.count:,}",
             f"{serial.octree.nbytes / 2**20:,.0f}", f"{t_serial:.1f}", "-"]]
    if not quick:
        tables.write("parallel-huge", ["model", "N", "run", "surface voxels", "octree MiB",
                                       "seconds", "same voxels"], rows,
                     "python tests/benchmarks/bench_parallel.py --huge", load)


if __name__ == "__main__":
    main()
