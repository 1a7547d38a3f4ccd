"""``Voxels``: the result of a voxelization - an octree of surface voxels on a grid.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z
>>> vox = iv.voxelize(x**2 + y**2 + z**2 - 1, bounds=((-1.2,) * 3, (1.2,) * 3),
...                   resolution=16, interior=True)
>>> vox.resolution, vox.count > 0
((16, 16, 16), True)
>>> dense = vox.to_dense()
>>> dense.shape, bool(dense[8, 8, 8])
((16, 16, 16), True)
"""
from __future__ import annotations

from typing import Any, Callable, Optional, Protocol, runtime_checkable

import numpy as np

from .. import validate
from .budget import size_text
from .grid import Grid
from .store import Octree

__all__ = ["Voxels", "VoxelSource", "DEFAULT_DENSE_LIMIT", "OUTPUTS"]

#: default memory limit of dense outputs (bytes)
DEFAULT_DENSE_LIMIT = 4 << 30
#: the output functions behind :meth:`Voxels.save`, :meth:`Voxels.render` and
#: :meth:`Voxels.to_pyvista`, registered by :mod:`implicitvox.io.files` (the layer
#: above this one) when it is imported
OUTPUTS: dict[str, Callable[..., Any]] = {}


@runtime_checkable
class VoxelSource(Protocol):
    """What :class:`Voxels` knows of the producer that made them.

    Each voxelizer hands its result a source (the shape and options, the
    triangles, the patches); ``Voxels`` calls it and imports no producer.
    """

    def refine(self, voxels: "Voxels", levels: int,
               progress: Optional[Callable[[float], Any]] = None,
               max_memory: Optional[int] = None) -> "Voxels":
        """``voxels`` continued ``levels`` levels deeper, on ``voxels.grid.finer(levels)``,
        refused (``MemoryError``) over ``max_memory`` as the voxelizer's first run."""

    def normals_at(self, points: np.ndarray) -> np.ndarray:
        """Unit normals ``(n, 3)`` of the source near ``points`` (for shading)."""


