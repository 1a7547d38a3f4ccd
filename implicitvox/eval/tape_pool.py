"""Tapes pruned per box, in compiled code: a pool of tapes derived from one base tape.

libfive and Fidget shorten the tape for every box at every level of the
subdivision (Keeter, *Massively Parallel Rendering of Complex Closed-Form
Implicit Surfaces*, SIGGRAPH 2020, §3); :mod:`implicitvox.eval.pruning` explains
why the result is bit for bit that of the whole tape. This module does the
same in Numba, so that the compiled subdivision (:mod:`implicitvox.octree.descend`)
can give each box its own tape:

* the base tape is put in SSA form: one *value* per constant, input and
  instruction (``Tape.graph``), each with its axis mask (which of ``x, y, z``
  it depends on: bit 0, 1, 2) and whether it reads a domain operation;
* a pool tape is a run of *rows*, one per instruction kept: the operation,
  the output and argument registers (allocated per tape, reused after the last
  read, constants and inputs at fixed registers), the masks, and the SSA
  values of the output and the arguments (:data:`ROW`);
* :func:`prune` derives a child tape from a parent tape and the branch choices
  settled over a box: a settled ``min``/``max`` becomes its winner (an alias:
  no row), ``abs`` of a positive argument the argument and of a negative one
  ``neg``; the rows the root no longer reads are dropped and the registers
  allocated again. A choice whose loser reads a domain operation is ignored
  (its "undefined" verdict must not be lost, as in :func:`pruning.simplify`);
* a derivation seen before is looked up, not repeated (a hash table keyed by
  the parent and the settled choices, each hit checked against the stored
  key), and equal tapes are stored once (a second table keyed by the rows'
  content, each hit compared row by row): boxes in different places that keep
  the same parts share one tape.

The pool only grows: a full pool makes :func:`prune_tape` return the parent (a
valid, longer tape), and :meth:`TapePool.grow` makes room between calls.

Examples
--------
>>> import numpy as np
>>> from implicitvox import x, y, z, min
>>> from implicitvox.eval.tape import build_tape
>>> pool = TapePool(build_tape(min(x - 1.0, y * y)))
>>> [ins.op.name for ins in pool.tape(0).instructions]
['addc', 'square', 'min']
>>> choices = np.zeros(3, dtype=np.int8); choices[2] = 1      # min: the first wins
>>> child = pool.prune(0, choices)
>>> [ins.op.name for ins in pool.tape(child).instructions]
['addc']
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..interval.rules import COMPILE
from .compiled import ABS, MAX, MIN, NEG, encode
from .opcodes import OPCODES
from .pruning import FIRST, SECOND
from .tape import Tape, Value, allocate

__all__ = ["TapePool", "prune_tape", "TAPE", "START", "ROWS", "ROOT", "OUTPUT", "REGISTERS",
           "ROW", "OP", "OUT", "ARG_A", "ARG_B", "ARG_C", "MASK", "MASK_A",
           "MASK_B", "MASK_C", "VALUE", "VALUE_A", "VALUE_B", "VALUE_C", "AXIS_MASKS",
           "INITIAL_ROWS", "INITIAL_TAPES"]

#: the columns of a row (int32)
ROW = 13
(OP, OUT, ARG_A, ARG_B, ARG_C, MASK, MASK_A, MASK_B, MASK_C, VALUE, VALUE_A, VALUE_B,
 VALUE_C) = range(ROW)
#: the columns of a tape's entry (int64): first row, rows, output value, its
#: register, registers used
TAPE = 5
START, ROWS, ROOT, OUTPUT, REGISTERS = range(TAPE)
#: the columns of a derivation's entry (int64): hash (0: free), tape, parent, the
#: first of its key entries, their number
(D_HASH, D_TAPE, D_PARENT, D_KEY, D_KEYS) = range(5)
#: what ``used`` counts: rows, tapes, key entries, derivations, contents; and a
#: flag set when a derivation found no room
(USED_ROWS, USED_TAPES, USED_KEYS, USED_DERIVATIONS, USED_CONTENTS, FULL) = range(6)
#: the axis masks of the inputs x, y, z
AXIS_MASKS = {"x": 1, "y": 2, "z": 4}
#: a new pool's room: rows (besides the base tape's) and tapes (powers of 2)
INITIAL_ROWS = 1 << 12
INITIAL_TAPES = 1 << 8
_NEG_OP = OPCODES["neg"]


class TapePool:
    """The base tape of a function and the tapes pruned from it (see the module).

    Tape 0 is the base tape. Every tape of the pool shares the fixed registers:
    register ``k < fixed`` holds SSA value ``k`` (the constants, then the inputs).

    Parameters
    ----------
    tape : Tape
        The base tape (without sweeps: :func:`implicitvox.eval.compiled.encode`
        must take it).
    rows, tapes : int, optional
        Initial capacity; :meth:`grow` doubles it as the runs need. Small by default
        (:data:`INITIAL_ROWS`, :data:`INITIAL_TAPES`): where the kernel backs memory
        with huge pages, the first write into a zeroed page clears 2 MiB, and the hash
        tables' scattered probes into a roomy pool cleared some 100 MB per run (40 ms
        for a cube).
    """

    def __init__(self, tape: Tape, rows: int = INITIAL_ROWS, tapes: int = INITIAL_TAPES):
        if not tape.branches:           # nothing to prune: the base tape alone
            rows, tapes = len(tape), 1
        compiled = encode(tape)
        if compiled is None:
            raise ValueError("a tape with a sweep has no compiled form")
        self.base = tape
        values, root, domain = tape.graph
        fixed = len(values) - len(tape)
        self.fixed = fixed
        self.undefined = tape.undefined
        #: branch instructions (min, max, abs) of the base tape
        self.branches = len(tape.branches)
        # per SSA value: axis mask, domain flag, parameters
        masks = np.zeros(len(values), dtype=np.int32)
        for k, value in enumerate(values):
            if value.kind == "var":
                masks[k] = AXIS_MASKS[value.param]
            elif value.kind == "op":
                for a in value.args:
                    masks[k] |= masks[a]
        self.masks = masks
        self.domain = np.array(domain, dtype=np.bool_)
        self.params = np.zeros((len(values), 3))
        self.params[fixed:] = compiled.params
        self.constant_lo = np.zeros(fixed)
        self.constant_hi = np.zeros(fixed)
        self.constant_value = np.zeros(fixed)       # the constants' point values
        self.inputs = np.full(3, -1, dtype=np.int32)
        for k, value in enumerate(values[:fixed]):
            if value.kind == "const":
                self.constant_value[k], self.constant_lo[k], self.constant_hi[k] = value.const
            else:
                self.inputs["xyz".index(value.param)] = k
        self.is_constant = np.array([v.kind == "const" for v in values[:fixed]], dtype=np.bool_)
        self._values = values
        self.rows = np.zeros((max(rows, len(tape), 1), ROW), dtype=np.int32)
        self.tapes = np.zeros((tapes, TAPE), dtype=np.int64)
        self.derivations = np.zeros((4 * tapes, 5), dtype=np.int64)   # (powers of 2)
        self.contents = np.zeros((4 * tapes, 2), dtype=np.int64)
        self.keys = np.zeros(max(rows, 16), dtype=np.int32)
        self.used = np.zeros(6, dtype=np.int64)
        self.scratch = np.zeros((4, len(values)), dtype=np.int32)
        self.kept = np.zeros((max(len(tape), 1), ROW), dtype=np.int32)
        for i, value in enumerate(values[fixed:]):
            row = self.kept[i]
            row[OP], row[VALUE] = compiled.code[i, 0], fixed + i
            row[VALUE_A:VALUE_A + 3] = -1
            row[VALUE_A:VALUE_A + len(value.args)] = value.args
        _add_tape(self.kept, len(tape), root, self.masks, fixed, self.rows, self.tapes,
                  self.used, self.scratch)
        self._tapes: dict[int, Tape] = {}

    def __len__(self) -> int:
        """Tapes in the pool."""
        return int(self.used[USED_TAPES])

    @property
    def nbytes(self) -> int:
        """Bytes the pool uses: its rows, tapes and keys, and its hash tables once
        written (the arrays are zeroed pages, taken as they are written)."""
        used = self.used
        tables = (self.derivations.nbytes if used[USED_DERIVATIONS] else 0) \
            + (self.contents.nbytes if used[USED_CONTENTS] else 0)
        return int(used[USED_ROWS] * self.rows.itemsize * ROW
                   + used[USED_TAPES] * self.tapes.itemsize * TAPE
                   + used[USED_KEYS] * self.keys.itemsize
                   + tables + self.scratch.nbytes + self.kept.nbytes)

    @property
    def rows_used(self) -> int:
        """Rows the pool's tapes hold."""
        return int(self.used[USED_ROWS])

    @property
    def registers(self) -> int:
        """Registers a run of any of its tapes needs (the fixed ones included)."""
        used = int(self.tapes[:len(self), REGISTERS].max()) if len(self) else 0
        return max(used, self.fixed, 1)

    @property
    def ran_out(self) -> bool:
        """Whether a run since the last :meth:`grow` found no room for a tape (its
        octants kept their parents' tapes)."""
        return bool(self.used[FULL])

    def lengths(self, tapes: np.ndarray) -> np.ndarray:
        """Rows of the pool tapes ``tapes``."""
        return self.tapes[tapes, ROWS]

    def grow(self, tapes: int = 0, rows: int = 0) -> None:
        """Make room for at least ``tapes`` more tapes of ``rows`` rows in all (arrays
        doubled until they fit; the hash tables kept at most half full). Call
        between runs."""
        used = self.used
        self.rows = _grown(self.rows, used[USED_ROWS] + rows)
        self.tapes = _grown(self.tapes, used[USED_TAPES] + tapes)
        self.keys = _grown(self.keys, used[USED_KEYS] + rows)
        room = _doublings(len(self.derivations), 2 * (used[USED_DERIVATIONS] + tapes))
        if room > len(self.derivations):
            self.derivations = _rehashed(self.derivations, room)
        room = _doublings(len(self.contents), 2 * (used[USED_CONTENTS] + tapes))
        if room > len(self.contents):
            self.contents = _rehashed(self.contents, room)
        used[FULL] = 0

    def __getstate__(self) -> dict:
        """The pool without its spare room (what is pickled and copied): the rows,
        tapes and keys used, the hash tables rehashed into the least room that
        keeps them at most half full (:meth:`grow` makes room again)."""
        used = self.used
        state = dict(self.__dict__)
        state["rows"] = self.rows[:max(int(used[USED_ROWS]), 1)].copy()
        state["tapes"] = self.tapes[:max(int(used[USED_TAPES]), 1)].copy()
        state["keys"] = self.keys[:max(int(used[USED_KEYS]), 16)].copy()
        state["derivations"] = _rehashed(self.derivations, _table_room(used[USED_DERIVATIONS]))
        state["contents"] = _rehashed(self.contents, _table_room(used[USED_CONTENTS]))
        for name in ("used", "scratch", "kept"):
            state[name] = getattr(self, name).copy()
        state["_tapes"] = {}
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    def copy(self) -> "TapePool":
        """An independent pool with the same tapes, under the same indices (each
        thread of a parallel run derives into its own)."""
        twin = TapePool.__new__(TapePool)
        twin.__setstate__(self.__getstate__())
        return twin

    def arrays(self) -> tuple:
        """The arrays compiled code reads and writes, in :func:`prune_tape`'s order."""
        return (self.rows, self.tapes, self.derivations, self.contents, self.keys, self.used,
                self.masks, self.domain, self.fixed, self.scratch, self.kept)

    def prune(self, tape: int, choices: np.ndarray) -> int:
        """The tape derived from pool tape ``tape`` by ``choices`` (int8, one per row
        of it: UNDECIDED, FIRST or SECOND); ``tape`` itself when nothing is settled."""
        if len(choices) != self.tapes[tape, ROWS]:
            raise ValueError(f"choices must have one entry per row of tape {tape} "
                             f"({self.tapes[tape, ROWS]}), not {len(choices)}")
        self.grow(1, len(choices))
        settled = np.flatnonzero(choices)
        key = (settled * 4 + np.asarray(choices)[settled]).astype(np.int32)
        return int(prune_tape(np.int64(tape), key, np.int64(len(key)), *self.arrays()))

    def tape(self, index: int) -> Tape:
        """Pool tape ``index`` as a :class:`Tape` (built once)."""
        found = self._tapes.get(index)
        if found is not None:
            return found
        start, count = int(self.tapes[index, START]), int(self.tapes[index, ROWS])
        graph: list[Value] = list(self._values[:self.fixed])
        local = {k: k for k in range(self.fixed)}
        for row in self.rows[start:start + count]:
            original = self._values[row[VALUE]]
            args = tuple(local[int(a)] for a in row[VALUE_A:VALUE_A + len(original.args)]
                         if a >= 0)
            if row[OP] == NEG and original.op.name == "abs":
                graph.append(Value("op", op=_NEG_OP, args=args[:1]))
            else:
                graph.append(Value("op", op=original.op, args=args, param=original.param))
            local[int(row[VALUE])] = len(graph) - 1
        built = allocate(graph, local[int(self.tapes[index, ROOT])])
        if self.undefined:
            built = Tape(built.instructions, built.n_registers, built.inputs, built.constants,
                         built.output, True)
        self._tapes[index] = built
        return built


