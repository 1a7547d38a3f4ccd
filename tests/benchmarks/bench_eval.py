"""Benchmark: ns per point of ``f(...)`` and ns per box of ``f.interval`` over 10^6 inputs.

Run: ``python tests/benchmarks/bench_eval.py [--n 1000000] [--repeat 3]``

Prints, for each model, the point cost and the interval cost per box of the array
evaluator (the numpy reference, :mod:`implicitvox.eval.interval`) and of the compiled
tape (:mod:`implicitvox.eval.compiled`, one thread), alternating, best of ``--repeat``,
with and without recording the branch choices; and, as a baseline in the same run,
the cost of a plain numpy expression. Random boxes of sides up to 0.1 in the cube
of side 2.2: every box its own tape's whole length. The
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

    from implicitvox.eval.compiled import encode, evaluate_boxes
    from implicitvox.eval.interval import evaluate_intervals
    from tests.benchmarks import cases
    sinsin = sin(3 * atan2(z, x)) * sin(4 * atan2(y, hypot(x, z))) - sqrt(x * x + y * y + z * z)
    tree, _ = spheres_tree()
    X, Y, Z = pts
    models = {"sinsin (plain numpy baseline)": sinsin,
              "sinsin34": cases.sinsin34().expr, "sinsin918": cases.sinsin918().expr,
              "gear": cases.gear().expr, "50 spheres min/max": tree,
              "menger3": cases.menger3().expr}
    baselines = {
        "sinsin (plain numpy baseline)":
        lambda: np.sin(3 * np.arctan2(Z, X)) * np.sin(4 * np.arctan2(Y, np.hypot(X, Z)))
        - np.sqrt(X * X + Y * Y + Z * Z),
    }
    box_lo, box_hi = lo.T.copy(), hi.T.copy()
    print(f"{'model':<30}{'instr':>6}{'numpy ns/pt':>13}{'point ns/pt':>13}"
          f"{'interval ns/box':>17}{'compiled':>10}{'speed-up':>10}{'+choices':>10}")
    for name, expr in models.items():
        f = ivx.compile(expr)
        tape = encode(f.tape)
        evaluate_boxes(tape, box_lo[:, :8], box_hi[:, :8])       # compiled (or loaded) first
        choices = np.empty((len(f.tape.branches), n), dtype=np.int8)
        t_point = best_of(lambda: f(X, Y, Z), args.repeat) / n * 1e9
        t_box = t_compiled = t_choices = float("inf")
        for _ in range(args.repeat):     # alternating, best of each
            t_box = min(t_box, best_of(lambda: evaluate_intervals(f.tape, lo_cols, hi_cols), 1))
            t_compiled = min(t_compiled, best_of(lambda: evaluate_boxes(tape, box_lo, box_hi), 1))
            t_choices = min(t_choices, best_of(
                lambda: evaluate_boxes(tape, box_lo, box_hi, choices), 1))
        t_box, t_compiled, t_choices = (t / n * 1e9 for t in (t_box, t_compiled, t_choices))
        base = baselines.get(name)
        t_np = best_of(base, args.repeat) / n * 1e9 if base else float("nan")
        print(f"{name:<30}{len(f.tape):>6}{t_np:>13.1f}{t_point:>13.1f}{t_box:>17.1f}"
              f"{t_compiled:>10.1f}{t_box / t_compiled:>9.2f}x{t_choices:>10.1f}")
        rows.append([name, len(f.tape), "-" if base is None else f"{t_np:.0f}", f"{t_point:.0f}",
                     f"{t_box:.0f}", f"{t_compiled:.0f}", f"{t_box / t_compiled:.2f}×",
                     f"{t_choices:.0f}"])
    tables.write("eval", ["model", "instructions", "plain numpy ns/point", "point ns/point",
                          "interval ns/box (numpy reference)", "compiled ns/box", "speed-up",
                          "compiled, choices recorded"], rows,
                 "python tests/benchmarks/bench_eval.py " + " ".join(sys.argv[1:]), load)


if __name__ == "__main__":
    main()
