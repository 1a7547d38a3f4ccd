"""Large batches take faster code paths in the interval kernels; they give the same bits.

The enclosure suite (``test_interval_enclosure.py``) checks each kernel on one
box at a time against mpmath. Batches of thousands of boxes, as the
subdivision passes them, take paths a single box never does: constants as
cached arrays (:mod:`implicitvox.interval.filled`), masked copies instead of
``np.where`` (:func:`implicitvox.interval.kernels.where_set`), the sums' range test in
``_norm``. Here every opcode runs on one big batch and on small pieces of it,
in float64 and (where the kernel supports it) float32, and the results must
be identical bit for bit, so the mpmath proof carries over.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from implicitvox.interval import filled
from implicitvox.eval.interval import apply_op
from implicitvox.interval.filled import filled_like
from implicitvox.interval.kernels import where_set
from implicitvox.eval.opcodes import OPCODES
from tests.support.strategies import param_for

BATCH = 3 * filled.MIN_SIZE
PIECE = 97   # far below MIN_SIZE: the scalar forms


def _values(rng: np.random.Generator, n: int, single: bool) -> np.ndarray:
    """A mix of magnitudes: moderate, wide, tiny, exact specials, and in the
    second half also the extremes where squares overflow or underflow (per
    float type): the pieces of the first half may take paths that the whole
    batch, holding extremes, does not."""
    top, bottom = (30, -40) if single else (300, -300)
    kinds = np.concatenate([rng.integers(0, 4, n // 2), rng.integers(0, 5, n - n // 2)])
    sign = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    out = np.select(
        [kinds == 0, kinds == 1, kinds == 2, kinds == 3],
        [rng.uniform(-50, 50, n), rng.uniform(-1e6, 1e6, n), rng.uniform(-1e-6, 1e-6, n),
         rng.choice([0.0, -0.0, 1.0, -1.0, 0.5], n)],
        sign * 10.0 ** rng.uniform(bottom, top, n))
    return out.astype(np.float32) if single else out


def _boxes(rng, arity: int, n: int, single: bool):
    los, his = [], []
    for _ in range(arity):
        a, b = _values(rng, n, single), _values(rng, n, single)
        los.append(np.minimum(a, b))
        his.append(np.maximum(a, b))
    return tuple(los), tuple(his)


def _run(name, param, los, his, single):
    with np.errstate(all="ignore"):
        result = apply_op(OPCODES[name], param, los, his, single)
    n = los[0].shape[0]
    return [np.broadcast_to(np.asarray(r), (n,)) for r in result]


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    if a.dtype == bool:
        return bool(np.array_equal(a, b))
    return bool(np.array_equal(a, b, equal_nan=True)) and bool(
        np.array_equal(np.signbit(a), np.signbit(b)))


def _float32_ok(name: str, param) -> bool:
    """Would a tape with this instruction run in float32 (as the subdivision does)?"""
    op = OPCODES[name]
    return op.float32 and op.float32_params(param)


@pytest.mark.parametrize("name", sorted(OPCODES))
@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_a_batch_and_its_pieces_give_the_same_bits(name, data):
    param = data.draw(param_for(name))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    for single in (False, True) if _float32_ok(name, param) else (False,):
        los, his = _boxes(rng, OPCODES[name].arity, BATCH, single)
        whole = _run(name, param, los, his, single)
        pieces = [_run(name, param, tuple(a[s:s + PIECE] for a in los),
                       tuple(a[s:s + PIECE] for a in his), single)
                  for s in range(0, BATCH, PIECE)]
        for k, part in enumerate(zip(*pieces)):
            joined = np.concatenate(part)
            assert whole[k].dtype == joined.dtype, (name, single, k)
            bad = np.flatnonzero(~(whole[k] == joined) & ~(np.isnan(whole[k]) & np.isnan(joined)))
            assert _same_bits(whole[k], joined), (
                f"{name} (param {param}, float32 {single}) output {k} differs at "
                f"{bad[:5]}: batch {whole[k][bad[:5]]} against pieces {joined[bad[:5]]}")


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("value", [0.0, -0.0, 1.0, -1.0, np.pi, 3.4028234663852886e38, 0.1])
def test_filled_constants_give_the_scalar_results(dtype, value):
    rng = np.random.default_rng(7)
    a = (rng.standard_normal(filled.MIN_SIZE + 5) * 3).astype(dtype)
    a[:4] = [0.0, -0.0, np.inf, np.nan]
    c = filled_like(value, a)
    assert isinstance(c, np.ndarray) and c.shape == a.shape and c.dtype == a.dtype
    for op in (np.minimum, np.maximum, np.fmin, np.fmax):
        assert _same_bits(op(a, c), op(a, value)), op.__name__
    assert bool(np.all(np.signbit(c) == np.signbit(value)))   # 0.0 and -0.0 kept apart


def test_filled_constants_are_read_only_and_only_for_mid_sized_float_arrays():
    a = np.zeros(filled.MIN_SIZE)
    with pytest.raises(ValueError):
        filled_like(2.0, a)[0] = 3.0
    assert filled_like(2.0, np.zeros(filled.MIN_SIZE - 1)) == 2.0
    assert filled_like(2.0, np.zeros(filled.MAX_SIZE + 1, dtype=np.float32)) == 2.0
    assert filled_like(2.0, np.zeros(filled.MIN_SIZE, dtype=np.int64)) == 2.0
    assert filled_like(2.0, 5.0) == 2.0
    big = filled_like(2.0, np.zeros((3, filled.MIN_SIZE)))   # the buffer grows
    assert big.shape == (3, filled.MIN_SIZE) and bool(np.all(big == 2.0))


@pytest.mark.parametrize("shape, mask_shape", [((5000,), (5000,)), ((2, 1, 3000), (2, 2, 3000)),
                                               ((7,), (7,)), ((), ())])
def test_where_set_is_np_where(shape, mask_shape):
    rng = np.random.default_rng(3)
    a = rng.standard_normal(shape).astype(np.float32)
    mask = rng.random(mask_shape) < 0.05
    expected = np.where(mask, 1.0, a)
    got = where_set(mask, 1.0, a)
    assert got.dtype == expected.dtype and _same_bits(np.asarray(got), np.asarray(expected))
    if a.shape == mask.shape and a.ndim:
        original = a.copy()
        where_set(mask, 1.0, a)
        assert _same_bits(a, original)                   # a copy unless owned
        assert where_set(mask, 1.0, a, owned=True) is a  # in place when owned


@pytest.mark.parametrize("source", [
    "sin(9*atan2(z, x)) * sin(18*elevation(x, z, y)) - radius(x, z, y)",
    "x", "0.1 + 0*x", "hypot(x, y) - 0.3"])
def test_native_float32_results_are_the_float64_ones(source):
    """``native=True`` only skips the conversion: the same ends, as float32."""
    import implicitvox as ivx
    from implicitvox.eval.interval import evaluate_intervals
    tape = ivx.compile(eval(source, {n: getattr(ivx, n) for n in ivx.__all__})).tape
    rng = np.random.default_rng(5)
    lo = tuple(rng.uniform(-1.0, 1.0, 5000).astype(np.float32) for _ in range(3))
    hi = tuple(a + np.float32(0.01) for a in lo)
    wide = evaluate_intervals(tape, lo, hi, np.float32)
    native = evaluate_intervals(tape, lo, hi, np.float32, native=True)
    for w, n in zip(wide, native):
        assert w.dtype == np.float64 and n.dtype == np.float32
        assert _same_bits(n.astype(np.float64), w)