def _doublings(length: int, needed: int) -> int:
    """``length`` doubled until it holds ``needed`` (``length`` itself if it does)."""
    length = max(int(length), 1)
    while length < needed:
        length *= 2
    return length


def _grown(a: np.ndarray, needed: int) -> np.ndarray:
    """``a``, or a copy doubled (at once, as often as it takes) to hold ``needed`` rows."""
    length = _doublings(len(a), needed)
    if length == len(a):
        return a
    out = np.zeros((length,) + a.shape[1:], dtype=a.dtype)
    out[:len(a)] = a
    return out


def _table_room(entries: int) -> int:
    """The least power of 2 (at least 16) that holds ``entries`` at most half full."""
    return max(16, 1 << int(2 * int(entries)).bit_length())


@njit(**COMPILE)
def _rehashed(table, room):
    """A hash table (column 0: the hash, 0 free) in ``room`` rows (a power of 2 with
    room for every entry)."""
    bigger = np.zeros((room, table.shape[1]), dtype=np.int64)
    mask = bigger.shape[0] - 1
    for k in range(table.shape[0]):
        h = table[k, 0]
        if h != 0:
            slot = h & mask
            while bigger[slot, 0] != 0:
                slot = (slot + 1) & mask
            for col in range(table.shape[1]):
                bigger[slot, col] = table[k, col]
    return bigger


