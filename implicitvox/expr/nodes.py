"""Expressions: the immutable DAG users write models in.

An :class:`Expr` is a node with an opcode name, a tuple of child expressions
and an optional parameter (the variable name, the constant's value, an integer
or real exponent, ...). Nodes are immutable and hashable; the hash is
structural and cached, so equal subexpressions are recognised in O(1) and the
tape computes them once. Python numbers and numpy scalars become constants in
one place, :func:`wrap`.

A solid is the set ``f(x, y, z) <= 0``; its surface is ``f = 0``.

Examples
--------
>>> from implicitvox import x, y, z, sqrt
>>> f = sqrt(x**2 + y**2 + z**2) - 1
>>> f
sqrt(x ** 2 + y ** 2 + z ** 2) - 1.0
>>> f.equals(sqrt(x**2 + y**2 + z**2) - 1.0)
True
>>> f < 0
Traceback (most recent call last):
...
TypeError: cannot compare an expression with '<': a solid is written as one function f with f <= 0 inside; write f itself (e.g. `a - b`), and use min/max for unions and intersections
"""
from __future__ import annotations

import math
import numbers
from typing import Any, Iterator, Mapping, Optional

import numpy as np

__all__ = ["Expr", "wrap", "constant", "x", "y", "z", "VARIABLES", "source_preview"]

VARIABLES = ("x", "y", "z")

# Precedence for printing; higher binds tighter.
_PREC_ADD, _PREC_MUL, _PREC_NEG, _PREC_POW, _PREC_ATOM = 1, 2, 3, 4, 5
_INFIX = {"add": (" + ", _PREC_ADD), "sub": (" - ", _PREC_ADD),
          "mul": (" * ", _PREC_MUL), "div": (" / ", _PREC_MUL)}
_REPR_LIMIT = 20_000  # characters; larger DAGs print as a summary


def _param_key(param: Any) -> Any:
    """Hashable key of a node parameter that tells 0.0 from -0.0."""
    if isinstance(param, float):
        return ("f", param.hex())
    if isinstance(param, tuple):
        return tuple(_param_key(p) for p in param)
    return param


