"""Expr -> Tape: the flat form every evaluator reads.

The pipeline in one line::

    Expr (DAG) -> Tape (deduplicated, folded, register-allocated) -> point | interval | gradient

A :class:`Tape` is a list of :class:`Instruction` rows ``out <- op(args...)``
over numbered registers, in an order where every argument is computed before
it is read. Building it

* **deduplicates**: structurally equal subexpressions get one register;
* **folds constants**: an operation on constants becomes a constant that
  keeps both its point value and an outward-rounded enclosure ``[lo, hi]``
  from the interval kernel, so ``sin(1.0)`` folded is still a sound interval;
* **drops exact identities**: ``a * 1``, ``a / 1`` and ``a - 0`` (which is
  ``a + (-0.0)``) are ``a`` bit for bit, so they take no instruction;
* **rewrites** ``a * a`` and ``a ** 2`` into ``square(a)`` (tighter intervals),
  and ``sqrt((a - c0)**2 + (b - c1)**2 + (w - c2)**2)`` (two or three terms,
  summed left to right as Python writes them) into one ``distance`` node: the
  same point values bit for bit, a tighter enclosure rounded once instead of
  after each of its ten steps;
* **allocates registers**: a register is reused once its last reader ran, so
  a long tape over a million boxes keeps few arrays alive.

None of the evaluators walks the expression; all of them read this.

Examples
--------
>>> from implicitvox import x, y, sin
>>> from implicitvox.eval.tape import build_tape
>>> tape = build_tape(sin(x) * sin(x) + y * 2.0)
>>> [ins.op.name for ins in tape.instructions]
['sin', 'square', 'mulc', 'add']
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import functools
import math

import numpy as np

from ..expr.nodes import Expr, VARIABLES
from .opcodes import OPCODES, Opcode
from .oracles import compile_oracle

__all__ = ["Tape", "Instruction", "Constant", "Value", "build_tape", "allocate", "compiled_oracle"]


@dataclass(frozen=True)
class Instruction:
    """``registers[out] <- op(registers[args[0]], ...; param)``."""

    op: Opcode
    out: int
    args: tuple[int, ...]
    param: Any


@dataclass(frozen=True)
class Constant:
    """A constant register: its point value and an enclosure of the exact value."""

    register: int
    value: float
    lo: float
    hi: float


@dataclass(frozen=True)
class Tape:
    """A flattened expression (see the module docstring)."""

    instructions: tuple[Instruction, ...]
    n_registers: int
    inputs: dict[str, int]
    constants: tuple[Constant, ...]
    output: int
    #: True when a constant subexpression is undefined (e.g. ``sqrt(-1)``):
    #: the function is then undefined (NaN) everywhere.
    undefined: bool = False

    def __len__(self) -> int:
        return len(self.instructions)

    @property
    def has_domain_ops(self) -> bool:
        return any(ins.op.domain for ins in self.instructions)

    @functools.cached_property
    def graph(self) -> tuple[tuple["Value", ...], int, tuple[bool, ...]]:
        """The tape as the graph :func:`allocate` takes: values (the constants,
        the inputs, then one per instruction, in order; arguments as indices),
        the root's index, and whether each value reads a domain operation."""
        values: list[Value] = []
        node_of: dict[int, int] = {}          # register -> value, as the tape runs
        for c in self.constants:
            node_of[c.register] = len(values)
            values.append(Value("const", const=(c.value, c.lo, c.hi)))
        for name, register in self.inputs.items():
            if register >= 0:
                node_of[register] = len(values)
                values.append(Value("var", param=name))
        domain = [False] * len(values)
        for ins in self.instructions:
            args = tuple(node_of[a] for a in ins.args)
            domain.append(ins.op.domain or any(domain[a] for a in args))
            node_of[ins.out] = len(values)
            values.append(Value("op", op=ins.op, args=args, param=ins.param))
        return tuple(values), node_of[self.output], tuple(domain)

    @functools.cached_property
    def branches(self) -> tuple[int, ...]:
        """Positions of the instructions with a choice (``min``, ``max``, ``abs``):
        the ones :mod:`implicitvox.eval.pruning` can settle over a box."""
        return tuple(i for i, ins in enumerate(self.instructions) if ins.op.choice)

    @functools.cached_property
    def choice_trees(self) -> tuple[int, ...]:
        """Per branch (in :attr:`branches` order): the instruction at the root of its
        *min tree* (``max`` tree), or -1. A min tree is a ``min`` whose arguments
        are ``min`` instructions read by nothing else, and theirs, and so on: the
        n-ary ``min`` of its leaves however it is bracketed (a chain ``min(min(a,
        b), c)`` from a union of many parts). Only trees of two or more
        instructions are named (:func:`implicitvox.eval.pruning.settle_in_tree`)."""
        values, root, _ = self.graph
        fixed = len(values) - len(self.instructions)
        uses = [0] * len(values)
        uses[root] += 1
        for value in values[fixed:]:
            for a in value.args:
                uses[a] += 1
        top = list(range(len(self.instructions)))        # instruction -> its tree's root
        member = [False] * len(self.instructions)
        for i in range(len(self.instructions) - 1, -1, -1):
            op = self.instructions[i].op.name
            if op not in ("min", "max"):
                continue
            for a in values[fixed + i].args:
                j = a - fixed
                if j >= 0 and uses[a] == 1 and self.instructions[j].op.name == op:
                    top[j], member[j], member[i] = top[i], True, True
        return tuple(top[i] if member[i] else -1 for i in self.branches)


