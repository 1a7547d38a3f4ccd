"""Benchmark: meshes out (:func:`implicitvox.mesh`) against dense sampling + marching cubes.

Run: ``python tests/benchmarks/bench_mesh_out.py [--resolutions 256 512 1024] [--models ...]``

For each model (Stolte's sin(3θ)sin(4φ) - r and sin(9θ)sin(18φ) - r, the
gear, the level-3 Menger sponge) and each resolution N, in a fresh child
process each (so the peak memory is the run's own, ``ru_maxrss``), one after
the other:

* ``mesh``: ``implicitvox.mesh(shape, resolution=N)`` (the largest cells are
  the N-grid's voxels; complex cells split up to 4 levels deeper);
* ``dense``: the function sampled on the (N+1)^3 lattice (float32, in slabs)
  and ``skimage.measure.marching_cubes`` at level 0 - the usual way, with no
  bound. Not run where the samples alone would pass ``--dense-limit`` GiB.

Each row: seconds, triangles, peak memory, and the measured Hausdorff
distance both ways in units of the N-grid's voxel: mesh to surface (a
certified upper bound per sample, :func:`implicitvox.meshing.hausdorff.distance_to_surface`,
over up to 200,000 samples of the triangles) and surface to mesh (exact, from
up to 200,000 points on the surface found on an independent 385^3 lattice).
The mesher's proven bound is √3 voxels. The load average is printed before
and after; the table goes to ``tests/benchmarks/results/mesh_out.md``.
"""
from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables

MODELS = ("sinsin34", "sinsin918", "gear", "menger3")
_SAMPLES = 200_000
_LATTICE = 385


def _shape(name: str):
    from implicitvox.expr.examples import example, menger
    return menger(3) if name == "menger3" else example(name)


def _dense(shape, grid):
    """Marching cubes on the lattice of the grid's voxel corners."""
    import implicitvox as ivx
    from skimage import measure
    f = ivx.compile(shape.expr)
    nx, ny, nz = (n + 1 for n in grid.shape)
    xs, ys, zs = (grid.edge(a, np.arange(n)) for a, n in enumerate((nx, ny, nz)))
    values = np.empty((nx, ny, nz), dtype=np.float32)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    for k, zk in enumerate(zs):
        values[:, :, k] = f(X, Y, np.full_like(X, zk))
    verts, faces, _, _ = measure.marching_cubes(values, 0.0, spacing=grid.voxel_size)
    import pyvista as pv
    return pv.PolyData(verts + np.asarray(grid.origin),
                       faces=np.hstack([np.full((len(faces), 1), 3), faces]).ravel())


def child(name: str, res: int, method: str) -> dict:
    """One run, in this process: build, note time and peak, then measure."""
    import implicitvox as ivx
    from implicitvox.meshing.hausdorff import (distance_to_mesh, distance_to_surface,
                                              mesh_samples, surface_points)
    from implicitvox.octree.grid import grid_of
    shape = _shape(name)
    grid = grid_of(shape.bounds, None, res, None)
    t = time.perf_counter()
    if method == "mesh":
        m = ivx.mesh(shape, resolution=res)
    else:
        m = _dense(shape, grid)
    seconds = time.perf_counter() - t
    peak = tables.peak_bytes()
    h = max(grid.voxel_size)
    f = ivx.compile(shape.expr)
    rng = np.random.default_rng(0)
    samples = mesh_samples(np.asarray(m.points), m.regular_faces)
    if len(samples) > _SAMPLES:
        samples = samples[rng.choice(len(samples), _SAMPLES, replace=False)]
    there = distance_to_surface(f, samples, 8 * h, settle=math.sqrt(3) * h)
    b = grid.bounds
    surface = surface_points(f, b, _LATTICE)
    if len(surface) > _SAMPLES:
        surface = surface[rng.choice(len(surface), _SAMPLES, replace=False)]
    back = distance_to_mesh(m, surface)
    out = {"seconds": seconds, "triangles": int(m.n_cells), "peak": peak,
           "there": float(there.max()) / h, "back": float(back.max()) / h}
    if method == "mesh":
        out["uncertified"] = int(m.field_data["uncertified_cells"][0])
    return out


def _fmt(r: dict, key: str, spec: str) -> str:
    return "-" if key not in r else format(r[key], spec)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolutions", type=int, nargs="+", default=[256, 512, 1024])
    parser.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    parser.add_argument("--dense-limit", type=float, default=4.0, metavar="GIB",
                        help="skip the dense baseline where its samples pass this")
    parser.add_argument("--mesh-limit", type=float, default=12.0, metavar="GIB",
                        help="skip the mesher where its estimate passes this")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if tables.answer_child(args.child, child):
        return
    from implicitvox.octree.budget import available_memory
    load = tables.load_average()
    print(f"load average before: {load}; memory available {available_memory() / 2**30:.1f} GiB")
    rows = []
    for name in args.models:
        for res in args.resolutions:
            cells = (res + 1) ** 3
            for method in ("mesh", "dense"):
                if method == "dense" and cells * 4 > args.dense_limit * 2**30:
                    r = {"error": f"not run: {cells * 4 / 2**30:.1f} GiB of samples"}
                elif method == "mesh":
                    from implicitvox.meshing.mesher import estimate_mesh_memory
                    from implicitvox.octree.grid import grid_of
                    shape = _shape(name)
                    _, need = estimate_mesh_memory(shape, grid_of(shape.bounds, None, res, None))
                    r = {"error": f"not run: estimated {need / 2**30:.1f} GiB"} \
                        if need > args.mesh_limit * 2**30 else \
                        tables.run_child(__file__, name, str(res), method)
                else:
                    r = tables.run_child(__file__, name, str(res), method)
                row = [name, res, method, _fmt(r, "seconds", ".2f"), _fmt(r, "triangles", ","),
                       "-" if "peak" not in r else f"{r['peak'] / 2**20:,.0f}",
                       _fmt(r, "there", ".3f"), _fmt(r, "back", ".3f"),
                       _fmt(r, "uncertified", ","), r.get("error", r.get("error_text", ""))]
                print(" | ".join(str(c) for c in row), flush=True)
                rows.append(row)
    header = ["model", "N", "method", "seconds", "triangles", "peak MiB",
              "mesh→surface (voxels)", "surface→mesh (voxels)", "uncertified cells", "note"]
    tables.write("mesh_out", header, rows, "python tests/benchmarks/bench_mesh_out.py "
                 + " ".join(sys.argv[1:]), load)


if __name__ == "__main__":
    main()
