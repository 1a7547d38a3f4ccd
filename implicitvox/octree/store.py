"""Stolte's pointer octree (§5.1), in arrays.

:class:`Octree` is the compact store the voxelizer returns. Level ``l``
(``0 <= l < depth``) holds one node per occupied octant, in Morton order:

* ``masks[l]`` - uint8, bit ``c`` set when child ``c`` (``x + 2y + 4z``)
  exists; at the last level (``depth - 1``) these are the 8-bit leaf masks
  whose bits are the voxels themselves;
* ``first[l]`` - uint32 (levels above the last), index in level ``l + 1`` of
  the node's first child: the children of a node are stored together, so a
  node's child pointers are ``first + rank`` of the set bit (Stolte's arrays
  of 8 pointers with the null ones squeezed out);
* ``payload`` - optional per-voxel arrays (normals), in Morton order.

A surface voxel costs about one leaf-mask bit-group plus its share of the
inner nodes: typically 0.5-2 bytes (at most 4 is the design bound; the
benchmarks print ``nbytes / count``).

:class:`PointerOctree` is Stolte's incremental ``store_in_octree`` (Fig. 9):
each new voxel ascends from the previous one to their common parent, then
descends creating nodes - cheap when voxels arrive in near-Morton order, as
the subdivision produces them. ``to_octree()`` converts it to the compact form;
:meth:`Octree.from_coords` is the bulk insert (sort by Morton code, build each
level from the one below with array operations).

Examples
--------
>>> import numpy as np
>>> t = Octree.from_coords(np.array([[0, 0, 0], [3, 1, 2], [1, 0, 0]]), depth=2)
>>> t.count, t.contains(np.array([[1, 0, 0], [2, 2, 2]])).tolist()
(3, [True, False])
>>> t.coords().tolist()
[[0, 0, 0], [1, 0, 0], [3, 1, 2]]
"""
from __future__ import annotations

import sys
from typing import Any, Iterator, Optional

import numpy as np

from . import morton

__all__ = ["Octree", "PointerOctree", "subtree_masks"]

_POPCOUNT = np.array([bin(v).count("1") for v in range(256)], dtype=np.uint8)
_BELOW = np.array([[bin(v & ((1 << c) - 1)).count("1") for c in range(8)] for v in range(256)],
                  dtype=np.uint8)  # set bits of mask v below slot c
_U = np.uint64
_SLOT_BIT = np.array([1 << c for c in range(8)], dtype=np.uint8)


def _low_byte(codes: np.ndarray) -> np.ndarray:
    """The lowest byte of each uint64 code, as a view where the layout allows."""
    if sys.byteorder == "little" and codes.flags.c_contiguous:
        return codes.view(np.uint8)[::8]
    return (codes & _U(255)).astype(np.uint8)


def subtree_masks(codes: np.ndarray, depth: int, level: int
                  ) -> tuple[list[np.ndarray], np.ndarray]:
    """The child masks of levels ``level`` to ``depth - 1`` (a list, shallowest
    first) of the voxels with sorted unique Morton codes ``codes`` at ``depth``,
    and the codes of their ancestors at ``level`` (sorted unique): each level
    from the one below with array operations."""
    masks: list[np.ndarray] = []
    level_codes = codes
    for _ in range(depth - 1, level - 1, -1):
        bits = _SLOT_BIT[_low_byte(level_codes) & 7]
        parents = level_codes >> _U(3)
        new_parent = np.empty(len(parents), dtype=bool)
        new_parent[:1] = True
        np.not_equal(parents[1:], parents[:-1], out=new_parent[1:])
        starts = np.flatnonzero(new_parent)
        del new_parent
        masks.append(np.bitwise_or.reduceat(bits, starts) if len(bits) else
                     np.zeros(0, dtype=np.uint8))
        level_codes = parents[starts]
    return masks[::-1], level_codes


def _running_counts(masks: list[np.ndarray]) -> list[np.ndarray]:
    """``first``: each node's index of its first child, the running count of the
    children of the nodes before it, for every level but the last."""
    first = []
    for m in masks[:-1]:
        counts = _POPCOUNT[m].astype(np.int64)
        first.append((np.cumsum(counts) - counts).astype(np.uint32))
    return first


