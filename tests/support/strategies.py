"""Hypothesis strategies shared by the tests: floats, boxes, expressions."""
from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

import implicitvox as ivx
from implicitvox.expr.nodes import Expr

moderate = st.floats(-50.0, 50.0, allow_nan=False)
wide = st.floats(-1e6, 1e6, allow_nan=False)
tiny = st.floats(-1e-6, 1e-6, allow_nan=False)
anywhere = st.one_of(moderate, wide, tiny, st.sampled_from([0.0, -0.0, 1.0, -1.0]))

#: argument ranges that exercise each opcode's interesting cases
ELEMENTS = {
    "exp": st.floats(-800.0, 800.0),
    "asin": st.floats(-2.0, 2.0),
    "acos": st.floats(-2.0, 2.0),
    "sin": st.one_of(moderate, wide, st.floats(-1e15, 1e15)),
    "cos": st.one_of(moderate, wide, st.floats(-1e15, 1e15)),
    "tan": st.one_of(moderate, wide),
}


def elements_for(name: str):
    return ELEMENTS.get(name, anywhere)


@st.composite
def interval(draw, elements=anywhere):
    a, b = draw(elements), draw(elements)
    return (a, b) if a <= b else (b, a)


@st.composite
def param_for(draw, name: str):
    if name == "powi":
        return draw(st.integers(-5, 7))
    if name in ("addc", "rsubc", "mulc"):
        return draw(anywhere)
    if name in ("repeat", "repeat_polar"):
        from implicitvox.eval.tape import compiled_oracle
        return compiled_oracle(name, draw(sweep_param(name)))
    if name == "periodic_angle":
        return (draw(st.sampled_from(["sin", "cos"])), float(draw(st.integers(-9, 9))),
                draw(st.floats(-3.0, 3.0)))
    if name == "distance":
        return tuple(draw(anywhere) for _ in range(3))
    if name == "divc":
        return draw(anywhere.filter(lambda v: v != 0.0))
    if name == "powr":
        p = draw(st.floats(-3.0, 3.0).filter(lambda v: v != int(v)))
        return p
    return None


def samples(lo: float, hi: float, rng: np.random.Generator, n_interior: int) -> list[float]:
    """Endpoints plus ``n_interior`` points drawn inside ``[lo, hi]``."""
    t = rng.random(n_interior)
    inner = np.clip(lo + t * (hi - lo), lo, hi) if np.isfinite(hi - lo) else np.array([])
    return [lo, hi] + [float(v) for v in inner]


# -- random nested expressions ---------------------------------------------------
UNARY = ["neg", "square", "sqrt", "abs", "exp", "log", "sin", "cos", "tan", "atan", "asin",
         "acos", "floor"]
BINARY = ["add", "sub", "mul", "div", "atan2", "hypot", "min", "max"]
TERNARY = ["radius", "elevation"]
LEAVES = st.one_of(st.sampled_from([ivx.x, ivx.y, ivx.z]),
                   st.floats(-3.0, 3.0).map(ivx.constant))


@st.composite
def sweep_param(draw, name: str):
    """The expression parameter of a sweep node: a small child model and its layout."""
    child = draw(expression(2))
    if name == "repeat_polar":
        return (child, draw(st.integers(1, 12)), draw(st.sampled_from(["x", "y", "z"])))
    spacing = tuple(draw(st.one_of(st.none(), st.floats(0.1, 2.0))) for _ in range(3))
    if all(v is None for v in spacing):
        spacing = (0.5, None, None)
    count = tuple(draw(st.one_of(st.none(), st.integers(1, 5))) for _ in range(3))
    return (child, spacing, count)


@st.composite
def expression(draw, depth: int, unary=tuple(UNARY), binary=tuple(BINARY),
               powers: bool = True) -> Expr:
    """An expression exactly ``depth`` levels deep (a leaf has depth 0)."""
    if depth == 0:
        return draw(LEAVES)
    kinds = ["unary", "binary"] + (["powi", "powr", "ternary", "sweep"] if powers else [])
    kind = draw(st.sampled_from(kinds))
    if kind == "unary":
        return Expr(draw(st.sampled_from(list(unary))), (draw(expression(depth - 1, unary,
                                                                       binary, powers)),))
    if kind == "powi":
        return Expr("powi", (draw(expression(depth - 1, unary, binary, powers)),),
                    draw(st.integers(-3, 4).filter(lambda n: n != 1)))
    if kind == "sweep":
        name = draw(st.sampled_from(["repeat", "repeat_polar"]))
        coords = tuple(draw(expression(draw(st.integers(0, depth - 1)), unary, binary, False))
                       for _ in range(3))
        return Expr(name, coords, draw(sweep_param(name)))
    if kind == "ternary":
        parts = [draw(expression(draw(st.integers(0, depth - 1)), unary, binary, powers))
                 for _ in range(2)] + [draw(expression(depth - 1, unary, binary, powers))]
        order = draw(st.permutations(parts))
        return Expr(draw(st.sampled_from(TERNARY)), tuple(order))
    if kind == "powr":
        return Expr("powr", (draw(expression(depth - 1, unary, binary, powers)),),
                    draw(param_for("powr")))
    deep = draw(expression(depth - 1, unary, binary, powers))
    other = draw(expression(draw(st.integers(0, depth - 1)), unary, binary, powers))
    args = (deep, other) if draw(st.booleans()) else (other, deep)
    return Expr(draw(st.sampled_from(list(binary))), args)


@st.composite
def box3(draw, elements=st.floats(-3.0, 3.0)):
    lo, hi = [], []
    for _ in range(3):
        a, b = draw(interval(elements))
        lo.append(a)
        hi.append(b)
    return lo, hi
