"""Benchmark: max-norm distance queries (µs per point, batches of 10^5), beside Varadhan §6.1.

Run: ``python tests/benchmarks/bench_linf.py``

Varadhan et al. (2003, §6.1, a 1.6 GHz Pentium IV) report per query: quadric 45-50 µs,
torus 1-1.2 ms, triangle 10 µs. The targets here: <= 1 µs quadric, <= 0.5 µs triangle,
<= 10 µs torus, <= 50 µs per point on the Stanford bunny (69,451 triangles). Points are uniform in the
primitive's box grown by half its size, and for the bunny also near its surface
(within 2 mm, where a voxelizer asks).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from implicitvox import linf
from implicitvox.triangles.inputs import as_triangles

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))     # the repository root
from tests.support.mesh_helpers import BUNNY  # noqa: E402
from tests.benchmarks import tables  # noqa: E402

N = 100_000


def per_point(fn, points, repeat=3) -> float:
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn(points)
        best = min(best, time.perf_counter() - t)
    return best / len(points) * 1e6


def main() -> None:
    load = tables.load_average()
    table = []
    rng = np.random.default_rng(0)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    box_pts = rng.uniform(-2, 2, (N, 3))
    w = rng.uniform(0.5, 2.0, (N, 3))
    rows = [
        ("half-space", linf.HalfSpace((1, 2, 3), 0.5), "-"),
        ("oriented box (polytope)", linf.ConvexPolyhedron.from_points(
            (np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)]) - 0.5) @ q.T),
         "-"),
        ("sphere (quadric)", linf.Sphere((0.1, 0.2, 0.3), 1.0), "45-50"),
        ("rotated ellipsoid (quadric)", linf.Ellipsoid((0.1, 0.2, 0.3), (1.2, 0.7, 0.4), q),
         "45-50"),
        ("rotated capped cylinder", linf.Cylinder((0.1, 0.2, 0.3), q[:, 0], 1.5, 0.5), "-"),
        ("rotated cone", linf.Frustum((0.1, 0.2, 0.3), q[:, 1], 1.5, 0.6, 0.0), "-"),
        ("rotated hyperboloid (quadric)", linf.Quadric.from_local(
            np.diag([1.0, 2.0, -0.5]), np.zeros(3), -0.3, q, (0.1, 0.2, 0.3)), "45-50"),
        ("torus, axis along y", linf.Torus((0.1, 0.2, 0.3), "y", 1.2, 0.4), "1000-1200"),
        ("rotated torus", linf.Torus((0.1, 0.2, 0.3), q[:, 2], 1.2, 0.4), "1000-1200"),
    ]
    print(f"{'query':<30} {'µs/point':>9} {'weighted':>9} {'Varadhan µs':>12}")
    for name, prim, paper in rows:
        plain = per_point(lambda p: prim.distance(p), box_pts)
        weighted = per_point(lambda p: prim.distance(p, w), box_pts)
        print(f"{name:<30} {plain:9.3f} {weighted:9.3f} {paper:>12}")
        table.append([name, f"{plain:.2f}", f"{weighted:.2f}", paper])
    tri = rng.normal(size=(N, 3, 3))
    t = time.perf_counter()
    linf.triangle_distance(box_pts, tri)
    cost = (time.perf_counter() - t) / N * 1e6
    print(f"{'triangle (one per point)':<30} {cost:9.3f} {'':>9} {'10':>12}")
    table.append(["triangle (one per point)", f"{cost:.2f}", "-", "10"])
    if BUNNY.exists():
        v, f = as_triangles(str(BUNNY))
        t = time.perf_counter()
        mesh = linf.TriangleMesh(v, f)
        print(f"bunny: {len(f):,} triangles, set-up {time.perf_counter() - t:.2f} s")
        lo, hi = v.min(0), v.max(0)
        pad = 0.5 * (hi - lo)
        uniform = rng.uniform(lo - pad, hi + pad, (N, 3))
        k = rng.integers(0, len(f), N)
        bary = rng.dirichlet([1, 1, 1], N)
        near = np.einsum("ni,nij->nj", bary, v[f][k]) + rng.normal(0, 0.002, (N, 3))
        for name, pts in (("bunny, uniform in its box", uniform), ("bunny, near the surface", near)):
            cost = per_point(mesh.distance, pts, repeat=1)
            print(f"{name:<30} {cost:9.3f} {'':>9} {'-':>12}")
            table.append([f"{name} ({len(f):,} triangles)", f"{cost:.2f}", "-", "-"])
    else:
        print(f"bunny not found at {BUNNY}: skipped")
    tables.write("linf", ["query", "µs per point", "weighted (µs)", "Varadhan §6.1 (µs)"], table,
                 "python tests/benchmarks/bench_linf.py", load)


if __name__ == "__main__":
    main()
