"""Does numpy compute its transcendental functions with the C library?

On AVX-512 machines numpy's float64 ``exp``, ``log``, ``power`` and the inverse
trigonometric functions run numpy's own SIMD kernels, which differ from the C
library's (and so from Numba's compiled ``math`` calls) by an ulp on some
arguments; on AVX2 machines they call the C library. Tests that compare the
compiled rules with the array kernels bit for bit hold only where the two agree.
"""
from __future__ import annotations

import functools
import math

import numpy as np

#: numpy's functions and the C library's (through Python's math module)
_PAIRS = ((np.exp, math.exp, (-30.0, 30.0)), (np.log, math.log, (1e-3, 1e3)),
          (np.tan, math.tan, (-1.5, 1.5)), (np.arctan, math.atan, (-10.0, 10.0)),
          (np.arcsin, math.asin, (-1.0, 1.0)), (np.arccos, math.acos, (-1.0, 1.0)))


@functools.lru_cache(maxsize=None)
def numpy_is_libm() -> bool:
    """True when numpy's float64 transcendental functions equal the C library's
    on 2,000 random arguments each (and ``**`` equals ``math.pow``)."""
    rng = np.random.default_rng(0)
    for ours, libm, (low, high) in _PAIRS:
        xs = rng.uniform(low, high, 2000)
        if not np.array_equal(ours(xs), [libm(v) for v in xs]):
            return False
    bases, powers = rng.uniform(0.0, 10.0, 2000), rng.uniform(-20.0, 20.0, 2000)
    return np.array_equal(bases ** powers, [math.pow(a, b) for a, b in zip(bases, powers)])


def assert_same_rule(ours: np.ndarray, theirs: np.ndarray, rtol: float = 1e-12) -> None:
    """Bit for bit where numpy's functions are the C library's; else within ``rtol``
    (an ulp of a function's value moves an end by about 1e-16 of it), the same
    infinities and NaNs in the same places."""
    if numpy_is_libm():
        np.testing.assert_array_equal(ours, theirs)
    else:
        np.testing.assert_allclose(ours, theirs, rtol=rtol, atol=1e-300)
