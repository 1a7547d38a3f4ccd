"""Files, pictures and the command line: the top layer.

* :mod:`.files` - ``save`` / ``load``: ``.npz`` (lossless), ``.vti``, ``.binvox``;
* :mod:`.field_files` - ``save_field`` / ``load_field``: distance fields (``.npz``, ``.vti``);
* :mod:`.render` - PyVista objects and off-screen pictures;
* :mod:`.cli` - the ``implicitvox`` command.
"""
from ..octree.voxels import OUTPUTS
from ..fields.field import OUTPUTS as FIELD_OUTPUTS
from .files import load, save
from .field_files import load_field, save_field
from .rendering import render, to_pyvista

OUTPUTS.update(save=save, render=render, to_pyvista=to_pyvista)
FIELD_OUTPUTS.update(save=save_field)

__all__ = ["load", "save", "load_field", "save_field", "render", "to_pyvista"]
