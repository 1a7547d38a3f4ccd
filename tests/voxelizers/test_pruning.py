"""Pruning changes nothing in the result: voxels, interior and normals are
bit-identical with and without it (digests), on the never-miss models, the
OpenSCAD fixtures, the many-part examples and random CSG trees."""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import implicitvox as ivx
from csg import Box, Cylinder, Sphere, read_openscad
from implicitvox.expr.examples import drilled_plate, menger, sphere_union
from implicitvox.octree import descend
from implicitvox.octree import subdivide as subdivision
from tests.properties.test_never_misses import MODELS

FIXTURES = Path(__file__).resolve().parents[1] / "openscad"
RES = 40


@pytest.fixture(autouse=True)
def prune_every_tape(monkeypatch):
    """Prune tapes of any length at every level above the voxels (the defaults leave
    short tapes and the last levels alone, for speed), so these small models and
    grids exercise the pruned paths: the array subdivision's knobs, and the compiled
    one's cost of a derivation."""
    monkeypatch.setattr(subdivision, "PRUNE_MIN_LENGTH", 0)
    monkeypatch.setattr(subdivision, "PRUNE_MIN_BELOW", 1)
    monkeypatch.setattr(subdivision, "PRUNE_EVERY", 1)
    monkeypatch.setattr(descend, "DERIVE_COST", 0)


def _digest(vox) -> str:
    h = hashlib.sha256(vox.coords().tobytes())
    for level in sorted(vox.interior):
        h.update(f"{level}:".encode() + np.ascontiguousarray(vox.interior[level]).tobytes())
    if vox.normals is not None:
        h.update(vox.normals.tobytes())
    return h.hexdigest()


def _both(shape, res=RES, **options):
    pruned = ivx.voxelize(shape, res, prune=True, **options)
    whole = ivx.voxelize(shape, res, prune=False, **options)
    assert whole.metadata["tapes_built"] == 0
    assert pruned.count == whole.count
    assert _digest(pruned) == _digest(whole)
    return pruned


@pytest.mark.parametrize("name", sorted(MODELS))
def test_never_miss_models(name):
    expr, bounds, _ = MODELS[name]()
    vox = _both(expr, bounds=bounds, interior=True, normals=True)
    if any(op in repr(expr) for op in ("min(", "max(")):
        assert vox.metadata["tapes_built"] > 0, "nothing was pruned"


@pytest.mark.parametrize("options", [{"mean_value": True}, {"subvoxel": 1, "normals": True},
                                     {"recheck": 4.0}, {"recheck": 0.0, "interior": True}])
@pytest.mark.parametrize("name", ["csg-box-minus-ball", "gear", "polar-teeth"])
def test_options(name, options):
    expr, bounds, _ = MODELS[name]()
    _both(expr, bounds=bounds, **options)


@pytest.mark.parametrize("model", sorted(p.stem for p in FIXTURES.glob("*.csg")))
def test_openscad_fixtures(model):
    _both(read_openscad(FIXTURES / f"{model}.csg", facets="true"), interior=True, normals=True)


@pytest.mark.parametrize("shape", [menger(2), sphere_union(40), drilled_plate(6, 6)],
                         ids=["menger", "spheres", "drilled-plate"])
def test_many_part_models_are_pruned_and_identical(shape, monkeypatch):
    vox = _both(shape, 64, interior=True, normals=True)
    assert vox.metadata["tapes_built"] > 0, "nothing was pruned"
    monkeypatch.undo()   # and with the default policy
    assert _both(shape, 64).count == vox.count


@st.composite
def solids(draw):
    """Random unions, intersections and differences of 2-50 csg primitives."""
    coord = st.floats(-1.0, 1.0, allow_nan=False)
    size = st.floats(0.1, 0.8, allow_nan=False)
    parts = []
    for _ in range(draw(st.integers(2, 50))):
        centre = tuple(draw(coord) for _ in range(3))
        kind = draw(st.sampled_from(["sphere", "box", "cylinder"]))
        if kind == "sphere":
            part = Sphere(draw(size), center=centre)
        elif kind == "box":
            part = Box(tuple(draw(size) for _ in range(3)), center=True).translate(centre)
        else:
            part = Cylinder(h=draw(size), r=draw(size) / 2, center=True).translate(centre)
        parts.append(part)
    while len(parts) > 1:
        k = draw(st.integers(0, len(parts) - 2))
        a, b = parts[k], parts.pop(k + 1)
        parts[k] = draw(st.sampled_from([a | b, a & b, a - b]))
    return parts[0]


