"""Every argument check, once (as pyvista's ``core/_validation``).

Each function checks one kind of value and returns it in canonical form, or
raises ``ValueError`` (``TypeError`` for a wrong kind of object) whose message
names the parameter and says what was expected and what came. Entry points
call these and nothing else for their checks, so the same mistake reads the
same everywhere.

Examples
--------
>>> from implicitvox import validate as v
>>> v.positive_int(3, "levels")
3
>>> v.positive_int(True, "levels")
Traceback (most recent call last):
...
ValueError: levels must be a positive int, got bool True
>>> v.number_in(0.5, "recheck", 0, 4)
0.5
>>> v.bounds(((0, 0, 0), (1, 2, 3)))
((0.0, 0.0, 0.0), (1.0, 2.0, 3.0))
"""
from __future__ import annotations

import math
import os
from typing import Any, Callable, Optional

import numpy as np

__all__ = ["integer", "positive_int", "int_in", "number", "positive_number", "number_in",
           "boolean", "choice", "bounds", "resolution", "voxel_size", "points",
           "writable_path", "max_memory", "workers", "executor", "progress", "MAX_WORKERS",
           "MIN_EXTENT"]

_INTS = (int, np.integer)
_NUMBERS = (int, float, np.integer, np.floating)


def _shown(value: Any) -> str:
    return f"{type(value).__name__} {value!r:.60}"


def _is_int(value: Any) -> bool:
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, _INTS)


def _is_real(value: Any) -> bool:
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, _NUMBERS) \
        and math.isfinite(value)


def integer(value: Any, name: str) -> int:
    """An int (numpy ints too, never a bool)."""
    if not _is_int(value):
        raise ValueError(f"{name} must be an int, got {_shown(value)}")
    return int(value)


def positive_int(value: Any, name: str) -> int:
    """An int of at least 1."""
    if not _is_int(value) or value < 1:
        raise ValueError(f"{name} must be a positive int, got {_shown(value)}")
    return int(value)


def int_in(value: Any, name: str, low: int, high: int) -> int:
    """An int in ``[low, high]``."""
    if not _is_int(value) or not low <= value <= high:
        raise ValueError(f"{name} must be an int from {low} to {high}, got {_shown(value)}")
    return int(value)


def number(value: Any, name: str) -> float:
    """A finite real number."""
    if not _is_real(value):
        raise ValueError(f"{name} must be a finite number, got {_shown(value)}")
    return float(value)


def positive_number(value: Any, name: str) -> float:
    """A finite number above 0."""
    if not _is_real(value) or not value > 0:
        raise ValueError(f"{name} must be a positive finite number, got {_shown(value)}")
    return float(value)


def number_in(value: Any, name: str, low: float, high: float, *,
              open_low: bool = False) -> float:
    """A number in ``[low, high]`` (``(low, high]`` with ``open_low``)."""
    ok = _is_real(value) and (low < value if open_low else low <= value) and value <= high
    if not ok:
        left = "(" if open_low else "["
        raise ValueError(f"{name} must be a number in {left}{low}, {high}], got {_shown(value)}")
    return float(value)


def boolean(value: Any, name: str) -> bool:
    """True or False (numpy bools too)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {_shown(value)}")
    return bool(value)


def choice(value: Any, name: str, options: tuple) -> Any:
    """One of ``options``."""
    if not isinstance(value, str) or value not in options:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, options))}, "
                         f"got {_shown(value)}")
    return value


def float_type(value: Any, name: str, options: tuple = ("float64", "float32")) -> str:
    """A float type's name among ``options``, given as a name or a numpy type."""
    try:
        shown = np.dtype(value).name if not isinstance(value, str) else value
    except TypeError:
        shown = None
    if shown not in options:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, options))}, "
                         f"got {_shown(value)}")
    return shown


#: the least extent bounds may have on an axis: voxels of 2**-21 of it are normal floats
MIN_EXTENT = float(np.finfo(np.float64).tiny) * 2.0 ** 21


