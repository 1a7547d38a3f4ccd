"""PyVista objects and off-screen pictures of voxels and meshes.

Rendering is headless: VTK draws through EGL (Mesa), set up before PyVista is
imported. Each voxel is drawn as a point shaded by its normal, as Stolte
displays voxels (§2: "each voxel is displayed as a 3D point with the voxel
normal"); for small sets ``style="cubes"`` draws the voxel boxes.
"""
from __future__ import annotations

import ctypes.util
import os
from typing import Any, Optional, Sequence

import numpy as np

from .. import validate
from ..octree.morton import CORNERS

__all__ = ["to_pyvista", "render", "render_mesh", "RenderError", "VIEW"]

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

_LIBRARIES = {"EGL": "libegl1 libegl-mesa0", "GL": "libgl1-mesa-dri"}


class RenderError(RuntimeError):
    """Off-screen rendering could not start."""


def _pyvista():
    import pyvista as pv
    pv.OFF_SCREEN = True
    return pv


def to_pyvista(vox: Any, kind: str = "points"):
    """``"points"``: PolyData of voxel centres (``Normals`` when stored);
    ``"cubes"``: UnstructuredGrid with one VTK_VOXEL cell per surface voxel."""
    pv = _pyvista()
    if kind == "points":
        cloud = pv.PolyData(vox.centers())
        if vox.normals is not None:
            cloud.point_data["Normals"] = vox.normals
        return cloud
    if kind == "cubes":
        coords = vox.coords()
        grid_idx = (coords[:, None, :] + CORNERS[None]).reshape(-1, 3)
        points = np.stack([vox.grid.edge(a, grid_idx[:, a]) for a in range(3)], axis=1)
        n = len(coords)
        cells = np.hstack([np.full((n, 1), 8), np.arange(8 * n).reshape(n, 8)]).ravel()
        return pv.UnstructuredGrid(cells, np.full(n, pv.CellType.VOXEL, dtype=np.uint8), points)
    raise ValueError(f"kind must be 'points' or 'cubes', got {kind!r}")


def _shading(vox: Any, light: np.ndarray) -> Optional[np.ndarray]:
    normals = vox.normals
    if normals is None and vox.source is not None and vox.count:
        normals = vox.source.normals_at(vox.centers())
    if normals is None:
        return None
    lambert = np.abs(normals @ light)  # two-sided: voxels have no inside face
    return 0.25 + 0.75 * lambert


def _missing_libraries() -> list[str]:
    return [pkg for lib, pkg in _LIBRARIES.items() if ctypes.util.find_library(lib) is None]


def render(vox: Any, path: str, *, window_size: Sequence[int] = (1024, 768),
           color: str = "#d9a441", background: str = "white", point_size: Optional[float] = None,
           style: str = "points", title: Optional[str] = None) -> str:
    """Render ``vox`` off screen to a PNG at ``path``; returns the path.

    Parameters
    ----------
    window_size : (int, int), default: (1024, 768)
    color : str
        Base colour, shaded by the normals (computed from the shape when not
        stored).
    point_size : float, optional
        Screen size of a voxel point; default from the count.
    style : {"points", "cubes"}
    title : str, optional
        Text drawn in the corner.
    """
    path = validate.writable_path(path)
    pv = _pyvista()
    plotter = _plotter(path, window_size, background)
    light = np.array([0.4, 0.5, 0.77])
    light /= np.linalg.norm(light)
    if vox.count == 0:
        plotter.add_text("no surface voxels", font_size=14, color="black")
    elif style == "cubes":
        plotter.add_mesh(to_pyvista(vox, "cubes"), color=color, show_edges=vox.count < 5000)
    else:
        cloud = to_pyvista(vox, "points")
        shade = _shading(vox, light)
        size = point_size or float(np.clip(900.0 / max(vox.resolution), 1.0, 12.0))
        base = np.array(pv.Color(color).float_rgb)
        if shade is not None:
            cloud.point_data["rgb"] = (np.clip(shade[:, None] * base[None], 0, 1) * 255).astype(np.uint8)
            plotter.add_mesh(cloud, scalars="rgb", rgb=True, point_size=size,
                             render_points_as_spheres=False, lighting=False)
        else:
            plotter.add_mesh(cloud, color=color, point_size=size)
    return _finish(plotter, path, title, _sample_corners(vox) if vox.count else None,
                   window_size)


