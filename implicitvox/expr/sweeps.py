"""Replication sweeps (Stolte §3): one model, repeated along axes or about an axis.

``repeat(expr, spacing, count)`` places instance ``k`` (per axis) at
``k * spacing``; a point belongs to the instance whose cell
``[(k - 1/2) s, (k + 1/2) s]`` holds it (Stolte's replication factor
``i = int((z +- b/2) / b)``, eq. 1), clamped to ``0 .. count - 1`` when the
count is finite, so points past the ends see the end instances. The value is
``expr`` at the point's local coordinates ``p - k s``.

``repeat_polar(expr, n, axis)`` makes ``n`` copies about an axis: the point
is turned back by ``k * 2 pi / n``, ``k`` the sector of its azimuth.

Intervals visit only the instances whose cells meet the box (Stolte §3.2,
``i0 .. i1``), and at most two local pieces per axis: the first instance's
clipped sub-box, and the union of the others (the whole cell once the box
spans three instances). So a box costs at most ``2**axes`` evaluations of
``expr`` however many instances it spans - a million as cheaply as one.

Examples
--------
>>> import implicitvox as iv
>>> from implicitvox import x, y, z, hypot
>>> torus = (hypot(x, y) - 0.6) ** 2 + z ** 2 - 0.1 ** 2
>>> stack = iv.repeat(torus, spacing=(None, None, 0.5))       # endless along z
>>> f = iv.compile(stack)
>>> float(f(0.6, 0.0, 5.0)) < 0 < float(f(0.6, 0.0, 5.25))
True
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .. import validate
from .nodes import Expr, wrap, x, y, z

__all__ = ["repeat", "repeat_polar", "FRAMES"]

#: axis -> (u, v, w) coordinate order, w along the axis
FRAMES = {"z": (0, 1, 2), "x": (1, 2, 0), "y": (0, 2, 1)}


def _spacing_and_count(spacing: Any, count: Any) -> tuple[tuple, tuple]:
    try:
        sp = tuple(spacing)
    except TypeError:
        sp = (spacing,) * 3
    if len(sp) != 3:
        raise ValueError(f"spacing must be one number or three (None: no repetition), got {spacing!r}")
    out = []
    for a, s in zip("xyz", sp):
        if s is None:
            out.append(None)
            continue
        out.append(validate.positive_number(s, f"spacing on {a} (or None)"))
    if not isinstance(count, (tuple, list, np.ndarray)):
        counts = (count,) * 3
    else:
        counts = tuple(count)
        if len(counts) != 3:
            raise ValueError(f"count must be None, one int or three, got {count!r}")
    counts = tuple(None if n is None else validate.positive_int(n, f"count on {a} (or None)")
                   for a, n in zip("xyz", counts))
    if all(s is None for s in out):
        raise ValueError("spacing repeats along no axis")
    return tuple(out), counts


def repeat(expr: Any, spacing: Any, count: Any = None) -> Expr:
    """Repeat ``expr`` every ``spacing`` along the axes (Stolte §3).

    Parameters
    ----------
    expr : Expr
        The model, around the origin.
    spacing : float or (sx, sy, sz)
        Distance between instances per axis; ``None`` for no repetition.
    count : int or (nx, ny, nz), optional
        Instances per axis (``0 .. n - 1``); ``None`` for endless.
    """
    sp, counts = _spacing_and_count(spacing, count)
    return Expr("repeat", (x, y, z), (wrap(expr), sp, counts))


def repeat_polar(expr: Any, n: int, axis: str = "z") -> Expr:
    """``n`` copies of ``expr`` turned about ``axis`` by ``2 pi / n`` each
    (gear teeth, bolt circles); copy 0 is ``expr`` itself, centred on the
    first of the other two axes."""
    n = validate.positive_int(n, "n")
    axis = validate.choice(axis, "axis", tuple(FRAMES))
    return Expr("repeat_polar", (x, y, z), (wrap(expr), n, axis))
