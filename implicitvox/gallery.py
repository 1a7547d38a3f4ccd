"""The gallery: where its pictures go, its charts, and one command that renders it all.

The scripts in the source tree's ``gallery/*/plot_*.py`` import this module
(no ``sys.path`` edits): ``RESOLUTION`` (``$IMPLICITVOX_GALLERY_RES``, default 256),
``out(name)`` (a path in ``$IMPLICITVOX_GALLERY_OUT``, default ``gallery/images``)
and ``save_chart`` (line charts drawn off screen by PyVista). ::

    python -m implicitvox.gallery                  # every script, at 256
    python -m implicitvox.gallery 06-fields --resolution 64 --out /tmp/pictures

runs the scripts one after the other, each in its own process, and says which
failed.

Examples
--------
>>> import os
>>> os.path.basename(out("gear.png"))
'gear.png'
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Optional, Sequence

__all__ = ["RESOLUTION", "GALLERY", "out", "save_chart", "scripts", "main"]

#: the gallery folder of the source tree (the scripts are not installed with the package)
GALLERY = Path(__file__).resolve().parents[1] / "gallery"
#: the resolution the scripts voxelize at
RESOLUTION = int(os.environ.get("IMPLICITVOX_GALLERY_RES", "256"))


def out(name: str) -> str:
    """The path of picture ``name`` in the output folder (made if missing)."""
    folder = Path(os.environ.get("IMPLICITVOX_GALLERY_OUT", GALLERY / "images"))
    folder.mkdir(parents=True, exist_ok=True)
    return str(folder / name)


def save_chart(path: str, title: str, x_label: str, y_label: str, series: list,
               y_range: Optional[tuple] = None) -> str:
    """A line chart drawn off screen by PyVista (``pyvista.Chart2D``): ``series`` is a
    list of ``(x, y, label, colour, style)``; a solid style also marks the points."""
    import pyvista as pv
    pv.OFF_SCREEN = True
    chart = pv.Chart2D(x_label=x_label, y_label=y_label)
    for x, y, label, colour, style in series:
        chart.line(x, y, color=colour, width=3, style=style, label=label)
        if style == "-":
            chart.scatter(x, y, color=colour, size=7)
    chart.title = title
    if y_range is not None:
        chart.y_range = list(y_range)
    plotter = pv.Plotter(window_size=(1000, 640), off_screen=True)
    plotter.add_chart(chart)
    plotter.screenshot(path)
    plotter.close()
    return path


def scripts(folders: Sequence[str] = ()) -> list[Path]:
    """The gallery's scripts, in order; only those in ``folders`` when given."""
    if not GALLERY.is_dir():
        raise FileNotFoundError(f"no gallery at {GALLERY}: the scripts live in the source tree "
                                "(a git checkout, installed with pip install -e .)")
    found = sorted(GALLERY.glob("*/plot_*.py"))
    if folders:
        unknown = set(folders) - {p.parent.name for p in found}
        if unknown:
            raise ValueError(f"no gallery folder {sorted(unknown)}; the folders are "
                             f"{sorted({p.parent.name for p in found})}")
        found = [p for p in found if p.parent.name in folders]
    return found


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Render the gallery; returns 0, or 1 when a script failed (each is named)."""
    parser = argparse.ArgumentParser(prog="python -m implicitvox.gallery",
                                     description="render the gallery's pictures")
    parser.add_argument("folders", nargs="*", help="only these folders (e.g. 06-fields)")
    parser.add_argument("--resolution", type=int, help="voxels along the longest side")
    parser.add_argument("--out", help="write the pictures here (default gallery/images)")
    args = parser.parse_args(argv)
    env: dict[str, Any] = dict(os.environ)
    env.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    if args.resolution is not None:
        env["IMPLICITVOX_GALLERY_RES"] = str(args.resolution)
    if args.out is not None:
        env["IMPLICITVOX_GALLERY_OUT"] = args.out
    failed = []
    for script in scripts(args.folders):
        name = f"{script.parent.name}/{script.name}"
        print(f"{name} ...", flush=True)
        done = subprocess.run([sys.executable, str(script)], env=env, cwd=script.parent)
        if done.returncode:
            failed.append(name)
    if failed:
        print(f"failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