def _finish(plotter: Any, path: str, title: Optional[str], points: Optional[np.ndarray],
            window_size: Sequence[int]) -> str:
    """Title, the view from :data:`VIEW` framed on ``points`` (when any), the screenshot."""
    if title:
        plotter.add_text(title, font_size=10, color="black")
    plotter.view_vector(VIEW, viewup=(0.0, 0.0, 1.0))
    plotter.reset_camera()
    if points is not None and len(points):
        _frame(plotter, points, window_size)
    plotter.screenshot(path)
    plotter.close()
    return path


def _plotter(path: str, window_size: Sequence[int], background: str) -> Any:
    """An off-screen plotter, or a :class:`RenderError` saying what is missing."""
    missing = _missing_libraries()
    if missing:
        raise RenderError("off-screen rendering needs the Debian packages "
                          f"{' '.join(missing)} (apt-get install them)")
    pv = _pyvista()
    try:
        plotter = pv.Plotter(off_screen=True, window_size=list(window_size))
    except Exception as err:  # VTK reports a failed context in many ways
        raise RenderError(f"could not start an off-screen render window: {err}") from err
    plotter.set_background(background)
    return plotter


#: triangles up to which :func:`render_mesh` draws edges by default
EDGES_UP_TO = 60000


def render_mesh(mesh: Any, path: str, *, window_size: Sequence[int] = (1024, 768),
                color: str = "#d9a441", background: str = "white",
                show_edges: Optional[bool] = None, title: Optional[str] = None) -> str:
    """Render a triangle mesh (``pyvista.PolyData``) off screen to a PNG at
    ``path``, flat shaded; returns the path. ``show_edges`` draws the triangles'
    edges (default: when there are at most :data:`EDGES_UP_TO` triangles, so
    they do not black out the picture)."""
    if show_edges is None:
        show_edges = mesh.n_cells <= EDGES_UP_TO
    path = validate.writable_path(path)
    plotter = _plotter(path, window_size, background)
    if mesh.n_cells == 0:
        plotter.add_text("no triangles", font_size=14, color="black")
    else:
        plotter.add_mesh(mesh, color=color, show_edges=show_edges, edge_color="#6b5428",
                         line_width=0.5, smooth_shading=False)
    points = np.asarray(mesh.points)
    return _finish(plotter, path, title, points[::max(1, len(points) // 20000)], window_size)


#: the share of the window's half-width (or half-height) the model's box may fill
FRAME_FILL = 0.92
#: the direction from the model to the camera, z up: OpenSCAD's opening view (its
#: default camera rotation 55, 0, 25: from the front, a little right, 35 degrees
#: above), so x reads left to right and text on the xy plane reads as written
VIEW = (0.34, -0.74, 0.57)


def _sample_corners(vox: Any, count: int = 4096) -> np.ndarray:
    """The corners of up to ``count`` surface voxels, spread over the model (every
    k-th in Morton order, and the extreme ones along each axis): what the picture
    must hold."""
    coords = vox.coords()
    step = max(1, len(coords) // count)
    picked = np.concatenate([coords[::step], coords[coords.argmin(axis=0)],
                             coords[coords.argmax(axis=0)]])
    offsets = np.array([[(k >> a) & 1 for a in range(3)] for k in range(8)])
    lo = np.asarray(vox.grid.origin) + (picked[:, None, :] + offsets[None]) * \
        np.asarray(vox.voxel_size)
    return lo.reshape(-1, 3)


def _frame(plotter: Any, points: np.ndarray, window_size: Sequence[int]) -> None:
    """Zoom so all ``points`` show, filling :data:`FRAME_FILL` of the window along
    its tighter direction: the points are projected with the camera (VTK's
    composite projection), and the zoom scales them (twice, as the perspective
    makes one step approximate)."""
    aspect = window_size[0] / window_size[1]
    for _ in range(2):
        m = plotter.camera.GetCompositeProjectionTransformMatrix(aspect, -1, 1)
        matrix = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
        projected = np.c_[points, np.ones(len(points))] @ matrix.T
        reach = float(np.abs(projected[:, :2] / projected[:, 3:4]).max())
        if not np.isfinite(reach) or reach <= 0:
            return
        plotter.camera.zoom(FRAME_FILL / reach)
