"""Test configuration: a reproducible hypothesis profile for CI.

Locally, hypothesis draws new examples each run (and keeps failures in its
database); with ``CI`` set, the ``ci`` profile derandomizes, so a CI run
executes a fixed, reproducible set of examples and cannot flake.
"""
from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")
