"""OpenSCAD's rotate_extrude as a mesh (csg.facets.rotation_mesh_outlines): closed, outward,
the volume of its trapezoid sectors, and the same solid as the sector function."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import implicitvox as ivx
from csg import Polyhedron, read_openscad
from csg.facets import rotation_mesh_outlines
from implicitvox.triangles.mesh_classifier import edges_shared

FIXTURES = Path(__file__).resolve().parents[1] / "openscad"

SQUARE = np.array([[1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0]])       # counter-clockwise
ON_AXIS = np.array([[0.0, 0.0], [1.5, 0.0], [1.0, 2.0], [0.0, 2.5]])       # an edge on x = 0
HOLED = (np.array([[1.0, -1.0], [3.0, -1.0], [3.0, 1.0], [1.0, 1.0]]),
         [np.array([[1.5, -0.5], [1.5, 0.5], [2.5, 0.5], [2.5, -0.5]])])  # hole clockwise


def _volume(v, f) -> float:
    t = v[f]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6)


def _polygon_sweep_volume(profile, holes, angle, n) -> float:
    """Pappus for the sectors: a profile point at radius rho sweeps the chord of a
    sector of width ``w``, ``2 rho sin(w / 2)`` long, at ``rho cos(w / 2)`` from the
    axis; so a region of first moment ``Mx`` (about the axis) sweeps ``sin(w) Mx``
    per sector (``2 pi Mx`` as the sectors shrink)."""
    def moment(p):                        # integral of x over the region, by Green
        x, z = p[:, 0], p[:, 1]
        x1, z1 = np.roll(x, -1), np.roll(z, -1)
        return float(np.sum((x * z1 - x1 * z) * (x + x1)) / 6)
    m = moment(profile) + sum(moment(h) for h in holes)
    w = math.radians(abs(angle) / n)
    return n * math.sin(w) * m


@pytest.mark.parametrize("angle, n", [(360.0, 7), (360.0, 30), (90.0, 3), (-120.0, 5),
                                      (250.0, 11)])
@pytest.mark.parametrize("pieces", ["square", "on axis", "holed"])
def test_sweep_is_closed_outward_with_the_sectors_volume(angle, n, pieces):
    outer, holes = {"square": (SQUARE, []), "on axis": (ON_AXIS, []), "holed": HOLED}[pieces]
    v, f = rotation_mesh_outlines([(outer, holes)], angle, n)
    assert edges_shared(v, f)
    t = v[f]
    assert np.all(np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1) > 0)
    assert _volume(v, f) == pytest.approx(_polygon_sweep_volume(outer, holes, angle, n),
                                          rel=1e-12)


def test_sweeps_fixture_is_openscads_own_mesh():
    """OpenSCAD's sweeps (odd sector counts from the -x axis, partial ones, a clockwise
    one, a profile on the axis) voxelize exactly as the STL OpenSCAD 2021.01 wrote."""
    stl = ivx.voxelize_mesh(str(FIXTURES / "sweeps.stl"), 128)
    vox = read_openscad(FIXTURES / "sweeps.csg", facets="openscad").voxelize(
        bounds=stl.bounds, voxel_size=stl.voxel_size)
    assert vox.grid == stl.grid
    assert vox.count == stl.count and np.all(vox.contains(stl.coords()))


def test_openscad_reader_sweeps_into_a_mesh():
    solid = read_openscad("rotate_extrude(angle = 360, $fn = 12) "
                               "polygon(points = [[0, 0], [2, 0], [1, 3]]);",
                          facets="openscad")
    assert isinstance(solid, Polyhedron)
    curved = read_openscad("rotate_extrude($fn = 12) multmatrix([[1, 0, 0, 3], [0, 1, 0, 0], "
                           "[0, 0, 1, 0], [0, 0, 0, 1]]) circle(r = 1);",
                           facets="true")
    assert not isinstance(curved, Polyhedron)
    vox = solid.voxelize(resolution=32)
    assert vox.count > 0 and isinstance(vox, ivx.Voxels)