@njit(**COMPILE)
def _add_tape(kept, n, root, masks, fixed, rows, tapes, used, scratch):
    """Append the tape of rows ``kept[:n]`` (OP, VALUE and VALUE_A..C filled; in
    order, arguments first) with output value ``root``: registers allocated (fixed
    values at their own, the others from ``fixed`` up, reused after their last
    read, never by the row that reads them), masks filled. Returns its index, or
    -1 when the pool is full."""
    t = used[USED_TAPES]
    if used[USED_ROWS] + n > rows.shape[0] or t >= tapes.shape[0]:
        used[FULL] = 1
        return -1
    last = scratch[0]          # per value: the row of its last read
    register = scratch[1]
    free = scratch[2]          # a stack of free registers
    for r in range(n):
        for s in range(3):
            v = kept[r, VALUE_A + s]
            if v >= fixed:
                last[v] = r
    if root >= fixed:
        last[root] = n          # read after every row
    n_free = 0
    top = fixed
    start = used[USED_ROWS]
    for r in range(n):
        row = rows[start + r]
        row[OP] = kept[r, OP]
        row[VALUE] = kept[r, VALUE]
        row[MASK] = masks[kept[r, VALUE]]
        for s in range(3):
            v = kept[r, VALUE_A + s]
            row[VALUE_A + s] = v
            if v < 0:
                row[ARG_A + s] = 0          # (unread)
                row[MASK_A + s] = 0
            else:
                row[ARG_A + s] = v if v < fixed else register[v]
                row[MASK_A + s] = masks[v]
        # the output never takes an argument's register: an output lane may be
        # computed before another lane reads the argument's (axis masks)
        if n_free > 0:
            n_free -= 1
            out = free[n_free]
        else:
            out = top
            top += 1
        register[kept[r, VALUE]] = out
        row[OUT] = out
        # then free the registers this row reads last (an argument may be read twice)
        for s in range(3):
            v = kept[r, VALUE_A + s]
            if v >= fixed and last[v] == r:
                last[v] = -1                # freed once
                free[n_free] = register[v]
                n_free += 1
    tapes[t, START] = start
    tapes[t, ROWS] = n
    tapes[t, ROOT] = root
    tapes[t, OUTPUT] = root if root < fixed else register[root]
    tapes[t, REGISTERS] = top
    used[USED_ROWS] += n
    used[USED_TAPES] += 1
    return t


