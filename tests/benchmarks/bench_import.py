"""How long ``import implicitvox`` takes, against ``import numpy`` alone, in fresh processes.

Run: ``python tests/benchmarks/bench_import.py [--repeat 7]``

Each round starts one interpreter for numpy and one for implicitvox (alternating,
so the machine's drift hits both) and times the import inside it; the table gives
the best and the median of the rounds, the difference being implicitvox's own cost.
It also lists which heavy modules the import loaded (none should be: mpmath, scipy,
pyvista and VTK load on first use).
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys

CODE = ("import time, sys; t = time.perf_counter(); import {mod}; "
        "print(time.perf_counter() - t); "
        "print(','.join(m for m in ('mpmath', 'scipy', 'pyvista', 'vtk', 'skimage') "
        "if m in sys.modules))")


def once(module: str) -> tuple[float, str]:
    out = subprocess.run([sys.executable, "-c", CODE.format(mod=module)], capture_output=True,
                         text=True, check=True).stdout.split("\n")
    return float(out[0]), out[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    times: dict[str, list[float]] = {"numpy": [], "implicitvox": []}
    loaded = ""
    for _ in range(args.repeat):
        for module in times:
            t, heavy = once(module)
            times[module].append(t)
            if module == "implicitvox":
                loaded = heavy
    print(f"load average {os.getloadavg()[0]:.2f}, {args.repeat} rounds, alternating")
    print("| import | best | median |")
    print("|---|---|---|")
    for module, ts in times.items():
        print(f"| {module} | {min(ts):.3f} s | {statistics.median(ts):.3f} s |")
    print(f"heavy modules loaded by import implicitvox: {loaded or 'none'}")


if __name__ == "__main__":
    main()
