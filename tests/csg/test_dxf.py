"""DXF import as OpenSCAD 2021.01 does it (csg.dxf), and polygon functions with no
inner seams (csg.planar): checked against point-in-polygon and exact meshes."""
from __future__ import annotations

from pathlib import Path

import ezdxf
import numpy as np
import pytest
from skimage.measure import points_in_poly

import csg
import implicitvox as iv
from csg import dxf
from csg.dxf import read_dxf
from csg.planar import Polygon

DRAWING = Path(__file__).resolve().parents[1] / "openscad" / "drawing.dxf"


def _save(doc, tmp_path, name="t.dxf") -> Path:
    path = tmp_path / name
    doc.saveas(path)
    return path


def test_layers_origin_and_scale():
    plate = read_dxf(DRAWING, layer="plate")
    assert len(plate.paths) == 4                 # outline, slot, hole, ellipse
    assert np.allclose(np.array(plate.bounds)[:, :2], [(0, 0), (40, 25)])
    plate = read_dxf(DRAWING, layer="plate", fn=16)        # fragments not by size
    moved = read_dxf(DRAWING, layer="plate", origin=(10, 5), scale=2, fn=16)
    outline = plate.points[plate.paths[0]]                 # (OpenSCAD moves an ellipse's
    assert np.allclose(moved.points[moved.paths[0]],       # axis too: it is left out here)
                       (outline - [10, 5]) * 2, atol=2 * dxf.GRID)
    everything = read_dxf(DRAWING)
    assert len(everything.paths) == sum(len(read_dxf(DRAWING, layer=k).paths)
                                        for k in ("plate", "tab", "teeth"))


def test_points_snap_to_openscads_grid_and_chain(tmp_path):
    """Ends within the grid's 2^-10 join; every point is a multiple of it."""
    doc = ezdxf.new()
    msp = doc.modelspace()
    corners = [(0, 0), (3, 0), (3, 2), (0, 2)]
    for k, (a, b) in enumerate(zip(corners, corners[1:] + corners[:1])):
        a = (a[0] + 3e-4 * (k % 2), a[1])        # ends off by less than a grid step
        msp.add_line(a, b)
    region = read_dxf(_save(doc, tmp_path))
    assert len(region.paths) == 1 and len(region.points) == 4
    assert np.all(region.points / dxf.GRID == np.round(region.points / dxf.GRID))


def test_arcs_take_openscads_fragments(tmp_path):
    doc = ezdxf.new()
    doc.modelspace().add_circle((0, 0), 10)
    doc.modelspace().add_arc((30, 0), 10, 0, 90)
    doc.modelspace().add_line((30, 0), (40, 0))
    doc.modelspace().add_line((30, 10), (30, 0))
    path = _save(doc, tmp_path)
    region = read_dxf(path, fn=12)
    sizes = sorted(len(p) for p in region.paths)
    assert sizes == [5, 12]                     # a quarter of 12 fragments (3) + the corner
    default = read_dxf(path)                    # $fa = 12, $fs = 2: 30 fragments for r = 10
    assert sorted(len(p) for p in default.paths) == [10, 30]


def test_open_paths_are_closed_and_blocks_placed(tmp_path):
    doc = ezdxf.new()
    doc.modelspace().add_lwpolyline([(0, 0), (4, 0), (2, 3)])          # open
    block = doc.blocks.new("B")
    block.add_lwpolyline([(0, 0), (1, 0), (1, 1), (0, 1)], close=True)
    doc.modelspace().add_blockref("B", (10, 0), dxfattribs={"xscale": 2, "rotation": 90})
    region = read_dxf(_save(doc, tmp_path), scale=3)
    triangle, square = sorted(region.paths, key=len)
    assert len(triangle) == 3
    box = region.points[square]
    # the block scaled by 2 in x, turned by 90 degrees, scaled by 3, at (10, 0) * 3
    assert np.allclose(box.min(axis=0), [30 - 3, 0], atol=dxf.GRID)
    assert np.allclose(box.max(axis=0), [30, 6], atol=dxf.GRID)


