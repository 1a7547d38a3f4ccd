"""Files: ``.npz`` (lossless: octree, grid, interior, payload, metadata),
``.vti`` (VTK image data, dense) and ``.binvox`` (run-length encoded, dense).

Examples
--------
>>> import os, tempfile
>>> import implicitvox as iv
>>> from implicitvox import x, y, z
>>> vox = iv.voxelize(x**2 + y**2 + z**2 - 1, bounds=((-1.2,) * 3, (1.2,) * 3), resolution=8)
>>> path = os.path.join(tempfile.mkdtemp(), "ball.npz")
>>> back = iv.load(vox.save(path))
>>> bool((back.coords() == vox.coords()).all())
True
"""
from __future__ import annotations

import json
import os
import re
from typing import Any

import numpy as np

from .. import validate
from ..triangles.isolated import run_isolated
from ..octree.budget import available_memory, size_text
from ..octree.grid import MAX_RESOLUTION, Grid
from ..octree.store import Octree
from ..octree.voxels import DEFAULT_DENSE_LIMIT, Voxels

__all__ = ["save", "load", "save_mesh", "check_unpacked", "FORMATS", "MESH_FORMATS",
           "NPZ_LIMIT", "BINVOX_LIMIT"]

FORMATS = (".npz", ".vti", ".binvox")
#: triangle mesh files :func:`save_mesh` writes (through PyVista's VTK writers)
MESH_FORMATS = (".stl", ".ply", ".obj", ".vtp", ".vtk")
_NPZ_VERSION = 1
#: bytes an .npz may unpack to at most (checked before anything is read)
NPZ_LIMIT = 16 << 30
#: voxels a .binvox may declare at most (the format is dense: one byte each in memory)
BINVOX_LIMIT = 1 << 31
_BINVOX_HEADER_LINES, _BINVOX_HEADER_LINE = 64, 4096


def check_unpacked(path: str, unpacked: int) -> None:
    """Refuse an ``.npz`` whose members unpack to more than :data:`NPZ_LIMIT`
    (``ValueError``) or than this process may still allocate (``MemoryError``,
    :func:`implicitvox.octree.budget.available_memory`), before anything is read."""
    if unpacked > NPZ_LIMIT:
        raise ValueError(f"{path!r} unpacks to {size_text(unpacked)}, over the limit "
                         f"of {size_text(NPZ_LIMIT)} (implicitvox.io.files.NPZ_LIMIT)")
    room = available_memory()
    if unpacked > room:
        raise MemoryError(f"{path!r} unpacks to {size_text(unpacked)}, more than the "
                          f"{size_text(room)} this process may still use")


def _suffix(path: str) -> str:
    ext = os.path.splitext(str(path))[1].lower()
    if ext in MESH_FORMATS:
        raise ValueError(f"{path!r} is a mesh file type, and voxels are not triangles: mesh the "
                         "shape with `implicitvox mesh` (or implicitvox.mesh, Voxels.to_mesh); "
                         f"voxel files are {FORMATS}")
    if ext not in FORMATS:
        raise ValueError(f"unknown voxel file type {ext!r} for {path!r}; use one of {FORMATS}")
    return ext


def save(vox: Voxels, path: str) -> str:
    """Write ``vox`` to ``path``; the suffix picks the format. Returns the path."""
    ext = _suffix(path)
    validate.writable_path(path)
    {".npz": _save_npz, ".vti": _save_vti, ".binvox": _save_binvox}[ext](vox, str(path))
    return str(path)