class Octree:
    """Compact pointer octree of voxels (see the module docstring).

    Parameters
    ----------
    depth : int
        Levels below the root; voxel coordinates are below ``2**depth``.
    masks, first : list of ndarray
        The per-level arrays.
    payload : dict of str to ndarray, optional
        Per-voxel arrays in Morton order.
    """

    def __init__(self, depth: int, masks: list[np.ndarray], first: list[np.ndarray],
                 payload: Optional[dict[str, np.ndarray]] = None):
        self.depth = depth
        self.masks = masks
        self.first = first
        self.payload = payload or {}

    # -- construction ---------------------------------------------------------
    @classmethod
    def from_coords(cls, coords: np.ndarray, depth: int,
                    payload: Optional[dict[str, np.ndarray]] = None) -> "Octree":
        """Bulk insert: voxels ``coords`` (n, 3), duplicates merged.

        ``payload`` arrays are aligned with ``coords`` and reordered to Morton
        order (the first of duplicates is kept).
        """
        coords = np.asarray(coords)
        if coords.ndim != 2 or coords.shape[1] != 3:
            raise ValueError(f"coords must have shape (n, 3), got {coords.shape}")
        if len(coords) and (coords.min() < 0 or coords.max() >= (1 << depth)):
            raise ValueError(f"coords must lie in [0, {1 << depth}) for depth {depth}")
        return cls.from_codes(morton.encode(coords), depth, payload)

    @classmethod
    def from_codes(cls, codes: np.ndarray, depth: int,
                   payload: Optional[dict[str, np.ndarray]] = None, *,
                   presorted: bool = False) -> "Octree":
        """Bulk insert of voxels given by Morton codes (uint64; sorted here, in
        place, duplicates merged), as :meth:`from_coords`. ``presorted``: the
        codes are strictly increasing already (checked), so no sort is needed."""
        codes = np.asarray(codes, dtype=np.uint64)
        if len(codes) and int(codes.max()) >= 1 << (3 * depth):
            raise ValueError(f"codes must lie in [0, 8**{depth}) for depth {depth}")
        if presorted:
            if len(codes) > 1 and not bool(np.all(codes[1:] > codes[:-1])):
                raise ValueError("presorted codes must be strictly increasing")
            return cls._build(codes, depth, dict(payload or {}))
        order = None
        if payload:
            order = np.argsort(codes, kind="stable")
            codes = codes[order]
        else:
            codes.sort()                       # in place: no second 8-byte-per-voxel array
        repeated = codes[1:] == codes[:-1]
        keep = None
        if repeated.any():
            keep = np.ones(len(codes), dtype=bool)
            keep[1:] = ~repeated
            codes = codes[keep]
        del repeated
        out_payload = {}
        for k, v in (payload or {}).items():
            v = np.asarray(v)[order]
            out_payload[k] = v if keep is None else v[keep]
        return cls._build(codes, depth, out_payload)

    @classmethod
    def _build(cls, codes: np.ndarray, depth: int,
               payload: dict[str, np.ndarray]) -> "Octree":
        if depth == 0:  # one voxel: a root mask with bit 0
            masks = [np.array([1], dtype=np.uint8)] if len(codes) else []
            return cls(0, masks, [], payload)
        masks, _ = subtree_masks(codes, depth, 0)
        return cls(depth, masks, _running_counts(masks), payload)

    @classmethod
    def from_subtrees(cls, depth: int, level: int, parts: list[tuple[np.ndarray, list]],
                      payload: Optional[dict[str, np.ndarray]] = None) -> "Octree":
        """The octree of voxels found subtree by subtree (a parallel run's workers).

        ``parts`` are :func:`subtree_masks` ``(masks, ancestors)`` of disjoint
        runs of subtrees rooted at ``level``, in Morton order (each run's
        voxels all below the next run's): the levels from ``level`` down are
        the runs' masks end to end, the levels above are built from their
        ancestors. The same octree as :meth:`from_codes` on all the codes;
        ``payload`` is already in Morton order.

        Examples
        --------
        >>> import numpy as np
        >>> codes = np.array([1, 5, 9, 200, 300], dtype=np.uint64)
        >>> parts = [subtree_masks(codes[:3], 3, 1), subtree_masks(codes[3:], 3, 1)]
        >>> whole = Octree.from_codes(codes.copy(), 3)
        >>> joined = Octree.from_subtrees(3, 1, parts)
        >>> all(np.array_equal(a, b) for a, b in zip(whole.masks + whole.first,
        ...                                           joined.masks + joined.first))
        True
        """
        parts = [p for p in parts if len(p[1])]
        if not parts or depth == 0:
            codes = np.concatenate([p[1] for p in parts]) if parts else np.zeros(0, dtype=_U)
            return cls._build(codes, depth, dict(payload or {}))
        ancestors = np.concatenate([a for _, a in parts])
        top, _ = subtree_masks(ancestors, level, 0)
        below = [np.concatenate([m[i] for m, _ in parts]) for i in range(depth - level)]
        masks = top + below
        return cls(depth, masks, _running_counts(masks), dict(payload or {}))

    def validate(self) -> None:
        """Check that the arrays describe an octree, before anything trusts them.

        Raises
        ------
        ValueError
            Naming the broken rule: the depth, an array's type or length, a
            level's length against its parents' child bits, ``first`` against
            the counts, a payload's length against the voxels.
        """
        d = self.depth
        if isinstance(d, bool) or not isinstance(d, (int, np.integer)) \
                or not 0 <= d <= morton.MAX_BITS:
            raise ValueError(f"depth must be an int from 0 to {morton.MAX_BITS}, got {d!r:.40}")
        if not self.masks:
            if self.first:
                raise ValueError("an empty octree has no 'first' arrays")
            return
        if len(self.masks) != max(d, 1) or len(self.first) != max(d - 1, 0):
            raise ValueError(f"a depth-{d} octree has {max(d, 1)} mask and {max(d - 1, 0)} "
                             f"'first' arrays, got {len(self.masks)} and {len(self.first)}")
        for level, m in enumerate(self.masks):
            if not isinstance(m, np.ndarray) or m.dtype != np.uint8 or m.ndim != 1:
                raise ValueError(f"masks[{level}] must be a 1-D uint8 array")
            if not np.all(m):
                raise ValueError(f"masks[{level}] holds a node without children")
        if len(self.masks[0]) != 1:
            raise ValueError(f"masks[0] is the root: 1 node, got {len(self.masks[0])}")
        for level in range(len(self.masks) - 1):
            counts = _POPCOUNT[self.masks[level]].astype(np.int64)
            if int(counts.sum()) != len(self.masks[level + 1]):
                raise ValueError(f"masks[{level}] has {int(counts.sum())} children, but "
                                 f"masks[{level + 1}] holds {len(self.masks[level + 1])} nodes")
            f = self.first[level]
            if not isinstance(f, np.ndarray) or f.dtype != np.uint32 or f.shape != counts.shape \
                    or not np.array_equal(f, np.cumsum(counts) - counts):
                raise ValueError(f"first[{level}] must be the uint32 running count of "
                                 f"masks[{level}]'s children")
        n = self.count
        for name, v in self.payload.items():
            if not isinstance(v, np.ndarray) or len(v) != n:
                raise ValueError(f"payload {name!r} must have one row per voxel ({n}), got "
                                 f"{len(v) if hasattr(v, '__len__') else type(v).__name__}")

    # -- queries -------------------------------------------------------------------
    @property
    def count(self) -> int:
        """Number of voxels."""
        if not self.masks:
            return 0
        return int(_POPCOUNT[self.masks[-1]].sum(dtype=np.int64))

    def __len__(self) -> int:
        return self.count

    @property
    def nbytes(self) -> int:
        """Bytes of the tree arrays (without payload)."""
        return int(sum(m.nbytes for m in self.masks) + sum(f.nbytes for f in self.first))

    def codes(self) -> np.ndarray:
        """Morton codes of the voxels, ascending."""
        if not self.masks:
            return np.zeros(0, dtype=_U)
        codes = np.zeros(1, dtype=_U)
        for mask in self.masks:
            bits = np.unpackbits(mask[:, None], axis=1, bitorder="little").astype(bool)
            node, slot = np.nonzero(bits)
            codes = (codes[node] << _U(3)) | slot.astype(_U)
        return codes

    def coords(self) -> np.ndarray:
        """Voxel coordinates (n, 3) in Morton order."""
        return morton.decode(self.codes())

    def __iter__(self) -> Iterator[tuple[int, int, int]]:
        """Voxels ``(i, j, k)`` in Morton order."""
        for row in self.coords():
            yield tuple(int(v) for v in row)

    def contains(self, coords: np.ndarray) -> np.ndarray:
        """Whether each voxel of ``coords`` (n, 3) is stored (vectorized descent)."""
        coords = np.asarray(coords, dtype=np.int64)
        n = len(coords)
        found = np.zeros(n, dtype=bool)
        if not self.masks or n == 0:
            return found
        inside = np.all((coords >= 0) & (coords < (1 << self.depth)), axis=1)
        idx = np.flatnonzero(inside)
        codes = morton.encode(coords[idx])
        node = np.zeros(len(idx), dtype=np.int64)
        for level in range(self.depth):
            slot = ((codes >> _U(3 * (self.depth - 1 - level))) & _U(7)).astype(np.int64)
            mask = self.masks[level][node]
            present = (mask >> slot) & 1 == 1
            idx, codes, node, slot, mask = (idx[present], codes[present], node[present],
                                            slot[present], mask[present])
            if level < self.depth - 1:
                node = self.first[level][node].astype(np.int64) + _BELOW[mask, slot]
        found[idx] = True
        return found

    def __repr__(self) -> str:
        return f"<Octree depth={self.depth} voxels={self.count} nbytes={self.nbytes}>"


