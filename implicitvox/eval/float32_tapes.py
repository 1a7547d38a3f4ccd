"""Which tapes can evaluate their intervals in float32.

numpy's float32 loops do twice the work per instruction of its float64 ones,
and its float32 ``sin``, ``cos`` and ``arctan2`` are vectorized (float64
``sin`` and ``cos`` call scalar libm): a tape evaluates about 3 times faster
in float32. libfive and Fidget evaluate their intervals in single precision
for the same reason. Outward rounding makes it as safe as float64 (the same
kernels, widened by float32 ulps, :data:`rounding.LIMITS`); it only costs
tightness where float32's 2**-24 is not small against a voxel, so
:func:`implicitvox.octree.level_dtype.interval_dtype` picks it only where

* every instruction of the tape is one whose kernel handles float32
  (the row's ``float32``), with its parameters exact in float32 (a constant
  operand that is not, such as 0.1, becomes an interval of two float32s), and
* the boxes themselves lose little: rounding a corner to float32 moves it by
  at most ``2**-24 |x|``, which must stay below 1/1024 of the box (so the
  choice is made per octree level, by the size of its boxes).

Each opcode row says whether its kernel handles float32
(:attr:`~implicitvox.eval.opcodes.Opcode.float32`) and, for rows with a
parameter, whether float32 holds it (``float32_params``); the level rule is
in :mod:`implicitvox.octree.level_dtype`.

Examples
--------
>>> from implicitvox import compile, x, sin
>>> supports_float32(compile(sin(x) + 0.5).tape), supports_float32(compile(x / 3).tape)
(True, False)
"""
from __future__ import annotations

from ..interval.float32 import in_float32_range
from .tape import Tape

__all__ = ["supports_float32"]


def supports_float32(tape: Tape) -> bool:
    """Can every instruction of ``tape`` run in float32 (see the module)?"""
    if tape.undefined or not all(in_float32_range(c.lo) and in_float32_range(c.hi)
                                 for c in tape.constants):
        return False
    return all(ins.op.float32 and ins.op.float32_params(ins.param) for ins in tape.instructions)

