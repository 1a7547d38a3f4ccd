"""OpenSCAD's ``surface`` (csg.heightmap): tables and images read as OpenSCAD 2021.01
reads them, closed meshes, bad files named (the fixture surface.scad compares with
OpenSCAD's own STL)."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

import csg
from csg import heightmap
from csg.heightmap import heightmap_mesh, read_heights


def _polydata(v, f):
    return pv.PolyData(v, np.hstack([np.full((len(f), 1), 3), f]))


def test_dat_rows_comments_and_short_rows(tmp_path):
    path = tmp_path / "t.dat"
    path.write_text("# heights\n\n1 2\t3\n  # another comment\n4 5\n")
    assert read_heights(path).tolist() == [[1, 2, 3], [4, 5, 0]]


@pytest.mark.parametrize("rows", [[[1, 2, 3], [4, 5, 6]], [[5, 6, 7], [8, 9, 10]],
                                  [[-3, 0.5, 2, 1], [0, 1, -1, 4], [2, 2, 2, 2]]])
def test_mesh_is_closed_outward_and_holds_the_volume(tmp_path, rows):
    """Each cell's four triangles meet at the mean of its corners: the volume above
    the bottom is, per cell, the mean of its corners minus the bottom; the bottom
    is at min(0, lowest - 1), as in OpenSCAD 2021.01."""
    table = np.array(rows, dtype=float)
    path = tmp_path / "t.dat"
    np.savetxt(path, table)
    v, f = heightmap_mesh(path)
    mesh = _polydata(v, f)
    bottom = min(0.0, table.min() - 1)
    cells = (table[:-1, :-1] + table[:-1, 1:] + table[1:, :-1] + table[1:, 1:]) / 4
    assert mesh.is_manifold
    assert mesh.volume == pytest.approx(float((cells - bottom).sum()), rel=1e-12)
    assert v[:, 2].min() == bottom
    # outward: the signed volume (divergence theorem) equals the volume only if the
    # triangles face out consistently
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    assert np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6 == pytest.approx(mesh.volume)
    centred, _ = heightmap_mesh(path, center=True)
    assert np.allclose(centred[:, :2].min(axis=0), -centred[:, :2].max(axis=0))


def test_png_heights_as_openscad_computes_them(tmp_path):
    import imageio.v3 as iio
    image = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], np.uint8)
    path = tmp_path / "t.png"
    iio.imwrite(path, image)
    luma = 0.2126 * image[..., 0] + 0.7152 * image[..., 1] + 0.0722 * image[..., 2]
    assert np.allclose(read_heights(path), 100 / 255 * luma[::-1])          # top row at top
    assert np.allclose(read_heights(path, invert=True), 100 / 255 * (1 - luma[::-1]))
    grey = tmp_path / "g.png"
    iio.imwrite(grey, np.array([[0, 51], [102, 255]], np.uint8))
    assert np.allclose(read_heights(grey), 100 / 255 * np.array([[102, 255], [0, 51]]))


def test_bad_files_are_named(tmp_path, monkeypatch):
    bad = tmp_path / "bad.dat"
    bad.write_text("1 2\n3 x\n")
    with pytest.raises(ValueError, match=r"bad.dat:2: not a number"):
        read_heights(bad)
    flat = tmp_path / "flat.dat"
    flat.write_text("1 2 3\n")
    with pytest.raises(ValueError, match="1 x 3 heights span no area"):
        heightmap_mesh(flat)
    broken = tmp_path / "broken.png"
    broken.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\x00" * 40)
    with pytest.raises(ValueError, match="broken.png: cannot read the PNG image"):
        read_heights(broken)
    big = tmp_path / "big.dat"
    big.write_text("1 2 3\n4 5 6\n")
    monkeypatch.setattr(heightmap, "MAX_SAMPLES", 4)
    with pytest.raises(ValueError, match="over 4 heights"):
        read_heights(big)


def test_surface_in_a_csg_file(tmp_path):
    (tmp_path / "h.dat").write_text("0 1\n1 2\n")
    solid = csg.read_openscad('surface(file = "h.dat", center = true, invert = false);',
                              base=tmp_path, facets="true")
    assert solid.bounds == ((-0.5, -0.5, -1.0), (0.5, 0.5, 2.0))
    with pytest.warns(csg.OpenSCADWarning, match="surface: cannot open"):
        csg.read_openscad('surface(file = "gone.dat"); cube(1);', base=tmp_path, facets="true")


def test_a_short_row_does_not_lower_the_bottom(tmp_path):
    """OpenSCAD's test model issue1223: a last row of one height leaves the others 0,
    and OpenSCAD's bottom is still min(0, lowest given height - 1) = 0, not -1."""
    path = tmp_path / "short.dat"
    path.write_text("9 6 7\n6 8 9\n5 3 2\n2\n")
    v, _ = heightmap_mesh(path)
    assert v[:, 2].min() == 0.0
    assert read_heights(path)[3].tolist() == [2.0, 0.0, 0.0]
