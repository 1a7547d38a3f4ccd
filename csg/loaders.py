"""Model loaders the ``implicitvox`` command finds through the entry-point group
``implicitvox.loaders`` (so the kernel never imports ``csg``)."""
from __future__ import annotations

from typing import Any

from .openscad import read_openscad
from .scene import load_json

__all__ = ["load_csg", "load_scene"]


def load_csg(path: str, facets: str = "openscad") -> Any:
    """An OpenSCAD ``.csg`` file as a solid (OpenSCAD's facets, or true curves with
    ``facets="true"``); a ``.scad`` file through the installed OpenSCAD
    (:func:`csg.scad.export_csg`)."""
    return read_openscad(path, facets=facets)


def load_scene(path: str, facets: str = "openscad") -> Any:
    """A JSON scene file as a solid (``facets`` does not apply)."""
    return load_json(path)
