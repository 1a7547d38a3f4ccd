"""Files: .npz bit for bit, .binvox read by an independent reader, .vti."""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox.expr.examples import gear, sinsin


@pytest.fixture(scope="module")
def vox():
    """Cubic voxels on a box that is not a cube (the gear's short axis)."""
    return ivx.voxelize(gear(), resolution=40, interior=True, normals=True)


def test_npz_round_trips_bit_for_bit(vox, tmp_path):
    back = ivx.load(vox.save(str(tmp_path / "v.npz")))
    assert back.grid == vox.grid
    for a, b in zip(vox.octree.masks + vox.octree.first, back.octree.masks + back.octree.first):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    assert back.normals.dtype == vox.normals.dtype
    assert back.normals.tobytes() == vox.normals.tobytes()
    assert sorted(back.interior) == sorted(vox.interior)
    for level in vox.interior:
        assert np.array_equal(back.interior[level], vox.interior[level])
    assert back.metadata["model"] == vox.metadata["model"]


def test_binvox_reads_back_with_trimesh(vox, tmp_path):
    from trimesh.exchange.binvox import load_binvox
    path = str(tmp_path / "v.binvox")
    vox.save(path)
    with open(path, "rb") as fh:
        grid = load_binvox(fh)
    dim = max(vox.resolution)
    expected = np.zeros((dim,) * 3, dtype=bool)
    n0, n1, n2 = vox.resolution
    expected[:n0, :n1, :n2] = vox.to_dense()
    assert np.array_equal(np.asarray(grid.matrix, dtype=bool), expected)
    back = ivx.load(path)  # and our own reader agrees
    assert np.array_equal(back.to_dense()[:n0, :n1, :n2], vox.to_dense())


def test_binvox_lands_on_the_same_voxels_with_the_binvox_package(vox, tmp_path):
    """The PyPI ``binvox`` reader: same voxels, at the same world positions."""
    from binvox import Binvox
    path = str(tmp_path / "v.binvox")
    vox.save(path)
    model = Binvox.read(path, "dense")
    dim = max(vox.resolution)
    assert list(model.dims) == [dim] * 3
    read = np.argwhere(model.data)
    n0, n1, n2 = vox.resolution
    expected = np.argwhere(vox.to_dense())
    assert np.array_equal(read, expected)
    # world positions from the file's translate and scale alone
    centres = np.asarray(model.translate) + (read + 0.5) * (model.scale / dim)
    np.testing.assert_allclose(centres, vox.grid.centers(expected), rtol=0, atol=1e-12)


def test_binvox_refuses_voxels_that_are_not_cubes(tmp_path):
    boxy = ivx.voxelize(sinsin(3, 4), resolution=(40, 32, 36))
    assert not boxy.grid.cubic
    with pytest.raises(ValueError, match="binvox stores cubic voxels only"):
        boxy.save(str(tmp_path / "v.binvox"))
    assert not (tmp_path / "v.binvox").exists()


def test_vti_round_trip(vox, tmp_path):
    back = ivx.load(vox.save(str(tmp_path / "v.vti")))
    assert back.resolution == vox.resolution
    np.testing.assert_allclose(back.voxel_size, vox.voxel_size)
    assert np.array_equal(back.to_dense(), vox.to_dense())


def test_bad_paths_and_files(vox, tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        vox.save(str(tmp_path / "no" / "such" / "v.npz"))
    with pytest.raises(ValueError, match="unknown voxel file type"):
        vox.save(str(tmp_path / "v.txt"))
    with pytest.raises(FileNotFoundError):
        ivx.load(str(tmp_path / "missing.npz"))
    bad = tmp_path / "bad.binvox"
    bad.write_bytes(b"not a binvox")
    with pytest.raises(ValueError, match="not a binvox"):
        ivx.load(str(bad))
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"\x00" * 100)
    with pytest.raises(ValueError, match="not an implicitvox"):
        ivx.load(str(junk))