@njit(**COMPILE)
def _hash_key(parent, key, n_key):
    """FNV-1a of the parent and the settled choices; never 0 (a free slot)."""
    h = np.uint64(14695981039346656037) ^ np.uint64(parent)
    for k in range(n_key):
        h = (h ^ np.uint64(key[k] & 0xFFFFFFFF)) * np.uint64(1099511628211)
    return np.int64(h >> np.uint64(1)) | 1


@njit(**COMPILE)
def _hash_rows(kept, n, root):
    """FNV-1a of a tape's content: its rows' values, operations and arguments, and
    its output; never 0."""
    h = np.uint64(14695981039346656037) ^ np.uint64(root)
    for r in range(n):
        for col in (OP, VALUE, VALUE_A, VALUE_B, VALUE_C):
            h = (h ^ np.uint64(kept[r, col] & 0xFFFFFFFF)) * np.uint64(1099511628211)
    return np.int64(h >> np.uint64(1)) | 1


@njit(**COMPILE)
def _find_derivation(h, parent, key, n_key, derivations, keys):
    """``(slot, tape)``: the table slot of the derivation ``(parent, key)`` and its
    tape, or the free slot to fill and -1 (slot -1: the table is full)."""
    mask = derivations.shape[0] - 1
    slot = h & mask
    for _ in range(derivations.shape[0]):
        entry = derivations[slot]
        if entry[D_HASH] == 0:
            return slot, -1
        if entry[D_HASH] == h and entry[D_PARENT] == parent and entry[D_KEYS] == n_key:
            same = True
            for k in range(n_key):
                if keys[entry[D_KEY] + k] != key[k]:
                    same = False
                    break
            if same:
                return slot, entry[D_TAPE]
        slot = (slot + 1) & mask
    return -1, -1