def save_mesh(mesh: Any, path: str) -> str:
    """Write a ``pyvista.PolyData`` of triangles to ``path`` (``.stl``, ``.ply``,
    ``.obj``, ``.vtp`` or ``.vtk``, by the suffix; binary where the format has
    it). Returns the path.

    Examples
    --------
    >>> import os, tempfile
    >>> import implicitvox as iv
    >>> from implicitvox import x, y, z
    >>> m = iv.mesh(x * x + y * y + z * z - 1, resolution=8, bounds=((-1.2,) * 3, (1.2,) * 3))
    >>> path = save_mesh(m, os.path.join(tempfile.mkdtemp(), "ball.stl"))
    >>> import pyvista as pv
    >>> pv.read(path).n_cells == m.n_cells
    True
    """
    ext = os.path.splitext(str(path))[1].lower()
    if ext not in MESH_FORMATS:
        raise ValueError(f"unknown mesh file type {ext!r} for {path!r}; use one of "
                         f"{MESH_FORMATS}")
    validate.writable_path(path)
    mesh.save(str(path))
    return str(path)


def load(path: str) -> Voxels:
    """Read voxels written by :func:`save` (``.npz``, ``.vti`` or ``.binvox``)."""
    ext = _suffix(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"no such voxel file: {path!r}")
    reader = {".npz": _load_npz, ".vti": _load_vti, ".binvox": _load_binvox}[ext]
    try:
        return reader(str(path))
    except (ValueError, MemoryError, FileNotFoundError):
        raise
    except Exception as err:  # noqa: BLE001 - hostile bytes: one documented error type
        raise ValueError(f"{path!r}: cannot read it as {ext}: {type(err).__name__}: "
                         f"{str(err)[:200]}") from None


# -- npz ------------------------------------------------------------------------------
def _save_npz(vox: Voxels, path: str) -> None:
    t = vox.octree
    arrays: dict[str, np.ndarray] = {
        "format": np.array([_NPZ_VERSION]),
        "origin": np.array(vox.grid.origin), "voxel_size": np.array(vox.grid.voxel_size),
        "shape": np.array(vox.grid.shape), "depth": np.array([t.depth]),
        "metadata": np.array(json.dumps(vox.metadata, default=str)),
    }
    for level, m in enumerate(t.masks):
        arrays[f"masks_{level}"] = m
    for level, f in enumerate(t.first):
        arrays[f"first_{level}"] = f
    for name, v in t.payload.items():
        arrays[f"payload_{name}"] = v
    for level, c in vox.interior.items():
        arrays[f"interior_{level}"] = c
    with open(path, "wb") as fh:
        np.savez_compressed(fh, **arrays)


