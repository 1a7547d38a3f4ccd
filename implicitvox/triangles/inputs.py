"""Triangle meshes in: ``(vertices, faces)`` arrays, PyVista or trimesh objects, or files.

Everything is checked here, once, with errors that say what and where: a
``(vertices, faces)`` pair gives float vertices ``(v, 3)`` and int faces
``(f, 3)``; faces must index existing vertices; the vertices the faces use
must be finite. Files (``.stl``, ``.ply``, ``.obj``, ``.vtk``, ``.vtp``) are
read through PyVista; polygons are split into triangles, lines and points
are ignored.

Examples
--------
>>> import numpy as np
>>> v, f = as_triangles((np.eye(3), [[0, 1, 2]]))
>>> v.shape, f.tolist()
((3, 3), [[0, 1, 2]])
>>> as_triangles((np.eye(3), [[0, 1, 3]]))
Traceback (most recent call last):
...
ValueError: faces[0] refers to vertex 3, but the mesh has 3 vertices (0..2)
"""
from __future__ import annotations

import logging
import os
import warnings
from typing import Any

import numpy as np

from .declared import check_declared_sizes
from .isolated import run_isolated

__all__ = ["as_triangles", "MESH_SUFFIXES"]

#: file types read through PyVista
MESH_SUFFIXES = (".stl", ".ply", ".obj", ".vtk", ".vtp")


def as_triangles(mesh: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (v, 3) float64, faces (f, 3) int64)`` from any accepted mesh input."""
    if isinstance(mesh, (str, os.PathLike)):
        path = os.fspath(mesh)
        # VTK's readers may crash on a corrupt file: they run in a child process
        size = os.path.getsize(path) if os.path.isfile(path) else 0
        import pyvista  # noqa: F401 - imported once here, not again in every child
        return run_isolated(_file_triangles, path, where=f"cannot read {path!r}",
                            max_bytes=(512 << 20) + 64 * size)
    if _is_pyvista(mesh):
        return _from_pyvista(mesh, type(mesh).__name__)
    if _is_trimesh(mesh):
        return _check(mesh.vertices, mesh.faces)
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        return _check(*mesh)
    raise TypeError("mesh must be (vertices, faces) arrays, a PyVista mesh, a trimesh.Trimesh "
                    f"or a path to {'/'.join(MESH_SUFFIXES)}, got {type(mesh).__name__}")


def _file_triangles(path: str) -> tuple[np.ndarray, np.ndarray]:
    return _from_pyvista(_read(path), f"file {path!r}")


def _is_trimesh(mesh: Any) -> bool:
    """A ``trimesh.Trimesh``, recognized without importing trimesh (an optional package)."""
    return any(c.__module__.startswith("trimesh") and c.__name__ == "Trimesh"
               for c in type(mesh).__mro__)


def _check(vertices: Any, faces: Any) -> tuple[np.ndarray, np.ndarray]:
    try:
        v = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("vertices must be an (n, 3) array of numbers") from None
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (n, 3), got {v.shape}")
    f = np.asarray(faces)
    if f.size == 0:
        f = f.reshape(0, 3)
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"faces must have shape (f, 3) (triangles), got {f.shape}")
    if not (np.issubdtype(f.dtype, np.integer) or
            (np.issubdtype(f.dtype, np.floating) and np.all(f == np.round(f)))):
        raise ValueError(f"faces must be integer vertex indices, got dtype {f.dtype}")
    f = f.astype(np.int64)
    if f.size:
        bad = np.flatnonzero(np.any((f < 0) | (f >= len(v)), axis=1))
        if len(bad):
            row = int(bad[0])
            wrong = int(f[row][(f[row] < 0) | (f[row] >= len(v))][0])
            raise ValueError(f"faces[{row}] refers to vertex {wrong}, but the mesh has "
                             f"{len(v)} vertices (0..{len(v) - 1})")
        used = np.zeros(len(v), dtype=bool)
        used[f.ravel()] = True
        bad_v = np.flatnonzero(used & ~np.all(np.isfinite(v), axis=1))
        if len(bad_v):
            k = int(bad_v[0])
            raise ValueError(f"vertex {k} is {v[k].tolist()}: the vertices of faces must be "
                             f"finite ({len(bad_v)} such vertices)")
    return v, f


def _is_pyvista(obj: Any) -> bool:
    return type(obj).__module__.startswith("pyvista")


def _read(path: str):
    import pyvista as pv
    if not os.path.exists(path):
        raise FileNotFoundError(f"mesh file not found: {path!r}")
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in MESH_SUFFIXES:
        raise ValueError(f"cannot read {path!r}: mesh files must be one of "
                         f"{', '.join(MESH_SUFFIXES)}")
    if os.path.getsize(path) == 0:
        raise ValueError(f"cannot read {path!r}: the file is empty")
    check_declared_sizes(path)      # before VTK allocates what the file declares
    vtk_errors = _Collect()
    root = logging.getLogger()
    root.addHandler(vtk_errors)      # VTK's messages come through logging: keep them
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                mesh = pv.read(path)
            except Exception as err:  # VTK readers raise many types
                raise ValueError(f"cannot read {path!r} as a {suffix} mesh: {err}") from None
    finally:
        root.removeHandler(vtk_errors)
    failed = [w for w in caught if "error while reading" in str(w.message)]
    if failed or vtk_errors.messages:
        why = vtk_errors.messages[0] if vtk_errors.messages else "the VTK reader failed"
        raise ValueError(f"cannot read {path!r} as a {suffix} mesh: {why}")
    return mesh


class _Collect(logging.Handler):
    """Keeps the first line of each log record (VTK's reader errors)."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage().splitlines()[0][:200])


def _from_pyvista(mesh, where: str) -> tuple[np.ndarray, np.ndarray]:
    import pyvista as pv
    if isinstance(mesh, pv.MultiBlock):
        mesh = mesh.combine()
    if not isinstance(mesh, pv.PolyData):
        if not hasattr(mesh, "extract_surface"):
            raise ValueError(f"{where}: expected a surface mesh, got {type(mesh).__name__}")
        mesh = mesh.extract_surface()
    if mesh.n_cells and not mesh.is_all_triangles:
        mesh = mesh.triangulate()
    faces = _triangle_faces(mesh)
    return _check(np.asarray(mesh.points, dtype=np.float64), faces)


def _triangle_faces(mesh) -> np.ndarray:
    """Triangles of a triangulated PolyData's polygon cells (lines, points ignored)."""
    cells = np.asarray(mesh.faces)
    if cells.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    if np.all(cells[::4] == 3) and len(cells) % 4 == 0:
        return cells.reshape(-1, 4)[:, 1:].astype(np.int64)
    raise ValueError("the mesh has polygons that could not be split into triangles")
