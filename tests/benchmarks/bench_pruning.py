"""Benchmark: per-region tape pruning (:mod:`implicitvox.eval.pruning`) against the whole tape.

Run: ``python tests/benchmarks/bench_pruning.py [--quick] [--repeat 2] [--profile]``

Prints, one process, each model voxelized with ``prune=True`` and
``prune=False`` alternately (best of ``--repeat`` each), the load average
before and after:

1. unions of N random spheres (:func:`implicitvox.expr.examples.sphere_union`),
   N = 1, 10, 100, 1000 at 256^3: seconds and microseconds per output voxel,
   both ways; the target is N = 1000 within 3x of N = 1 (pruned);
2. the Menger sponge, levels 2 and 3, at 256^3, 512^3 and 1024^3 (the level-3
   sponge at 512^3: target 5x faster pruned);
3. a plate with 20 x 20 drilled holes;
4. per model: the tapes built and the leaf tapes' lengths (median and max
   instructions, per voxel) against the whole tape's;
5. with ``--profile``: the share of the time in the interval kernels
   (``implicitvox/interval/``) on the level-3 sponge at 512^3, both ways (cProfile).

The voxels are checked identical (a digest of the sorted codes) in every row.
Also a row with ``normals=True``, where every surface voxel's gradient is
taken with its pruned tape.
"""
from __future__ import annotations

import argparse
import cProfile
import hashlib
import os
import pstats
import time

import numpy as np

import implicitvox as ivx
from implicitvox.expr.examples import drilled_plate, menger, sphere_union
from implicitvox.octree.grid import Grid
from implicitvox.octree.subdivide import subdivide

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    import sys
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables


def _load() -> str:
    return tables.load_average()


def _run(shape, res: int, prune: bool, options: dict):
    t = time.perf_counter()
    vox = ivx.voxelize(shape, res, prune=prune, **options)
    return time.perf_counter() - t, vox


def _digest(vox) -> str:
    return hashlib.sha256(vox.coords().tobytes()).hexdigest()[:12]


def compare(label: str, shape, res: int, repeat: int, options: dict | None = None) -> dict:
    """Alternate pruned and whole runs; the best of each, and the check that they agree."""
    options = options or {}
    best = {True: float("inf"), False: float("inf")}
    digests, count = set(), 0
    for _ in range(repeat):
        for prune in (True, False):
            dt, vox = _run(shape, res, prune, options)
            best[prune] = min(best[prune], dt)
            digests.add(_digest(vox))
            count = vox.count
    assert len(digests) == 1, f"{label}: pruned and whole runs differ"
    leaf = _leaf_lengths(shape, res)
    row = {"label": label, "res": res, "voxels": count, "pruned": best[True],
           "whole": best[False], "speedup": best[False] / best[True], **leaf}
    print(f"{label:<22}{res:>6}{count:>11,}{best[True]:>9.2f}{best[False]:>9.2f}"
          f"{row['speedup']:>8.1f}{1e6 * best[True] / max(count, 1):>9.2f}"
          f"{1e6 * best[False] / max(count, 1):>9.2f}{leaf['tapes']:>7}"
          f"{leaf['median']:>7.0f}{leaf['max']:>6}{leaf['whole_len']:>7}", flush=True)
    return row


def _leaf_lengths(shape, res: int) -> dict:
    """Instructions of the tapes the voxels were left with (per voxel), by a bare subdivision."""
    func = ivx.compile(shape.expr)
    sub = subdivide(func, Grid.from_bounds(shape.bounds, res))
    lengths = np.repeat([len(t) for _, t in sub.tapes], [n for n, _ in sub.tapes])
    return {"tapes": sub.tapes_built, "median": float(np.median(lengths)) if len(lengths) else 0,
            "max": int(lengths.max()) if len(lengths) else 0, "whole_len": len(func.tape)}


def kernel_share(shape, res: int, prune: bool) -> tuple[float, float]:
    """(seconds, share of them inside implicitvox/interval/) of one voxelization, cProfiled."""
    profile = cProfile.Profile()
    profile.enable()
    ivx.voxelize(shape, res, prune=prune)
    profile.disable()
    stats = pstats.Stats(profile)
    total = sum(v[2] for v in stats.stats.values())     # tottime of every function
    kernels = sum(v[2] for k, v in stats.stats.items() if "/implicitvox/interval/" in k[0])
    return total, kernels / total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="at most 512^3, no N = 1000")
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()
    load_before = _load()
    print(f"load average before: {load_before}  ({os.cpu_count()} cpus)")
    print(f"{'model':<22}{'res':>6}{'voxels':>11}{'pruned':>9}{'whole':>9}{'x':>8}"
          f"{'us/v p':>9}{'us/v w':>9}{'tapes':>7}{'leaf~':>7}{'max':>6}{'whole':>7}")
    rows = []
    counts = (1, 10, 100) if args.quick else (1, 10, 100, 1000)
    for n in counts:
        rows.append(compare(f"{n} spheres", sphere_union(n), 256, args.repeat))
    per_voxel = {r["label"]: r["pruned"] / r["voxels"] for r in rows}
    if "1000 spheres" in per_voxel:
        print(f"  1000 spheres / 1 sphere, us per voxel, pruned: "
              f"{per_voxel['1000 spheres'] / per_voxel['1 spheres']:.1f}x (target <= 3x)")
    for level in (2, 3):
        for res in (256, 512) if args.quick else (256, 512, 1024):
            rows.append(compare(f"menger {level}", menger(level), res,
                                1 if res >= 1024 else args.repeat))
    rows.append(compare("drilled plate 20x20", drilled_plate(20, 20), 256, args.repeat))
    rows.append(compare("menger 3 +normals", menger(3), 256, 1, {"normals": True}))
    shares = {}
    if args.profile:
        for prune in (False, True):
            seconds, share = kernel_share(menger(3), 512, prune)
            shares[prune] = share
            print(f"cProfile menger 3 at 512^3, prune={prune}: {seconds:.1f} s profiled, "
                  f"{share:.0%} in the interval kernels")
    print(f"load average after: {_load()}")
    header = ["model", "resolution", "voxels", "pruned", "whole tape", "speed-up",
              "µs per voxel (pruned, whole)", "leaf tape: median, max (whole)"]
    table = [[r["label"], f"{r['res']}³", f"{r['voxels']:,}", f"{r['pruned']:.2f} s",
              f"{r['whole']:.2f} s", f"{r['speedup']:.1f}×",
              f"{1e6 * r['pruned'] / r['voxels']:.2f}, {1e6 * r['whole'] / r['voxels']:.2f}",
              f"{r['median']:.0f}, {r['max']} ({r['whole_len']})"] for r in rows]
    if shares:
        table.append(["menger 3, cProfile", "512³", "", "", "", "",
                      f"interval kernels: {shares[True]:.0%} of the time pruned, "
                      f"{shares[False]:.0%} whole", ""])
    command = "python tests/benchmarks/bench_pruning.py" + (" --quick" if args.quick else "") \
        + (" --profile" if args.profile else "")
    tables.write("pruning", header, table, command, load_before)


if __name__ == "__main__":
    main()
