"""Benchmark: the pilot's estimate of the surface voxels against the count a run finds.

Run: ``python tests/benchmarks/bench_estimate.py [--res 256 512] [--models NAME ...]``

A run is refused before it starts when its estimated memory passes the budget,
so the estimate is what a user reads first. For the seven comparison models
(:mod:`tests.benchmarks.cases`), ``sin(1000x) sin(1000y) sin(1000z)`` (a
surface that fills space) and three OpenSCAD models, per resolution: the
pilot's estimate (:func:`implicitvox.octree.pilot.estimate_surface`: its depth,
the growth it measured, seconds), the voxels a serial run finds, and their
ratio (target: within 2x either way). ``sin1000`` at 512³ holds every one of the
grid's 134 M voxels (about 6.5 GiB kept, 20-30 s); above 512³ it is not run (it
would keep 8 times that).
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))     # the repository root
from tests.benchmarks import tables  # noqa: E402
from tests.benchmarks.cases import CASES  # noqa: E402

FIXTURES = Path(__file__).resolve().parents[1] / "openscad"
OPENSCAD = ("knob", "bracket", "lettering")


def models() -> dict:
    from csg import read_openscad
    out = {name: make for name, make in CASES.items()}
    for name in OPENSCAD:
        out[f"{name}.csg"] = (lambda n=name: read_openscad(str(FIXTURES / f"{n}.csg")))
    return out


def main() -> None:
    import implicitvox as iv
    from implicitvox.eval.function import Function
    from implicitvox.expr.shape import as_shape, exact_classifier
    from implicitvox.octree.grid import grid_of
    from implicitvox.octree.pilot import estimate_surface

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", type=int, nargs="+", default=[256, 512])
    parser.add_argument("--models", nargs="+", help="only these (default: all)")
    args = parser.parse_args()
    load = tables.load_average()
    rows, worst = [], 1.0
    header = ("model", "resolution", "pilot", "growth per level", "estimated voxels",
              "voxels found", "estimate / found", "pilot s", "run s")
    print(" | ".join(header))
    for name, make in models().items():
        if args.models and name not in args.models:
            continue
        shape = as_shape(make())
        for res in args.res:
            if name == "sin1000" and res > 512:
                continue
            grid = grid_of(shape.bounds, None, res, None)
            t = time.perf_counter()
            est = estimate_surface(Function(shape.expr), grid, exact=exact_classifier(shape))
            t_pilot = time.perf_counter() - t
            t = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = iv.voxelize(shape, res, workers=1, max_memory=20 << 30).count
            t_run = time.perf_counter() - t
            ratio = est.voxels / max(found, 1)
            worst = max(worst, ratio, 1 / ratio)
            row = (name, f"{res}³", f"{1 << est.pilot_depth}³", f"{est.growth:.2f}",
                   f"{est.voxels:,}", f"{found:,}", f"{ratio:.2f}", f"{t_pilot:.2f}",
                   f"{t_run:.2f}")
            print(" | ".join(row), flush=True)
            rows.append(row)
    print(f"worst ratio either way: {worst:.2f}x (target: 2x)")
    tables.write("estimate", header, rows, "python tests/benchmarks/bench_estimate.py", load)


if __name__ == "__main__":
    main()
