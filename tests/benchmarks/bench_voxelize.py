"""Benchmark: sin(n theta) sin(m phi) - r over [-1.1, 1.1]^3 (Stolte Fig. 6).

Run: ``python tests/benchmarks/bench_voxelize.py [--max-res 1024] [--dense 256 512]``

Prints, single process:

1. per (n, m) and resolution: seconds (best of ``--repeat``), surface voxels, octree bytes (and bytes
   per voxel), and the growth factor of the time and of the voxel count per
   resolution doubling (Stolte: it tends to 4);
2. the dense corner-sign baseline (f at every voxel corner, evaluated in
   slabs) at the ``--dense`` resolutions, with the speed-up, and our time
   without the recheck of suspect voxels (``recheck=0``), for its cost;
3. tightness at ``--tight-res``: the share of output voxels in which a dense
   sampling (10^3 points on the closed voxel) finds a sign change, for the
   defaults (``recheck=0.25``), ``recheck=0`` (no recheck), ``0.1`` and ``1``,
   ``mean_value=True``, ``subvoxel=1`` and ``mean_value=True, subvoxel=2``.

The interval evaluation runs in float32 for these models at every level
(:func:`implicitvox.octree.level_dtype.interval_dtype`; the "fp" column).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import implicitvox as ivx
from implicitvox.expr.examples import sinsin
from implicitvox.octree.grid import Grid
from implicitvox.octree.level_dtype import interval_dtype

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    import sys
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables

MODELS = [(3, 4), (5, 6), (9, 10), (9, 18)]


def corner_sign_dense(func: ivx.Function, grid: Grid) -> tuple[int, float]:
    """The dense baseline: count voxels with a corner sign change; slabs of x."""
    t = time.perf_counter()
    ys = grid.edge(1, np.arange(grid.shape[1] + 1))
    zs = grid.edge(2, np.arange(grid.shape[2] + 1))
    Y, Z = np.meshgrid(ys, zs, indexing="ij")
    count = 0
    previous = None
    for i in range(grid.shape[0] + 1):
        plane = func(np.full(Y.shape, grid.edge(0, i)), Y, Z) <= 0
        if previous is not None:
            stack = [previous[:-1, :-1], previous[1:, :-1], previous[:-1, 1:], previous[1:, 1:],
                     plane[:-1, :-1], plane[1:, :-1], plane[:-1, 1:], plane[1:, 1:]]
            anyneg = np.logical_or.reduce(stack)
            allneg = np.logical_and.reduce(stack)
            count += int(np.count_nonzero(anyneg & ~allneg))
        previous = plane
    return count, time.perf_counter() - t


def tightness(func: ivx.Function, vox: ivx.Voxels, k: int = 10, chunk: int = 20_000) -> float:
    t = np.linspace(0.0, 1.0, k)
    offsets = np.stack(np.meshgrid(t, t, t, indexing="ij"), -1).reshape(-1, 3)
    coords = vox.coords()
    size = np.array(vox.voxel_size)
    hits = 0
    for s in range(0, len(coords), chunk):
        c = coords[s:s + chunk]
        lo = np.stack([vox.grid.edge(a, c[:, a]) for a in range(3)], axis=1)
        pts = lo[:, None, :] + offsets[None] * size
        v = func(pts[..., 0], pts[..., 1], pts[..., 2])
        hits += int(np.count_nonzero((v.min(axis=1) <= 0) & (v.max(axis=1) >= 0)))
    return hits / max(len(coords), 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-res", type=int, default=1024)
    parser.add_argument("--dense", type=int, nargs="*", default=[256, 512])
    parser.add_argument("--tight-res", type=int, default=256)
    parser.add_argument("--repeat", type=int, default=2,
                        help="runs per timing, the best kept (the first run of a size pays "
                             "its page faults)")
    args = parser.parse_args()
    resolutions = [r for r in (128, 256, 512, 1024, 2048) if r <= args.max_res]
    load_before = tables.load_average()
    counts: dict = {}
    speedups: dict = {}
    tight: dict = {}

    print("== voxelization (defaults, single process) ==")
    print(f"{'n,m':>6}{'res':>6}{'fp':>9}{'seconds':>9}{'voxels':>12}{'octree B':>12}{'B/vox':>7}"
          f"{'t x':>6}{'vox x':>7}")
    timings: dict = {}
    for n, m in MODELS:
        prev = None
        for res in resolutions:
            dt = float("inf")
            for _ in range(args.repeat):
                t = time.perf_counter()
                vox = ivx.voxelize(sinsin(n, m), resolution=res)
                dt = min(dt, time.perf_counter() - t)
            timings[(n, m, res)] = dt
            counts[(n, m, res)] = vox.count
            growth = (f"{dt / prev[0]:6.2f}{vox.count / prev[1]:7.2f}" if prev else " " * 13)
            fp = interval_dtype(ivx.compile(sinsin(n, m).expr).tape, vox.grid).name
            print(f"{n},{m:>3}{res:>6}{fp:>9}{dt:>9.2f}{vox.count:>12,}{vox.octree.nbytes:>12,}"
                  f"{vox.octree.nbytes / vox.count:>7.2f}{growth}")
            prev = (dt, vox.count)

    print("\n== dense corner-sign baseline (Frey & Borouchaki; Stolte §1) ==")
    print(f"{'n,m':>6}{'res':>6}{'dense s':>9}{'ours s':>9}{'speed-up':>10}{'dense vox':>12}"
          f"{'no recheck s':>14}")
    for n, m in MODELS:
        func = ivx.compile(sinsin(n, m).expr)
        for res in args.dense:
            grid = Grid.from_bounds(sinsin(n, m).bounds, res)
            count, dense_s = corner_sign_dense(func, grid)
            ours = timings.get((n, m, res))
            if ours is None:
                t = time.perf_counter()
                ivx.voxelize(sinsin(n, m), resolution=res)
                ours = time.perf_counter() - t
            bare = float("inf")
            for _ in range(args.repeat):
                t = time.perf_counter()
                ivx.voxelize(sinsin(n, m), resolution=res, recheck=0.0)
                bare = min(bare, time.perf_counter() - t)
            print(f"{n},{m:>3}{res:>6}{dense_s:>9.2f}{ours:>9.2f}{dense_s / ours:>10.1f}{count:>12,}"
                  f"{bare:>14.2f}")
            speedups[(n, m, res)] = dense_s / ours

    print(f"\n== tightness at {args.tight_res}^3: share of voxels with a sampled sign change ==")
    variants = [("defaults", {}), ("recheck=0", {"recheck": 0.0}),
                ("recheck=0.1", {"recheck": 0.1}), ("recheck=1", {"recheck": 1.0}),
                ("mean_value", {"mean_value": True}), ("subvoxel=1", {"subvoxel": 1}),
                ("mean+sub=2", {"mean_value": True, "subvoxel": 2})]
    print(f"{'n,m':>6}" + "".join(f"{name:>18}" for name, _ in variants))
    for n, m in MODELS:
        func = ivx.compile(sinsin(n, m).expr)
        cells = []
        for _, options in variants:
            t = time.perf_counter()
            vox = ivx.voxelize(sinsin(n, m), resolution=args.tight_res, **options)
            dt = time.perf_counter() - t
            share = tightness(func, vox)
            tight[(n, m, options.get("recheck"), len(options))] = share
            cells.append(f"{share:.3f} ({dt:5.1f}s)")
        print(f"{n},{m:>3}" + "".join(f"{c:>18}" for c in cells))
    _write_table(args, resolutions, timings, counts, speedups, tight, load_before)


def _write_table(args, resolutions, timings, counts, speedups, tight, load_before) -> None:
    """The README's table: the two largest resolutions, their growth, the dense
    baseline at the largest dense resolution, the tightness with and without recheck."""
    top, big = resolutions[-2:] if len(resolutions) > 1 else resolutions * 2
    dense = max(args.dense) if args.dense else None
    header = ["(n, m)", f"{top}³", f"{big}³",
              f"voxels ×, time × per doubling ({top}³→{big}³)",
              f"vs dense corner signs at {dense}³", f"tightness at {args.tight_res}³ "
              "(without recheck)"]
    rows = []
    for n, m in MODELS:
        t0, t1 = timings[(n, m, top)], timings[(n, m, big)]
        growth = f"×{counts[(n, m, big)] / counts[(n, m, top)]:.2f}, ×{t1 / t0:.1f}"
        rows.append([f"({n}, {m})", f"{t0:.2f} s", f"{t1:.2f} s", growth,
                     f"{speedups[(n, m, dense)]:.0f}×" if dense else "",
                     f"{tight[(n, m, None, 0)]:.2f} ({tight[(n, m, 0.0, 1)]:.2f})"])
    tables.write("voxelize", header, rows, "python tests/benchmarks/bench_voxelize.py "
                 f"--max-res {args.max_res}", load_before)


if __name__ == "__main__":
    main()