@dataclass
class Value:
    """A node of the deduplicated graph a tape is allocated from (:func:`allocate`)."""

    kind: str                     # "var" | "const" | "op"
    op: Opcode | None = None
    args: tuple[int, ...] = ()
    param: Any = None
    const: tuple[float, float, float] | None = None  # value, lo, hi (lo > hi: undefined)


def _fold(op: Opcode, args: list[Value], param: Any) -> tuple[float, float, float]:
    """Point value and enclosure of ``op`` over constant arguments."""
    consts = [a.const for a in args]
    if any(c[1] > c[2] for c in consts):
        return (np.nan, np.inf, -np.inf)
    with np.errstate(all="ignore"):
        value = op.point(tuple(np.float64(c[0]) for c in consts), param)
        result = op.interval(tuple(np.array([c[1]]) for c in consts),
                             tuple(np.array([c[2]]) for c in consts), param)
    if op.domain:
        lo, hi, empty = result
        if empty[0]:
            return (np.nan, np.inf, -np.inf)
    else:
        lo, hi = result
    return (float(value), float(lo[0]), float(hi[0]))


def build_tape(expr: Expr) -> Tape:
    """Flatten ``expr`` into a :class:`Tape` (iterative; any depth)."""
    values: list[Value] = []
    index_of_key: dict[Any, int] = {}
    index_of_node: dict[int, int] = {}

    def intern(key: Any, value: Value) -> int:
        found = index_of_key.get(key)
        if found is not None:
            return found
        values.append(value)
        index_of_key[key] = len(values) - 1
        return len(values) - 1

    for node in expr.walk():
        if node.op == "var":
            idx = intern(("var", node.param), Value("var", param=node.param))
        elif node.op == "const":
            v = node.param
            idx = intern(("const", v.hex(), v.hex(), v.hex()), Value("const", const=(v, v, v)))
        else:
            if node.op not in OPCODES:
                raise ValueError(f"unknown opcode {node.op!r} in expression")
            op = OPCODES[node.op]
            args = tuple(index_of_node[id(a)] for a in node.args)
            param = compiled_oracle(op.name, node.param) if op.oracle else node.param
            if (op.name == "mul" and args[0] == args[1]) or (op.name == "powi" and param == 2):
                op, args, param = OPCODES["square"], args[:1], None
            op, args, param = _with_constant_operand(op, args, param, values)
            if _is_identity(op, param):
                index_of_node[id(node)] = args[0]
                continue
            op, args, param = _periodic_of_angle(op, args, param, values)
            op, args, param = _distance_of_squares(op, args, param, values, intern)
            if not op.oracle and all(values[a].kind == "const" for a in args):
                # (an oracle on constants stays an instruction: folding it would need the
                # evaluators, which read tapes)
                c = _fold(op, [values[a] for a in args], param)
                key = ("const",) + tuple(float(t).hex() for t in c)
                idx = intern(key, Value("const", const=c))
            else:
                idx = intern((op.name, _param_key(param), args),
                             Value("op", op=op, args=args, param=param))
        index_of_node[id(node)] = idx
    return allocate(values, index_of_node[id(expr)])


