"""The DSL: coercion, immutability, hashing, structural equality, printing."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import implicitvox as ivx
from implicitvox import x, y, z
from tests.support.strategies import expression

NAMESPACE = {name: getattr(ivx, name) for name in ivx.__all__}


def test_numbers_and_numpy_scalars_are_coerced_in_one_place():
    for value in (2, 2.0, np.float32(2.0), np.int64(2), np.float64(2.0), np.array(2.0)):
        assert (x * value).equals(x * 2.0)
        assert (value * x).equals(2.0 * x)


@pytest.mark.parametrize("bad, error, match", [
    ("2", TypeError, "got str"), (True, TypeError, "got bool"), ([1.0], TypeError, "got list"),
    (np.ones(3), TypeError, "got ndarray"), (float("nan"), ValueError, "NaN"),
    (10**400, ValueError, "too large"),
])
def test_bad_operands_name_what_they_got(bad, error, match):
    with pytest.raises(error, match=match):
        x + bad


def test_bool_and_comparisons_raise_with_advice():
    with pytest.raises(TypeError, match="compile"):
        bool(x)
    with pytest.raises(TypeError, match="min/max"):
        if x:  # noqa: SIM108
            pass
    with pytest.raises(TypeError, match="'<'"):
        x < 1


def test_expressions_are_immutable_and_hashable():
    e = x + 1
    with pytest.raises(AttributeError):
        e.op = "sub"
    assert hash(x + 1) == hash(e) and len({x + 1, e, x + 2}) == 2


def test_structural_equality_is_a_method_and_sees_bits():
    assert (x * y + 1).equals(x * y + 1.0)
    assert not (x - y).equals(y - x)
    assert not ivx.constant(0.0).equals(ivx.constant(-0.0))
    assert not (x + 1).equals("x + 1")


def test_deep_expressions_need_no_recursion():
    e = x
    for i in range(20_000):
        e = e + i
    f = x
    for i in range(20_000):
        f = f + i
    assert e.equals(f)
    assert len(ivx.compile(e).tape) == 20_000
    assert "distinct nodes" in repr(e) or len(repr(e)) > 0


def test_powers_choose_integer_real_and_general_forms():
    assert (x ** 3).op == "powi" and (x ** 3.0).op == "powi" and (x ** -2).param == -2
    assert (x ** 0.5).op == "powr"
    assert (x ** y).op == "exp" and (2 ** x).op == "exp"
    assert (x ** 1) is x


def test_min_max_are_nary_and_fall_back_to_builtins():
    assert ivx.min(3, 1, 2) == 1 and ivx.max([3, 1, 2]) == 3 and ivx.abs(-2) == 2
    m = ivx.min(x, y, z, 1.0)
    f = ivx.compile(m)
    assert float(f(5.0, 4.0, 3.0)) == 1.0 and float(f(-5.0, 4.0, 3.0)) == -5.0
    with pytest.raises(ValueError, match="at least one"):
        ivx.min()


def test_clip_and_remap():
    f = ivx.compile(ivx.clip(x, -1, 1))
    assert list(f(np.array([-3.0, 0.5, 3.0]), 0, 0)) == [-1.0, 0.5, 1.0]
    g = ivx.compile((x * x + y).remap(x=z + 1, y=2))
    assert float(g(0, 0, 2)) == 11.0


@settings(max_examples=200, deadline=None)
@given(expr=expression(5))
def test_repr_reads_back_as_python(expr):
    assert eval(repr(expr), dict(NAMESPACE)).equals(expr)


@settings(max_examples=100, deadline=None)
@given(expr=expression(5), limit=st.sampled_from([0, 1, 3, 8, 20, 60, 2000]))
def test_a_source_preview_is_the_start_of_the_repr(expr, limit):
    from implicitvox.expr.nodes import source_preview
    assert source_preview(expr, limit) == repr(expr)[:limit]


def test_a_huge_model_is_previewed_not_summarized():
    from implicitvox.expr.examples import sphere_union
    from implicitvox.expr.nodes import source_preview
    model = sphere_union(2000).expr
    assert repr(model).startswith("<Expr")                # the repr's summary
    preview = source_preview(model, 300)
    assert len(preview) == 300 and preview.startswith("min(")


@pytest.mark.parametrize("text", [
    "-x ** 2", "(-x) ** 2", "x - (y - z)", "x / (y * z)", "-(x + 1.5)", "x ** (-2)",
    "x ** 0.5", "x - -1.5", "min(min(x, y), z)", "atan2(y, x) * -1.0", "float('inf') + x",
])
def test_repr_of_tricky_forms_reads_back(text):
    expr = eval(text, dict(NAMESPACE))
    assert eval(repr(expr), dict(NAMESPACE)).equals(expr)


def test_a_deep_expression_pickles_flat_and_shared():
    """A union of thousands of parts is a chain thousands deep; pickling it must not
    recurse (the parallel runs pickle the shape), and shared nodes stay shared."""
    import pickle
    parts = [ivx.sqrt((x - 0.001 * i) ** 2 + y * y + z * z) - 0.5 for i in range(2000)]
    deep = ivx.min(*parts)
    back = pickle.loads(pickle.dumps(deep, protocol=pickle.HIGHEST_PROTOCOL))
    assert back == deep and hash(back) == hash(deep)
    square = x * x
    shared = pickle.loads(pickle.dumps(square + square))
    assert shared.args[0] is shared.args[1]


def test_affine_leaves_out_what_changes_nothing_and_keeps_the_floats():
    """Zero coefficients are left out, 1 and -1 take the term itself, a zero offset
    adds nothing: fewer instructions, the floats of the full sum (signed zeros aside)."""
    from implicitvox.eval.tape import build_tape
    rng = np.random.default_rng(3)
    P = rng.uniform(-5, 5, (3, 5000))
    P[:, :50] = 0.0
    for _ in range(40):
        c = rng.choice([0.0, 1.0, -1.0, 0.3, -2.75, 1e-300], size=3)
        d = float(rng.choice([0.0, -0.0, 1.25]))
        e = ivx.affine(c, (x, y, z), d)
        full = ((c[0] * P[0] + c[1] * P[1]) + c[2] * P[2]) + d
        got = ivx.compile(e)(*P)
        assert np.array_equal(got, full), (c, d)        # == : 0.0 and -0.0 are equal
        scaled = int(np.sum((c != 0) & (np.abs(c) != 1)))
        adds = max(int(np.sum(c != 0)) - 1, 0) + (d != 0 and c.any())
        negs = int(np.sum(c == -1.0))
        assert len(build_tape(e).instructions) <= scaled + adds + negs, (c, d)
    assert ivx.affine([0.0, 0.0, 0.0], (x, y, z), 2.0) == ivx.constant(2.0)
