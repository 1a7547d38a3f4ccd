"""Hostile numbers in every numeric field of OpenSCAD's ``.csg`` files.

A mutant is a fixture (``tests/openscad/*.csg``, OpenSCAD's own exports) with one
of its numbers (a size, a coordinate, a matrix entry, ``$fn``, an angle, ...)
replaced by a hostile one: huge (past Clipper's range, past float32, near the
float's end), tiny, subnormal, infinite, NaN, zero. The fuzz test and the fuzz
benchmark draw from the same list, so a failure in one is reproduced by the other.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Iterator

import numpy as np

FIXTURES = Path(__file__).resolve().parents[1] / "openscad"
#: what a number becomes
HOSTILE = ("1e20", "-1e20", "1e16", "-1e16", "1e14", "7.1e13", "1e38", "1e300", "-1e300",
           "1e308", "1e-300", "5e-324", "-5e-324", "2.2e-308", "1e999", "-1e999", "nan",
           "-nan", "inf", "0", "-0", "1e-20", "-1")
_NUMBER = re.compile(r"(?<![\w.$])-?\d+(\.\d*)?([eE][-+]?\d+)?")


def numeric_fields(text: str) -> list[tuple[int, int]]:
    """The spans of every number in a ``.csg`` text."""
    return [m.span() for m in _NUMBER.finditer(text)]


def mutants(count: int, seed: int) -> Iterator[tuple[str, str]]:
    """``count`` mutants ``(label, text)``: a fixture, a field, a hostile number, each
    drawn in turn from a seeded generator (every fixture, then again)."""
    files = sorted(FIXTURES.glob("*.csg"))
    texts = [f.read_text() for f in files]
    fields = [numeric_fields(t) for t in texts]
    rng = np.random.default_rng(seed)
    for k in range(count):
        i = k % len(files)
        if not fields[i]:
            continue
        start, stop = fields[i][int(rng.integers(0, len(fields[i])))]
        value = HOSTILE[int(rng.integers(0, len(HOSTILE)))]
        line = texts[i].count("\n", 0, start) + 1
        yield (f"{files[i].name}:{line}: {texts[i][start:stop]} -> {value}",
               texts[i][:start] + value + texts[i][stop:])
