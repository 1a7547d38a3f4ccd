"""``DistanceField``: signed distances at voxel centres, in bricks, with their error.

The samples live in bricks of 8³ (:mod:`.bricks`): the band's samples hold
the distance (negative inside) and a bound on its error; the other samples
of a band brick, and every point beyond the bricks, hold the *background*
``±(band + 1)`` voxels with the sign of the side they are on (proved by the
voxelizer's interior octants), as OpenVDB's narrow-band level sets do.

Reconstruction (Bærentzen §3.2): :meth:`DistanceField.sample` interpolates
trilinearly between the 8 nearest samples; :meth:`DistanceField.gradient`
takes central differences at those 8 samples and interpolates them (the 28
samples of Bærentzen's Fig. 3); :meth:`DistanceField.isosurface` extracts the
0-isosurface with scikit-image's marching cubes.

Examples
--------
>>> import numpy as np, implicitvox as iv
>>> from implicitvox import linf
>>> field = iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 32, band=2)
>>> field.kind, field.max_error
('exact', 0.0)
>>> float(field.sample(np.array([[0.0, 0.0, 0.95]]))[0].round(3))    # inside: negative
-0.05
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from .. import validate
from ..octree.budget import size_text
from ..octree.grid import Grid
from ..octree.voxels import DEFAULT_DENSE_LIMIT, Voxels
from .bricks import BRICK, BrickIndex, brick_coords, masked_coords

__all__ = ["DistanceField", "OUTPUTS", "NORMS", "DTYPES", "stored"]

NORMS = ("euclidean", "linf")
#: the float types a field stores its values and error bounds in
DTYPES = ("float64", "float32")
#: writers behind :meth:`DistanceField.save`, registered by :mod:`implicitvox.io.files`
OUTPUTS: dict[str, Callable[..., Any]] = {}


def stored(values: np.ndarray, errors: np.ndarray, dtype: str
           ) -> tuple[np.ndarray, np.ndarray]:
    """Distances and their error bounds (float64) as a field of ``dtype`` stores them.

    float64 keeps them. float32 rounds each value to nearest and adds the rounding,
    ``|stored - value|`` (exact in float64: the two are that close), to its bound,
    the sum rounded up (past float64's rounding where both terms are nonzero, then
    to float32), so that ``|stored - true| <= stored error`` still holds.

    >>> v, e = stored(np.array([0.1, -2.0]), np.array([0.0, 1e-3]), "float32")
    >>> v.dtype.name, bool(e[0] >= abs(0.1 - float(v[0])) > 0), float(e[1]) > 1e-3
    ('float32', True, True)
    """
    if dtype == "float64":
        return values, errors
    small = values.astype(np.float32)
    with np.errstate(invalid="ignore"):            # NaN beyond the grid, inf never
        off = np.abs(small.astype(np.float64) - values)
    total = errors + off
    summed = (errors > 0) & (off > 0)              # else one term is 0: the sum is exact
    total[summed] = np.nextafter(total[summed], np.inf)
    bound = total.astype(np.float32)
    low = bound < total
    bound[low] = np.nextafter(bound[low], np.float32(np.inf))
    return small, bound


class DistanceField:
    """Signed distances on a grid's voxel centres, in a narrow band (see the module
    docstring).

    Attributes
    ----------
    grid : Grid
        The grid; sample ``(i, j, k)`` is the centre of voxel ``(i, j, k)``.
    norm : str
        ``"euclidean"`` or ``"linf"`` (the max-norm, weighted by the voxel
        size over its longest edge when voxels are not cubes).
    band : int or None
        Every sample within ``band`` voxels (per axis) of a surface voxel is
        computed; None: every sample of the grid.
    keys : ndarray of uint64 (k,)
        Sorted Morton codes of the bricks' indices.
    values, errors : ndarray (k, 8, 8, 8)
        Distances and their error bounds (``|value - true| <= error``; 0 for
        the background samples, whose value is a clamp, not a distance), float64
        or float32 (each bound then holds the rounding to float32 too: :func:`stored`).
    active : ndarray of bool (k, 8, 8, 8)
        The band's samples.
    kind : str
        How the distances were found: ``"exact"``, ``"box test"`` or ``"certified"``.
    signed : bool
        False for an open mesh (unsigned distances, no inside).
    """

    def __init__(self, grid: Grid, norm: str, band: Optional[int], keys: np.ndarray,
                 values: np.ndarray,
                 errors: np.ndarray, active: np.ndarray, kind: str,
                 voxels: Optional[Voxels] = None, metadata: Optional[dict] = None,
                 signed: bool = True):
        self.grid = grid
        self.norm = norm
        self.band = band
        self.keys = keys
        self.values = values
        self.errors = errors
        self.active = active
        self.kind = kind
        self.voxels = voxels
        self.metadata = metadata or {}
        self.signed = signed
        self._index = BrickIndex(keys)

    # -- sizes ---------------------------------------------------------------------------
    @property
    def background(self) -> float:
        """The magnitude stored beyond the band: ``band + 1`` longest voxel edges (for a
        field everywhere, the grid's longest side)."""
        reach = max(self.grid.shape) if self.band is None else self.band + 1
        return reach * max(self.grid.voxel_size)

    @property
    def count(self) -> int:
        """Samples in the band."""
        return int(self.active.sum())

    @property
    def nbytes(self) -> int:
        return int(self.keys.nbytes + self.values.nbytes + self.errors.nbytes + self.active.nbytes)

    @property
    def max_error(self) -> float:
        """The largest error bound of a band sample (world units)."""
        return float(self.errors[self.active].max()) if self.count else 0.0

    def coords(self) -> np.ndarray:
        """Voxel indices (n, 3) of the band's samples, brick by brick."""
        return masked_coords(self.keys, self.active)

    def band_values(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(coords (n, 3), values (n,), errors (n,))`` of the band's samples."""
        return self.coords(), self.values[self.active], self.errors[self.active]

    # -- look-ups -------------------------------------------------------------------------
    def at(self, coords: np.ndarray) -> np.ndarray:
        """Values at voxel indices (n, 3): the stored sample, or the background with
        the side's sign where no brick holds it; NaN outside the grid."""
        coords = np.asarray(coords, dtype=np.int64).reshape(-1, 3)
        brick, local = self._index.locate(coords)
        out = np.empty(len(coords))
        held = brick >= 0
        out[held] = self.values[brick[held], local[held, 0], local[held, 1], local[held, 2]]
        rest = np.flatnonzero(~held)
        if len(rest):
            out[rest] = np.where(self.in_solid(coords[rest]), -self.background, self.background)
        outside = np.any((coords < 0) | (coords >= np.asarray(self.grid.shape)), axis=1)
        out[outside] = np.nan
        return out

    def in_solid(self, coords: np.ndarray) -> np.ndarray:
        """Whether voxels (n, 3) lie in the voxelizer's FULL octants (inside the solid,
        proved); False for voxels read from a file without them."""
        inside = np.zeros(len(coords), dtype=bool)
        if self.voxels is None:
            return inside
        from ..octree import morton
        depth = self.grid.depth
        finest = morton.encode(np.asarray(coords, dtype=np.int64))
        for level, octants in self.voxels.interior.items():
            if not len(octants):
                continue
            codes = np.sort(morton.encode(np.asarray(octants, dtype=np.int64)))
            mine = finest >> np.uint64(3 * (depth - level))   # the octant's code at ``level``
            at = np.minimum(np.searchsorted(codes, mine), len(codes) - 1)
            inside |= codes[at] == mine
        return inside

    def _lattice(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The lower corner sample (n, 3) of each point's trilinear cell and the
        fractions (n, 3) within it."""
        p = validate.points(points)
        h = np.asarray(self.grid.voxel_size)
        u = (p - np.asarray(self.grid.origin)) / h - 0.5          # in sample units
        u = np.where(np.abs(u - np.round(u)) < 1e-9, np.round(u), u)  # on a sample: exactly
        base = np.floor(u).astype(np.int64)
        return base, u - base

    def sample(self, points: Any) -> np.ndarray:
        """The trilinear reconstruction at ``points`` (n, 3) (Bærentzen §3.2); NaN where
        a needed sample lies outside the grid."""
        base, t = self._lattice(points)
        out = np.zeros(len(base))
        for corner in np.ndindex(2, 2, 2):
            c = np.asarray(corner)
            weight = np.prod(np.where(c, t, 1 - t), axis=1)
            out += np.where(weight > 0, weight * self.at(base + c), 0.0)
        return out

    def gradient(self, points: Any) -> np.ndarray:
        """Gradients (n, 3) at ``points``: central differences at the 8 samples around
        each point, interpolated trilinearly (Bærentzen §4, Fig. 3)."""
        base, t = self._lattice(points)
        h = np.asarray(self.grid.voxel_size)
        out = np.zeros((len(base), 3))
        for corner in np.ndindex(2, 2, 2):
            c = base + np.asarray(corner)
            weight = np.prod(np.where(np.asarray(corner), t, 1 - t), axis=1)
            for a in range(3):
                step = np.zeros(3, dtype=np.int64)
                step[a] = 1
                diff = (self.at(c + step) - self.at(c - step)) / (2 * h[a])
                out[:, a] += weight * diff
        return out

    # -- dense outputs ------------------------------------------------------------------
    def to_dense(self, max_memory: int = DEFAULT_DENSE_LIMIT) -> np.ndarray:
        """The field on the whole grid (in the field's float type), background beyond
        the band.

        Raises
        ------
        MemoryError
            If the array would need more than ``max_memory`` bytes.
        """
        need = self.values.itemsize * int(np.prod(self.grid.shape, dtype=np.float64))
        if need > max_memory:
            raise MemoryError(f"a dense {self.grid.shape} distance field needs "
                              f"{size_text(need)}, over max_memory={size_text(max_memory)}")
        dense = np.full(self.grid.shape, self.background, dtype=self.values.dtype)
        if self.voxels is not None:
            solid = self.voxels.to_dense(interior=True, max_memory=max_memory)
            dense[solid] = -self.background
        coords = brick_coords(self.keys)
        inside = np.all(coords < np.asarray(self.grid.shape), axis=-1)
        c = coords[inside]
        dense[c[:, 0], c[:, 1], c[:, 2]] = self.values[inside]
        return dense

    def isosurface(self, level: float = 0.0, max_memory: int = DEFAULT_DENSE_LIMIT) -> Any:
        """The ``level`` isosurface of the trilinear field as a ``pyvista.PolyData`` of
        triangles (scikit-image's marching cubes), with the field's gradients as
        point normals (Bærentzen §3.2)."""
        import pyvista as pv
        from skimage.measure import marching_cubes
        level = validate.number(level, "level")
        dense = self.to_dense(max_memory)
        if not (dense.min() < level < dense.max()):
            return pv.PolyData()
        verts, faces, _, _ = marching_cubes(dense, level=level, spacing=self.grid.voxel_size)
        points = verts + np.asarray(self.grid.origin) + 0.5 * np.asarray(self.grid.voxel_size)
        cells = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
        mesh = pv.PolyData(points, cells)
        g = self.gradient(points)
        norm = np.linalg.norm(g, axis=1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            mesh.point_data["Normals"] = np.where(norm > 0, g / norm, 0.0)
        return mesh

    def to_pyvista(self, max_memory: int = DEFAULT_DENSE_LIMIT) -> Any:
        """A ``pyvista.ImageData`` whose points are the voxel centres, with point arrays
        ``distance``, ``error`` and ``band`` (1 in the band)."""
        import pyvista as pv
        image = pv.ImageData(dimensions=self.grid.shape, spacing=self.grid.voxel_size,
                             origin=tuple(o + h / 2 for o, h in zip(self.grid.origin,
                                                                     self.grid.voxel_size)))
        dense = self.to_dense(max_memory)
        errors = np.zeros(self.grid.shape, dtype=self.errors.dtype)
        band = np.zeros(self.grid.shape, dtype=np.uint8)
        c, _, e = self.band_values()
        errors[c[:, 0], c[:, 1], c[:, 2]] = e
        band[c[:, 0], c[:, 1], c[:, 2]] = 1
        image.point_data["distance"] = dense.ravel(order="F")
        image.point_data["error"] = errors.ravel(order="F")
        image.point_data["band"] = band.ravel(order="F")
        return image

    def save(self, path: str) -> str:
        """Write ``.npz`` (the bricks, lossless) or ``.vti`` (dense, for ParaView)
        by the file's suffix (:func:`implicitvox.io.files.save_field`)."""
        try:
            writer = OUTPUTS["save"]
        except KeyError:
            raise RuntimeError("DistanceField.save is provided by implicitvox.io.files: "
                               "import implicitvox") from None
        return writer(self, path)

    def __repr__(self) -> str:
        where = "everywhere" if self.band is None else f"in a {self.band}-voxel band"
        return (f"<DistanceField {self.norm}, {self.count:,} samples {where}, "
                f"{len(self.keys):,} bricks of {BRICK}³, grid {self.grid.shape}, "
                f"{self.kind}, max error {self.max_error:.3g}>")
