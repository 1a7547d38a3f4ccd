"""Nothing a user computes changes unnoticed: every digest equals the committed one.

See :mod:`tests.golden.digests` for what is hashed and how to regenerate.
"""
from __future__ import annotations

import json

from tests.golden.digests import GOLDEN, compute


def test_every_digest_is_unchanged():
    expected = json.loads(GOLDEN.read_text())
    got = compute()
    assert sorted(got) == sorted(expected), "the set of golden cases changed"
    changed = sorted(k for k in expected if got[k] != expected[k])
    assert not changed, f"{len(changed)} digests changed, first: {changed[:10]}"
