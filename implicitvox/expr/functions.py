"""DSL functions: ``sqrt, square, abs, exp, log, sin, cos, tan, atan, atan2,
asin, acos, hypot, min, max, floor, clip, affine``.

Each returns an :class:`~implicitvox.expr.nodes.Expr`. ``min`` and ``max`` take any
number of arguments (or one iterable) and fall back to Python's built-ins when
no argument is an expression, so ``from implicitvox import *`` does not break
``min(1, 2)``; the same holds for ``abs``.

Examples
--------
>>> from implicitvox import x, y, z, min, max, sqrt
>>> min(x, y, z)
min(min(x, y), z)
>>> min(3, 4)
3
>>> max(sqrt(x), 0)
max(sqrt(x), 0.0)
"""
from __future__ import annotations

import builtins
from typing import Any, Sequence

from .nodes import Expr, wrap

__all__ = ["sqrt", "square", "abs", "exp", "log", "sin", "cos", "tan", "atan", "atan2",
           "asin", "acos", "hypot", "min", "max", "floor", "clip", "affine"]


def _unary(op: str, a: Any) -> Expr:
    return Expr(op, (wrap(a),))


def sqrt(a: Any) -> Expr:
    """Square root; defined for ``a >= 0``."""
    return _unary("sqrt", a)


def square(a: Any) -> Expr:
    """``a * a``, with the tight interval ``[0, ...]`` over intervals holding 0."""
    return _unary("square", a)


def abs(a: Any) -> Any:  # noqa: A001 - the DSL shadows the built-in on purpose
    """Absolute value (Python's ``abs`` for plain numbers)."""
    if not isinstance(a, Expr):
        return builtins.abs(a)
    return _unary("abs", a)


def exp(a: Any) -> Expr:
    """Exponential."""
    return _unary("exp", a)


def log(a: Any) -> Expr:
    """Natural logarithm; defined for ``a >= 0`` (``log(0) = -inf``)."""
    return _unary("log", a)


def sin(a: Any) -> Expr:
    """Sine (radians)."""
    return _unary("sin", a)


def cos(a: Any) -> Expr:
    """Cosine (radians)."""
    return _unary("cos", a)


def tan(a: Any) -> Expr:
    """Tangent (radians); intervals holding a pole give ``(-inf, inf)``."""
    return _unary("tan", a)


def atan(a: Any) -> Expr:
    """Arc tangent, in ``(-pi/2, pi/2)``."""
    return _unary("atan", a)


def asin(a: Any) -> Expr:
    """Arc sine; defined for ``-1 <= a <= 1``."""
    return _unary("asin", a)


def acos(a: Any) -> Expr:
    """Arc cosine; defined for ``-1 <= a <= 1``."""
    return _unary("acos", a)


def floor(a: Any) -> Expr:
    """Largest integer not above ``a`` (as a float)."""
    return _unary("floor", a)


def atan2(b: Any, a: Any) -> Expr:
    """Angle of the point ``(a, b)``: ``atan2(y, x)`` in ``(-pi, pi]`` as numpy's."""
    return Expr("atan2", (wrap(b), wrap(a)))


def hypot(a: Any, b: Any) -> Expr:
    """``sqrt(a**2 + b**2)`` without overflow."""
    return Expr("hypot", (wrap(a), wrap(b)))


def _nary(op: str, args: tuple[Any, ...], fallback: Any) -> Any:
    if len(args) == 1 and not isinstance(args[0], Expr):
        try:
            args = tuple(args[0])
        except TypeError:
            raise TypeError(f"{op}() of a single argument needs an iterable, "
                            f"got {type(args[0]).__name__}") from None
    if not args:
        raise ValueError(f"{op}() needs at least one argument")
    if not builtins.any(isinstance(a, Expr) for a in args):
        return fallback(args)
    nodes = [wrap(a) for a in args]
    # A left-leaning chain prints like the call; a balanced tree would be
    # shallower, but tapes are flat, so depth does not matter to evaluation.
    result = nodes[0]
    for node in nodes[1:]:
        result = Expr(op, (result, node))
    return result


def min(*args: Any) -> Any:  # noqa: A001
    """Minimum of any number of expressions (union of solids)."""
    return _nary("min", args, builtins.min)


def max(*args: Any) -> Any:  # noqa: A001
    """Maximum of any number of expressions (intersection of solids)."""
    return _nary("max", args, builtins.max)


def clip(a: Any, lo: Any, hi: Any) -> Expr:
    """``a`` limited to ``[lo, hi]``: ``max(lo, min(a, hi))``."""
    return Expr("max", (wrap(lo), Expr("min", (wrap(a), wrap(hi)))))




def affine(coefficients: Sequence[float], terms: Sequence[Any], offset: float = 0.0) -> Any:
    """``c[0] * t[0] + c[1] * t[1] + ... + offset``, summed left to right, with the
    fewest operations: a term whose coefficient is 0 is left out (the function
    does not depend on it), a coefficient 1 (-1) takes the term itself (negated),
    and an offset 0 adds nothing.

    Where the terms are finite, the floats are those of the full sum up to the
    sign of a zero (adding a zero product changes no other value, and ``t * 1``
    is ``t``); the tape is shorter and its enclosures are at least as tight (no
    rounding after an operation that changes nothing). Transforms and planes
    of CSG solids are written with it: a rotation by a right angle or a box's
    face has mostly zero coefficients.

    Examples
    --------
    >>> from implicitvox import x, y, z
    >>> affine([1.0, 0.0, 0.0], [x, y, z], 2.5)
    x + 2.5
    >>> affine([0.0, -1.0, 3.0], [x, y, z])
    -y + z * 3.0
    >>> affine([0.0, 0.0], [x, y], 1.0)
    1.0
    """
    result: Any = None
    for c, t in zip(coefficients, terms):
        c = float(c)
        if c == 0.0:
            continue
        term = t if c == 1.0 else -t if c == -1.0 else t * c
        result = term if result is None else result + term
    offset = float(offset)
    if result is None:
        return wrap(offset)
    return result + offset if offset != 0.0 else result
