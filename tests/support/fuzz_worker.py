"""The fuzz suite's reader process: reads the files named on stdin, one line each.

A line ``voxelize <path>`` reads an OpenSCAD ``.csg`` in both facet modes (its
imports from the fixtures' folder) and voxelizes each at 16³ on one worker
under a 256 MiB budget. For every path it answers one line: ``ok``, ``refused <Type>`` (a documented
error: ``ValueError`` and its subclasses, ``FileNotFoundError``,
``MemoryError``) or ``bad <Type>: <message>`` (anything else). The parent
process watches it with a time limit per input, so a hang or a crash (a
signal from a native reader) shows as what it is.
"""
from __future__ import annotations

import os
import sys
import warnings

warnings.simplefilter("ignore")
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import implicitvox as ivx  # noqa: E402
from csg import load_json, read_openscad  # noqa: E402
from implicitvox.triangles.inputs import as_triangles  # noqa: E402

DOCUMENTED = (ValueError, FileNotFoundError, MemoryError)


def read(path: str) -> None:
    suffix = os.path.splitext(path)[1].lower()
    if suffix == ".csg":
        for facets in ("true", "openscad"):
            read_openscad(path, facets=facets)
    elif suffix == ".json":
        load_json(path)
    elif suffix in (".npz", ".binvox", ".vti"):
        vox = ivx.load(path)
        vox.coords()
    else:
        as_triangles(path)


def voxelize(path: str) -> None:
    from tests.support.hostile_csg import FIXTURES
    for facets in ("openscad", "true"):
        solid = read_openscad(path, facets=facets, base=str(FIXTURES))
        solid.voxelize(16, workers=1, max_memory=1 << 28)


def main() -> None:
    for line in sys.stdin:
        path = line.rstrip("\n")
        try:
            if path.startswith("voxelize "):
                voxelize(path[len("voxelize "):])
            else:
                read(path)
            answer = "ok"
        except DOCUMENTED as err:
            answer = f"refused {type(err).__name__}"
        except Exception as err:  # noqa: BLE001 - what the suite exists to find
            answer = f"bad {type(err).__name__}: {str(err)[:300]!r}"
        print(answer, flush=True)


if __name__ == "__main__":
    main()
