"""Heavy optional modules, imported on first use (``import implicitvox`` stays light).

mpmath serves only the exact reference (tests); scipy only the mesh fill, the
hull constructions and the mesher's vertex splitting; neither is imported until a function touches it.

Examples
--------
>>> from implicitvox.lazy import mpmath
>>> float(mpmath.sqrt(4))
2.0
"""
from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any

__all__ = ["LazyModule", "mpmath"]


class LazyModule:
    """A stand-in for module ``name`` that imports it at the first attribute access."""

    __slots__ = ("_name", "_module")

    def __init__(self, name: str):
        self._name = name
        self._module: ModuleType | None = None

    def __getattr__(self, attr: str) -> Any:
        module = self._module
        if module is None:
            module = self._module = importlib.import_module(self._name)
        return getattr(module, attr)

    def __repr__(self) -> str:
        state = "loaded" if self._module is not None else "not loaded yet"
        return f"<lazy module {self._name!r} ({state})>"


#: :mod:`mpmath`, loaded on first use
mpmath = LazyModule("mpmath")