class Voxels:
    """Surface voxels (and optionally interior octants and normals) of a shape.

    Attributes
    ----------
    grid : Grid
        Origin, voxel size and voxels per axis.
    octree : Octree
        The surface voxels, with payload ``"normals"`` when computed.
    interior : dict of int to ndarray
        FULL octants per octree level (coordinates at that level); empty
        unless voxelized with ``interior=True``.
    metadata : dict
        Strings and numbers describing the run (model, timings, ...).
    source : VoxelSource or None
        The producer's handle (for :meth:`refine` and shading); ``None`` for
        voxels read from a file.
    """

    def __init__(self, grid: Grid, octree: Octree, interior: Optional[dict[int, np.ndarray]] = None,
                 metadata: Optional[dict[str, Any]] = None,
                 source: Optional[VoxelSource] = None):
        self.grid = grid
        self.octree = octree
        self.interior = interior or {}
        self.metadata = metadata or {}
        self.source = source

    # -- geometry -------------------------------------------------------------------
    @property
    def resolution(self) -> tuple[int, int, int]:
        """Voxels per axis."""
        return self.grid.shape

    @property
    def voxel_size(self) -> tuple[float, float, float]:
        return self.grid.voxel_size

    @property
    def bounds(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        return self.grid.bounds

    @property
    def count(self) -> int:
        """Number of surface voxels."""
        return self.octree.count

    def __len__(self) -> int:
        return self.count

    @property
    def normals(self) -> Optional[np.ndarray]:
        """Unit normals (n, 3) at the voxel centres in Morton order, or None."""
        return self.octree.payload.get("normals")

    def coords(self) -> np.ndarray:
        """Surface voxel indices (n, 3), in Morton order."""
        return self.octree.coords()

    def centers(self) -> np.ndarray:
        """Surface voxel centres (n, 3), in Morton order."""
        return self.grid.centers(self.coords())

    def contains(self, coords: np.ndarray) -> np.ndarray:
        """Whether each voxel index (n, 3) is a surface voxel."""
        return self.octree.contains(coords)

    @property
    def interior_count(self) -> int:
        """Number of voxels inside FULL octants."""
        return sum(self._expanded_count(level, c) for level, c in self.interior.items())

    def _expanded_count(self, level: int, coords: np.ndarray) -> int:
        scale = 1 << (self.grid.depth - level)
        first = coords.astype(np.int64) * scale
        last = np.minimum(first + scale, np.asarray(self.grid.shape))
        return int(np.prod(last - first, axis=1).sum())

    def interior_coords(self, max_memory: int = DEFAULT_DENSE_LIMIT) -> np.ndarray:
        """Voxel indices (n, 3) inside FULL octants (expanded; memory-checked)."""
        n = self.interior_count
        need = n * 3 * 8
        if need > max_memory:
            raise MemoryError(f"interior_coords needs {need / 2**30:.2f} GiB for {n} voxels, over "
                              f"max_memory={max_memory / 2**30:.2f} GiB; use to_dense() or "
                              f"the per-level octants in .interior")
        parts = []
        for level, coords in self.interior.items():
            scale = 1 << (self.grid.depth - level)
            offsets = np.stack(np.meshgrid(*[np.arange(scale)] * 3, indexing="ij"), -1).reshape(-1, 3)
            vox = (coords.astype(np.int64)[:, None, :] * scale + offsets[None]).reshape(-1, 3)
            parts.append(vox[np.all(vox < np.asarray(self.grid.shape), axis=1)])
        return np.concatenate(parts) if parts else np.zeros((0, 3), dtype=np.int64)

    def to_dense(self, interior: bool = True, max_memory: int = DEFAULT_DENSE_LIMIT) -> np.ndarray:
        """Boolean array of the grid's shape: surface voxels (and interior ones).

        Raises
        ------
        MemoryError
            If the array would need more than ``max_memory`` bytes.
        """
        need = int(np.prod(self.grid.shape))
        if need > max_memory:
            raise MemoryError(f"a dense {self.grid.shape} array needs {size_text(need)}, over "
                              f"max_memory={size_text(max_memory)}")
        dense = np.zeros(self.grid.shape, dtype=bool)
        c = self.coords()
        dense[c[:, 0], c[:, 1], c[:, 2]] = True
        if interior:
            n0, n1, n2 = self.grid.shape
            for level, coords in self.interior.items():
                # mark the octants on a grid of that level, then upsample and crop
                scale = 1 << (self.grid.depth - level)
                coarse = np.zeros([-(-n // scale) for n in self.grid.shape], dtype=bool)
                coarse[coords[:, 0], coords[:, 1], coords[:, 2]] = True
                fine = coarse.repeat(scale, 0).repeat(scale, 1).repeat(scale, 2)
                dense |= fine[:n0, :n1, :n2]
        return dense

    # -- continuing -------------------------------------------------------------------
    def refine(self, levels: int = 1, progress: Any = None,
               max_memory: Optional[int] = None) -> "Voxels":
        """Continue the subdivision ``levels`` more levels (Stolte §1: "continued
        from that point").

        The result is on ``self.grid.finer(levels)`` (each voxel split
        ``2**levels`` times per axis, the same edges) and equals a direct
        voxelization on that grid, bit for bit: for cubic voxels,
        ``voxelize(shape, bounds=self.bounds, voxel_size=self.voxel_size[0] / 2**levels)``
        with the same options.

        ``max_memory`` bounds the run as in :func:`implicitvox.voxelize`
        (default: half the memory available).

        Raises
        ------
        ValueError
            If ``levels`` is not a positive int, the result would exceed the
            octree's 21 levels, or the voxels were read from a file (no source).
        MemoryError
            When the estimate, or the run itself, exceeds ``max_memory``.
        """
        levels = validate.positive_int(levels, "levels")
        if self.grid.depth + levels > 21:
            raise ValueError(f"refine({levels}) of a depth-{self.grid.depth} grid exceeds the "
                             "octree's 21 levels")
        if self.source is None:
            raise ValueError("refine needs the shape: these voxels were loaded from a file; "
                             "voxelize the shape again at the finer resolution")
        return self.source.refine(self, levels, progress, max_memory)

    # -- outputs ------------------------------------------------------------------------
    def to_mesh(self, tolerance: Optional[float] = None, *, refine: Optional[int] = None,
                progress: Any = None, max_memory: Optional[int] = None) -> Any:
        """Triangles of the shape's surface within a guaranteed Hausdorff distance
        (:func:`implicitvox.mesh`), over these voxels' bounds.

        With ``tolerance`` None the voxels are the largest cells (the bound is
        ``√3`` voxel sizes); else the tolerance picks the cells. Needs the shape:
        voxels of an implicit or csg shape (not read from a file, not of a
        triangle mesh, whose triangles are its mesh).

        Examples
        --------
        >>> import implicitvox as iv
        >>> from implicitvox import x, y, z
        >>> vox = iv.voxelize(x * x + y * y + z * z - 1, 16, bounds=((-1.2,) * 3, (1.2,) * 3))
        >>> m = vox.to_mesh()
        >>> m.n_cells > 100, round(float(m.field_data["linf_bound"][0]), 3)
        (True, 0.15)
        """
        to_mesh = getattr(self.source, "to_mesh", None)
        if to_mesh is None:
            what = "were loaded from a file" if self.source is None else \
                "came from triangles or patches (mesh them with their own triangles)"
            raise ValueError(f"to_mesh needs an implicit shape: these voxels {what}; call "
                             "implicitvox.mesh on the shape")
        return to_mesh(self, tolerance, refine=refine, progress=progress, max_memory=max_memory)

    def to_pyvista(self, kind: str = "points"):
        """PyVista object: ``"points"`` (PolyData of centres, with normals) or
        ``"cubes"`` (UnstructuredGrid of voxel cells); see
        :func:`implicitvox.io.rendering.to_pyvista`."""
        return _output("to_pyvista")(self, kind)

    def render(self, path: str, **kwargs: Any) -> str:
        """Render off screen to a PNG (see :func:`implicitvox.io.rendering.render`)."""
        return _output("render")(self, path, **kwargs)

    def save(self, path: str) -> str:
        """Write ``.npz`` (lossless), ``.vti`` or ``.binvox`` by the file's suffix
        (see :func:`implicitvox.io.files.save`)."""
        return _output("save")(self, path)

    def __repr__(self) -> str:
        return (f"<Voxels {self.count} surface voxels, resolution {self.resolution}, "
                f"bounds {self.bounds}>")


def _output(name: str) -> Callable[..., Any]:
    try:
        return OUTPUTS[name]
    except KeyError:
        raise RuntimeError(f"Voxels.{name} is provided by implicitvox.io.files, which registers it "
                           "when imported: import implicitvox") from None
