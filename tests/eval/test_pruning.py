"""Pruned tapes compute, bit for bit, what the whole tape computes over the box they
were pruned for: enclosures over its sub-boxes, values and gradients at its points."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import implicitvox as ivx
from implicitvox import x, y, z
from implicitvox.eval.gradient import evaluate_gradients
from implicitvox.eval.interval import evaluate_intervals
from implicitvox.eval.point import evaluate_points
from implicitvox.eval.pruning import FIRST, SECOND, UNDECIDED, Pruner, settle, simplify
from implicitvox.eval.tape import build_tape


def _sphere(c, r):
    return ivx.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) - r


def _box(c, h):
    return ivx.max(abs(x - c[0]) - h[0], abs(y - c[1]) - h[1], abs(z - c[2]) - h[2])


@st.composite
def csg_trees(draw, leaves=st.integers(2, 50)):
    """Random unions, intersections and differences of 2-50 spheres and boxes."""
    n = draw(leaves)
    coord = st.floats(-1.0, 1.0, allow_nan=False, width=32)
    size = st.floats(0.0625, 0.625, allow_nan=False, width=32)
    parts = []
    for _ in range(n):
        c = tuple(draw(coord) for _ in range(3))
        parts.append(_sphere(c, draw(size)) if draw(st.booleans())
                     else _box(c, tuple(draw(size) for _ in range(3))))
    while len(parts) > 1:
        k = draw(st.integers(0, len(parts) - 2))
        a, b = parts[k], parts.pop(k + 1)
        parts[k] = draw(st.sampled_from([ivx.min(a, b), ivx.max(a, b), ivx.max(a, -b)]))
    return parts[0]


def _choices(tape, lo, hi, dtype):
    columns = tuple(np.array([v], dtype=dtype) for v in lo), \
        tuple(np.array([v], dtype=dtype) for v in hi)
    out = np.zeros((len(tape.branches), 1), dtype=np.int8)
    evaluate_intervals(tape, *columns, dtype=dtype, choices=out)
    return out[:, 0]


def _sub_boxes(lo, hi, rng, n):
    lo, hi = np.asarray(lo), np.asarray(hi)
    a = lo + rng.random((n, 3)) * (hi - lo)
    b = lo + rng.random((n, 3)) * (hi - lo)
    a[: n // 4] = lo        # boxes sharing the parent's faces and corners too
    b[n // 4: n // 2] = hi
    return np.minimum(a, b), np.maximum(a, b)


def _same(a, b):
    return np.array_equal(np.asarray(a).view(np.uint8), np.asarray(b).view(np.uint8))


@settings(max_examples=60, deadline=None)
@given(csg_trees(), st.floats(-1.2, 1.0), st.floats(-1.2, 1.0), st.floats(-1.2, 1.0),
       st.sampled_from([0.05, 0.2, 0.6]), st.sampled_from([np.float64, np.float32]),
       st.integers(0, 2**32 - 1))
def test_a_pruned_tape_is_the_whole_tape_over_its_box(expr, bx, by, bz, size, dtype, seed):
    tape = build_tape(expr)
    lo, hi = (bx, by, bz), (bx + size, by + size, bz + size)
    choices = _choices(tape, lo, hi, dtype)
    pruned = simplify(tape, choices)
    assert len(pruned) <= len(tape)
    rng = np.random.default_rng(seed)
    sub_lo, sub_hi = _sub_boxes(lo, hi, rng, 64)
    for sub_dtype in {np.dtype(dtype), np.dtype(np.float64)}:   # float32 parents, float64 kids
        whole = evaluate_intervals(tape, tuple(sub_lo.T), tuple(sub_hi.T), sub_dtype)
        short = evaluate_intervals(pruned, tuple(sub_lo.T), tuple(sub_hi.T), sub_dtype)
        assert _same(whole[0], short[0]) and _same(whole[1], short[1])
    points = sub_lo + rng.random(sub_lo.shape) * (sub_hi - sub_lo)
    assert _same(evaluate_points(tape, *points.T), evaluate_points(pruned, *points.T))
    v0, g0 = evaluate_gradients(tape, *points.T)
    v1, g1 = evaluate_gradients(pruned, *points.T)
    assert _same(v0, v1) and _same(g0, g1)


def test_far_parts_of_a_union_are_dropped():
    spheres = [_sphere((i * 1.0, 0.0, 0.0), 0.3) for i in range(10)]
    tape = build_tape(ivx.min(*spheres))
    choices = _choices(tape, (-0.2, -0.2, -0.2), (0.2, 0.2, 0.2), np.float64)
    assert np.count_nonzero(choices) == 9
    pruned = simplify(tape, choices)
    assert len(pruned) == len(build_tape(spheres[0]))
    assert [i.op.name for i in pruned.instructions] == \
        [i.op.name for i in build_tape(spheres[0]).instructions]


@pytest.mark.parametrize("name, lo, hi, expected", [
    ("min", ((0.0, 2.0),), ((1.0, 3.0),), FIRST),
    ("min", ((2.0, 0.0),), ((3.0, 1.0),), SECOND),
    ("max", ((0.0, 2.0),), ((1.0, 3.0),), SECOND),
    ("min", ((0.0, 1.0),), ((1.0, 2.0),), UNDECIDED),     # touching: no gap
    ("min", ((0.0, 1.0 + 1e-12),), ((1.0, 2.0),), UNDECIDED),   # a gap within the margin
    ("min", ((-np.inf, 2.0),), ((1.0, 3.0),), UNDECIDED),  # unbounded
    ("min", ((np.inf, 2.0),), ((-np.inf, 3.0),), UNDECIDED),   # empty (undefined) operand
    ("abs", ((0.5,),), ((1.0,),), FIRST),
    ("abs", ((-1.0,),), ((-0.5,),), SECOND),
    ("abs", ((-1.0,),), ((0.5,),), UNDECIDED),
])
def test_settle(name, lo, hi, expected):
    lo = tuple(np.array([v]) for v in lo[0])
    hi = tuple(np.array([v]) for v in hi[0])
    assert settle(name, lo, hi, np.float64).tolist() == [expected]


def test_a_part_of_a_union_is_dropped_against_the_whole_union():
    """Over [0, 1]^3: 2x in [0, 2], x + 1.5 in [1.5, 2.5], x in [0, 1]. Against 2x alone
    x + 1.5 may still win; against the whole union's upper bound 1 (from x, which
    comes later in the chain) it never does."""
    tape = build_tape(ivx.min(2.0 * x, x + 1.5, x))
    assert tape.choice_trees == (len(tape) - 1,) * 2      # one min tree of two instructions
    box = (0.0, 0.0, 0.0), (1.0, 1.0, 1.0)
    assert settle("min", *[tuple(np.array([v]) for v in end) for end in ((0.0, 1.5), (2.0, 2.5))],
                  np.float64).tolist() == [UNDECIDED]            # the pair alone: undecided
    assert _choices(tape, *box, np.float64).tolist() == [FIRST, UNDECIDED]
    kept = simplify(tape, _choices(tape, *box, np.float64))
    assert [ins.op.name for ins in kept.instructions] == ["mulc", "min"]


def test_a_min_read_twice_is_no_part_of_a_tree():
    inner = ivx.min(x, y)
    tape = build_tape(ivx.min(inner, z) + inner)
    assert tape.choice_trees == (-1, -1)


def test_a_branch_reading_a_domain_operation_is_kept():
    """Dropping sqrt(g) would lose the whole tape's verdict "undefined" where g < 0."""
    expr = ivx.min(x - 5.0, ivx.sqrt(y))
    tape = build_tape(expr)
    choices = _choices(tape, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), np.float64)
    assert choices.tolist() == [FIRST]
    assert len(simplify(tape, choices)) == len(tape)
    # over y < 0 the two tapes agree: undefined
    lo, hi = (np.array([0.0]), np.array([-1.0]), np.array([0.0])), \
        (np.array([1.0]), np.array([-0.5]), np.array([1.0]))
    assert evaluate_intervals(simplify(tape, choices), lo, hi)[0][0] == np.inf


def test_the_pruner_shares_equal_tapes_and_groups_boxes():
    spheres = [_sphere((i * 1.0, 0.0, 0.0), 0.3) for i in range(6)]
    tape = build_tape(ivx.min(*spheres))
    lo = [(-0.2, -0.2, -0.2), (4.8, -0.2, -0.2), (-0.15, -0.2, -0.2), (-5.0, -5.0, -5.0)]
    choices = np.stack([_choices(tape, a, tuple(np.add(a, 0.4 if i < 3 else 10.0)), np.float64)
                        for i, a in enumerate(lo)], axis=1)
    pruner = Pruner()
    groups = pruner.groups(tape, choices, np.arange(4), levels_below=8)
    members = sorted(sorted(m.tolist()) for m, _ in groups)
    assert members == [[0, 2], [1], [3]]   # 0 and 2 share sphere 0's tape
    by_member = {int(m[0]): t for m, t in groups}
    assert len(by_member[0]) < len(tape) and by_member[3] is tape
    assert pruner.pruned(tape, choices[:, 0]) is by_member[0]   # cached
    # too few boxes below for a shorter tape to pay: one group, pruned by shared choices
    assert len(pruner.groups(tape, choices, np.arange(3), levels_below=0)) == 1
