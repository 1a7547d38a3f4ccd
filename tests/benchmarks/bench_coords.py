"""Benchmark: coordinate nodes and replication sweeps (Stolte §4.1, §3).

Run: ``python tests/benchmarks/bench_coords.py [--n 1000000]``

1. ns per box of the interval of ``r``, ``theta``, ``phi`` (the coordinate
   nodes) beside the equivalent ``sqrt``/``atan2``/``hypot`` compositions, with
   the width of each (phi's composition loses tightness at the axis);
2. ns per box of ``repeat`` with 1 instance and with 10^6 instances in range
   of the boxes (Stolte's i0..i1: the cost must not grow with the count),
   beside the model alone.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import implicitvox as ivx
from implicitvox import atan2, hypot, sqrt, x, y, z


def per_box(f: ivx.Function, lo, hi, repeat: int = 3) -> tuple[float, np.ndarray]:
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        flo, fhi = f.interval_columns(lo, hi)
        best = min(best, time.perf_counter() - t)
    return best / lo[0].shape[0] * 1e9, fhi - flo


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    lo = rng.uniform(-1.0, 1.0, (args.n, 3))
    hi = lo + rng.uniform(0.0, 0.05, (args.n, 3))
    cols = tuple(lo.T.copy()), tuple(hi.T.copy())

    print("== coordinates: interval ns per box (median width) ==")
    print(f"{'':8}{'node ns':>10}{'compos. ns':>12}{'node width':>12}{'compos. width':>15}")
    pairs = {"r": (ivx.r, sqrt(x * x + y * y + z * z)),
             "theta": (ivx.theta, atan2(y, x)),
             "phi": (ivx.phi, atan2(z, hypot(x, y)))}
    for name, (node, composition) in pairs.items():
        t1, w1 = per_box(ivx.compile(node), *cols)
        t2, w2 = per_box(ivx.compile(composition), *cols)
        print(f"{name:8}{t1:>10.1f}{t2:>12.1f}{np.median(w1):>12.4g}{np.median(w2):>15.4g}")

    print("\n== repeat: interval ns per box, boxes spanning [-1, 1] ==")
    ball = sqrt(x * x + y * y + z * z) - 0.3
    big_lo = rng.uniform(-1.0, 0.0, (args.n, 3))
    big_hi = big_lo + rng.uniform(0.0, 1.0, (args.n, 3))
    big = tuple(big_lo.T.copy()), tuple(big_hi.T.copy())
    models = {
        "model alone": ball,
        "repeat, 1 instance": ivx.repeat(ball, spacing=(2.0, None, None), count=(1, None, None)),
        "repeat, 10^6 in range": ivx.repeat(ball, spacing=(2.0 / 10**6, None, None),
                                            count=(10**6, None, None)),
        "repeat, endless": ivx.repeat(ball, spacing=(2.0 / 10**6, None, None)),
    }
    times = {}
    for name, expr in models.items():
        times[name], _ = per_box(ivx.compile(expr.remap(x=x + 1.0) if "10^6" in name else expr),
                                 *big)
        print(f"{name:<24}{times[name]:>10.1f} ns/box")
    ratio = times["repeat, 10^6 in range"] / times["repeat, 1 instance"]
    print(f"10^6 instances / 1 instance: {ratio:.2f}x (target <= 1.5)")


if __name__ == "__main__":
    main()
