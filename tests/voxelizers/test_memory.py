"""Memory: estimated before a run, guarded during it, limited by the process's own limits."""
from __future__ import annotations

import subprocess
import sys
import textwrap
import warnings

import pytest

import implicitvox as ivx
from implicitvox import sin, x, y, z
from implicitvox.eval.function import Function
from implicitvox.octree import pilot
from implicitvox.octree.grid import Grid
from implicitvox.voxelizers.implicit import estimate_memory

CUBE = ((-1.0,) * 3, (1.0,) * 3)
#: a surface that fills space: it grows x8 per level, the estimate assumes x4
WIGGLY = sin(100 * x) * sin(100 * y) * sin(100 * z)


def test_the_pilot_sees_a_surface_that_fills_space():
    """The pilot measures the growth per level: x8 here, not Stolte's x4."""
    estimate, _ = estimate_memory(Function(WIGGLY), Grid.from_bounds(CUBE, 128))
    assert estimate.growth == 8.0 and estimate.pilot_depth == 5
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        vox = ivx.voxelize(WIGGLY, 128, bounds=CUBE, workers=1)
    assert vox.count / 2 <= estimate.voxels <= 2 * vox.count
    # the refusal says how it was estimated
    with pytest.raises(MemoryError, match=r"estimated from 32,768 at a 32³ pilot growing "
                                          r"8\.0× per level"):
        ivx.voxelize(WIGGLY, 128, bounds=CUBE, max_memory=1 << 20, workers=1)


def test_a_run_that_beats_its_estimate_stops_at_the_budget(monkeypatch):
    # a pilot that assumed Stolte's x4 whatever it saw (as before it measured)
    monkeypatch.setattr(pilot, "MOST_GROWTH", pilot.LEAST_GROWTH)
    estimate, estimated = estimate_memory(Function(WIGGLY), Grid.from_bounds(CUBE, 128))
    voxels = estimate.voxels
    # the pilot (32³) finds every cell ambiguous, and extrapolates x4 per level
    assert voxels == 32 ** 3 * 4 ** 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        with pytest.raises(MemoryError, match="stopped after .* surface voxels .the estimate "
                                              f"said ~{voxels:,}.*over the budget"):
            ivx.voxelize(WIGGLY, 128, bounds=CUBE, max_memory=int(estimated * 1.1), workers=1)
        # workers need room of their own: counted in the estimate, refused before starting
        with pytest.raises(MemoryError, match=r"2 workers\) needs an estimated"):
            ivx.voxelize(WIGGLY, 128, bounds=CUBE, max_memory=int(estimated * 1.1), workers=2)
        # with room for what it really keeps, the same run completes
        vox = ivx.voxelize(WIGGLY, 128, bounds=CUBE, max_memory=int(estimated * 2), workers=1)
    assert vox.count > voxels * 1.5


def test_small_jobs_pass_under_a_small_budget():
    vox = ivx.voxelize(x * x + y * y + z * z - 0.5, 16, bounds=CUBE, max_memory=4 << 20)
    assert vox.count > 0


def test_refine_is_estimated_and_guarded_too():
    coarse = ivx.voxelize(x * x + y * y + z * z - 0.5, 16, bounds=CUBE)
    with pytest.raises(MemoryError, match="over the budget"):
        coarse.refine(4, max_memory=1 << 20)
    import pyvista as pv
    mesh = ivx.voxelize_mesh(pv.Sphere(), 16)
    with pytest.raises(MemoryError, match="over the budget"):
        mesh.refine(4, max_memory=1 << 16)


def test_the_default_budget_respects_the_address_space_limit():
    code = textwrap.dedent("""
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, resource.RLIM_INFINITY))
        from implicitvox.octree.budget import available_memory, memory_budget
        print(available_memory() <= 3 << 30, memory_budget(None) <= 3 << 29)
        """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["True", "True"], out.stderr


def test_a_surface_that_fills_the_grid_is_flagged():
    with pytest.warns(UserWarning, match="interval arithmetic could not separate"):
        ivx.voxelize(sin(60 * x) * sin(60 * y) * sin(60 * z), 32, bounds=CUBE)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        ivx.voxelize(x * x + y * y + z * z - 0.5, 32, bounds=CUBE)   # a plain sphere is not
