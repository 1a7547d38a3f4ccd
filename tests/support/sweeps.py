"""Sizes of the brute-force sweeps: a quarter in the suite, in full on request.

The max-norm distance tests check every primitive against an independent
oracle (linear programming, duality, dense sampling, SLSQP) on 10⁴ points or
10⁶ boxes; at that size they cost about ten CPU-minutes, most of the suite's
budget. The suite runs a quarter of each sweep, the same kinds of points in
the same proportions; ``IMPLICITVOX_FULL_SWEEPS=1 python -m pytest tests/linf``
runs them in full.
"""
from __future__ import annotations

import os

#: the full sweeps, asked for in the environment
FULL = os.environ.get("IMPLICITVOX_FULL_SWEEPS", "") == "1"


def size(n: int) -> int:
    """A sweep's size: ``n`` in full, else a quarter of it."""
    return n if FULL else n // 4