@settings(max_examples=12, deadline=None)
@given(solids())
def test_random_csg_trees(solid):
    bounds = ((-1.5,) * 3, (1.5,) * 3)
    _both(solid, 24, bounds=bounds, interior=True, normals=True)


@pytest.mark.parametrize("carry", ["as is", "copy", "pickle"])
def test_subtrees_continue_on_the_heads_pruned_tapes(carry):
    """A head run's pending octants keep their pruned tapes; continued from them in
    a copied or pickled pool (as a thread or a process does), the pieces find the
    serial run's voxels and interior, and the head's pool is left as it was."""
    import pickle

    from implicitvox.eval.function import Function
    from implicitvox.octree.grid import Grid
    from implicitvox.octree.octants import PrunedTapes

    func = Function(menger(2).expr)
    grid = Grid.from_bounds(((-1.0,) * 3, (1.0,) * 3), 64)
    serial = subdivision.subdivide(func, grid, interior=True)
    head = subdivision.subdivide(func, grid, interior=True, until_level=3)
    seeds = head.pending_tapes
    assert seeds is not None and len(seeds) == len(head.pending)
    assert (seeds.tapes > 0).any(), "no pending octant has a pruned tape"
    pool = seeds.pool
    before = (len(pool), pool.rows[:pool.used[0]].copy())
    twin = {"as is": pool, "copy": pool.copy(),
            "pickle": pickle.loads(pickle.dumps(pool))}[carry]
    assert len(twin) == len(pool)
    assert all(twin.tape(i).instructions == pool.tape(i).instructions for i in range(len(pool)))
    codes, interior = [head.codes], {lvl: [c] for lvl, c in head.interior.items()}
    for part in np.array_split(np.arange(len(head.pending)), 3):
        coords = subdivision.unpack(head.pending[part])
        piece = subdivision.subdivide(func, grid, interior=True, start=(3, coords),
                                      start_tapes=PrunedTapes(twin, seeds.tapes[part]))
        codes.append(piece.codes)
        for lvl, c in piece.interior.items():
            interior.setdefault(lvl, []).append(c)
    assert np.array_equal(np.sort(np.concatenate(codes)), np.sort(serial.codes))
    for lvl, c in serial.interior.items():
        joined = np.concatenate(interior[lvl])
        assert np.array_equal(joined[np.lexsort(joined.T[::-1])], c[np.lexsort(c.T[::-1])])
    assert len(pool) == before[0] and np.array_equal(pool.rows[:pool.used[0]], before[1])


def _pool_sizes(monkeypatch) -> list:
    """Record, after each call of the compiled descent, whether it has run out of room
    and the rows its pool holds."""
    seen = []
    original = descend.Descent.children

    def spy(self, *args, **kwargs):
        out = original(self, *args, **kwargs)
        seen.append((self.filled, len(self.pool.rows)))
        return out
    monkeypatch.setattr(descend.Descent, "children", spy)
    return seen


def test_a_small_model_keeps_a_small_tape_pool(monkeypatch):
    seen = _pool_sizes(monkeypatch)
    solid = (Box((1.0, 1.0, 1.0), center=True) | Sphere(0.6, center=(0.5, 0.0, 0.0))) \
        - Cylinder(h=2.0, r=0.2, center=True)
    _both(solid, 128)
    assert seen and not any(filled for filled, _ in seen)
    assert max(rows for _, rows in seen) <= 1 << 14


def test_a_pool_that_runs_out_gives_the_same_voxels(monkeypatch):
    monkeypatch.setattr(descend, "RESERVE_TAPES", 1)
    monkeypatch.setattr(descend, "RESERVE_GROWTH", 1)
    seen = _pool_sizes(monkeypatch)
    _both(sphere_union(40), 64, interior=True, normals=True)
    assert any(filled for filled, _ in seen)
