"""The compiled interval rules (interval/rules.py) and the compiled tape (eval/compiled.py).

The enclosure suites (tests/properties/test_interval_enclosure.py) run every rule
against mpmath; here: libm's error inside compiled code stays within the margins
the rules widen by, the rules equal the array kernels bit for bit wherever they
use the same formula (and numpy's functions are the C library's: see
tests/support/libm.py), and the recorded branch choices are pruning.settle's.
"""
from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from numba import njit

import implicitvox as ivx
from implicitvox.eval import compiled
from implicitvox.eval.interval import apply_op, evaluate_intervals
from implicitvox.eval.opcodes import OPCODES
from implicitvox.eval.pruning import settle
from implicitvox.eval.tape import build_tape
from implicitvox.interval import rounding
from tests.interval.test_rounding import CRAFTED
from tests.properties.test_interval_enclosure import single_instruction
from tests.support.libm import assert_same_rule
from tests.support.reference import contains, mp_value


@njit
def _unary(which, xs):
    out = np.empty_like(xs)
    for i in range(xs.size):
        x = xs[i]
        if which == 0:
            out[i] = math.exp(x)
        elif which == 1:
            out[i] = math.log(x)
        elif which == 2:
            out[i] = math.sin(x)
        elif which == 3:
            out[i] = math.cos(x)
        elif which == 4:
            out[i] = math.tan(x)
        elif which == 5:
            out[i] = math.atan(x)
        elif which == 6:
            out[i] = math.asin(x)
        else:
            out[i] = math.acos(x)
    return out


@njit
def _binary(which, xs, ys):
    out = np.empty_like(xs)
    for i in range(xs.size):
        if which == 0:
            out[i] = math.atan2(xs[i], ys[i])
        elif which == 1:
            out[i] = math.pow(xs[i], ys[i])
        else:
            out[i] = math.hypot(xs[i], ys[i])
    return out


def _worst_ulps(computed, exact_values) -> float:
    worst = 0.0
    for c, exact in zip(computed, exact_values):
        ulp = np.spacing(abs(float(exact)))
        worst = max(worst, float(abs(mpmath.mpf(float(c)) - exact) / ulp))
    return worst


UNARY = [("exp", mpmath.exp, -700.0, 700.0), ("log", mpmath.log, None, None),
         ("sin", mpmath.sin, -1e6, 1e6), ("cos", mpmath.cos, -1e6, 1e6),
         ("tan", mpmath.tan, -1e3, 1e3), ("atan", mpmath.atan, -1e3, 1e3),
         ("asin", mpmath.asin, -1.0, 1.0), ("acos", mpmath.acos, -1.0, 1.0)]


@pytest.mark.parametrize("which, case", list(enumerate(UNARY)), ids=[c[0] for c in UNARY])
def test_compiled_libm_error_is_within_the_margin(which, case):
    """libm as compiled code calls it, measured against mpmath at 40 digits: below
    TRANSCENDENTAL_ULPS, the widening of every rule that calls it."""
    name, mpfunc, lo, hi = case
    rng = np.random.default_rng(17)
    xs = 10.0 ** rng.uniform(-300, 300, 2000) if lo is None else rng.uniform(lo, hi, 2000)
    with mpmath.workdps(40):
        worst = _worst_ulps(_unary(which, xs), [mpfunc(mpmath.mpf(float(v))) for v in xs])
    assert worst < rounding.TRANSCENDENTAL_ULPS, f"{name}: {worst:.2f} ulp"


