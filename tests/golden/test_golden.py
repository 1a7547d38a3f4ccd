"""Nothing a user computes changes unnoticed: every digest equals the committed one.

See :mod:`tests.golden.digests` for what is hashed and how to regenerate.
"""
from __future__ import annotations

import json

import pytest

from tests.golden.digests import GOLDEN, GOLDEN_SIMD, compute, simd_target, split


@pytest.fixture(scope="module")
def digests():
    return split(compute())


def test_every_digest_is_unchanged(digests):
    expected = json.loads(GOLDEN.read_text())
    got, _ = digests
    assert sorted(got) == sorted(expected), "the set of golden cases changed"
    changed = sorted(k for k in expected if got[k] != expected[k])
    assert not changed, f"{len(changed)} digests changed, first: {changed[:10]}"


def test_simd_dependent_digests_are_unchanged(digests):
    sets = json.loads(GOLDEN_SIMD.read_text())
    target = simd_target()
    if target not in sets:
        pytest.skip(f"no opcode and enclosure digests recorded for numpy's {target} kernels "
                    f"(recorded: {sorted(sets)}); `python -m tests.golden.digests` on such a "
                    "machine adds them")
    _, got = digests
    expected = sets[target]
    assert sorted(got) == sorted(expected), "the set of golden cases changed"
    changed = sorted(k for k in expected if got[k] != expected[k])
    assert not changed, f"{len(changed)} digests changed, first: {changed[:10]}"