def bounds(value: Any, name: str = "bounds") -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``((x0, y0, z0), (x1, y1, z1))``, finite, with positive extent on every axis."""
    try:
        b = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name} must be ((x0, y0, z0), (x1, y1, z1)), got "
                         f"{value!r:.80}") from None
    if b.shape != (2, 3):
        raise ValueError(f"{name} must be ((x0, y0, z0), (x1, y1, z1)), got shape {b.shape}")
    if not np.all(np.isfinite(b)):
        raise ValueError(f"{name} must be finite numbers, got {b.tolist()}")
    for a in range(3):
        if not b[1, a] > b[0, a]:
            raise ValueError(f"{name} have zero or negative extent on axis {'xyz'[a]}: "
                             f"{b[0, a]!r} .. {b[1, a]!r}")
        with np.errstate(over="ignore"):
            extent = float(b[1, a] - b[0, a])
        if not np.isfinite(extent):
            raise ValueError(f"{name} have an extent on axis {'xyz'[a]} beyond the largest "
                             f"float: {float(b[0, a])!r} .. {float(b[1, a])!r}")
        if extent < MIN_EXTENT:
            raise ValueError(f"{name} have an extent of {extent!r} on axis {'xyz'[a]}, below "
                             f"{MIN_EXTENT!r} (implicitvox.validate.MIN_EXTENT): its voxels "
                             "would be smaller than the smallest normal float")
    return tuple(b[0].tolist()), tuple(b[1].tolist())


def resolution(value: Any, limit: int, name: str = "resolution"
               ) -> int | tuple[int, int, int]:
    """Voxels along the longest side (an int), or per axis (3 ints), each in ``[1, limit]``."""
    if isinstance(value, (tuple, list, np.ndarray)):
        if len(value) != 3:
            raise ValueError(f"{name} must be an int or 3 ints, got {value!r:.60}")
        return tuple(int_in(v, f"{name}[{i}]", 1, limit) for i, v in enumerate(value))
    return int_in(value, name, 1, limit)


def voxel_size(value: Any, name: str = "voxel_size") -> float | tuple[float, float, float]:
    """A positive pitch, or 3 of them (per axis, asked for explicitly)."""
    if isinstance(value, (tuple, list, np.ndarray)):
        if len(value) != 3:
            raise ValueError(f"{name} must be a number or 3 numbers, got {value!r:.60}")
        return tuple(positive_number(v, f"{name}[{i}]") for i, v in enumerate(value))
    return positive_number(value, name)


def points(value: Any, name: str = "points", *, finite: bool = True) -> np.ndarray:
    """An ``(n, 3)`` (or one ``(3,)``) float64 array: finite coordinates, or with
    ``finite=False`` infinities allowed (box corners) but never NaN."""
    try:
        p = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name} must be a real array of shape (n, 3), got "
                         f"{type(value).__name__}") from None
    if p.ndim == 1 and p.shape[0] == 3:
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3) or (3,), got {p.shape}")
    bad = ~np.isfinite(p) if finite else np.isnan(p)
    if bad.any():
        i = int(np.argwhere(bad)[0][0])
        raise ValueError(f"{name} holds {'a non-finite value' if finite else 'NaN'} "
                         f"(row {i})")
    return p


def progress(value: Any, name: str = "progress") -> Optional[Callable[[float], Any]]:
    """None or a callable taking the fraction done (a float from 0 to 1)."""
    if value is None or callable(value):
        return value
    raise ValueError(f"{name} must be None or a callable taking the fraction done, "
                     f"got {_shown(value)}")


def writable_path(path: Any, name: str = "path") -> str:
    """A file path whose folder exists and may be written."""
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"{name} must be a file path, got {_shown(path)}")
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise ValueError(f"cannot write {name} {path!r}: folder {folder!r} does not exist")
    if not os.access(folder, os.W_OK):
        raise ValueError(f"cannot write {name} {path!r}: folder {folder!r} is not writable")
    return path


def max_memory(value: Any, name: str = "max_memory") -> Optional[int]:
    """``None`` (the default budget) or a positive whole number of bytes, at most 2**62."""
    if value is None:
        return None
    if not _is_real(value) or not 1 <= value <= 2 ** 62:
        raise ValueError(f"{name} must be a positive number of bytes (at most 2**62), "
                         f"got {_shown(value)}")
    return int(value)


#: the most worker processes a run may ask for (a bound before anything is started)
MAX_WORKERS = 1024


def workers(value: Any, name: str = "workers") -> Optional[int]:
    """None (all the cores this process may use) or an int from 1 to :data:`MAX_WORKERS`."""
    if value is None:
        return None
    return int_in(value, name, 1, MAX_WORKERS)


def executor(value: Any, name: str = "executor") -> Any:
    """None, a ``concurrent.futures.Executor`` (anything with ``submit``) or a
    ``dask.distributed.Client``."""
    if value is None or callable(getattr(value, "submit", None)):
        return value
    raise TypeError(f"{name} must be a concurrent.futures.Executor or a "
                    f"dask.distributed.Client, got {type(value).__name__}")
