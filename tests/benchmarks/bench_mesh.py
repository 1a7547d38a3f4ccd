"""Benchmark: exact mesh voxelization of the Stanford bunny, beside Open3D and trimesh.

Run: ``python tests/benchmarks/bench_mesh.py [--res 64 128 256 512] [--no-trimesh]``
(``pip install -e ".[bench]"`` for Open3D and trimesh.)

Prints per resolution, in the same run:

* implicitvox ``voxelize_mesh``: seconds (best of ``--repeat``), voxels, and the
  share of 10^6 surface samples whose voxel is missing (0 by construction);
* Open3D ``VoxelGrid.create_from_triangle_mesh`` with the same voxel size
  (C++, exact box-triangle test per triangle's bounding box): the same figures;
* trimesh ``voxelized`` (subdivide until edges are short, mark vertices): the same;
* Varadhan et al. Table 2 beside it: bunny at 64^3, 128^3, 256^3 in 1.65, 2.01, 3.51 s (1.6 GHz Pentium IV, 2003);
* the Utah teapot's 32 Bézier patches (``voxelize_bezier``) at each resolution;
* the box-triangle test itself on the pairs the bunny's descent tests at 256³ (the
  children its triangles' bounding boxes reach, one level above the voxels): ns per
  pair, the compiled kernel (:func:`implicitvox.triangles.tribox_kernels.meet_pairs`,
  with the exact path for the pairs it is unsure of) against the array path
  (``Triangles.meet_by_arrays``), alternating, best of ``--repeat``, the answers equal.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import implicitvox as ivx
from implicitvox.triangles.inputs import as_triangles

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))     # the repository root
from tests.support.mesh_helpers import BUNNY, sample_surface  # noqa: E402
from tests.benchmarks import tables  # noqa: E402

VARADHAN = {64: "1.65", 128: "2.01", 256: "3.51"}


def best_of(repeat: int, run):
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - t)
    return best, out


def missed_share(index_sets: set, idx: np.ndarray) -> float:
    keys = idx[:, 0] * 1_000_003 ** 2 + idx[:, 1] * 1_000_003 + idx[:, 2]
    return float(np.mean(~np.isin(keys, index_sets)))


def keys_of(idx: np.ndarray) -> np.ndarray:
    idx = idx.astype(np.int64)
    return np.unique(idx[:, 0] * 1_000_003 ** 2 + idx[:, 1] * 1_000_003 + idx[:, 2])


def box_test_row(tri: np.ndarray, repeat: int) -> list:
    """The box-triangle test per pair, compiled against the array path (see the docstring)."""
    from implicitvox.octree.grid import Grid
    from implicitvox.triangles.pair_kernels import child_pairs
    from implicitvox.triangles.pairs import start_pairs
    from implicitvox.triangles.tribox import Triangles
    tris = Triangles(tri)
    grid = Grid.from_bounds((tuple(tri.min(axis=(0, 1))), tuple(tri.max(axis=(0, 1)))), 256)
    stack, _ = start_pairs(tris, grid)
    level, nodes, t, _ = max(stack, key=lambda entry: (entry[0], len(entry[1])))
    _, t, lo, hi, _ = child_pairs(tris, grid, level, nodes, t, test=False)
    ids = np.arange(len(t))
    best = {"compiled": np.inf, "arrays": np.inf}
    answers = {}
    for _ in range(max(repeat, 2)):
        for name, run in (("compiled", tris.meet_boxes), ("arrays", tris.meet_by_arrays)):
            start = time.process_time()
            answers[name] = run(t, lo, hi)
            best[name] = min(best[name], time.process_time() - start)
    assert np.array_equal(answers["compiled"], answers["arrays"])
    ns = {k: 1e9 * v / len(ids) for k, v in best.items()}
    print(f"\nbox-triangle test, {len(ids):,} pairs of the bunny at 256³ (level {level + 1}): "
          f"compiled {ns['compiled']:.0f} ns/pair, arrays {ns['arrays']:.0f} ns/pair, "
          f"{ns['arrays'] / ns['compiled']:.1f}x; {answers['arrays'].mean():.0%} meet")
    return ["bunny", "256³", "box-triangle test per pair: compiled / array path",
            f"{ns['compiled']:.0f} / {ns['arrays']:.0f} ns ({ns['arrays'] / ns['compiled']:.1f}x)",
            f"{len(ids):,} pairs", "-", ""]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", type=int, nargs="+", default=[64, 128, 256, 512])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-trimesh", action="store_true", help="skip trimesh (slow)")
    args = parser.parse_args()
    load = tables.load_average()
    rows = []
    v, f = as_triangles(str(BUNNY))
    tri = v[f]
    points = sample_surface(tri, 10**6, np.random.default_rng(0))
    print(f"bunny: {len(v):,} vertices, {len(f):,} triangles; 10^6 surface samples")
    print("Varadhan et al. 2003, Table 2: bunny at 64^3, 128^3, 256^3 in 1.65, 2.01, 3.51 s "
          "(1.6 GHz Pentium IV)\n")
    try:
        import open3d as o3d
        o3d_mesh = o3d.io.read_triangle_mesh(str(BUNNY))
    except ImportError:
        o3d = None
        print("open3d not installed: pip install -e '.[bench]'")
    try:
        import trimesh
        tm = None if args.no_trimesh else trimesh.load(str(BUNNY), force="mesh")
    except ImportError:
        tm = None
    print(f"{'res':>5} {'tool':<12} {'seconds':>8} {'voxels':>10} {'missed':>8} {'vs iv':>6}")
    for n in args.res:
        secs, vox = best_of(args.repeat, lambda: ivx.voxelize_mesh(str(BUNNY), n))
        idx = vox.grid.voxels_holding(points)
        miss = float(np.mean(~(vox.contains(idx[0]) | vox.contains(idx[1]))))
        print(f"{n:>5} {'implicitvox':<12} {secs:8.3f} {vox.count:>10,} {miss:8.2%} {1:6.2f}")
        rows.append(["bunny", f"{n}³", "implicitvox voxelize_mesh", f"{secs:.2f}", f"{vox.count:,}",
                     f"{miss:.2%}", VARADHAN.get(n, "-")])
        h = vox.voxel_size[0]
        if o3d is not None:
            t_o3d, grid = best_of(args.repeat, lambda: o3d.geometry.VoxelGrid
                                  .create_from_triangle_mesh(o3d_mesh, voxel_size=h))
            got = np.array([g.grid_index for g in grid.get_voxels()])
            pidx = np.floor((points - np.asarray(grid.origin)) / h).astype(np.int64)
            m = missed_share(keys_of(got), pidx)
            print(f"{'':>5} {'open3d':<12} {t_o3d:8.3f} {len(got):>10,} {m:8.2%} "
                  f"{secs / t_o3d:6.2f}")
            rows.append(["bunny", f"{n}³", f"Open3D {o3d.__version__} VoxelGrid",
                         f"{t_o3d:.2f}", f"{len(got):,}", f"{m:.2%}", ""])
        if tm is not None:
            t_tm, grid = best_of(1, lambda: tm.voxelized(h))
            got = grid.sparse_indices
            origin = grid.transform[:3, 3]
            pidx = np.round((points - origin) / h).astype(np.int64)
            m = missed_share(keys_of(got), pidx)
            print(f"{'':>5} {'trimesh':<12} {t_tm:8.3f} {len(got):>10,} {m:8.2%} "
                  f"{secs / t_tm:6.2f}")
            rows.append(["bunny", f"{n}³", f"trimesh {trimesh.__version__} voxelized",
                         f"{t_tm:.2f}", f"{len(got):,}", f"{m:.2%}", ""])
    print("\nUtah teapot, 32 Bezier patches (voxelize_bezier, flatness 1/8 voxel)")
    patches = ivx.utah_teapot()
    for n in args.res:
        secs, vox = best_of(args.repeat, lambda: ivx.voxelize_bezier(patches, n))
        print(f"{n:>5} {'implicitvox':<12} {secs:8.3f} {vox.count:>10,}")
        rows.append(["Utah teapot, 32 patches", f"{n}³", "implicitvox voxelize_bezier",
                     f"{secs:.2f}", f"{vox.count:,}", "-", ""])
    rows.append(box_test_row(tri, args.repeat))
    tables.write("mesh", ["model", "N", "tool", "seconds (best of repeats)", "voxels",
                          "surface samples missed", "Varadhan Table 2 (s)"], rows,
                 "python tests/benchmarks/bench_mesh.py " + " ".join(sys.argv[1:]), load)


if __name__ == "__main__":
    main()
