"""The interior of a closed mesh, from its surface voxels.

Voxels the surface does not meet fall into 6-connected components
(:func:`scipy.ndimage.label`); two face-neighbours that both miss the surface
are on the same side of it, so each component is wholly inside or wholly
outside a closed mesh. The generalized winding number
(:mod:`implicitvox.triangles.winding`) at a few voxel centres of each component says
which: inside iff it exceeds 1/2. Only a handful of points per component are
evaluated, never one per voxel.

Open meshes (the Stanford bunny keeps the scan's holes in its base): where
the holes are narrower than a voxel the surface voxels seal them and the
interior is found as for a closed mesh; where a hole is wider, the inside
and outside are one component and the winding numbers sampled in it
disagree. Such a component is filled by the majority of its samples and a
:class:`UserWarning` says the mesh is not closed at this resolution.

The interior is returned as the largest aligned octants it fills (per
octree level), the form :class:`~implicitvox.octree.voxels.Voxels` stores.
"""
from __future__ import annotations

import warnings

import numpy as np
from ..lazy import LazyModule
from ..octree import morton
from ..octree.grid import Grid
from .winding import winding_numbers

__all__ = ["interior_octants", "octants_from_dense", "BYTES_PER_VOXEL"]

ndimage = LazyModule("scipy.ndimage")

#: dense working memory of the fill, per grid voxel (mask, labels, interior)
BYTES_PER_VOXEL = 7

_EXTRA_SAMPLES = 7          # extra winding-number samples in each large component
_LARGE = 1000               # voxels that make a component large
_MAX_CHECKED = 16           # large components sampled more than once


def interior_octants(grid: Grid, surface_codes: np.ndarray, triangles: np.ndarray,
                     seed: int = 0) -> dict[int, np.ndarray]:
    """FULL octants per level of the solid bounded by ``triangles`` (t, 3, 3)."""
    surface = np.zeros(grid.shape, dtype=bool)
    c = morton.decode(surface_codes)
    surface[c[:, 0], c[:, 1], c[:, 2]] = True
    labels, count = ndimage.label(~surface)
    del surface
    if count == 0:
        return {}
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    slices = ndimage.find_objects(labels)
    rng = np.random.default_rng(seed)
    large = set(np.argsort(sizes[1:])[::-1][:_MAX_CHECKED] + 1)
    owner, samples = [], []
    for lab, sl in enumerate(slices, start=1):
        where = np.flatnonzero(labels[sl] == lab)
        local_shape = tuple(s.stop - s.start for s in sl)
        pick = where[:1]
        if lab in large and sizes[lab] > _LARGE:
            pick = np.concatenate([pick, rng.choice(where, _EXTRA_SAMPLES, replace=False)])
        idx = np.stack(np.unravel_index(pick, local_shape), axis=1) + [s.start for s in sl]
        samples.append(idx)
        owner.append(np.full(len(idx), lab))
    samples_a, owner_a = np.concatenate(samples), np.concatenate(owner)
    w = winding_numbers(grid.centers(samples_a), triangles)
    votes_in = np.bincount(owner_a, weights=(w > 0.5), minlength=count + 1)
    votes = np.bincount(owner_a, minlength=count + 1)
    inside = votes_in * 2 > votes
    mixed = np.flatnonzero((votes_in > 0) & (votes_in < votes))
    if len(mixed):
        warnings.warn(f"the mesh is not closed at this resolution: {len(mixed)} region(s) of "
                      "voxels are partly inside and partly outside it by their winding "
                      "numbers; each was filled by the majority", UserWarning, stacklevel=3)
    inside[0] = False                      # label 0: the surface voxels themselves
    return octants_from_dense(inside[labels], grid.depth)


def octants_from_dense(mask: np.ndarray, depth: int) -> dict[int, np.ndarray]:
    """The largest aligned octants (per level, coordinates at that level) filled by ``mask``.

    Level ``depth`` is the voxel level; an octant at level ``L`` spans
    ``2**(depth - L)`` voxels per axis. Octants reaching past the mask's edge
    count as filled only if the part inside is (past it, nothing is stored).

    Examples
    --------
    >>> m = np.zeros((4, 4, 4), dtype=bool); m[:2, :2, :2] = True; m[3, 3, 3] = True
    >>> {k: v.tolist() for k, v in octants_from_dense(m, 2).items()}
    {1: [[0, 0, 0]], 2: [[3, 3, 3]]}
    """
    levels = [mask]
    for _ in range(depth):
        m = levels[-1]
        pad = [(0, s % 2) for s in m.shape]
        if any(p[1] for p in pad):
            # cells past the grid are "filled" so border octants can merge
            m = np.pad(m, pad, constant_values=True)
        s = m.shape
        levels.append(m.reshape(s[0] // 2, 2, s[1] // 2, 2, s[2] // 2, 2).all(axis=(1, 3, 5)))
    out: dict[int, np.ndarray] = {}
    for up in range(depth, -1, -1):       # up = levels above the voxels
        full = levels[up]
        if up < depth:
            parent = levels[up + 1]
            full = full & ~parent.repeat(2, 0).repeat(2, 1).repeat(2, 2)[
                :full.shape[0], :full.shape[1], :full.shape[2]]
        coords = np.argwhere(full)
        if len(coords):
            out[depth - up] = coords.astype(np.int32)
    return dict(sorted(out.items()))
