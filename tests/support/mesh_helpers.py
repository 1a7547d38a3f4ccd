"""Helpers for mesh tests: surface samples, the test meshes, the exact oracle on voxel subsets."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tests.support.clip_oracle import triangle_meets_box

def _find_bunny() -> Path:
    """The Stanford bunny in the workspace's shared data (not redistributed with the
    repository): ``$IMPLICITVOX_BUNNY``, else ``../shared`` beside the checkout, else
    ``/work/shared``."""
    import os
    rel = Path("shared") / "data" / "meshes" / "stanford-bunny.obj"
    for cand in (os.environ.get("IMPLICITVOX_BUNNY"), Path(__file__).resolve().parents[3] / rel,
                 Path("/work") / rel):
        if cand and Path(cand).exists():
            return Path(cand)
    return Path(__file__).resolve().parents[3] / rel


#: the Stanford bunny (see :func:`_find_bunny`)
BUNNY = _find_bunny()


def sample_surface(tri: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` points on triangles ``(t, 3, 3)``, uniform by area."""
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    pick = rng.choice(len(tri), n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    flip = r1 + r2 > 1
    r1[flip], r2[flip] = 1 - r1[flip], 1 - r2[flip]
    t = tri[pick]
    return t[:, 0] + r1[:, None] * (t[:, 1] - t[:, 0]) + r2[:, None] * (t[:, 2] - t[:, 0])


def misses(vox, points: np.ndarray) -> int:
    """Points none of whose holding voxels is in ``vox``."""
    idx, below = vox.grid.voxels_holding(points)
    return int((~(vox.contains(idx) | vox.contains(below))).sum())


def voxel_box(grid, c):
    lo = np.array([grid.edge(a, c[a]) for a in range(3)])
    hi = np.array([grid.edge(a, c[a] + 1) for a in range(3)])
    return lo, hi


def oracle_meets(tri: np.ndarray, grid, coords: np.ndarray) -> np.ndarray:
    """Exact (rational clipping): does some triangle meet each voxel ``coords (n, 3)``?"""
    tlo, thi = tri.min(axis=1), tri.max(axis=1)
    out = np.zeros(len(coords), dtype=bool)
    for k, c in enumerate(coords):
        lo, hi = voxel_box(grid, c)
        cand = np.flatnonzero(np.all((tlo <= hi) & (thi >= lo), axis=1))
        out[k] = any(triangle_meets_box(tri[t], lo, hi) for t in cand)
    return out


def neighbours_outside(vox, rng: np.random.Generator, n: int) -> np.ndarray:
    """Up to ``n`` voxels next to output voxels (26-neighbourhood) that are not output."""
    c = vox.coords().astype(np.int64)
    pick = c[rng.choice(len(c), min(len(c), 4 * n), replace=False)]
    offsets = rng.integers(-1, 2, (len(pick), 3))
    cand = pick + offsets
    ok = np.all((cand >= 0) & (cand < np.asarray(vox.resolution)), axis=1)
    cand = np.unique(cand[ok], axis=0)
    cand = cand[~vox.contains(cand)]
    return cand[:n]
