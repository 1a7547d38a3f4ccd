"""The two ways :func:`csg.read_openscad` builds curved solids: OpenSCAD's facets, or true curves.

The ``.csg`` reader (:mod:`csg.openscad`) asks its facet mode, and nothing else,
whenever the two differ:

* how a sphere, a cylinder, a circle and a ``rotate_extrude`` are built
  (:meth:`FacetMode.sphere`, :meth:`~FacetMode.cylinder`, :meth:`~FacetMode.circle`,
  :meth:`~FacetMode.sweep`);
* whether a ``linear_extrude`` keeps the section's function (:meth:`~FacetMode.extrusion`);
* what happens where an operation needs OpenSCAD's facets (the hull, Minkowski sum,
  offset or projection of curved solids, the box ``resize`` measures):
  :meth:`~FacetMode.facet` and :meth:`~FacetMode.faceted_body`. With OpenSCAD's
  facets the model has them already; with true curves the subtree is built again
  by the reader's one faceted twin, with a warning, as OpenSCAD builds it.

Examples
--------
>>> from csg.facet_modes import FACET_MODES
>>> sorted(FACET_MODES)
['openscad', 'true']
>>> FACET_MODES["true"].circle(2.0, lambda: 30)
Circle(r=2.0)
>>> len(FACET_MODES["openscad"].circle(2.0, lambda: 30).points)
30
"""
from __future__ import annotations

import warnings
from typing import Any, Callable, Optional

from . import facets as fx
from .openscad_parser import OpenSCADWarning
from .planar import Circle, Polygon, RotateExtrude
from .polytopes import convex_solid
from .primitives import Cylinder, Sphere
from .solid import Solid

__all__ = ["FacetMode", "OpenSCADFacets", "TrueCurves", "FACET_MODES"]

Fragments = Callable[[], int]


class FacetMode:
    """What differs between the facet modes (module docstring)."""

    #: the ``facets=`` value that picks this mode
    name = ""

    def sphere(self, r: float, fragments: Fragments) -> Solid:
        """A sphere of radius ``r`` (``fragments()``: OpenSCAD's count for it)."""
        raise NotImplementedError

    def cylinder(self, h: float, r1: float, r2: float, center: bool,
                 fragments: Fragments) -> Solid:
        """A cylinder or cone along z."""
        raise NotImplementedError

    def circle(self, r: float, fragments: Fragments) -> Solid:
        """A disc of radius ``r``."""
        raise NotImplementedError

    def sweep(self, builder: Any, node: Any, body: Solid, angle: float) -> Optional[Solid]:
        """``rotate_extrude(angle)`` of the section ``body``."""
        raise NotImplementedError

    def extrusion(self, straight: bool, text: bool) -> bool:
        """Whether a ``linear_extrude`` keeps its section's function (else it becomes
        OpenSCAD's mesh); ``straight``: no twist and an even scale; ``text``: its
        section holds text (always a mesh: a glyph's function is loose)."""
        raise NotImplementedError

    def unflat(self, builder: Any, node: Any, error: Exception, keep: Callable[[], Solid]
               ) -> Solid:
        """A ``linear_extrude`` of a section with no outline (a true circle): ``keep()``
        extrudes its function, or the ``error`` stands."""
        raise NotImplementedError

    def facet(self, builder: Any, node: Any, what: str, error: Exception,
              rebuild: Callable[[Any], Any]) -> Any:
        """Where ``what`` (hull, minkowski, offset, projection) met a curved solid
        (``error``): ``rebuild(faceted builder)`` builds it on OpenSCAD's facets, or the
        error stands."""
        raise NotImplementedError

    def faceted_body(self, builder: Any, node: Any, body: Solid) -> Optional[Solid]:
        """The children of ``node`` on OpenSCAD's facets (``body``: as built here)."""
        raise NotImplementedError


class OpenSCADFacets(FacetMode):
    """``facets="openscad"``: the solid OpenSCAD 2021.01 renders and exports, its
    spheres, cylinders and circles the polytopes of its fragments, its sweeps and
    twisted extrusions its meshes."""

    name = "openscad"

    def sphere(self, r: float, fragments: Fragments) -> Solid:
        return convex_solid(fx.sphere_points(r, fragments()))

    def cylinder(self, h: float, r1: float, r2: float, center: bool,
                 fragments: Fragments) -> Solid:
        z1, z2 = (-h / 2, h / 2) if center else (0.0, h)
        return convex_solid(fx.cylinder_points(r1, r2, z1, z2, fragments()))

    def circle(self, r: float, fragments: Fragments) -> Solid:
        return Polygon(fx.circle_points(r, fragments()))

    def sweep(self, builder: Any, node: Any, body: Solid, angle: float) -> Optional[Solid]:
        return builder.faceted_sweep(node, body, angle)

    def extrusion(self, straight: bool, text: bool) -> bool:
        return straight and not text

    def unflat(self, builder: Any, node: Any, error: Exception, keep: Callable[[], Solid]
               ) -> Solid:
        raise builder.error(node, f"linear_extrude: {error}") from None

    def facet(self, builder: Any, node: Any, what: str, error: Exception,
              rebuild: Callable[[Any], Any]) -> Any:
        raise error                       # the model is OpenSCAD's facets already

    def faceted_body(self, builder: Any, node: Any, body: Solid) -> Optional[Solid]:
        return body


class TrueCurves(FacetMode):
    """``facets="true"``: the true curves OpenSCAD's facets approximate; where an
    operation is only defined on OpenSCAD's facets, they are taken, with a warning."""

    name = "true"

    def sphere(self, r: float, fragments: Fragments) -> Solid:
        return Sphere(r)

    def cylinder(self, h: float, r1: float, r2: float, center: bool,
                 fragments: Fragments) -> Solid:
        return Cylinder(h=h, r1=r1, r2=r2, center=center)

    def circle(self, r: float, fragments: Fragments) -> Solid:
        return Circle(r)

    def sweep(self, builder: Any, node: Any, body: Solid, angle: float) -> Optional[Solid]:
        return RotateExtrude(body, angle)

    def extrusion(self, straight: bool, text: bool) -> bool:
        return not text

    def unflat(self, builder: Any, node: Any, error: Exception, keep: Callable[[], Solid]
               ) -> Solid:
        return keep()

    def facet(self, builder: Any, node: Any, what: str, error: Exception,
              rebuild: Callable[[Any], Any]) -> Any:
        if not getattr(error, "curved", True):
            raise error
        kind = "circles are taken as OpenSCAD's polygons" if what == "offset" else \
            "curved children are taken as OpenSCAD's facets"
        warnings.warn(f"{builder.source}:{node.line}:{node.column}: {what}: its {kind} "
                      "($fn, $fa, $fs), as OpenSCAD does", OpenSCADWarning, stacklevel=6)
        return rebuild(builder.faceted_twin)

    def faceted_body(self, builder: Any, node: Any, body: Solid) -> Optional[Solid]:
        return builder.faceted_twin.group(node)


#: the modes by their ``facets=`` name
FACET_MODES: dict[str, FacetMode] = {mode.name: mode for mode in (OpenSCADFacets(),
                                                                  TrueCurves())}
