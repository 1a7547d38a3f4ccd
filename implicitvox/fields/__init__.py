"""Distance fields with a known error (Varadhan §4.2; Bærentzen et al. §3-§6).

* :mod:`.bricks` - the narrow band in bricks of 8³ samples;
* :mod:`.kernels` - exact, box-test and certified distances, per kind of shape;
* :mod:`.certified` - lower and upper bounds by interval branch and bound;
* :mod:`.field` - ``DistanceField``: look-ups, trilinear reconstruction,
  gradients, the isosurface, dense outputs;
* :mod:`.sampled` - ``distance_field``;
* :mod:`.bounds`, :mod:`.errors` - the analytic and empirical error bounds (Bærentzen §6);
* :mod:`.suitability` - the S_r-open / S_r-closed criterion (Bærentzen §4-§5);
* :mod:`.prefilter` - prefiltering, for comparison (Bærentzen §3.1).
"""
from .field import DistanceField
from .sampled import distance_field
from .bounds import analytic_error_bound
from .errors import sphere_reconstruction_errors
from .suitability import Suitability, suitability
from .prefilter import prefilter_comparison, prefiltered, prefiltered_samples

__all__ = ["DistanceField", "distance_field", "analytic_error_bound",
           "sphere_reconstruction_errors", "Suitability", "suitability", "prefiltered",
           "prefiltered_samples", "prefilter_comparison"]
