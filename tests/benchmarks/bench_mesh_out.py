"""Benchmark: meshes out (:func:`implicitvox.mesh`) against libfive and against dense
sampling + marching cubes.

Run: ``python tests/benchmarks/bench_mesh_out.py [--resolutions 256 512 1024] [--models ...]
[--repeat 3]``

The peer is libfive (https://libfive.com), built from source outside the repository
by ``sh tests/benchmarks/build_libfive.sh`` and driven by its Python bindings
(:mod:`tests.benchmarks.libfive_peer`); without it its rows say "not built". For
each model (the sphere, the torus, the gear, Stolte's sin(3θ)sin(4φ) - r and
sin(9θ)sin(18φ) - r, ten blended spheres, the level-3 Menger sponge) and each
resolution N, each run in a fresh child process (so the peak memory is its own,
``ru_maxrss``):

* ``mesh``: ``implicitvox.mesh(shape, resolution=N)`` on one worker (the largest
  cells are the N-grid's voxels; complex cells split up to 4 levels deeper), and
  ``mesh, 2 workers``;
* ``libfive``: ``libfive_tree_render_mesh_st`` (one thread) of the same expression
  over the same grid box at N cells along its longest side;
* ``dense``: the function sampled on the (N+1)^3 lattice (float32, in slabs)
  and ``skimage.measure.marching_cubes`` at level 0 - the usual way, with no
  bound. Not run where the samples alone would pass ``--dense-limit`` GiB.

The mesher and libfive run alternately, ``--repeat`` times each; the best time is
reported (with the peak of that run). Each row: seconds, triangles, peak memory,
and the measured Hausdorff distance both ways in units of the N-grid's voxel:
mesh to surface (a certified upper bound per sample,
:func:`implicitvox.meshing.hausdorff.distance_to_surface`, over up to 200,000
samples of the triangles) and surface to mesh (exact, from up to 200,000 points
on the surface found on an independent 385^3 lattice). The mesher's proven bound
is √3 voxels. The load average is printed before and after; the table goes to
``tests/benchmarks/results/mesh_out.md``.
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

MODELS = ("sphere", "torus", "gear", "sinsin34", "sinsin918", "blended spheres", "menger3")
METHODS = ("mesh", "mesh, 2 workers", "libfive", "dense")
_SAMPLES = 200_000
_LATTICE = 385


def _shape(name: str):
    """The models (as ``bench_kernel.py`` builds them)."""
    from implicitvox import hypot, sqrt, x, y, z
    from implicitvox.expr.examples import example, menger
    from implicitvox.expr.shape import ExprShape
    if name == "menger3":
        return menger(3)
    if name == "blended spheres":
        from csg import Blobby
        rng = np.random.default_rng(10)
        return Blobby(rng.uniform(-0.6, 0.6, size=(10, 3)).tolist(),
                      rng.uniform(0.3, 0.5, size=10).tolist())
    if name == "torus":
        return ExprShape(sqrt((hypot(x, y) - 0.7) ** 2 + z ** 2) - 0.25,
                         ((-1.0, -1.0, -0.3), (1.0, 1.0, 0.3)))
    return example(name)


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


def _libfive(shape, grid):
    """libfive's mesh of the shape's expression over the grid's box, N cells along its
    longest side (the same cells as the N-grid), one thread."""
    import pyvista as pv
    from tests.benchmarks import libfive_peer
    lib = libfive_peer.load()
    tree = libfive_peer.tree(lib, shape.expr)
    t = time.perf_counter()
    verts, tris = libfive_peer.render(lib, tree, grid.bounds, 1.0 / max(grid.voxel_size))
    seconds = time.perf_counter() - t
    faces = np.hstack([np.full((len(tris), 1), 3), tris]).ravel()
    return pv.PolyData(verts, faces=faces) if len(tris) else pv.PolyData(), seconds


def child(name: str, res: int, method: str) -> dict:
    """One run, in this process: build, note time and peak, then measure."""
    import implicitvox as ivx
    from implicitvox.meshing.hausdorff import (distance_to_mesh, distance_to_surface,
                                              mesh_samples, surface_points)
    from implicitvox.octree.grid import grid_of
    shape = _shape(name)
    grid = grid_of(shape.bounds, None, res, None)
    if method.startswith("mesh"):
        workers = 2 if "2" in method else 1
        ivx.mesh(shape, resolution=16, workers=1)        # Numba's cache loaded
        t = time.perf_counter()
        m = ivx.mesh(shape, resolution=res, workers=workers)
        seconds = time.perf_counter() - t
    elif method == "libfive":
        m, seconds = _libfive(shape, grid)
    else:
        t = time.perf_counter()
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
    surface = surface_points(f, grid.bounds, _LATTICE)
    if len(surface) > _SAMPLES:
        surface = surface[rng.choice(len(surface), _SAMPLES, replace=False)]
    back = distance_to_mesh(m, surface)
    out = {"seconds": seconds, "triangles": int(m.n_cells), "peak": peak,
           "there": float(there.max()) / h, "back": float(back.max()) / h}
    if method.startswith("mesh"):
        out["uncertified"] = int(m.field_data["uncertified_cells"][0])
    return out


def _fmt(r: dict, key: str, spec: str) -> str:
    return "-" if key not in r else format(r[key], spec)


def _runs(name: str, res: int, args) -> dict:
    """Every method's result for one case: the mesher and libfive alternately,
    ``--repeat`` times, each its best run."""
    from tests.benchmarks import libfive_peer
    from implicitvox.meshing.mesher import estimate_meshing_memory
    from implicitvox.octree.grid import grid_of
    shape = _shape(name)
    _, _, need = estimate_meshing_memory(shape, grid_of(shape.bounds, None, res, None))
    cells = (res + 1) ** 3
    skip = {}
    if need > args.mesh_limit * 2**30:
        skip["mesh"] = skip["mesh, 2 workers"] = f"not run: estimated {need / 2**30:.1f} GiB"
    if libfive_peer.load() is None:
        skip["libfive"] = "not built (tests/benchmarks/build_libfive.sh)"
    if cells * 4 > args.dense_limit * 2**30:
        skip["dense"] = f"not run: {cells * 4 / 2**30:.1f} GiB of samples"
    best: dict = {}
    for _ in range(args.repeat):
        for method in METHODS:
            if method in skip or (method == "dense" and method in best):
                continue
            r = tables.run_child(__file__, name, str(res), method)
            if method not in best or r.get("seconds", math.inf) < \
                    best[method].get("seconds", math.inf):
                best[method] = r
    best.update({m: {"error": why} for m, why in skip.items()})
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolutions", type=int, nargs="+", default=[256, 512])
    parser.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    parser.add_argument("--repeat", type=int, default=1,
                        help="runs of the mesher and of libfive, alternately (the best kept)")
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
            results = _runs(name, res, args)
            for method in METHODS:
                r = results[method]
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