def _load_npz(path: str) -> Voxels:
    """Every field checked before it is trusted (types, shapes, sizes against each
    other and against the octree's rules); a bad file is refused whole."""
    def bad(field: str, why: str) -> ValueError:
        return ValueError(f"{path!r}: field {field!r}: {why}")

    try:
        data = np.load(path, allow_pickle=False)
    except (ValueError, OSError, EOFError) as err:
        raise ValueError(f"{path!r} is not an implicitvox .npz file: {err}") from None
    if not hasattr(data, "files"):
        raise ValueError(f"{path!r} is not an implicitvox .npz file (one array, not an archive)")
    with data:
        check_unpacked(path, sum(info.file_size for info in data.zip.infolist()))
        try:
            version = data["format"] if "format" in data else None
        except ValueError as err:
            raise ValueError(f"{path!r} is not an implicitvox .npz file: {err}") from None
        if version is None or version.shape != (1,) or version.dtype.kind not in "iu" \
                or int(version[0]) != _NPZ_VERSION:
            raise ValueError(f"{path!r} is not an implicitvox .npz file (version {_NPZ_VERSION})")

        def field(name: str, kind: str, shape: tuple | None = None) -> np.ndarray:
            if name not in data:
                raise bad(name, "missing")
            try:
                a = data[name]
            except ValueError as err:
                raise bad(name, f"unreadable ({err})") from None
            if a.dtype.kind not in kind:
                raise bad(name, f"has dtype {a.dtype}")
            if shape is not None and a.shape != shape:
                raise bad(name, f"must have shape {shape}, got {a.shape}")
            return a

        origin = field("origin", "f", (3,))
        size = field("voxel_size", "f", (3,))
        shape = field("shape", "iu", (3,))
        depth_a = field("depth", "iu", (1,))
        if not np.all(np.isfinite(origin)):
            raise bad("origin", f"must be finite, got {origin.tolist()}")
        if not (np.all(np.isfinite(size)) and np.all(size > 0)):
            raise bad("voxel_size", f"must be positive and finite, got {size.tolist()}")
        if not np.all((shape >= 1) & (shape <= MAX_RESOLUTION)):
            raise bad("shape", f"must be 3 counts from 1 to {MAX_RESOLUTION}, got "
                               f"{shape.tolist()}")
        grid = Grid(tuple(float(v) for v in origin), tuple(float(v) for v in size),
                    tuple(int(v) for v in shape))
        depth = int(depth_a[0])
        if depth != grid.depth:
            raise bad("depth", f"a grid of {grid.shape} has depth {grid.depth}, got {depth}")
        n_masks = max(depth, 1) if "masks_0" in data else 0
        masks = [field(f"masks_{lvl}", "u") for lvl in range(n_masks)]
        first = [field(f"first_{lvl}", "u") for lvl in range(max(n_masks - 1, 0))]
        payload = {k[len("payload_"):]: field(k, "f") for k in data.files
                   if k.startswith("payload_")}
        tree = Octree(depth, masks, first, payload)
        try:
            tree.validate()
        except ValueError as err:
            raise ValueError(f"{path!r}: the octree is inconsistent: {err}") from None
        if tree.count and not np.all(tree.coords() < np.asarray(grid.shape)):
            raise bad("masks", f"voxels lie outside the grid {grid.shape}")
        if "normals" in payload and (payload["normals"].ndim != 2
                                     or payload["normals"].shape[1] != 3):
            raise bad("payload_normals", f"must have shape (n, 3), got {payload['normals'].shape}")
        interior = {}
        for k in data.files:
            if not k.startswith("interior_"):
                continue
            level = k[len("interior_"):]
            if not level.isdigit() or not 0 <= int(level) <= depth:
                raise bad(k, f"the level must be 0 to {depth}")
            c = field(k, "iu")
            span = np.asarray([-(-n // (1 << (depth - int(level)))) for n in grid.shape])
            if c.ndim != 2 or c.shape[1] != 3 or (len(c) and not np.all((c >= 0) & (c < span))):
                raise bad(k, f"must be (n, 3) octant coordinates below {span.tolist()}")
            interior[int(level)] = c.astype(np.int32)
        text = field("metadata", "U", ())
        try:
            metadata = json.loads(str(text))
        except ValueError as err:
            raise bad("metadata", f"is not JSON ({err})") from None
        if not isinstance(metadata, dict):
            raise bad("metadata", "must be a JSON object")
    return Voxels(grid, tree, interior, metadata)


# -- vti -----------------------------------------------------------------------------
def _save_vti(vox: Voxels, path: str) -> None:
    import pyvista as pv
    image = pv.ImageData(dimensions=np.array(vox.grid.shape) + 1, spacing=vox.grid.voxel_size,
                         origin=vox.grid.origin)
    surface = vox.to_dense(interior=False)
    image.cell_data["surface"] = surface.ravel(order="F").astype(np.uint8)
    if vox.interior:
        solid = vox.to_dense(interior=True) & ~surface
        image.cell_data["interior"] = solid.ravel(order="F").astype(np.uint8)
    image.save(path)


def _load_vti(path: str) -> Voxels:
    cells = _check_vti_extent(path)
    import pyvista  # noqa: F401 - imported once here, not again in every child
    # VTK's XML reader may crash on a corrupt file: it runs in a child process, which
    # may allocate what the declared cells need (a few arrays of a byte or a float each)
    shape, origin, spacing, surface, inside = run_isolated(
        _vti_arrays, path, where=f"cannot read {path!r}", max_bytes=(256 << 20) + 32 * cells)
    grid = Grid(tuple(origin.tolist()), tuple(spacing.tolist()), shape)
    interior = {} if inside is None else {grid.depth: np.argwhere(inside).astype(np.int32)}
    tree = Octree.from_coords(np.argwhere(surface), grid.depth)
    return Voxels(grid, tree, interior, {"source": os.path.basename(path)})


def _vti_arrays(path: str):
    """The image's grid and its surface and interior masks, every field checked."""
    import pyvista as pv
    image = pv.read(path)
    if not isinstance(image, pv.ImageData) or "surface" not in image.cell_data:
        raise ValueError(f"{path!r} has no 'surface' cell array (not written by implicitvox)")
    shape = tuple(int(d) - 1 for d in image.dimensions)
    origin, spacing = np.asarray(image.origin, float), np.asarray(image.spacing, float)
    if not all(1 <= n <= MAX_RESOLUTION for n in shape):
        raise ValueError(f"{path!r}: field 'WholeExtent' gives {shape} cells (1 to "
                         f"{MAX_RESOLUTION} per axis)")
    if not (np.all(np.isfinite(origin)) and np.all(np.isfinite(spacing)) and np.all(spacing > 0)):
        raise ValueError(f"{path!r}: fields 'Origin' and 'Spacing' must be finite, the spacing "
                         f"positive, got {origin.tolist()}, {spacing.tolist()}")
    masks = []
    for name in ("surface", "interior"):
        if name not in image.cell_data:
            masks.append(None)
            continue
        values = np.asarray(image.cell_data[name])
        if values.size != int(np.prod(shape)):
            raise ValueError(f"{path!r}: field {name!r} has {values.size} values for {shape} "
                             "cells")
        masks.append(values.reshape(shape, order="F").astype(bool))
    return shape, origin, spacing, masks[0], masks[1]


def _check_vti_extent(path: str) -> int:
    """The image's declared cells, bounded before VTK allocates them."""
    with open(path, "rb") as fh:
        head = fh.read(1 << 14)
    m = re.search(rb'WholeExtent\s*=\s*"([^"]{0,200})"', head)
    if m is None:
        raise ValueError(f"{path!r}: no ImageData 'WholeExtent' in its header (not a .vti file)")
    try:
        ext = [int(v) for v in m.group(1).split()]
    except ValueError:
        raise ValueError(f"{path!r}: field 'WholeExtent' is {m.group(1)[:60]!r}") from None
    if len(ext) != 6:
        raise ValueError(f"{path!r}: field 'WholeExtent' must hold 6 ints, got {len(ext)}")
    cells = 1
    for lo, hi in zip(ext[0::2], ext[1::2]):
        cells *= max(hi - lo, 0)
    if cells > BINVOX_LIMIT:
        raise ValueError(f"{path!r}: field 'WholeExtent' declares {cells:,} cells, over the "
                         f"limit of {BINVOX_LIMIT:,} (implicitvox.io.files.BINVOX_LIMIT)")
    return cells


# -- binvox --------------------------------------------------------------------------
def _save_binvox(vox: Voxels, path: str) -> None:
    """binvox 1: a cubic ``dim^3`` grid, voxels in x-z-y order (y fastest), RLE bytes.

    The format has one scale for all three axes: voxels that are not cubes are
    refused (a ``ValueError``), never written wrong.
    """
    if not vox.grid.cubic:
        raise ValueError(f"binvox stores cubic voxels only (one scale), these are "
                         f"{vox.grid.voxel_size}: use .npz or .vti, or voxelize with one "
                         "resolution or voxel_size")
    dim = max(vox.grid.shape)
    if dim ** 3 > DEFAULT_DENSE_LIMIT:
        raise MemoryError(f"binvox is dense: {dim}^3 voxels is too large")
    dense = np.zeros((dim, dim, dim), dtype=bool)
    n0, n1, n2 = vox.grid.shape
    dense[:n0, :n1, :n2] = vox.to_dense(interior=bool(vox.interior))
    flat = dense.transpose(0, 2, 1).ravel()  # index = x * dim*dim + z * dim + y
    scale = vox.grid.voxel_size[0] * dim
    with open(path, "wb") as fh:
        fh.write(b"#binvox 1\n")
        fh.write(f"dim {dim} {dim} {dim}\n".encode())
        fh.write("translate {} {} {}\n".format(*vox.grid.origin).encode())
        fh.write(f"scale {scale!r}\n".encode())
        fh.write(b"data\n")
        fh.write(_rle(flat))


def _rle(flat: np.ndarray) -> bytes:
    """binvox run-length pairs (value, count <= 255), vectorized."""
    if flat.size == 0:
        return b""
    change = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    starts = np.r_[0, change]
    lengths = np.diff(np.r_[starts, flat.size])
    values = flat[starts].astype(np.uint8)
    pieces = -(-lengths // 255)  # runs longer than 255 split
    rep_values = np.repeat(values, pieces)
    counts = np.full(pieces.sum(), 255, dtype=np.int64)
    last = np.cumsum(pieces) - 1
    counts[last] = lengths - 255 * (pieces - 1)
    out = np.empty(2 * len(counts), dtype=np.uint8)
    out[0::2], out[1::2] = rep_values, counts
    return out.tobytes()


def _load_binvox(path: str) -> Voxels:
    with open(path, "rb") as fh:
        header: dict[str, Any] = {}
        if fh.readline().strip() != b"#binvox 1":
            raise ValueError(f"{path!r} is not a binvox 1 file")
        for _ in range(_BINVOX_HEADER_LINES):
            line = fh.readline(_BINVOX_HEADER_LINE)
            if not line:
                raise ValueError(f"{path!r}: binvox header ends before 'data'")
            words = line.decode("ascii", "replace").split()
            if words and words[0] == "data":
                break
            if words:
                header[words[0]] = words[1:]
        else:
            raise ValueError(f"{path!r}: no 'data' line in the first {_BINVOX_HEADER_LINES} "
                             "lines of the binvox header")
        raw = np.frombuffer(fh.read(), dtype=np.uint8)
    try:
        dims = [int(v) for v in header["dim"]]
        origin = tuple(float(v) for v in header.get("translate", [0, 0, 0]))
        scale = float(header.get("scale", [1.0])[0])
    except (KeyError, ValueError, IndexError):
        raise ValueError(f"{path!r}: bad binvox header {header}") from None
    if len(dims) != 3 or not all(1 <= d <= MAX_RESOLUTION for d in dims):
        raise ValueError(f"{path!r}: field 'dim' must be 3 counts from 1 to {MAX_RESOLUTION}, "
                         f"got {dims}")
    total = dims[0] * dims[1] * dims[2]
    if total > BINVOX_LIMIT:
        raise ValueError(f"{path!r}: {dims} is {total:,} voxels, over the limit of "
                         f"{BINVOX_LIMIT:,} (implicitvox.io.files.BINVOX_LIMIT; binvox is dense)")
    if len(origin) != 3 or not all(np.isfinite(origin)):
        raise ValueError(f"{path!r}: field 'translate' must be 3 finite numbers, got {origin}")
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"{path!r}: field 'scale' must be positive and finite, got {scale}")
    if raw.size % 2:
        raise ValueError(f"{path!r}: the run-length data has an odd number of bytes")
    values, counts = raw[0::2], raw[1::2].astype(np.int64)
    if int(counts.sum()) != total:
        raise ValueError(f"{path!r}: {int(counts.sum())} voxels in the data, header says {dims}")
    flat = np.repeat(values.astype(bool), counts)
    dense = flat.reshape(dims[0], dims[2], dims[1]).transpose(0, 2, 1)
    size = scale / max(dims)
    grid = Grid(origin, (size, size, size), tuple(dims))
    tree = Octree.from_coords(np.argwhere(dense), grid.depth)
    return Voxels(grid, tree, {}, {"source": os.path.basename(path)})
