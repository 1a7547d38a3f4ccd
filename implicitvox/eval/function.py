"""``compile(expr)``: an expression turned into point, interval and gradient evaluators.

Examples
--------
>>> import numpy as np
>>> import implicitvox as iv
>>> from implicitvox import x, y, z
>>> f = iv.compile(x**2 + y**2 + z**2 - 1)
>>> f(np.array([0.0, 1.0]), 0.0, 0.0)
array([-1.,  0.])
>>> lo, hi = f.interval([[0.5, 0.5, 0.5]], [[1.0, 1.0, 1.0]])
>>> bool(lo[0] <= -0.25 and hi[0] >= 2.0)
True
>>> value, grad = f.gradient(1.0, 0.0, 0.0)
>>> grad
array([2., 0., 0.])
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .. import validate
from ..expr.nodes import Expr
from .gradient import evaluate_gradients
from .interval import evaluate_intervals
from .point import evaluate_points
from .tape import Tape, build_tape

__all__ = ["Function", "compile"]


def _as_expr(obj: Any) -> Expr:
    if isinstance(obj, Expr):
        return obj
    inner = getattr(obj, "expr", None)
    if isinstance(inner, Expr):
        return inner
    raise TypeError(
        f"compile() needs an implicitvox expression (built from x, y, z) or a shape "
        f"with an .expr attribute, got {type(obj).__name__} {obj!r:.60}")


def compile(expr: Any) -> "Function":  # noqa: A001 - the public name the docs use
    """Compile an expression (or a shape with ``.expr``) into a :class:`Function`.

    Parameters
    ----------
    expr : Expr or Shape
        The implicit function ``f``; the solid is ``f <= 0``.

    Returns
    -------
    Function

    Raises
    ------
    TypeError
        If ``expr`` is not an expression.
    """
    return Function(_as_expr(expr))


def _points(X: Any, Y: Any, Z: Any) -> tuple[tuple[int, ...], np.ndarray, np.ndarray, np.ndarray]:
    try:
        arrays = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in (X, Y, Z)))
    except (TypeError, ValueError) as err:
        raise ValueError(f"X, Y, Z must be broadcastable real arrays: {err}") from None
    shape = arrays[0].shape
    return shape, *(a.reshape(-1) for a in arrays)


class Function:
    """A compiled implicit function (see :func:`compile`).

    Attributes
    ----------
    expr : Expr
        The expression it was compiled from.
    tape : Tape
        The flat form the evaluators read.
    """

    def __init__(self, expr: Expr):
        self.expr = expr
        self.tape: Tape = build_tape(expr)

    def __repr__(self) -> str:
        return f"<Function of {len(self.tape)} instructions: {self.expr!r:.80}>"

    def __call__(self, X: Any, Y: Any, Z: Any) -> np.ndarray:
        """Values at points; ``X, Y, Z`` broadcast together (NaN in, NaN out)."""
        shape, xs, ys, zs = _points(X, Y, Z)
        return evaluate_points(self.tape, xs, ys, zs).reshape(shape)

    def gradient(self, X: Any, Y: Any, Z: Any) -> tuple[np.ndarray, np.ndarray]:
        """Values and gradients at points.

        Returns
        -------
        values : ndarray
            Shape of the broadcast inputs.
        gradient : ndarray
            That shape plus a last axis of 3: ``(df/dx, df/dy, df/dz)``.
        """
        shape, xs, ys, zs = _points(X, Y, Z)
        value, grad = evaluate_gradients(self.tape, xs, ys, zs)
        return value.reshape(shape), np.moveaxis(grad, 0, -1).reshape(shape + (3,))

    def interval(self, lo: Any, hi: Any) -> tuple[np.ndarray, np.ndarray]:
        """Enclosures of ``f`` over boxes, rounded outward.

        Parameters
        ----------
        lo, hi : array_like, shape (n, 3) or (3,)
            Box corners; every ``lo <= hi``, no NaN. Infinite coordinates are
            allowed (the result may then be infinite).

        Returns
        -------
        flo, fhi : ndarray, shape (n,)
            ``flo <= f(p) <= fhi`` for every point ``p`` of box ``i`` where
            ``f`` is defined, in exact arithmetic. A box on which ``f`` is
            nowhere defined gets the empty interval ``(+inf, -inf)``.

        Raises
        ------
        ValueError
            For wrong shapes, NaN, or ``lo > hi``.
        """
        lo_arr = validate.points(lo, "lo", finite=False)
        hi_arr = validate.points(hi, "hi", finite=False)
        if lo_arr.shape != hi_arr.shape:
            raise ValueError(f"lo and hi must have the same shape (n, 3); got {lo_arr.shape} "
                             f"and {hi_arr.shape}")
        bad = lo_arr > hi_arr
        if bad.any():
            i, k = np.argwhere(bad)[0]
            raise ValueError(f"box {i} has lo > hi on axis {'xyz'[k]}: "
                             f"{lo_arr[i, k]!r} > {hi_arr[i, k]!r}")
        return self.interval_columns(tuple(lo_arr.T), tuple(hi_arr.T))

    def interval_columns(self, lo: tuple[np.ndarray, ...], hi: tuple[np.ndarray, ...],
                         dtype=np.float64, native: bool = False
                         ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`interval` on per-axis columns, unchecked (the subdivision's fast path);
        ``dtype`` float32 only where :func:`implicitvox.octree.level_dtype.interval_dtype` allows;
        ``native``: results in ``dtype`` (see :func:`evaluate_intervals`)."""
        return evaluate_intervals(self.tape, lo, hi, dtype, native)