def _exact_constant(value: Value) -> float | None:
    if value.kind == "const" and value.const[1] == value.const[2] == value.const[0]:
        return value.const[0]
    return None


def _with_constant_operand(op: Opcode, args: tuple[int, ...], param: Any,
                           values: list[Value]) -> tuple[Opcode, tuple[int, ...], Any]:
    """``a + c``, ``a - c``, ``c - a``, ``a * c``, ``a / c`` with an exact constant
    ``c`` become the one-argument rows ``addc, rsubc, mulc, divc``."""
    if op.name not in ("add", "sub", "mul", "div"):
        return op, args, param
    ca, cb = (_exact_constant(values[a]) for a in args)
    if (ca is None) == (cb is None):
        return op, args, param
    if op.name in ("add", "mul"):
        name = "addc" if op.name == "add" else "mulc"
        return (OPCODES[name], args[1:], ca) if cb is None else (OPCODES[name], args[:1], cb)
    if op.name == "sub":
        return (OPCODES["rsubc"], args[1:], ca) if cb is None else \
            (OPCODES["addc"], args[:1], -cb)
    if cb is not None and cb != 0.0:
        return OPCODES["divc"], args[:1], cb
    return op, args, param


def _is_identity(op: Opcode, param: Any) -> bool:
    """Whether ``op(a; param)`` is ``a`` itself, bit for bit, for every float ``a``
    (infinities, NaN and the sign of zero included): ``a * 1``, ``a / 1`` and
    ``a + (-0.0)``. (``a + 0.0`` is not: it turns ``-0.0`` into ``0.0``.)"""
    if op.name in ("mulc", "divc"):
        return param == 1.0
    return op.name == "addc" and param == 0.0 and math.copysign(1.0, param) < 0


def _periodic_of_angle(op: Opcode, args: tuple[int, ...], param: Any,
                       values: list[Value]) -> tuple[Opcode, tuple[int, ...], Any]:
    """``sin``/``cos`` of ``k * atan2(v, u) + c`` (``k`` an integer) become one
    ``periodic_angle`` node, tight across the branch cut
    (:func:`implicitvox.interval.kernels.angle_interval`)."""
    if op.name not in ("sin", "cos"):
        return op, args, param
    node, k, c = values[args[0]], 1.0, 0.0
    if node.kind == "op" and node.op.name == "addc":
        c, node = node.param, values[node.args[0]]
    if node.kind == "op" and node.op.name == "mulc":
        k, node = node.param, values[node.args[0]]
    if node.kind != "op" or node.op.name != "atan2" or k != int(k) or not np.isfinite(c):
        return op, args, param
    return OPCODES["periodic_angle"], node.args, (op.name, float(k), float(c))


