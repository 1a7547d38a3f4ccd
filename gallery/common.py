"""Shared set-up for the gallery scripts: where pictures go, at what resolution."""
from __future__ import annotations

import os
from pathlib import Path

RESOLUTION = int(os.environ.get("IMPLICITVOX_GALLERY_RES", "256"))
OUT = Path(os.environ.get("IMPLICITVOX_GALLERY_OUT", Path(__file__).parent / "images"))
OUT.mkdir(parents=True, exist_ok=True)


def out(name: str) -> str:
    return str(OUT / name)


def save_chart(path: str, title: str, x_label: str, y_label: str, series: list,
               y_range: tuple = None) -> str:
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