def test_compiled_atan2_pow_hypot_error_is_within_the_margin():
    rng = np.random.default_rng(18)
    ys, xs = rng.uniform(-10, 10, 1500), rng.uniform(-10, 10, 1500)
    bases, powers = rng.uniform(0.0, 10.0, 1500), rng.uniform(-20.0, 20.0, 1500)
    with mpmath.workdps(40):
        atan2 = _worst_ulps(_binary(0, ys, xs), [mpmath.atan2(mpmath.mpf(float(a)),
                                                              mpmath.mpf(float(b)))
                                                 for a, b in zip(ys, xs)])
        power = _worst_ulps(_binary(1, bases, powers), [mpmath.power(mpmath.mpf(float(a)),
                                                                     mpmath.mpf(float(b)))
                                                        for a, b in zip(bases, powers)])
        hypot = _worst_ulps(_binary(2, ys, xs), [mpmath.sqrt(mpmath.mpf(float(a)) ** 2
                                                             + mpmath.mpf(float(b)) ** 2)
                                                 for a, b in zip(ys, xs)])
    assert atan2 < rounding.TRANSCENDENTAL_ULPS, f"atan2: {atan2:.2f} ulp"
    assert power < rounding.POW_ULPS and hypot < rounding.POW_ULPS, (power, hypot)


#: where the rules and the array kernels compute the ends differently: the rules
#: call libm's sin and cos, the kernels derive them from numpy's tan (which is
#: vectorized); both enclose (the suites above), the bits differ
DIFFERENT_FORMULA = {"sin", "cos", "periodic_angle"}
PARAMS = {"addc": 0.3, "rsubc": -1.7, "mulc": -2.5, "divc": 3.3, "powi": 3, "powr": 0.7,
          "distance": (0.1, -0.2, 0.3), "periodic_angle": ("sin", 3.0, 0.5)}


@pytest.mark.parametrize("name", sorted(n for n, op in OPCODES.items()
                                        if not op.oracle and n not in DIFFERENT_FORMULA))
def test_rules_equal_the_array_kernels_bit_for_bit(name):
    op = OPCODES[name]
    rng = np.random.default_rng(5)
    n = 4000
    lo = rng.uniform(-3.0, 3.0, (3, n)) * 10.0 ** rng.integers(-3, 4, (3, n))
    hi = lo + rng.exponential(0.5, (3, n))
    lo[:, :50], hi[:, :50] = -np.inf, np.inf       # unbounded boxes too
    hi[:, 50:100] = np.inf
    # and the values the property suites draw at their edges: zeros of both signs,
    # subnormals, the largest floats, ends on the domains' bounds, points
    special = np.array([0.0, -0.0, 5e-324, -5e-324, 1e-310, 1e300, -1e300, 1.7e308, -1.7e308,
                        1.0, -1.0, np.pi, -np.pi, np.pi / 2, 1e15, -1e15])
    k = len(special)
    lo[:, 100:100 + k * k] = np.repeat(special, k)
    hi[:, 100:100 + k * k] = np.maximum(np.tile(special, k), lo[:, 100:100 + k * k])
    hi[:, 400:500] = lo[:, 400:500]                 # degenerate boxes
    param = PARAMS.get(name)
    flo, fhi = compiled.evaluate_boxes(compiled.encode(single_instruction(op, param)), lo, hi)
    with np.errstate(all="ignore"):
        result = apply_op(op, param, tuple(lo[:op.arity]), tuple(hi[:op.arity]))
    nlo = np.array(np.broadcast_to(result[0], (n,)), dtype=float)
    nhi = np.array(np.broadcast_to(result[1], (n,)), dtype=float)
    if op.domain:
        empty = np.broadcast_to(result[2], (n,))
        nlo[empty], nhi[empty] = np.inf, -np.inf
    assert_same_rule(flo, nlo)
    assert_same_rule(fhi, nhi)


def test_crafted_inputs_are_enclosed_by_the_compiled_tape():
    for expr, point in CRAFTED:
        tape = compiled.encode(build_tape(expr))
        column = np.array(point)[:, None]
        flo, fhi = compiled.evaluate_boxes(tape, column, column)
        assert contains(float(flo[0]), float(fhi[0]), mp_value(expr, point)), repr(expr)


