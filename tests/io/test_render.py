"""PyVista objects and off-screen pictures."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import implicitvox as ivx
from implicitvox.expr.examples import gear


@pytest.fixture(scope="module")
def vox():
    return ivx.voxelize(gear(), resolution=48, normals=True)


def test_points_carry_centres_and_normals(vox):
    cloud = vox.to_pyvista("points")
    assert cloud.n_points == vox.count
    np.testing.assert_allclose(cloud.points, vox.centers())
    assert cloud.point_data["Normals"].shape == (vox.count, 3)


def test_cubes_are_voxel_cells_of_the_right_volume(vox):
    cubes = vox.to_pyvista("cubes")
    assert cubes.n_cells == vox.count
    assert cubes.volume == pytest.approx(vox.count * np.prod(vox.voxel_size), rel=1e-9)
    with pytest.raises(ValueError, match="kind"):
        vox.to_pyvista("spheres")


@pytest.mark.parametrize("style", ["points", "cubes"])
def test_render_writes_a_shaded_picture(vox, tmp_path, style):
    path = vox.render(str(tmp_path / "gear.png"), style=style, window_size=(400, 300))
    image = np.asarray(Image.open(path).convert("RGB"))
    assert image.shape == (300, 400, 3)
    background = np.all(image == 255, axis=2)
    assert 0.02 < 1 - background.mean() < 0.9          # the gear covers part of the frame
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 20  # shaded, not flat


def test_render_refuses_an_unwritable_path(vox):
    with pytest.raises(ValueError, match="cannot write"):
        vox.render("/no/such/folder/x.png")


def test_render_names_the_missing_library(vox, tmp_path, monkeypatch):
    import ctypes.util
    from implicitvox.io import rendering as render_module
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)
    with pytest.raises(render_module.RenderError, match="libegl1 libegl-mesa0"):
        vox.render(str(tmp_path / "x.png"))
