"""Benchmark: this checkout's voxelizer against a baseline checkout, one thread, alternating.

Run: ``python tests/benchmarks/bench_kernel.py --baseline DIR [--res 512] [--full]
[--repeat 3] [--models a,b]``

``DIR`` is a second checkout of the project (issue #48 compares against commit
514cd8c: ``git worktree add /tmp/base 514cd8c``). Every model is voxelized
(``workers=1``, the defaults otherwise) in a fresh process of each checkout, the
two alternating, best of ``--repeat`` for each; a run's time covers
``voxelize`` alone (the model is built and a small run warms the caches first,
so the compiled kernel's first compilation is not counted: ``bench_import.py``
and the README measure that). Printed per model and resolution: both times,
the speed-up, the voxel counts and the difference of the voxel sets (this
checkout's voxels missing from the baseline's, and the reverse), and the load
average before and after. ``--full`` adds 1024^3 (several minutes).

The models: the CSG set (the level-3 Menger sponge, a union of 100 spheres, the
20 x 20 drilled plate, ten blended spheres) and the formulas (sin(3θ)sin(4φ) − r,
sin(9θ)sin(18φ) − r, the gear, the torus, the sphere).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables

HERE = Path(__file__).resolve().parents[2]
CSG = ["menger3", "100 spheres", "drilled plate", "blended spheres"]
FORMULAS = ["sinsin34", "sinsin918", "gear", "torus", "sphere"]

#: run in the checkout's own interpreter process: builds the model, warms up, times
CHILD = r"""
import json, sys, time, warnings
import numpy as np
warnings.simplefilter("ignore")
sys.path.insert(0, {root!r})
import implicitvox as iv
name, res, out = {name!r}, {res}, {out!r}
if name == "100 spheres":
    from implicitvox.expr.examples import sphere_union as make; shape = make(100)
elif name == "drilled plate":
    from implicitvox.expr.examples import drilled_plate as make; shape = make(20, 20)
elif name == "menger3":
    from implicitvox.expr.examples import menger as make; shape = make(3)
elif name == "blended spheres":
    from csg import Blobby
    rng = np.random.default_rng(10)
    shape = Blobby(rng.uniform(-0.6, 0.6, size=(10, 3)).tolist(),
                   rng.uniform(0.3, 0.5, size=10).tolist())
elif name == "torus":
    from implicitvox import hypot, sqrt, x, y, z
    from implicitvox.expr.shape import ExprShape
    shape = ExprShape(sqrt((hypot(x, y) - 0.7) ** 2 + z ** 2) - 0.25,
                      ((-1.0, -1.0, -0.3), (1.0, 1.0, 0.3)))
else:
    from implicitvox.expr.examples import example; shape = example(name)
iv.voxelize(shape, resolution=64, workers=1)
t = time.perf_counter()
vox = iv.voxelize(shape, resolution=res, workers=1)
seconds = time.perf_counter() - t
np.save(out, np.sort(vox.coords().astype(np.uint64) @ np.array([1, 1 << 21, 1 << 42],
                                                               dtype=np.uint64)))
print(json.dumps({{"seconds": seconds, "count": int(vox.count), "module": iv.__file__}}))
"""


def run_once(root: Path, name: str, res: int, out: str) -> dict:
    code = CHILD.format(root=str(root), name=name, res=res, out=out)
    env = dict(os.environ, PYTHONPATH=str(root))
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, cwd=str(root))
    if done.returncode:
        raise RuntimeError(f"{root} {name} {res}: {done.stderr[-2000:]}")
    got = json.loads(done.stdout.strip().splitlines()[-1])
    if not Path(got["module"]).resolve().is_relative_to(root.resolve()):
        raise RuntimeError(f"the run for {root} imported {got['module']}")
    return got


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", required=True, type=Path)
    parser.add_argument("--res", type=int, default=512)
    parser.add_argument("--full", action="store_true", help="also 1024^3")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--models", default=",".join(CSG + FORMULAS))
    args = parser.parse_args()
    load = tables.load_average()
    resolutions = [args.res] + ([1024] if args.full and args.res != 1024 else [])
    rows = []
    print(f"{'model':<18}{'res':>6}{'baseline s':>12}{'this s':>10}{'speed-up':>10}"
          f"{'voxels (base / this)':>26}{'this-base':>11}{'base-this':>11}")
    with tempfile.TemporaryDirectory() as tmp:
        for res in resolutions:
            for name in args.models.split(","):
                best = {"base": float("inf"), "this": float("inf")}
                counts = {}
                for r in range(args.repeat):
                    for side, root in (("base", args.baseline), ("this", HERE)):
                        got = run_once(root, name, res, f"{tmp}/{side}.npy")
                        best[side] = min(best[side], got["seconds"])
                        counts[side] = got["count"]
                base, this = np.load(f"{tmp}/base.npy"), np.load(f"{tmp}/this.npy")
                extra = len(np.setdiff1d(this, base, assume_unique=True))
                missing = len(np.setdiff1d(base, this, assume_unique=True))
                speed = best["base"] / best["this"]
                print(f"{name:<18}{res:>6}{best['base']:>12.3f}{best['this']:>10.3f}"
                      f"{speed:>9.2f}x{counts['base']:>13,} / {counts['this']:<11,}"
                      f"{extra:>11,}{missing:>11,}", flush=True)
                rows.append([name, f"{res}³", f"{best['base']:.3f} s", f"{best['this']:.3f} s",
                             f"{speed:.2f}×", f"{counts['base']:,}", f"{counts['this']:,}",
                             f"{extra:,}", f"{missing:,}"])
    tables.write("kernel", ["model", "resolution", "baseline", "this checkout", "speed-up",
                            "voxels, baseline", "voxels, this", "this − baseline",
                            "baseline − this"], rows,
                 "python tests/benchmarks/bench_kernel.py " + " ".join(sys.argv[1:]), load)


if __name__ == "__main__":
    main()
