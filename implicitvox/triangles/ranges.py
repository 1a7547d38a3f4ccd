"""Ragged ranges as flat arrays: the index arithmetic behind candidate pairs.

Every "each item has a variable number of partners" step (triangles over grid
cells, boxes over cells, points over a cell's triangles) expands per-item
counts into flat ``(owner, offset)`` arrays with no Python loop.

Examples
--------
>>> import numpy as np
>>> owner, offset = expand(np.array([2, 0, 3]))
>>> owner.tolist(), offset.tolist()
([0, 0, 2, 2, 2], [0, 1, 0, 1, 2])
>>> owner, cells = expand_boxes(np.array([[0, 5]]), np.array([[1, 6]]))
>>> cells.tolist()
[[0, 5], [0, 6], [1, 5], [1, 6]]
"""
from __future__ import annotations

import numpy as np

__all__ = ["expand", "expand_boxes", "gather", "buckets", "grid_cells", "ENTRIES_PER_ITEM"]

#: a bucket grid over ``n`` items holds at most about this many (cell, item) entries per
#: item (and at least 2**20 in all): long, thin items spanning many cells coarsen the grid
#: instead of filling memory
ENTRIES_PER_ITEM = 64


def expand(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``owner`` (item ``i`` repeated ``counts[i]`` times) and ``offset`` (0, 1, ... within it)."""
    counts = np.asarray(counts, dtype=np.int64)
    owner = np.repeat(np.arange(len(counts)), counts)
    offset = np.arange(len(owner)) - np.repeat(np.cumsum(counts) - counts, counts)
    return owner, offset


def expand_boxes(first: np.ndarray, last: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every integer cell of the boxes ``first[i] .. last[i]`` (inclusive, ``(n, d)``):
    ``owner`` and the cells ``(m, d)``, row-major within each box."""
    ext = last - first + 1
    owner, k = expand(np.prod(ext, axis=1))
    e = ext[owner]
    cols = []
    for a in range(first.shape[1] - 1, -1, -1):          # the last axis varies fastest
        cols.append(k % e[:, a])
        k = k // e[:, a]
    return owner, first[owner] + np.stack(cols[::-1], axis=1)


def grid_cells(lo: np.ndarray, hi: np.ndarray, span_lo: np.ndarray, span: np.ndarray,
               cells: int) -> int:
    """The cells per axis (at most ``cells``) of a uniform grid over ``span_lo + [0, span]``
    such that the items' boxes ``lo .. hi`` ``(n, d)`` cover at most
    ``max(ENTRIES_PER_ITEM * n, 2**20)`` cells in all: halved until they do.

    >>> import numpy as np
    >>> lo, hi = np.zeros((10, 2)), np.ones((10, 2))     # ten boxes over the whole span
    >>> grid_cells(lo, hi, np.zeros(2), np.ones(2), 1024)
    256
    """
    limit = max(ENTRIES_PER_ITEM * len(lo), 1 << 20)
    while cells > 1:
        size = span / cells
        first = np.clip(np.floor((lo - span_lo) / size), 0, cells - 1)
        last = np.clip(np.floor((hi - span_lo) / size), 0, cells - 1)
        if np.prod(last - first + 1, axis=1).sum() <= limit:
            break
        cells //= 2
    return max(int(cells), 1)


def gather(starts: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``owner`` and flat indices ``starts[i] .. starts[i] + counts[i] - 1``."""
    owner, offset = expand(counts)
    return owner, np.repeat(starts, counts) + offset


def buckets(keys: np.ndarray, items: np.ndarray, n_keys: int) -> tuple[np.ndarray, np.ndarray]:
    """Items grouped by key (a CSR layout): ``items`` sorted by key, and ``start`` with
    the items of key ``k`` at ``start[k] .. start[k + 1] - 1``."""
    order = np.argsort(keys, kind="stable")
    return items[order], np.searchsorted(keys[order], np.arange(n_keys + 1))
