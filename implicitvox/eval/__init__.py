"""Expressions compiled and evaluated: the opcode table, tapes and the evaluators.

``Expr -> Tape -> point | interval | gradient``: :mod:`.opcodes` (one row per
operation), :mod:`.tape` (flattened, deduplicated, folded), :mod:`.point`,
:mod:`.interval`, :mod:`.gradient` and :mod:`.mean_value` (the evaluators),
:mod:`.oracles` (sweeps, driven by the evaluators), :mod:`.float32_tapes` (which
tapes run in float32), :mod:`.reference` (mpmath, for the tests) and
:mod:`.function` (``Function``, ``compile``: the user's handle).
"""
from .function import Function, compile  # noqa: A004 - the public name the docs use

__all__ = ["Function", "compile"]
