"""The one place for argument checks: each names the parameter, what it wants, what came."""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox import validate as v
from implicitvox import x, y, z

SPHERE = x * x + y * y + z * z - 1


@pytest.mark.parametrize("check, value, message", [
    (lambda x: v.positive_int(x, "levels"), 0, "levels must be a positive int, got int 0"),
    (lambda x: v.positive_int(x, "levels"), np.True_, "levels must be a positive int, got bool"),
    (lambda x: v.int_in(x, "subvoxel", 0, 4), 5, "subvoxel must be an int from 0 to 4, got int 5"),
    (lambda x: v.number_in(x, "recheck", 0, 4), float("nan"), "recheck must be a number in"),
    (lambda x: v.positive_number(x, "r"), float("inf"), "r must be a positive finite number"),
    (lambda x: v.boolean(x, "interior"), 1, "interior must be True or False, got int 1"),
    (lambda x: v.choice(x, "axis", ("x", "y", "z")), "w", "axis must be one of 'x', 'y', 'z'"),
    (lambda x: v.bounds(x), ((0, 0, 0), (1, 0, 1)), "zero or negative extent on axis y"),
    (lambda x: v.bounds(x), ((0, 0, 0), (1, np.inf, 1)), "bounds must be finite"),
    (lambda x: v.resolution(x, 64), (8, 8), "resolution must be an int or 3 ints"),
    (lambda x: v.voxel_size(x), -0.5, "voxel_size must be a positive finite number"),
    (lambda x: v.points(x), [[0, 0, np.inf]], "points holds a non-finite value \\(row 0\\)"),
    (lambda x: v.max_memory(x), float("inf"), "max_memory must be a positive number of bytes"),
    (lambda x: v.writable_path(x, "--out"), "/no/such/dir/x.npz", "cannot write --out"),
])
def test_bad_values_are_named(check, value, message):
    with pytest.raises(ValueError, match=message):
        check(value)


def test_good_values_come_back_canonical():
    assert v.positive_int(np.int64(3), "n") == 3 and type(v.positive_int(np.int64(3), "n")) is int
    assert v.resolution([4, 5, 6], 64) == (4, 5, 6)
    assert v.max_memory(1.5e9) == 1_500_000_000 and v.max_memory(None) is None
    assert v.points([1, 2, 3]).shape == (1, 3)
    assert v.points([[0, -np.inf, 0]], finite=False).shape == (1, 3)


@pytest.mark.parametrize("call, message", [
    # bounds too small for a normal voxel size, or spanning more than a float holds
    (lambda: ivx.voxelize(SPHERE, 8, bounds=((0, 0, 0), (5e-324,) * 3)),
     r"extent of 5e-324 on axis x, below .*MIN_EXTENT"),
    (lambda: ivx.voxelize(SPHERE, 8, bounds=((-1e308,) * 3, (1e308,) * 3)),
     "extent on axis x beyond the largest float"),
    (lambda: ivx.voxelize(SPHERE, voxel_size=5e-324, bounds=((0,) * 3, (1,) * 3)),
     "voxel_size 5e-324 gives inf voxels on axis x"),
    (lambda: ivx.voxelize(SPHERE, 8, bounds=((-1,) * 3, (1,) * 3), progress="notcallable"),
     "progress must be None or a callable"),
    (lambda: ivx.mesh(SPHERE, 0.5, bounds=((-1,) * 3, (1,) * 3), progress=3),
     "progress must be None or a callable"),
    (lambda: ivx.repeat(SPHERE, spacing=(1.5, None, None), count=1.5),
     "count on x .or None. must be a positive int, got float 1.5"),
    (lambda: ivx.repeat_polar(SPHERE, 1.5), "must be a positive int, got float 1.5"),
])
def test_hostile_arguments_name_the_parameter(call, message):
    """No deep traceback from numpy or math: a ValueError raised by the checks."""
    with pytest.raises(ValueError, match=message) as info:
        call()
    assert info.traceback[-1].path.name == "validate.py" or \
        "octree/grid.py" in str(info.traceback[-1].path)