@njit(**COMPILE)
def _find_content(h, kept, n, root, contents, rows, tapes):
    """``(slot, tape)`` for the tape of rows ``kept[:n]`` and output ``root``, as
    :func:`_find_derivation`."""
    mask = contents.shape[0] - 1
    slot = h & mask
    for _ in range(contents.shape[0]):
        if contents[slot, 0] == 0:
            return slot, -1
        if contents[slot, 0] == h:
            t = contents[slot, 1]
            if tapes[t, ROWS] == n and tapes[t, ROOT] == root:
                start = tapes[t, START]
                same = True
                for r in range(n):
                    for col in (OP, VALUE, VALUE_A, VALUE_B, VALUE_C):
                        if rows[start + r, col] != kept[r, col]:
                            same = False
                    if not same:
                        break
                if same:
                    return slot, t
        slot = (slot + 1) & mask
    return -1, -1


@njit(**COMPILE)
def prune_tape(tape, key, n_key, rows, tapes, derivations, contents, keys, used, masks, domain,
               fixed, scratch, kept):
    """The pool tape derived from ``tape`` by the settled choices ``key[:n_key]`` (each
    ``row * 4 + choice``, by increasing row; see the module): looked up, found by
    content, or built and added; ``tape`` itself when nothing is settled or the
    pool is full."""
    if n_key == 0:
        return tape
    h = _hash_key(tape, key, n_key)
    slot, found = _find_derivation(h, tape, key, n_key, derivations, keys)
    if found >= 0:
        return found
    if slot < 0 or 2 * (used[USED_DERIVATIONS] + 1) > derivations.shape[0] \
            or used[USED_KEYS] + n_key > keys.shape[0]:
        used[FULL] = 1                  # no room to remember it: the parent's tape
        return tape
    child = _derive(tape, key, n_key, rows, tapes, contents, used, masks, domain, fixed,
                    scratch, kept)
    if child < 0:
        return tape
    entry = derivations[slot]
    entry[D_HASH], entry[D_TAPE], entry[D_PARENT] = h, child, tape
    entry[D_KEY], entry[D_KEYS] = used[USED_KEYS], n_key
    for k in range(n_key):
        keys[used[USED_KEYS] + k] = key[k]
    used[USED_KEYS] += n_key
    used[USED_DERIVATIONS] += 1
    return child


