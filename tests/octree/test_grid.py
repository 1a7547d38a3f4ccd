"""The grid: cubic voxels by default, the one default-bounds rule, per-axis only when asked."""
from __future__ import annotations

import numpy as np
import pytest

from implicitvox.octree.grid import MAX_RESOLUTION, Grid, padded_bounds


def test_resolution_counts_cubes_along_the_longest_side():
    g = Grid.from_bounds(((0, 0, 0), (2.0, 0.61, 1.0)), 20)
    assert g.cubic and g.voxel_size == (0.1, 0.1, 0.1) and g.shape == (20, 7, 10)
    hi = g.bounds[1]
    assert hi[1] >= 0.61 and hi[1] - 0.61 < 0.1     # past the bounds by less than a voxel


def test_a_side_that_divides_evenly_gets_no_extra_voxel():
    # 0.3 / 0.1 is 2.9999999999999996 in floats: still 3 voxels, not 4
    g = Grid.from_bounds(((0, 0, 0), (1.0, 0.3, 0.7)), voxel_size=0.1)
    assert g.shape == (10, 3, 7)


def test_per_axis_sizes_only_when_asked():
    g = Grid.from_bounds(((0, 0, 0), (1, 2, 3)), (10, 10, 10))
    assert not g.cubic and g.voxel_size == (0.1, 0.2, 0.3)
    g = Grid.from_bounds(((0, 0, 0), (1, 2, 3)), voxel_size=(0.5, 0.5, 1.0))
    assert g.shape == (2, 4, 3)


def test_resolution_or_voxel_size_and_their_limits():
    with pytest.raises(ValueError, match="one of resolution"):
        Grid.from_bounds(((0, 0, 0), (1, 1, 1)))
    with pytest.raises(ValueError, match="one of resolution"):
        Grid.from_bounds(((0, 0, 0), (1, 1, 1)), 8, voxel_size=0.1)
    with pytest.raises(ValueError, match="over the octree"):
        Grid.from_bounds(((0, 0, 0), (1, 1, 1)), voxel_size=1e-9)
    assert Grid.from_bounds(((0, 0, 0), (1, 1, 1)), MAX_RESOLUTION).depth == 21


def test_default_bounds_grow_by_half_a_voxel():
    lo, hi = padded_bounds(((0, 0, 0), (4, 2, 1)), 9)      # voxel 4 / 8 = 0.5
    np.testing.assert_allclose(lo, (-0.25,) * 3)
    np.testing.assert_allclose(hi, (4.25, 2.25, 1.25))
    g = Grid.from_bounds((lo, hi), 9)
    centres = g.centers(np.array([[0, 0, 0], [8, 0, 0]]))
    np.testing.assert_allclose(centres[:, 0], (0.0, 4.0))   # first and last centres on the extremes
    flat = padded_bounds(((0, 0, 5), (2, 2, 5)), 5)          # a flat shape gets depth
    assert flat[1][2] - flat[0][2] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="no extent"):
        padded_bounds(((1, 1, 1), (1, 1, 1)), 8)


def test_finer_keeps_every_edge():
    g = Grid.from_bounds(((-1.1, -0.3, -1), (1.2, 0.35, 1)), 23)
    f = g.finer(3)
    m = np.arange(g.shape[1] + 1)
    assert np.array_equal(g.edge(1, m), f.edge(1, 8 * m))
