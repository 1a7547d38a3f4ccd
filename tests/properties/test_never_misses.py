"""The promise: no voxel the surface passes through is ever missed.

Over twelve models, at least 20,000 points on each true surface (bisection
to machine precision on segments whose ends differ in sign) must all lie in
output voxels. The dense corner-sign method, run on the same grids, misses
voxels on the thin cases.
"""
from __future__ import annotations

import numpy as np
import pytest

import implicitvox as ivx
from implicitvox import hypot, max, min, sqrt, x, y, z
from implicitvox.expr.examples import blobby, gear, lobed_plate, replicated_torus, sinsin
from implicitvox.octree.grid import Grid
from tests.support.surface import corner_sign_voxels, found, surface_brackets

RES = 64
N_POINTS = 20_000
CUBE = ((-1.0,) * 3, (1.0,) * 3)
H = 2.0 / RES

_NORMAL = np.array([0.36, 0.48, 0.8])
_NORMAL /= np.linalg.norm(_NORMAL)
_OFFSET = 0.0123456789
_SHEET_HALF_THICKNESS = H / 250  # the sheet is 1/125 of a voxel thick
_TINY_CENTER = np.array([0.01371, -0.02913, 0.00731])
_TINY_RADIUS = 0.3 * H


def _sheet():
    n = _NORMAL
    f = abs(n[0] * x + n[1] * y + n[2] * z - _OFFSET) - _SHEET_HALF_THICKNESS

    def inside(rng, count):
        p = rng.uniform(-1, 1, (count, 3))
        return p - (p @ n - _OFFSET)[:, None] * n[None]
    return f, CUBE, inside


def _tiny_sphere():
    c = _TINY_CENTER
    f = sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) - _TINY_RADIUS

    def inside(rng, count):
        d = rng.normal(size=(count, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return c + d * rng.uniform(0, 0.9 * _TINY_RADIUS, (count, 1))
    return f, CUBE, inside


def _shape(s):
    return s.expr, s.bounds, None


MODELS = {
    "sphere": lambda: (sqrt(x * x + y * y + z * z) - 0.8, CUBE, None),
    "torus": lambda: ((hypot(x, y) - 0.6) ** 2 + z ** 2 - 0.2 ** 2, CUBE, None),
    "gear": lambda: _shape(gear()),
    "sinsin34": lambda: _shape(sinsin(3, 4)),
    "sinsin918": lambda: _shape(sinsin(9, 18)),
    "blobby": lambda: _shape(blobby()),
    "thin-sheet": _sheet,
    "tiny-sphere": _tiny_sphere,
    "tangent-spheres": lambda: (min(sqrt((x + 0.4) ** 2 + y * y + z * z) - 0.4,
                                    sqrt((x - 0.4) ** 2 + y * y + z * z) - 0.4), CUBE, None),
    "csg-box-minus-ball": lambda: (max(max(abs(x), abs(y), abs(z)) - 0.6,
                                       0.75 - sqrt(x * x + y * y + z * z)), CUBE, None),
    "replicated-torus": lambda: _shape(replicated_torus()),
    "repeat-torus": lambda: (ivx.repeat((hypot(x, y) - 0.6) ** 2 + z ** 2 - 0.15 ** 2,
                                        spacing=(None, None, 0.37)), CUBE, None),
    "polar-teeth": lambda: (max(ivx.repeat_polar(sqrt((x - 0.7) ** 2 + y ** 2) - 0.08, 9),
                                abs(z) - 0.3), CUBE, None),
    "lobed-plate": lambda: _shape(lobed_plate()),
}


def _run(name, **options):
    expr, bounds, inside = MODELS[name]()
    vox = ivx.voxelize(expr, RES, bounds=bounds, **options)
    func = ivx.compile(expr)
    step = float(np.max(vox.voxel_size))
    a, b = surface_brackets(func, bounds, step, N_POINTS, np.random.default_rng(11), inside)
    return vox, func, a, b


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_surface_point_lies_in_an_output_voxel(name):
    vox, func, a, b = _run(name)
    assert len(a) == N_POINTS, f"only {len(a)} surface points sampled"
    assert np.all(func(*a.T) < 0) and np.all(func(*b.T) >= 0)
    assert np.all(np.abs(a - b) <= 4 * np.spacing(np.abs(a) + 1e-300) + 1e-300)  # bisected
    hit = found(vox.contains, vox.grid, a, b)
    assert hit.all(), f"{name}: {np.count_nonzero(~hit)} of {len(a)} surface points missed"


@pytest.mark.parametrize("name", ["sinsin34", "thin-sheet", "tiny-sphere", "gear"])
@pytest.mark.parametrize("options", [{"subvoxel": 2}, {"mean_value": True}, {"recheck": 4.0}])
def test_options_never_miss_either(name, options):
    vox, func, a, b = _run(name, **options)
    assert found(vox.contains, vox.grid, a, b).all()


@pytest.mark.parametrize("name", ["thin-sheet", "tiny-sphere"])
def test_corner_sign_method_misses_the_thin_cases(name):
    vox, func, a, b = _run(name)
    dense = corner_sign_voxels(func, vox.grid)
    corner_hit = found(lambda c: dense[c[:, 0], c[:, 1], c[:, 2]], vox.grid, a, b)
    assert not corner_hit.all(), "corner signs found every voxel of a sub-voxel feature?"
    assert found(vox.contains, vox.grid, a, b).all()


def test_surface_sampler_detects_a_missing_voxel():
    """The check can fail: drop one hit voxel and the sampler must notice."""
    vox, func, a, b = _run("sphere")
    coords = vox.coords()
    dropped = coords[len(coords) // 2]
    keep = ~np.all(coords == dropped, axis=1)
    fewer = ivx.Octree.from_coords(coords[keep], vox.grid.depth)
    a, b = surface_brackets(func, vox.bounds, float(np.max(vox.voxel_size)), 200_000,
                            np.random.default_rng(5))
    assert not found(fewer.contains, vox.grid, a, b).all()


def test_grid_voxel_lookup_agrees_with_the_edge_formula():
    grid = Grid.from_bounds(((-1.1, 0.3, -2.0), (0.9, 0.7, 5.0)), (37, 11, 64))
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(*r, 5000) for r in [(-1.1, 0.9), (0.3, 0.7), (-2, 5)]])
    pts[:100, 0] = grid.edge(0, rng.integers(0, 38, 100))  # exactly on edges
    for cand in grid.voxels_holding(pts):
        for axis in range(3):
            lo = grid.edge(axis, cand[:, axis])
            hi = grid.edge(axis, cand[:, axis] + 1)
            assert np.all((lo <= pts[:, axis]) & (pts[:, axis] <= hi))
