"""Distance-field files: ``.npz`` (the bricks, lossless, read back by
:func:`load_field`) and ``.vti`` (dense VTK image data for ParaView: point
arrays ``distance``, ``error`` and ``band``), in the field's float type
(float64 or float32).

Examples
--------
>>> import os, tempfile
>>> import implicitvox as iv
>>> from implicitvox import linf
>>> field = iv.distance_field(linf.Sphere((0, 0, 0), 1.0), 16, band=1)
>>> back = load_field(field.save(os.path.join(tempfile.mkdtemp(), "ball.npz")))
>>> bool((back.values == field.values).all()), back.kind
(True, 'exact')
"""
from __future__ import annotations

import json
import os

import numpy as np

from .. import validate
from ..fields.bricks import BRICK, MAX_BAND
from ..fields.field import DTYPES, NORMS, DistanceField
from ..octree.grid import MAX_RESOLUTION, Grid
from .files import check_unpacked

__all__ = ["save_field", "load_field", "FIELD_FORMATS"]

FIELD_FORMATS = (".npz", ".vti")
_VERSION = 1
_KINDS = ("exact", "box test", "certified")


def save_field(field: DistanceField, path: str) -> str:
    """Write a distance field by the suffix of ``path``; returns the path."""
    ext = os.path.splitext(str(path))[1].lower()
    if ext not in FIELD_FORMATS:
        raise ValueError(f"unknown distance-field file type {ext!r} for {path!r}; use one of "
                         f"{FIELD_FORMATS}")
    validate.writable_path(path)
    if ext == ".vti":
        field.to_pyvista().save(str(path))
        return str(path)
    with open(path, "wb") as fh:
        np.savez_compressed(
            fh, format=np.array([_VERSION]), origin=np.array(field.grid.origin),
            voxel_size=np.array(field.grid.voxel_size), shape=np.array(field.grid.shape),
            norm=np.array(field.norm), band=np.array([field.band or 0]), kind=np.array(field.kind),
            keys=field.keys, values=field.values, errors=field.errors, active=field.active,
            signed=np.array([field.signed]),
            metadata=np.array(json.dumps(field.metadata, default=str)))
    return str(path)


def load_field(path: str) -> DistanceField:
    """Read a field written by :func:`save_field` as ``.npz``; every field is checked
    (a bad file is refused whole, with the field named)."""
    if os.path.splitext(str(path))[1].lower() != ".npz":
        raise ValueError(f"{path!r}: distance fields are read from .npz (the lossless form)")
    if not os.path.isfile(path):
        raise FileNotFoundError(f"no such distance-field file: {path!r}")

    def bad(name: str, why: str) -> ValueError:
        return ValueError(f"{path!r}: field {name!r}: {why}")

    try:
        data = np.load(path, allow_pickle=False)
    except Exception as err:  # noqa: BLE001 - hostile bytes: one documented error type
        raise ValueError(f"{path!r}: not an .npz file ({type(err).__name__})") from None
    with data:
        declared = 0
        for name in data.files:
            header = data.zip.getinfo(name + ".npy")
            declared += header.file_size
        check_unpacked(path, declared)
        need = ("format", "origin", "voxel_size", "shape", "norm", "band", "kind", "keys",
                "values", "errors", "active", "signed")
        for name in need:
            if name not in data.files:
                raise bad(name, "missing")
        arrays = {name: data[name] for name in need}
        meta = str(data["metadata"]) if "metadata" in data.files else "{}"
    if arrays["format"].tolist() != [_VERSION]:
        raise bad("format", f"unsupported version {arrays['format'].tolist()}")
    origin, size = arrays["origin"], arrays["voxel_size"]
    shape = arrays["shape"]
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise bad("origin", "must be 3 finite numbers")
    if size.shape != (3,) or not np.all(np.isfinite(size) & (size > 0)):
        raise bad("voxel_size", "must be 3 positive finite numbers")
    if shape.shape != (3,) or shape.dtype.kind not in "iu" or \
            not np.all((shape >= 1) & (shape <= MAX_RESOLUTION)):
        raise bad("shape", f"must be 3 counts from 1 to {MAX_RESOLUTION}")
    norm, kind = str(arrays["norm"]), str(arrays["kind"])
    if norm not in NORMS:
        raise bad("norm", f"must be one of {NORMS}, got {norm!r}")
    if kind not in _KINDS:
        raise bad("kind", f"must be one of {_KINDS}, got {kind!r}")
    band = arrays["band"]
    if band.shape != (1,) or band.dtype.kind not in "iu" or not 0 <= int(band[0]) <= MAX_BAND:
        raise bad("band", f"must be one count from 0 (everywhere) to {MAX_BAND}")
    keys = arrays["keys"]
    if keys.dtype != np.uint64 or keys.ndim != 1 or np.any(keys[1:] <= keys[:-1]):
        raise bad("keys", "must be strictly increasing uint64 Morton codes")
    k = len(keys)
    stored = arrays["values"].dtype
    if stored.name not in DTYPES:
        raise bad("values", f"must be one of {DTYPES}, got {stored.name}")
    for name, dtype in (("values", stored), ("errors", stored), ("active", np.bool_)):
        if arrays[name].dtype != dtype or arrays[name].shape != (k, BRICK, BRICK, BRICK):
            raise bad(name, f"must be {np.dtype(dtype).name} of shape ({k}, 8, 8, 8)")
    grid = Grid(tuple(origin.tolist()), tuple(size.tolist()), tuple(int(n) for n in shape))
    from ..octree import morton
    bricks = morton.decode(keys).astype(np.int64)
    if k and np.any(bricks * BRICK >= np.asarray(grid.shape)):
        raise bad("keys", "a brick lies outside the grid")
    if np.any(~np.isfinite(arrays["values"][arrays["active"]])) or \
            np.any(~(arrays["errors"] >= 0)):
        raise bad("values", "band samples must be finite, errors non-negative")
    signed = arrays["signed"]
    if signed.shape != (1,) or signed.dtype != np.bool_:
        raise bad("signed", "must be one bool")
    return DistanceField(grid, norm, int(band[0]) or None, keys, arrays["values"], arrays["errors"],
                         arrays["active"], kind, metadata=json.loads(meta) if meta else {},
                         signed=bool(signed[0]))
