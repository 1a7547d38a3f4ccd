"""Test configuration: a reproducible hypothesis profile for CI.

Locally, hypothesis draws new examples each run (and keeps failures in its
database); with ``CI`` set, the ``ci`` profile derandomizes, so a CI run
executes a fixed, reproducible set of examples and cannot flake.

pytest-xdist runs one test per core already, so runs that do not ask for
workers stay serial (``IMPLICITVOX_WORKERS=1``, the default a user sets the
same way); the parallel tests ask for theirs (``tests/parallel``), and one
checks the default itself.
"""
from __future__ import annotations

import os

from hypothesis import settings

os.environ.setdefault("IMPLICITVOX_WORKERS", "1")

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)


def pytest_configure(config):
    """Compile the kernel once, here in the controller, before pytest-xdist starts its
    workers: they (and the processes the tests start) then load Numba's on-disk
    cache instead of each compiling the same functions (about 25 s apiece cold)."""
    if hasattr(config, "workerinput"):       # a worker: the controller did it
        return
    from implicitvox.linf import mesh_walk
    from implicitvox.octree.descend import warm_up
    warm_up()
    mesh_walk.warm_up()
if os.environ.get("CI"):
    settings.load_profile("ci")
