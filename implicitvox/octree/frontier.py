"""The subdivision's frontier: octants waiting to be classified, by level and by tape.

The subdivision takes octants deepest level first, so the frontier holds at
most a few chunks per level whatever the resolution. With pruned tapes
(:mod:`implicitvox.eval.pruning`) a chunk's children split into groups with
different tapes; the frontier gathers the groups of one level that share a
tape (the same object: the pruner shares equal tapes) from every chunk, so
they are evaluated together in full-sized batches instead of one small batch
per group.

Examples
--------
>>> import numpy as np
>>> frontier = Frontier()
>>> tape_a, tape_b = ["tape A"], ["tape B"]      # (any objects: compared by identity)
>>> frontier.push(3, np.arange(5, dtype=np.uint64), tape_a, None)
>>> frontier.push(3, np.arange(5, 8, dtype=np.uint64), tape_a, None)
>>> frontier.push(2, np.arange(4, dtype=np.uint64), tape_b, None)
>>> level, codes, tape, leaf_tape = frontier.pop(6)
>>> level, codes.tolist(), tape
(3, [5, 6, 7, 0, 1, 2], ['tape A'])
>>> len(frontier), sorted(frontier.sizes())
(6, [(2, 4), (3, 2)])
"""
from __future__ import annotations

from typing import Any, Iterator, Optional

import numpy as np

__all__ = ["Frontier"]


class Frontier:
    """Pending octants (Morton codes) with the tape valid over them and the tape
    of their ancestor at the leaf level (or None)."""

    def __init__(self) -> None:
        # level -> {(id(tape), id(leaf_tape)): [tape, leaf_tape, [codes, ...], count]}
        self._levels: dict[int, dict[tuple[int, int], list]] = {}
        self._count = 0

    def __len__(self) -> int:
        """Octants pending."""
        return self._count

    def __bool__(self) -> bool:
        return self._count > 0

    def push(self, level: int, codes: np.ndarray, tape: Any, leaf_tape: Optional[Any]) -> None:
        """Add octants ``codes`` at ``level`` (tapes compared by identity)."""
        if not len(codes):
            return
        groups = self._levels.setdefault(level, {})
        entry = groups.setdefault((id(tape), id(leaf_tape)), [tape, leaf_tape, [], 0])
        entry[2].append(codes)
        entry[3] += len(codes)
        self._count += len(codes)

    def pop(self, limit: int) -> tuple[int, np.ndarray, Any, Optional[Any]]:
        """Up to ``limit`` octants of one tape at the deepest level (the group
        pushed last there)."""
        level = max(self._levels)
        groups = self._levels[level]
        key = next(reversed(groups))
        tape, leaf_tape, parts, count = groups[key]
        taken, size = [], 0
        while parts and size < limit:
            part = parts.pop()
            if size + len(part) > limit:
                part, back = part[:limit - size], part[limit - size:]
                parts.append(back)
            taken.append(part)
            size += len(part)
        groups[key][3] = count - size
        if not parts:
            del groups[key]
            if not groups:
                del self._levels[level]
        self._count -= size
        return level, taken[0] if len(taken) == 1 else np.concatenate(taken), tape, leaf_tape

    def sizes(self) -> Iterator[tuple[int, int]]:
        """``(level, octants)`` of every group pending."""
        for level, groups in self._levels.items():
            for entry in groups.values():
                yield level, entry[3]
