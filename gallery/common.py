"""Shared set-up for the gallery scripts: where pictures go, at what resolution."""
from __future__ import annotations

import os
from pathlib import Path

RESOLUTION = int(os.environ.get("IMPLICITVOX_GALLERY_RES", "256"))
OUT = Path(os.environ.get("IMPLICITVOX_GALLERY_OUT", Path(__file__).parent / "images"))
OUT.mkdir(parents=True, exist_ok=True)


def out(name: str) -> str:
    return str(OUT / name)