class PointerOctree:
    """Stolte's incremental octree (§5.1, Fig. 9).

    Nodes are rows of 8 child pointers in a growing array (Stolte's blocks of
    cells); ``-1`` is a null pointer. The path to the previously stored voxel
    is kept, so storing a voxel ascends only to the common parent (``mask2``
    in Fig. 9) and descends from there, creating missing nodes.

    Examples
    --------
    >>> t = PointerOctree(depth=3)
    >>> for v in [(0, 0, 0), (1, 0, 0), (7, 7, 7)]:
    ...     t.store(*v)
    >>> t.to_octree().coords().tolist()
    [[0, 0, 0], [1, 0, 0], [7, 7, 7]]
    """

    def __init__(self, depth: int, block: int = 4096):
        self.depth = depth
        self._block = block
        self._nodes = np.full((block, 8), -1, dtype=np.int64)
        self._used = 1                      # node 0 is the root
        self._values: list[Any] = []        # leaf slots point here
        self._path = [0]                    # node at each level of the previous voxel
        self._previous: Optional[tuple[int, int, int]] = None

    def _alloc(self) -> int:
        if self._used == len(self._nodes):  # a new block of cells
            grown = np.full((len(self._nodes) + self._block, 8), -1, dtype=np.int64)
            grown[:len(self._nodes)] = self._nodes
            self._nodes = grown
        self._used += 1
        return self._used - 1

    def store(self, i: int, j: int, k: int, payload: Any = None) -> None:
        """Store voxel ``(i, j, k)`` with an optional payload (Fig. 9)."""
        if not all(0 <= v < (1 << self.depth) for v in (i, j, k)):
            raise ValueError(f"voxel {(i, j, k)} outside [0, {1 << self.depth})^3")
        self._values.append(payload)
        if self.depth == 0:
            self._nodes[0, 0] = len(self._values) - 1
            return
        # Ascend: keep the levels where the new voxel shares the previous one's octant.
        level = 0
        if self._previous is not None:
            pi, pj, pk = self._previous
            while level < self.depth - 1:
                shift = self.depth - 1 - level
                if (i >> shift, j >> shift, k >> shift) != (pi >> shift, pj >> shift, pk >> shift):
                    break
                level += 1
        del self._path[level + 1:]
        node = self._path[level]
        # Descend, creating nodes, until the leaf level.
        while True:
            shift = self.depth - 1 - level
            slot = ((i >> shift) & 1) | (((j >> shift) & 1) << 1) | (((k >> shift) & 1) << 2)
            if level == self.depth - 1:
                self._nodes[node, slot] = len(self._values) - 1  # the voxel's payload
                break
            child = self._nodes[node, slot]
            if child < 0:
                child = self._alloc()
                self._nodes[node, slot] = child
            node = int(child)
            self._path.append(node)
            level += 1
        self._previous = (i, j, k)

    def to_octree(self) -> Octree:
        """The compact :class:`Octree` read off the pointers, level by level.

        Payloads (if every stored voxel had one) become ``payload["value"]``.
        """
        weights = (1 << np.arange(8)).astype(np.int64)
        level_nodes = np.zeros(1, dtype=np.int64)
        masks: list[np.ndarray] = []
        first: list[np.ndarray] = []
        leaves = np.zeros(0, dtype=np.int64)
        for level in range(max(self.depth, 1)):
            rows = self._nodes[level_nodes]
            if self.depth == 0:
                rows = rows[:, :1]
            present = rows >= 0
            masks.append((present * weights[:rows.shape[1]]).sum(axis=1).astype(np.uint8))
            children = rows[present]           # node order, then slot order: Morton order
            if level < self.depth - 1:
                counts = present.sum(axis=1)
                first.append((np.cumsum(counts) - counts).astype(np.uint32))
                level_nodes = children
            else:
                leaves = children
        if not masks[0].any():
            masks = []
        payload = {}
        if self._values and all(v is not None for v in self._values):
            payload = {"value": np.array(self._values)[leaves]}
        return Octree(self.depth, masks, first, payload)

    @property
    def node_count(self) -> int:
        """Nodes created so far (root included)."""
        return self._used
