"""How long ``import implicitvox`` takes, against ``import numpy`` alone, in fresh processes.

Run: ``python tests/benchmarks/bench_import.py [--repeat 7]``

Each round starts one interpreter for numpy and one for implicitvox (alternating,
so the machine's drift hits both) and times the import inside it; the table gives
the best and the median of the rounds, the difference being implicitvox's own cost.
It also lists which heavy modules the import loaded (none should be: mpmath, scipy,
pyvista, VTK and Numba load on first use).

With ``--first-run``: the README's first command (``implicitvox voxelize --example
sinsin34 --resolution 256``, which runs on the array path) and the same for the gear
(a model the compiled kernel takes), each cold (Numba's cache in a fresh folder:
the kernel is compiled) and then warm (the cache that run wrote), in fresh processes;
seconds of wall time, written to ``results/first-run.md``.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables

CODE = ("import time, sys; t = time.perf_counter(); import {mod}; "
        "print(time.perf_counter() - t); "
        "print(','.join(m for m in ('mpmath', 'scipy', 'pyvista', 'vtk', 'skimage') "
        "if m in sys.modules))")


def once(module: str) -> tuple[float, str]:
    out = subprocess.run([sys.executable, "-c", CODE.format(mod=module)], capture_output=True,
                         text=True, check=True).stdout.split("\n")
    return float(out[0]), out[1]


def first_runs() -> None:
    """Cold and warm runs of the command line (see the module docstring)."""
    load = tables.load_average()
    rows = []
    for example in ("sinsin34", "gear"):
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache)
            seconds = []
            for _ in ("cold", "warm"):
                t = time.perf_counter()
                subprocess.run([sys.executable, "-m", "implicitvox.io.cli", "voxelize",
                                "--example", example, "--resolution", "256"],
                               check=True, capture_output=True, env=env)
                seconds.append(time.perf_counter() - t)
        print(f"{example}: cold {seconds[0]:.2f} s, warm {seconds[1]:.2f} s")
        rows.append([f"`implicitvox voxelize --example {example} --resolution 256`",
                     f"{seconds[0]:.1f} s", f"{seconds[1]:.1f} s"])
    tables.write("first-run", ["command", "first run (compiles the kernel)",
                               "later runs (from the cache)"], rows,
                 "python tests/benchmarks/bench_import.py --first-run", load)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--first-run", action="store_true",
                        help="time cold and warm runs of the command line instead")
    args = parser.parse_args()
    if args.first_run:
        first_runs()
        return
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
