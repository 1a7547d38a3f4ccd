"""Interval kernels on ``(lo, hi)`` arrays, every end rounded outward (numpy only).

The libmpi of this project; it imports nothing else of implicitvox.

* :mod:`.rounding` - outward rounding steps, ulp bounds of numpy's functions;
* :mod:`.kernels` - arithmetic, transcendentals and coordinate kernels;
* :mod:`.derivatives` - interval chain rules (for the mean value form);
* :mod:`.float32` - float32 ends rounded outward;
* :mod:`.filled` - cached constant arrays for numpy's fast loops.
"""
from . import derivatives, filled, float32, kernels, rounding

__all__ = ["derivatives", "filled", "float32", "kernels", "rounding"]
