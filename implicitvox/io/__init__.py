"""Files, pictures and the command line: the top layer.

* :mod:`.files` - ``save`` / ``load``: ``.npz`` (lossless), ``.vti``, ``.binvox``;
* :mod:`.render` - PyVista objects and off-screen pictures;
* :mod:`.cli` - the ``implicitvox`` command.
"""
from ..octree.voxels import OUTPUTS
from .files import load, save
from .rendering import render, to_pyvista

OUTPUTS.update(save=save, render=render, to_pyvista=to_pyvista)

__all__ = ["load", "save", "render", "to_pyvista"]