def test_choices_are_those_of_settle():
    """The branch choices recorded over boxes equal pruning.settle's on the array
    evaluator's operand enclosures (two spheres cut by a slab, and abs; no min tree,
    whose branches the array evaluator settles against the whole tree)."""
    from implicitvox import x, y, z
    balls = [ivx.sqrt((x - c) ** 2 + y ** 2 + z ** 2) - 0.3 for c in (-0.6, 0.6)]
    expr = ivx.max(ivx.min(*balls), ivx.abs(z - 0.1) - 0.2)
    tape = build_tape(expr)
    assert set(tape.choice_trees) == {-1}
    # abs writes over its argument's register: its choice must be read first
    assert any(ins.op.name == "abs" and ins.out in ins.args for ins in tape.instructions)
    rng = np.random.default_rng(3)
    lo = rng.uniform(-1.0, 1.0, (3, 3000))
    hi = lo + rng.uniform(0.0, 0.3, (3, 3000))
    got = np.empty((len(tape.branches), 3000), dtype=np.int8)
    compiled.evaluate_boxes(compiled.encode(tape), lo, hi, got)
    expected = np.empty_like(got)
    evaluate_intervals(tape, tuple(lo), tuple(hi), choices=expected)
    np.testing.assert_array_equal(got, expected)
    assert len(np.unique(got)) == 3            # every kind of choice is exercised


def test_a_read_only_install_compiles_in_memory(tmp_path):
    """Where Numba can write no cache (the package's ``__pycache__`` folders and the
    user's cache unwritable), the kernel still imports, uncached, and runs."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    shutil.copytree(root / "implicitvox", tmp_path / "implicitvox",
                    ignore=shutil.ignore_patterns("__pycache__"))
    for folder in (tmp_path / "implicitvox").rglob("*"):
        if folder.is_dir():
            (folder / "__pycache__").write_text("not a folder: nothing can be cached here")
    (tmp_path / "implicitvox" / "__pycache__").write_text("not a folder")
    code = ("import numpy as np\n"
            "from implicitvox.interval import rules\n"
            "assert rules.COMPILE['cache'] is False, rules.COMPILE\n"
            "lo, hi = rules.i_add(0.1, 0.1, 0.7, 0.7)\n"
            "assert lo < 0.1 + 0.7 < hi\n"
            "import implicitvox.octree.descend\n"
            "print('ok')\n")
    env = {"PATH": "/usr/bin:/bin", "HOME": "/dev/null", "XDG_CACHE_HOME": "/dev/null/cache",
           "PYTHONPATH": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, env=env, timeout=300)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]


def test_exact_zeros_stay_exact_in_both_kernels():
    """A sum that rounds to 0 is exact, and so is a product or quotient with an exact
    [0, 0]: both kernels keep them 0 (else they grow to subnormal widths, which
    compiled code pays about a hundred cycles per operation for), and a gradient
    component the function does not depend on stays exactly [0, 0]."""
    from implicitvox.eval.mean_value_kernels import tape_interval_gradients
    from implicitvox.interval import kernels, rules
    inf = np.inf
    cases = [("i_add", (0.0, 0.0, 0.0, 0.0)), ("i_sub", (1.5, 1.5, 1.5, 1.5)),
             ("i_mul", (0.0, 0.0, -inf, 5.0)), ("i_mul", (-2.0, 3.0, 0.0, 0.0)),
             ("i_div", (0.0, 0.0, 1.0, 2.0)), ("i_mulc", (0.0, 0.0, -3.0)),
             ("i_divc", (0.0, 0.0, 7.0)), ("i_addc", (-0.5, 2.0, 0.5))]
    for name, args in cases:
        for module in (rules, kernels):
            lo, hi = getattr(module, name)(*args)
            assert float(lo) == 0.0 and float(hi if name != "i_addc" else lo) == 0.0, \
                (name, module.__name__, lo, hi)
    # a quotient by an interval holding 0 is still everything
    assert rules.i_div(0.0, 0.0, -1.0, 1.0) == (-inf, inf)
    # non-zero sums are still widened
    assert rules.i_add(1.0, 1.0, 2.0, 2.0)[0] < 3.0
    from implicitvox import x, y
    tape = build_tape(x * y * ivx.sin(x) + ivx.exp(y))
    lo = np.array([[0.1, -1.0], [0.2, 0.5], [0.0, 0.0]])
    _, _, glo, ghi, _ = tape_interval_gradients(tape, lo, lo + 0.01, libm=True)
    assert np.all(glo[2] == 0.0) and np.all(ghi[2] == 0.0)