class Expr:
    """An immutable expression node.

    Build expressions from :data:`x`, :data:`y`, :data:`z`, numbers, the
    operators ``+ - * / **`` and the functions in :mod:`implicitvox.expr.functions`;
    do not call the constructor directly.

    Parameters
    ----------
    op : str
        Opcode name (a row of :mod:`implicitvox.eval.opcodes`).
    args : tuple of Expr
        Child expressions.
    param : object, optional
        Opcode parameter (constant value, variable name, exponent).
    """

    __slots__ = ("op", "args", "param", "_key", "_hash")
    __array_ufunc__ = None  # numpy scalars defer to our reflected operators

    op: str
    args: tuple["Expr", ...]
    param: Any

    def __init__(self, op: str, args: tuple["Expr", ...] = (), param: Any = None):
        key = (op, _param_key(param))
        object.__setattr__(self, "op", op)
        object.__setattr__(self, "args", tuple(args))
        object.__setattr__(self, "param", param)
        object.__setattr__(self, "_key", key)
        object.__setattr__(self, "_hash", hash((key, tuple(a._hash for a in args))))

    # -- immutability, hashing, equality ---------------------------------
    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("expressions are immutable")

    def __delattr__(self, name: str) -> None:
        raise AttributeError("expressions are immutable")

    def __hash__(self) -> int:
        return self._hash

    def equals(self, other: Any) -> bool:
        """Return True if ``other`` is an expression with the same structure.

        Constants compare by bit pattern (``0.0`` and ``-0.0`` differ).
        Iterative, so arbitrarily deep expressions compare without recursion.
        """
        if self is other:
            return True
        if not isinstance(other, Expr):
            return False
        stack = [(self, other)]
        seen: set[tuple[int, int]] = set()
        while stack:
            a, b = stack.pop()
            if a is b:
                continue
            if a._hash != b._hash or a._key != b._key or len(a.args) != len(b.args):
                return False
            pair = (id(a), id(b))
            if pair not in seen:
                seen.add(pair)
                stack.extend(zip(a.args, b.args))
        return True

    def __eq__(self, other: Any) -> bool:  # type: ignore[override]
        return self.equals(other)

    def __ne__(self, other: Any) -> bool:  # type: ignore[override]
        return not self.equals(other)

    def _compare(self, symbol: str) -> None:
        raise TypeError(
            f"cannot compare an expression with '{symbol}': a solid is written as one "
            "function f with f <= 0 inside; write f itself (e.g. `a - b`), and use "
            "min/max for unions and intersections")

    def __lt__(self, other: Any) -> bool:
        self._compare("<")

    def __le__(self, other: Any) -> bool:
        self._compare("<=")

    def __gt__(self, other: Any) -> bool:
        self._compare(">")

    def __ge__(self, other: Any) -> bool:
        self._compare(">=")

    def __bool__(self) -> bool:
        raise TypeError(
            "the truth value of an expression is undefined (it is a function of x, y, z): "
            "evaluate it with implicitvox.compile(expr)(X, Y, Z), and write conditions "
            "with implicitvox.min/max/clip instead of if/and/or or Python's min/max")

    # -- arithmetic -------------------------------------------------------
    def __add__(self, other: Any) -> "Expr":
        return Expr("add", (self, wrap(other)))

    def __radd__(self, other: Any) -> "Expr":
        return Expr("add", (wrap(other), self))

    def __sub__(self, other: Any) -> "Expr":
        return Expr("sub", (self, wrap(other)))

    def __rsub__(self, other: Any) -> "Expr":
        return Expr("sub", (wrap(other), self))

    def __mul__(self, other: Any) -> "Expr":
        return Expr("mul", (self, wrap(other)))

    def __rmul__(self, other: Any) -> "Expr":
        return Expr("mul", (wrap(other), self))

    def __truediv__(self, other: Any) -> "Expr":
        return Expr("div", (self, wrap(other)))

    def __rtruediv__(self, other: Any) -> "Expr":
        return Expr("div", (wrap(other), self))

    def __neg__(self) -> "Expr":
        return Expr("neg", (self,))

    def __pos__(self) -> "Expr":
        return self

    def __abs__(self) -> "Expr":
        return Expr("abs", (self,))

    def __pow__(self, exponent: Any) -> "Expr":
        return power(self, exponent)

    def __rpow__(self, base: Any) -> "Expr":
        return power(wrap(base), self)

    # -- structure --------------------------------------------------------
    @property
    def is_constant(self) -> bool:
        """True for a constant node."""
        return self.op == "const"

    def walk(self) -> Iterator["Expr"]:
        """Yield every distinct node once, children before parents (iterative)."""
        seen: set[int] = set()
        stack: list[tuple[Expr, bool]] = [(self, False)]
        while stack:
            node, expanded = stack.pop()
            if id(node) in seen:
                continue
            if expanded:
                seen.add(id(node))
                yield node
            else:
                stack.append((node, True))
                stack.extend((a, False) for a in reversed(node.args) if id(a) not in seen)

    def remap(self, x: Any = None, y: Any = None, z: Any = None) -> "Expr":
        """Return the expression with ``x``, ``y``, ``z`` replaced.

        Unnamed variables stay as they are. Shared subexpressions stay shared.

        Examples
        --------
        >>> from implicitvox import x, y, z
        >>> (x * x + y).remap(x=x - 1)
        (x - 1.0) * (x - 1.0) + y
        """
        mapping = {name: wrap(v) for name, v in zip(VARIABLES, (x, y, z)) if v is not None}
        return substitute(self, mapping)

    def __repr__(self) -> str:
        return _to_source(self)

    def __reduce__(self) -> tuple:
        # flat, children first (:meth:`walk`): pickle's own recursion would overflow on a
        # chain thousands deep (the union of thousands of parts); shared nodes stay shared
        nodes: list[tuple] = []
        index: dict[int, int] = {}
        for node in self.walk():
            index[id(node)] = len(nodes)
            nodes.append((node.op, tuple(index[id(a)] for a in node.args), node.param))
        return (_from_nodes, (tuple(nodes),))


def _from_nodes(nodes: tuple) -> Expr:
    """The expression :meth:`Expr.__reduce__` flattened: ``(op, argument indices,
    param)`` per node, children first, the root last."""
    built: list[Expr] = []
    for op, args, param in nodes:
        built.append(Expr(op, tuple(built[i] for i in args), param))
    return built[-1]


def substitute(expr: Expr, mapping: Mapping[str, Expr]) -> Expr:
    """Replace variables by expressions (``mapping``: name -> Expr), iteratively."""
    done: dict[int, Expr] = {}
    for node in expr.walk():
        if node.op == "var":
            done[id(node)] = mapping.get(node.param, node)
        elif node.args:
            new_args = tuple(done[id(a)] for a in node.args)
            same = all(n is o for n, o in zip(new_args, node.args))
            done[id(node)] = node if same else Expr(node.op, new_args, node.param)
        else:
            done[id(node)] = node
    return done[id(expr)]


def constant(value: Any) -> Expr:
    """Return a constant expression (``value`` a finite or infinite real, not NaN)."""
    return wrap(value)


def wrap(value: Any) -> Expr:
    """Coerce ``value`` to an :class:`Expr`: the one place numbers enter the DAG.

    Parameters
    ----------
    value : Expr, int, float, numpy scalar or 0-d array
        An expression is returned as it is; a real number becomes a constant.

    Raises
    ------
    TypeError
        For booleans, strings, arrays and other objects.
    ValueError
        For NaN, or an integer too large for a float.

    Examples
    --------
    >>> wrap(2)
    2.0
    >>> wrap("2")
    Traceback (most recent call last):
    ...
    TypeError: expected an expression or a real number, got str '2'
    """
    if isinstance(value, Expr):
        return value
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(
            f"expected an expression or a real number, got {type(value).__name__} {value!r:.60}")
    try:
        v = float(value)
    except OverflowError:
        raise ValueError(f"the number {value!r:.40} is too large for a float constant") from None
    if math.isnan(v):
        raise ValueError("a constant cannot be NaN")
    return Expr("const", (), v)


