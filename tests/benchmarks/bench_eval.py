"""Benchmark: ns per point of ``f(...)`` and ns per box of ``f.interval`` over 10^6 inputs.

Run: ``python tests/benchmarks/bench_eval.py [--n 1000000] [--repeat 3]``

Prints, for each model, the point cost, the interval cost, and their ratio
(target on a 2-core machine: interval at most 6x point), and, as a baseline
in the same run, the cost of the equivalent plain numpy expression. The
``instr`` column is the tape's length after its rewrites: each sphere
``sqrt((x-a)**2 + (y-b)**2 + (z-c)**2) - r`` is one fused ``distance`` and one
``addc`` (see :mod:`implicitvox.eval.tape`).
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import implicitvox as ivx
from implicitvox import atan2, hypot, sin, sqrt, x, y, z

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables


def spheres_tree(n: int = 50, seed: int = 0):
    rng = np.random.default_rng(seed)
    centers = rng.uniform(-1, 1, (n, 3))
    radii = rng.uniform(0.05, 0.3, n)
    balls = [sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) - r
             for (cx, cy, cz), r in zip(centers, radii)]
    half = n // 2
    return ivx.max(ivx.min(*balls[:half]), -ivx.min(*balls[half:]) - 0.5), (centers, radii)


def best_of(func, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        func()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    load = tables.load_average()
    rows = []
    n = args.n
    rng = np.random.default_rng(0)
    pts = rng.uniform(-1.1, 1.1, (3, n))
    lo = rng.uniform(-1.1, 1.0, (n, 3))
    hi = lo + rng.uniform(0.0, 0.1, (n, 3))
    lo_cols, hi_cols = tuple(lo.T.copy()), tuple(hi.T.copy())

    sinsin = sin(3 * atan2(z, x)) * sin(4 * atan2(y, hypot(x, z))) - sqrt(x * x + y * y + z * z)
    tree, _ = spheres_tree()
    X, Y, Z = pts
    baselines = {
        "sinsin": lambda: np.sin(3 * np.arctan2(Z, X)) * np.sin(4 * np.arctan2(Y, np.hypot(X, Z)))
        - np.sqrt(X * X + Y * Y + Z * Z),
        "50 spheres min/max": None,
    }
    print(f"{'model':<22}{'instr':>6}{'numpy ns/pt':>13}{'point ns/pt':>13}"
          f"{'interval ns/box':>17}{'ratio':>8}")
    for name, expr in (("sinsin", sinsin), ("50 spheres min/max", tree)):
        f = ivx.compile(expr)
        t_point = best_of(lambda: f(X, Y, Z), args.repeat) / n * 1e9
        t_box = best_of(lambda: f.interval_columns(lo_cols, hi_cols), args.repeat) / n * 1e9
        base = baselines[name]
        t_np = best_of(base, args.repeat) / n * 1e9 if base else float("nan")
        print(f"{name:<22}{len(f.tape):>6}{t_np:>13.1f}{t_point:>13.1f}{t_box:>17.1f}"
              f"{t_box / t_point:>8.2f}")
        rows.append([name, len(f.tape), "-" if base is None else f"{t_np:.0f}", f"{t_point:.0f}",
                     f"{t_box:.0f}", f"{t_box / t_point:.2f}"])
    tables.write("eval", ["model", "instructions", "numpy ns/point", "point ns/point",
                          "interval ns/box", "interval / point"], rows,
                 "python tests/benchmarks/bench_eval.py " + " ".join(sys.argv[1:]), load)


if __name__ == "__main__":
    main()
