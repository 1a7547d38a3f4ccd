"""Meshes with a guaranteed Hausdorff bound (Varadhan et al. §5.2): the
adaptive grid without complex cells (``adaptive``), certified edge crossings
(``edges``), the quadric vertex (``qef``), dual contouring (``contour``),
``mesh`` (``mesher``) and the measured distances that check the bound
(``hausdorff``)."""
from .mesher import mesh

__all__ = ["mesh"]
