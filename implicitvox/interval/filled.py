"""Constants as arrays, for numpy's fast ``minimum``/``maximum`` loops.

numpy (2.x, measured with 2.4 on this project's machine) runs ``minimum``,
``maximum``, ``fmin`` and ``fmax`` several times slower when one operand is a
scalar than when both are arrays: over 65,536 float32 values, 21 us against
3 us (the scalar loop is not vectorized). The interval kernels clamp against
constants after most operations (the largest float in the outward rounding,
0 in the magnitudes, +-1 after a sine), so they pass such constants as
:func:`filled_like` arrays: read-only views into one cached buffer per
constant and float type. The values are those of the scalar form; only the
loop numpy picks differs.

Examples
--------
>>> import numpy as np
>>> a = np.linspace(-2.0, 2.0, 5000, dtype=np.float32)
>>> bool(np.array_equal(np.maximum(a, filled_like(0.0, a)), np.maximum(a, 0.0)))
True
>>> filled_like(1.0, np.zeros(3))   # small arrays: the scalar itself
1.0
"""
from __future__ import annotations

from typing import Any, Union

import numpy as np

__all__ = ["filled_like"]

#: below this many values the scalar loop's cost does not matter
MIN_SIZE = 2048
#: above this many values the scalar is returned (the buffers stay small)
MAX_SIZE = 1 << 18
_FLOATS = (np.dtype(np.float32), np.dtype(np.float64))
_buffers: dict[tuple[bytes, np.dtype], np.ndarray] = {}


def filled_like(value: float, a: Any) -> Union[float, np.ndarray]:
    """``value`` in ``a``'s float type and shape, as a read-only array, for a
    float32 or float64 array ``a`` of ``MIN_SIZE`` to ``MAX_SIZE`` values;
    ``value`` itself otherwise.

    The array is a view of a cached buffer filled with ``value`` rounded to
    nearest in ``a``'s type, as numpy converts a Python float operand; so
    ``np.minimum(a, filled_like(c, a))`` equals ``np.minimum(a, c)``.
    """
    size = getattr(a, "size", 0)
    dtype = getattr(a, "dtype", None)
    if size < MIN_SIZE or size > MAX_SIZE or dtype not in _FLOATS:
        return value
    key = (np.float64(value).tobytes(), dtype)   # bytes: 0.0 and -0.0 kept apart
    buffer = _buffers.get(key)
    if buffer is None or buffer.size < size:
        buffer = np.full(max(size, MIN_SIZE), value, dtype=dtype)
        buffer.flags.writeable = False
        _buffers[key] = buffer
    return buffer[:size].reshape(a.shape)
