"""Exact ray-crossing winding numbers: the bucket grid changes nothing, and stays small."""
import numpy as np
import pyvista as pv

from implicitvox.triangles import crossings
from implicitvox.triangles.crossings import RayWinding
from implicitvox.triangles.inputs import as_triangles
from implicitvox.triangles.ranges import ENTRIES_PER_ITEM


def _one_cell(monkeypatch, tris: np.ndarray) -> RayWinding:
    """The same winding numbers with every triangle in one cell (no grid at all)."""
    with monkeypatch.context() as m:
        m.setattr(crossings, "CELLS_PER_ROOT", 1e-9)
        plain = RayWinding(tris)
    assert plain.cells == 1
    return plain


def test_points_on_cell_and_shadow_edges_find_their_triangles(monkeypatch):
    # no slack around a shadow's cells: a point on the edge of a shadow's box (a
    # vertex's y or z) or on a cell boundary must still meet the shadow's triangles
    v, f = as_triangles(pv.Sphere(radius=1.0, theta_resolution=17, phi_resolution=13))
    tris = v[f]
    grid = RayWinding(tris)
    assert grid.cells > 4
    rng = np.random.default_rng(5)
    corners = tris.reshape(-1, 3)
    p = rng.uniform(-1.2, 1.2, (6000, 3))
    p[:2000, 1] = corners[rng.integers(len(corners), size=2000), 1]
    p[2000:4000, 2] = corners[rng.integers(len(corners), size=2000), 2]
    k = rng.integers(0, grid.cells + 1, size=(2000, 2))
    p[4000:, 1:] = grid.lo2 + k * grid.size                  # cell boundaries
    expected = _one_cell(monkeypatch, tris)(p)
    assert np.array_equal(grid(p), expected)
    assert set(np.unique(expected)) == {0, 1}                # both sides are tested


def test_long_thin_triangles_coarsen_the_grid_instead_of_filling_memory(monkeypatch):
    # 1,000 slivers whose shadows' boxes each cover the whole yz square: a grid of
    # 2 sqrt(n) cells a side would hold 4 million (cell, triangle) entries
    n = 1000
    t = np.linspace(0.0, 1.0, n)
    tris = np.stack([np.stack([t, np.zeros(n), np.zeros(n)], 1),
                     np.stack([t, np.ones(n), np.ones(n)], 1),
                     np.stack([t + 1e-3, np.ones(n), np.full(n, 1.001)], 1)], axis=1)
    grid = RayWinding(tris)
    assert len(grid.cell_tris) <= max(ENTRIES_PER_ITEM * n, 1 << 20)
    p = np.random.default_rng(2).uniform(-0.1, 1.1, (1500, 3))
    assert np.array_equal(grid(p), _one_cell(monkeypatch, tris)(p))


def _grid_boxes(n: int, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The kept cells of an n³ grid over [-1.2, 1.2]³ as boxes (corners computed per
    cell, as the octree computes them: shared faces are equal floats)."""
    ijk = np.argwhere(keep)
    edges = np.linspace(-1.2, 1.2, n + 1)
    return edges[ijk], edges[ijk + 1]


def test_face_groups_join_boxes_sharing_faces_and_no_others():
    # two slabs of cells with a gap, and two cells touching only along an edge
    keep = np.zeros((8, 8, 8), dtype=bool)
    keep[0:2] = True
    keep[4:6] = True
    lo, hi = _grid_boxes(8, keep)
    lo = np.concatenate([lo, [[5.0, 5, 5], [6, 6, 5]]])
    hi = np.concatenate([hi, [[6.0, 6, 6], [7, 7, 6]]])
    group, first = crossings.face_groups(lo, hi)
    assert len(first) == 4
    slab = lo[:, 0] < -0.5
    assert len(np.unique(group[:len(slab) - 2][slab[:-2]])) == 1
    assert group[-1] != group[-2]
    assert np.array_equal(group[first], np.arange(len(first)))


def test_boxes_off_the_surface_get_the_winding_of_their_corners():
    # every grid cell that no triangle of a faceted sphere meets: one query per
    # group, the same numbers as asking each box's own corner
    v, f = as_triangles(pv.Sphere(radius=1.0, theta_resolution=17, phi_resolution=13))
    winding = RayWinding(v[f])
    from implicitvox.triangles.tribox import Triangles
    tris = Triangles(v[f])
    lo, hi = _grid_boxes(16, np.ones((16, 16, 16), dtype=bool))
    box = np.repeat(np.arange(len(lo)), len(f))
    tri = np.tile(np.arange(len(f)), len(lo))
    met = np.zeros(len(lo), dtype=bool)
    met[box[tris.meet_boxes(tri, lo[box], hi[box])]] = True
    lo, hi = lo[~met], hi[~met]
    w = winding.of_boxes(lo, hi)
    assert np.array_equal(w, winding(lo))
    assert set(np.unique(w)) == {0, 1}
    assert len(crossings.face_groups(lo, hi)[1]) == 2        # inside and outside


def test_the_compiled_crossings_are_the_array_paths():
    """Per (point, triangle) pair, the compiled crossing equals the exact array path's,
    rays through shadow vertices and edges (simulation of simplicity) included; scaled
    by 2**-1000 the filters are unsure of nearly every sign and the exact path answers."""
    from implicitvox.triangles.crossing_kernels import crossing_pairs
    from implicitvox.triangles.tribox_kernels import UNSURE
    v, f = as_triangles(pv.Cube(x_length=2.0, y_length=2.0, z_length=2.0))
    w, g = as_triangles(pv.Sphere(radius=1.0, theta_resolution=9, phi_resolution=7))
    tris = np.concatenate([v[f], w[g]])
    rng = np.random.default_rng(7)
    corners = tris.reshape(-1, 3)
    p = rng.uniform(-1.5, 1.5, (400, 3))
    p[:150, 1:] = corners[rng.integers(len(corners), size=150), 1:]    # through vertices
    p[150:250, 1:] = np.round(p[150:250, 1:] * 2) / 2                  # on the cube's edges
    plain = RayWinding(tris)
    for scale in (1.0, 2.0 ** -1000):
        ray = RayWinding(tris * scale)
        pairs = np.flatnonzero(ray.tris.normal_sign[:, 0] != 0)
        tri = np.tile(pairs, len(p))
        q = np.repeat(p * scale, len(pairs), axis=0)
        want = ray.crossings_by_arrays(tri, q)
        assert set(np.unique(want)) == {-1, 0, 1}
        got = crossing_pairs(ray.tris, tri, q).astype(np.int64)
        sure = got != UNSURE
        assert np.array_equal(got[sure], want[sure])
        unsure_crossings = (got[want != 0] == UNSURE).mean()
        # unscaled, the filters certify nearly every crossing; scaled, none (exact path)
        assert unsure_crossings < 0.1 if scale == 1.0 else unsure_crossings == 1.0
        assert np.array_equal(ray(p * scale), plain(p))
