"""Closed meshes: volume, hull, convexity (implicitvox.triangles.closed)."""
import numpy as np
import pytest

from implicitvox.triangles.closed import hull_mesh, is_convex_mesh, mesh_volume


def test_hull_mesh_is_outward_and_its_volume_is_the_boxes():
    corners = np.array([[i, j, k] for i in (0, 2) for j in (0, 1) for k in (0, 3)], float)
    v, f = hull_mesh(corners)
    assert mesh_volume(v, f) == pytest.approx(6.0) and is_convex_mesh(v, f)
    assert mesh_volume(v, f[:, ::-1]) == pytest.approx(-6.0)


@pytest.mark.parametrize("points", [
    np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]]),                # flat
    np.array([[0, 0, 0], [1e308, 0, 0], [0, 1e308, 0], [0, 0, 1e308]]),      # overflowing
])
def test_a_hull_without_volume_is_a_value_error_not_qhulls(points):
    with pytest.raises(ValueError, match="has no volume, or its points are beyond"):
        hull_mesh(points)
