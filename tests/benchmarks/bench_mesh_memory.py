"""Benchmark: the mesher's memory estimate against the memory a run takes.

Run: ``python tests/benchmarks/bench_mesh_memory.py [--res 256 512] [--models NAME ...]``

:func:`implicitvox.mesh` refuses a run before it starts when its estimate
(:func:`implicitvox.meshing.mesher.estimate_meshing_memory`: the pilot's surface
voxels, :data:`~implicitvox.meshing.mesher.LEAVES_PER_VOXEL` leaves each,
:data:`~implicitvox.meshing.adaptive.BYTES_PER_CELL` bytes per leaf) passes the
budget, and a guard stops it when the leaves it holds do. Each case runs in a
fresh process, one worker: the resident memory after Numba's cache is loaded and
the voxelization's arrays are freed (the start), then the mesh, then the peak
(``ru_maxrss``). The table gives the leaves per estimated voxel, the bytes per leaf
(the peak's growth over the start), and the estimate over that growth: above 1 the
estimate is cautious, below 1 the guard is what holds the run to its budget. The
seven models of ``bench_mesh_out.py``; the Menger sponge at 256 only (its 512 needs
about 3 GB and 40 s).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))     # the repository root
from tests.benchmarks import tables  # noqa: E402
from tests.benchmarks.bench_mesh_out import MODELS, _shape  # noqa: E402


def _resident() -> int:
    """This process's resident memory now, in bytes."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) * 1024
    return 0


def child(name: str, res: int, _method: str) -> dict:
    """One case in this process: the estimate, the start, the mesh, the peak."""
    import gc
    import implicitvox as ivx
    from implicitvox.meshing.mesher import estimate_meshing_memory
    from implicitvox.octree.grid import grid_of
    shape = _shape(name)
    ivx.mesh(shape, resolution=16, workers=1)                    # Numba's cache loaded
    estimate, leaves_estimated, need = estimate_meshing_memory(
        shape, grid_of(shape.bounds, None, res, None))
    gc.collect()
    start = _resident()
    t = time.perf_counter()
    m = ivx.mesh(shape, resolution=res, workers=1)
    seconds = time.perf_counter() - t
    return {"pilot": int(estimate.voxels), "leaves": int(m.field_data["leaves"][0]),
            "need": int(need), "growth": tables.peak_bytes() - start, "seconds": seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", type=int, nargs="+", default=[256, 512])
    parser.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if tables.answer_child(args.child, child):
        return
    load = tables.load_average()
    header = ("model", "N", "estimated surface voxels", "leaves", "leaves per voxel",
              "bytes per leaf", "estimate", "measured growth", "estimate / measured",
              "seconds")
    print(" | ".join(header))
    rows = []
    for res in args.res:
        for name in args.models:
            if name == "menger3" and res > 256:
                continue
            r = tables.run_child(__file__, name, str(res), "mesh")
            if "error_text" in r:
                row = (name, str(res), "-", "-", "-", "-", "-", "-", "-", r["error_text"])
            else:
                row = (name, str(res), f"{r['pilot']:,}", f"{r['leaves']:,}",
                       f"{r['leaves'] / r['pilot']:.2f}", f"{r['growth'] / r['leaves']:,.0f}",
                       f"{r['need'] / 2**20:,.0f} MiB", f"{r['growth'] / 2**20:,.0f} MiB",
                       f"{r['need'] / r['growth']:.2f}", f"{r['seconds']:.2f}")
            print(" | ".join(row), flush=True)
            rows.append(row)
    tables.write("mesh-memory", header, rows, "python tests/benchmarks/bench_mesh_memory.py",
                 load)


if __name__ == "__main__":
    main()
