"""Benchmark: hostile numbers in every numeric field of OpenSCAD's ``.csg`` files.

Run: ``python tests/benchmarks/bench_fuzz_csg.py [--count 2000] [--seed 1]``

Each mutant is an OpenSCAD fixture with one number (a size, a coordinate, a
matrix entry, ``$fn``, an angle) replaced by a huge, tiny, subnormal, infinite
or NaN one (:mod:`tests.support.hostile_csg`), read in both facet modes and
voxelized at 16³ in a watched worker process (the fuzz suite's,
:func:`tests.properties.test_fuzz_readers.run_csg_mutants`). Prints the outcomes
(read and voxelized, or refused with a documented error), and every crash
(a signal), hang (over 20 s) or undocumented error (a deep traceback): the
target is none.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))     # the repository root
from tests.benchmarks import tables  # noqa: E402


def main() -> None:
    from tests.properties.test_fuzz_readers import run_csg_mutants
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    load = tables.load_average()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        outcomes, failures = run_csg_mutants(Path(folder), args.count, args.seed)
    seconds = time.perf_counter() - t0
    for failure in failures:
        print("FAILED", failure)
    kinds = {"crash": 0, "hang": 0, "bad": 0}
    for failure in failures:
        for kind in kinds:
            if f": {kind}" in failure:
                kinds[kind] += 1
    row = (f"{args.count:,}", f"{outcomes.get('ok', 0):,}",
           ", ".join(f"{k[len('refused '):]} {v:,}" for k, v in sorted(outcomes.items())
                     if k.startswith("refused")) or "none",
           str(kinds["crash"]), str(kinds["hang"]), str(kinds["bad"]), f"{seconds:.0f}")
    header = ("mutants", "read and voxelized", "refused (documented error)", "crashes",
              "hangs", "deep tracebacks", "seconds")
    print(" | ".join(header))
    print(" | ".join(row))
    tables.write("fuzz-csg", header, [row],
                 f"python tests/benchmarks/bench_fuzz_csg.py --count {args.count} "
                 f"--seed {args.seed}", load)


if __name__ == "__main__":
    main()