@njit(**COMPILE)
def _derive(tape, key, n_key, rows, tapes, contents, used, masks, domain, fixed, scratch, kept):
    """The rows of ``tape`` pruned by ``key`` (see :func:`prune_tape`): the pool tape
    of that content, added if new (-1: no room)."""
    start = tapes[tape, START]
    n = tapes[tape, ROWS]
    # resolve: an alias per settled branch (SSA values)
    resolved = scratch[3]
    negate = scratch[2]
    for r in range(n):
        v = rows[start + r, VALUE]
        resolved[v] = v
        negate[r] = 0
    for k in range(n_key):
        r = key[k] >> 2
        c = key[k] & 3
        row = rows[start + r]
        v = row[VALUE]
        a, b = row[VALUE_A], row[VALUE_B]
        op = row[OP]
        if op == ABS:
            if c == FIRST:
                resolved[v] = a if a < fixed else resolved[a]
            else:
                negate[r] = 1
        elif op == MIN or op == MAX:
            if c == FIRST and not domain[b]:
                resolved[v] = a if a < fixed else resolved[a]
            elif c == SECOND and not domain[a]:
                resolved[v] = b if b < fixed else resolved[b]
    root = tapes[tape, ROOT]
    if root >= fixed:
        root = resolved[root]
    # liveness, backwards
    live = scratch[1]
    row_of = scratch[0]             # value -> its row in this tape
    for r in range(n):
        row_of[rows[start + r, VALUE]] = r
        live[r] = 0
    if root >= fixed:
        live[row_of[root]] = 1
    for r in range(n - 1, -1, -1):
        if live[r] == 0:
            continue
        row = rows[start + r]
        count = 1 if negate[r] else 3
        for s in range(count):
            a = row[VALUE_A + s]
            if a >= fixed:
                ra = resolved[a]
                if ra >= fixed:
                    live[row_of[ra]] = 1
    m = 0
    for r in range(n):
        if live[r] == 0:
            continue
        row = rows[start + r]
        v = row[VALUE]
        if resolved[v] != v:        # an alias: its winner is computed instead
            continue
        kept[m, VALUE] = v
        if negate[r]:
            kept[m, OP] = NEG
            a = row[VALUE_A]
            kept[m, VALUE_A] = a if a < fixed else resolved[a]
            kept[m, VALUE_B] = -1
            kept[m, VALUE_C] = -1
        else:
            kept[m, OP] = row[OP]
            for s in range(3):
                a = row[VALUE_A + s]
                kept[m, VALUE_A + s] = a if a < fixed else resolved[a]
        m += 1
    h = _hash_rows(kept, m, root)
    slot, found = _find_content(h, kept, m, root, contents, rows, tapes)
    if found >= 0:
        return found
    if slot < 0 or 2 * (used[USED_CONTENTS] + 1) > contents.shape[0]:
        used[FULL] = 1
        return -1
    child = _add_tape(kept, m, root, masks, fixed, rows, tapes, used, scratch)
    if child >= 0:
        contents[slot, 0], contents[slot, 1] = h, child
        used[USED_CONTENTS] += 1
    return child