def power(base: Expr, exponent: Any) -> Expr:
    """``base ** exponent``.

    An integral exponent gives ``powi`` (defined for every base; even powers
    are non-negative); a real constant exponent gives ``powr``, defined for
    ``base >= 0``; an expression exponent gives ``exp(exponent * log(base))``,
    defined for ``base > 0``.
    """
    exponent = wrap(exponent)
    if exponent.op == "const":
        p = exponent.param
        if math.isfinite(p) and p == int(p) and abs(p) <= 2**31:
            n = int(p)
            return base if n == 1 else Expr("powi", (base,), n)
        return Expr("powr", (base,), p)
    return Expr("exp", (Expr("mul", (exponent, Expr("log", (base,)))),))


x = Expr("var", (), "x")
y = Expr("var", (), "y")
z = Expr("var", (), "z")


# -- printing ----------------------------------------------------------------
def _const_source(v: float) -> tuple[str, int]:
    if math.isinf(v):
        return ("float('inf')" if v > 0 else "-float('inf')"), (_PREC_ATOM if v > 0 else _PREC_NEG)
    text = repr(v)
    return text, (_PREC_NEG if text.startswith("-") else _PREC_ATOM)


def _node_source(node: Expr, parts: list[tuple[str, int]],
                 has_var: dict[int, bool]) -> tuple[str, int]:
    op = node.op
    if op == "const":
        return _const_source(node.param)
    if op == "var":
        return node.param, _PREC_ATOM
    if not any(has_var[id(a)] for a in node.args):
        # Python would fold an operator on plain numbers (and min/max/abs fall
        # back to the built-ins): print the constants as Exprs.
        parts = [(f"constant({_const_source(a.param)[0]})", _PREC_ATOM) if a.op == "const"
                 else part for a, part in zip(node.args, parts)]
    if op in _INFIX:
        symbol, prec = _INFIX[op]
        (a, pa), (b, pb) = parts
        left = a if pa >= prec else f"({a})"
        right = b if pb > prec else f"({b})"
        return left + symbol + right, prec
    if op == "neg":
        a, pa = parts[0]
        return "-" + (a if pa >= _PREC_NEG else f"({a})"), _PREC_NEG
    if op in ("powi", "powr"):
        a, pa = parts[0]
        p = node.param
        exponent = repr(p) if op == "powi" or not (p < 0) else f"({p!r})"
        if op == "powi" and p < 0:
            exponent = f"({p})"
        return (a if pa > _PREC_POW else f"({a})") + " ** " + exponent, _PREC_POW
    if op == "repeat":
        child, spacing, count = node.param
        return (f"repeat({_to_source(child)}, spacing={spacing!r}, count={count!r})"
                f"{_remapped(parts)}", _PREC_ATOM)
    if op == "repeat_polar":
        child, n, axis = node.param
        return f"repeat_polar({_to_source(child)}, {n}, axis={axis!r}){_remapped(parts)}", \
            _PREC_ATOM
    name = _FUNCTION_NAMES.get(op, op)
    extra = [] if node.param is None else [repr(node.param)]
    return f"{name}({', '.join([p for p, _ in parts] + extra)})", _PREC_ATOM


_FUNCTION_NAMES = {"min": "min", "max": "max"}


def _remapped(parts: list[tuple[str, int]]) -> str:
    """``.remap(...)`` for a sweep read at coordinates other than x, y, z."""
    names = [p for p, _ in parts]
    if names == list(VARIABLES):
        return ""
    return ".remap(" + ", ".join(f"{v}={p}" for v, p in zip(VARIABLES, names) if p != v) + ")"


def _to_source(expr: Expr, limit: Optional[int] = None) -> str:
    """Python source for ``expr`` (iterative; a summary for huge DAGs), or with
    ``limit`` its first ``limit`` characters (every node's text cut there: a
    node's text starts with its first argument's, or with text of its own, so
    the cut texts give the whole text's first ``limit`` characters)."""
    out: dict[int, tuple[str, int]] = {}
    has_var: dict[int, bool] = {}
    for node in expr.walk():
        parts = [out[id(a)] for a in node.args]
        if limit is None and sum(len(p) for p, _ in parts) > _REPR_LIMIT:
            count = sum(1 for _ in expr.walk())
            return f"<Expr {expr.op}: {count} distinct nodes, too large to print>"
        has_var[id(node)] = node.op == "var" or any(has_var[id(a)] for a in node.args)
        text, precedence = _node_source(node, parts, has_var)
        out[id(node)] = (text if limit is None else text[:limit], precedence)
    return out[id(expr)][0]


def source_preview(expr: Expr, limit: int = 2000) -> str:
    """The first ``limit`` characters of ``repr(expr)``, in time proportional to the
    expression's nodes (a run's metadata names its model so).

    Examples
    --------
    >>> source_preview((x - 1.0) * (x - 1.0) + y, 12)
    '(x - 1.0) * '
    """
    return _to_source(expr, int(limit))
