"""Mesh files' declared sizes, checked against the file before a reader allocates them.

VTK's readers trust the counts a file declares: a 330-byte PLY that declares a
billion vertices makes VTK allocate them and abort the process
(``std::bad_alloc``). Here each format's declarations are read first and
refused when the file cannot hold what it declares:

* binary STL: 84 header bytes and 50 per declared triangle, exactly;
* PLY: each element's count times its smallest record (binary: the property
  sizes; ASCII: two bytes a line) must fit in what follows the header;
* legacy VTK: every ``POINTS``, ``POLYGONS``, ``CELLS``, ... count times two
  bytes (the least an ASCII or binary record takes) must fit in the file;
* XML VTK (``.vtp``): ``NumberOfPoints`` and ``NumberOfPolys`` at most
  :data:`MAX_ELEMENTS` (the data may be compressed, so the size says less);
* OBJ declares nothing: its reader grows with the lines it reads.

Examples
--------
>>> import os, struct, tempfile
>>> path = os.path.join(tempfile.mkdtemp(), "lie.stl")
>>> with open(path, "wb") as fh:
...     _ = fh.write(b"\\0" * 80 + struct.pack("<I", 10**9))
>>> check_declared_sizes(path)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: cannot read '...lie.stl': it declares 1,000,000,000 triangles (50,000,000,084 bytes), but the file has 84 bytes
"""
from __future__ import annotations

import mmap
import os
import re
import struct

__all__ = ["check_declared_sizes", "MAX_ELEMENTS"]

#: points or cells a compressed (XML) VTK file may declare at most
MAX_ELEMENTS = 1 << 28
_PLY_SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2,
              "int16": 2, "uint16": 2, "int": 4, "uint": 4, "int32": 4, "uint32": 4,
              "float": 4, "float32": 4, "double": 8, "float64": 8}
_PLY_HEADER_BYTES = 1 << 16
_VTK_COUNTS = re.compile(rb"\b(POINTS|POLYGONS|CELLS|TRIANGLE_STRIPS|LINES|VERTICES|"
                         rb"POINT_DATA|CELL_DATA)\s+(\d{1,30})")
_VTP_COUNTS = re.compile(rb"NumberOf(Points|Polys|Strips|Lines|Verts|Cells)\s*=\s*\"(\d{1,30})\"")


def _refuse(path: str, what: str) -> ValueError:
    return ValueError(f"cannot read {path!r}: {what}")


def check_declared_sizes(path: str) -> None:
    """Raise ``ValueError`` if the mesh file at ``path`` declares more than it holds."""
    suffix = os.path.splitext(path)[1].lower()
    size = os.path.getsize(path)
    with open(path, "rb") as fh:
        if suffix == ".stl":
            _check_stl(path, fh, size)
        elif suffix == ".ply":
            _check_ply(path, fh, size)
        elif suffix in (".vtk", ".vtp") and size:
            with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
                if suffix == ".vtk":
                    _check_vtk(path, data, size)
                else:
                    _check_vtp(path, data)


def _check_stl(path: str, fh, size: int) -> None:
    head = fh.read(84)
    if len(head) < 84:
        return                              # too short for binary: ASCII (or VTK refuses)
    declared = struct.unpack("<I", head[80:84])[0]
    need = 84 + 50 * declared
    if need == size:
        return
    text = head[:5].lower() == b"solid" and b"facet" in (head + fh.read(1024)).lower()
    if not text:
        raise _refuse(path, f"it declares {declared:,} triangles ({need:,} bytes), but the "
                            f"file has {size:,} bytes")


def _check_ply(path: str, fh, size: int) -> None:
    header = fh.read(_PLY_HEADER_BYTES)
    end = header.find(b"end_header")
    if end < 0:
        raise _refuse(path, f"no 'end_header' in the first {_PLY_HEADER_BYTES} bytes")
    body = size - (header.index(b"\n", end) + 1 if b"\n" in header[end:] else end + 10)
    lines = header[:end].decode("ascii", "replace").splitlines()
    binary = any(line.startswith("format binary") for line in lines)
    elements: list[list] = []
    for line in lines:
        words = line.split()
        if len(words) == 3 and words[0] == "element":
            if not words[2].isdigit():
                raise _refuse(path, f"element {words[1]!r} has count {words[2]!r}")
            elements.append([words[1], int(words[2]), 0])
        elif words[:1] == ["property"] and elements:
            if words[1] == "list" and len(words) >= 4:
                elements[-1][2] += _PLY_SIZES.get(words[2], 1)  # an empty list: its count
            elif len(words) >= 3:
                elements[-1][2] += _PLY_SIZES.get(words[1], 1)
    need = sum(count * (max(record, 1) if binary else 2) for _, count, record in elements)
    if need > body:
        desc = ", ".join(f"{count:,} {name}" for name, count, _ in elements)
        raise _refuse(path, f"its header declares {desc} (at least {need:,} bytes), but "
                            f"{body:,} bytes follow it")


def _check_vtk(path: str, data, size: int) -> None:
    for m in _VTK_COUNTS.finditer(data):
        count = int(m.group(2))
        if 2 * count > size:
            raise _refuse(path, f"it declares {m.group(1).decode()} {count:,}, more than "
                                f"its {size:,} bytes can hold")


def _check_vtp(path: str, data) -> None:
    for m in _VTP_COUNTS.finditer(data):
        count = int(m.group(2))
        if count > MAX_ELEMENTS:
            raise _refuse(path, f"it declares NumberOf{m.group(1).decode()} = {count:,}, over "
                                f"the limit of {MAX_ELEMENTS:,} "
                                "(implicitvox.triangles.declared.MAX_ELEMENTS)")