def test_unsupported_entities_warn_and_bad_files_are_named(tmp_path):
    doc = ezdxf.new()
    doc.modelspace().add_lwpolyline([(0, 0), (1, 0), (1, 1)], close=True)
    doc.modelspace().add_text("hello")
    with pytest.warns(csg.OpenSCADWarning, match="unsupported DXF entity 'TEXT'"):
        assert read_dxf(_save(doc, tmp_path)) is not None
    garbage = tmp_path / "garbage.dxf"
    garbage.write_bytes(b"\x00\x01 not a drawing \xff" * 50)
    with pytest.raises(ValueError, match="garbage.dxf: not a readable DXF file"):
        read_dxf(garbage)
    empty = ezdxf.new()
    empty.modelspace().add_line((0, 0), (1, 1))            # no area
    assert read_dxf(_save(empty, tmp_path, "line.dxf")) is None


def test_segments_are_bounded(tmp_path, monkeypatch):
    doc = ezdxf.new()
    doc.modelspace().add_circle((0, 0), 1)
    monkeypatch.setattr(dxf, "MAX_SEGMENTS", 10)
    with pytest.raises(ValueError, match="over 10 segments"):
        read_dxf(_save(doc, tmp_path), fn=64)


def _comb(teeth: int) -> np.ndarray:
    """A comb: a spine with ``teeth`` deep, narrow teeth (many pockets)."""
    pts = [(0.0, 0.0), (2.0 * teeth, 0.0)]
    for k in range(teeth - 1, -1, -1):
        pts += [(2.0 * k + 1.2, 1.0), (2.0 * k + 1.2, 6.0), (2.0 * k + 0.8, 6.0), (2.0 * k + 0.8, 1.0)]
    return np.array(pts[:2] + [(2.0 * teeth, 1.0)] + pts[2:] + [(0.0, 1.0)])


def _star(rng, k: int) -> np.ndarray:
    a = np.sort(rng.uniform(0, 2 * np.pi, k))
    r = rng.uniform(0.2, 1.0, k)
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


def test_polygon_sign_is_point_in_polygon():
    rng = np.random.default_rng(3)
    for poly in [_comb(5), _comb(12)] + [_star(rng, int(rng.integers(5, 40))) for _ in range(30)]:
        f = iv.Function(Polygon(poly).expr)
        lo, hi = poly.min(axis=0) - 0.5, poly.max(axis=0) + 0.5
        q = rng.uniform(lo, hi, (3000, 2))
        value = f(q[:, 0], q[:, 1], np.zeros(len(q)))
        assert np.array_equal(value < 0, points_in_poly(q, poly))


def test_extruded_polygon_has_the_prisms_voxels():
    """A non-convex polygon extruded holds every voxel of the exact voxelization of
    its prism's triangle mesh, and adds only voxels within a voxel of a corner
    (where the interval extension of the pockets' max and min cannot decide).
    A triangulation's inner edges, where a min over triangles is 0, used to add
    false surface voxels along every inner edge."""
    from csg import facets as fx
    rng = np.random.default_rng(5)
    for poly in (_comb(6), _star(rng, 25)):
        solid = csg.linear_extrude(Polygon(poly), 1.93)     # caps off the voxel faces
        v, f = fx.extrusion_mesh(poly, 1.93, 0.0, np.ones(2), 1, 0.0)
        mesh = iv.voxelize_mesh((v, f), 64)
        vox = solid.voxelize(bounds=mesh.bounds, voxel_size=mesh.voxel_size)
        assert vox.contains(mesh.coords()).all()
        extra = vox.coords()[~mesh.contains(vox.coords())]
        centres = np.stack([vox.grid.edge(a, extra[:, a]) + vox.voxel_size[a] / 2
                            for a in range(2)], axis=1)
        to_corner = np.linalg.norm(centres[:, None, :] - poly[None], axis=2).min(axis=1)
        assert np.all(to_corner <= np.linalg.norm(vox.voxel_size[:2]))
        assert len(extra) < 0.01 * mesh.count