def _distance_of_squares(op: Opcode, args: tuple[int, ...], param: Any, values: list[Value],
                         intern) -> tuple[Opcode, tuple[int, ...], Any]:
    """``sqrt(t0 + t1)`` or ``sqrt((t0 + t1) + t2)``, each ``t`` a ``square(a)`` or
    ``square(a + k)``, becomes ``distance(a0, a1, a2; centre)`` (a missing third
    term is ``(0 - 0)**2``, which adds exactly nothing)."""
    if op.name != "sqrt":
        return op, args, param
    total = values[args[0]]
    if total.kind != "op" or total.op.name != "add":
        return op, args, param
    first = values[total.args[0]]
    if first.kind == "op" and first.op.name == "add" and _square_term(first.args[0], values) \
            and _square_term(first.args[1], values):
        terms = [first.args[0], first.args[1], total.args[1]]
    else:
        terms = list(total.args)
    found = [_square_term(t, values) for t in terms]
    if not all(found):
        return op, args, param
    if len(found) == 2:
        zero = intern(("const", 0.0.hex(), 0.0.hex(), 0.0.hex()),
                      Value("const", const=(0.0, 0.0, 0.0)))
        found.append((zero, 0.0))
    return (OPCODES["distance"], tuple(r for r, _ in found),
            tuple(float(c) for _, c in found))


def _square_term(index: int, values: list[Value]) -> tuple[int, float] | None:
    """``(a, c)`` when ``values[index]`` is ``square(a - c)`` (``c`` may be 0)."""
    term = values[index]
    if term.kind != "op" or term.op.name != "square":
        return None
    inner = term.args[0]
    shifted = values[inner]
    if shifted.kind == "op" and shifted.op.name == "addc":
        return shifted.args[0], -shifted.param
    return inner, 0.0


def _param_key(param: Any) -> Any:
    if hasattr(param, "key"):
        return param.key()
    if isinstance(param, tuple):
        return tuple(_param_key(p) for p in param)
    return param.hex() if isinstance(param, float) else param


def allocate(values: list[Value], root: int) -> Tape:
    """The tape of ``values[root]``: registers assigned in the order of ``values``
    (topological: arguments first), reused once their last reader has run;
    values the root does not depend on are left out."""
    live = _reachable(values, root)
    last_use: dict[int, int] = {}
    for i in live:
        for a in values[i].args:
            last_use[a] = i
    register: dict[int, int] = {}
    free: list[int] = []
    n_registers = 0
    inputs: dict[str, int] = {}
    constants: list[Constant] = []
    instructions: list[Instruction] = []
    undefined = False

    def new_register() -> int:
        nonlocal n_registers
        if free:
            return free.pop()
        n_registers += 1
        return n_registers - 1

    for i in live:
        v = values[i]
        if v.kind == "var":
            register[i] = n_registers
            n_registers += 1
            inputs[v.param] = register[i]
        elif v.kind == "const":
            register[i] = n_registers
            n_registers += 1
            value, lo, hi = v.const
            undefined |= lo > hi
            constants.append(Constant(register[i], value, lo, hi))
    for i in live:
        v = values[i]
        if v.kind != "op":
            continue
        args = tuple(register[a] for a in v.args)
        # free the op-argument registers whose last reader is this instruction
        for a in set(v.args):
            if last_use.get(a) == i and values[a].kind == "op" and a != root:
                free.append(register[a])
        register[i] = new_register()
        instructions.append(Instruction(v.op, register[i], args, v.param))
    for name in VARIABLES:
        inputs.setdefault(name, -1)
    return Tape(tuple(instructions), n_registers, inputs, tuple(constants),
                register[root], undefined)


def _reachable(values: list[Value], root: int) -> list[int]:
    """Indices of values the root depends on, in increasing (topological) order."""
    needed = {root}
    for i in range(root, -1, -1):
        if i in needed:
            needed.update(values[i].args)
    return sorted(needed)


@functools.lru_cache(maxsize=256)
def compiled_oracle(op: str, param: Any) -> Any:
    """The compiled sweep (:mod:`implicitvox.eval.oracles`) of a ``repeat`` or
    ``repeat_polar`` node's parameter, its child taped once (cached: the
    mpmath reference asks once per point)."""
    return compile_oracle(op, param, build_tape)
