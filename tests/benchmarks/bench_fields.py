"""Benchmark: distance fields (:func:`implicitvox.distance_field`) against scipy's transforms.

Run: ``python tests/benchmarks/bench_fields.py [--cases NAME ...] [--quick]``

Each case runs in a fresh child process (so the peak memory is its own,
``ru_maxrss``), the field (after a 16³ one, untimed, for Numba to compile or load
its cache; the best of two runs, as kernels that only the workers run compile on
their first use) and then its baseline, one after the other:

* ``bunny-linf``: the Stanford bunny's max-norm field in a 4-voxel band at 256³
  on one thread (``workers=1``; Varadhan et al. Table 2: 3.51 s at 256 on a
  1.6 GHz Pentium IV, for the voxelization by distances), and ``bunny-linf-512``
  at 512³ with the default workers. Baseline: scipy's chessboard distance
  transform (``distance_transform_cdt``) of the exact surface voxelization, the
  usual integer approximation. Error: against brute force over all 69,451
  triangles on 500 band samples (ours) and against our exact values (the
  baseline).
* ``bunny-euclidean``: the bunny's Euclidean field in a 4-voxel band at 256³.
  Baseline: scipy's ``distance_transform_edt`` of the surface voxelization
  (unsigned: the bunny is open), error as above.
* ``torus``: a ring torus (exact Euclidean kernel) in a 4-voxel band at 512³.
  Baseline: scipy's ``distance_transform_edt`` of the dense voxelization
  (inside voxels by the voxelizer, signed as ``edt(outside) - edt(inside)``),
  error against the analytic distance on the band.
* ``sinsin34`` and ``sinsin34-256``: Stolte's sin(3θ)sin(4φ) - r, certified
  Euclidean distances (any expression) in a 2-voxel band at 128³ and 256³; the
  same EDT baseline, whose error is measured against the certified values
  (each within its stored bound, ≤ 1e-3 voxel).

Errors are in voxels. The table goes to ``tests/benchmarks/results/fields.md``.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

try:
    from tests.benchmarks import tables
except ImportError:        # run as a script from elsewhere
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
    from tests.benchmarks import tables

BUNNY = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "meshes",
                     "stanford-bunny.obj")
#: case: (model, resolution, norm, band, workers: None for the default)
CASES = {"bunny-linf": ("bunny", 256, "linf", 4, 1),
         "bunny-linf-512": ("bunny", 512, "linf", 4, None),
         "bunny-euclidean": ("bunny", 256, "euclidean", 4, None),
         "torus": ("torus", 512, "euclidean", 4, None),
         "sinsin34": ("sinsin34", 128, "euclidean", 2, None),
         "sinsin34-256": ("sinsin34", 256, "euclidean", 2, None)}
QUICK = {"bunny-linf": 128, "bunny-linf-512": 160, "bunny-euclidean": 128, "torus": 256,
         "sinsin34": 48, "sinsin34-256": 64}


def _shape(model: str):
    from implicitvox import linf
    from implicitvox.expr.examples import example
    from implicitvox.linf.triangle_mesh import TriangleMesh
    from implicitvox.triangles.inputs import as_triangles
    if model == "bunny":
        return TriangleMesh(*as_triangles(os.path.abspath(BUNNY)))
    if model == "torus":
        return linf.Torus((0.0, 0.0, 0.0), (0.3, 0.4, 0.866), 0.7, 0.25)
    return example(model)


def child(name: str, res: int, method: str) -> dict:
    """One run in this process: the field, or its baseline; time, peak, error."""
    import implicitvox as ivx
    from scipy import ndimage
    model, _, norm, band, workers = CASES[name]
    shape = _shape(model)
    if method == "field":
        # a small field first: Numba compiles (or loads from its cache) outside the timing;
        # then the best of two, as the workers' kernels compile on their first use
        ivx.distance_field(shape, 16, norm=norm, band=band, check_suitability=False)
        seconds, field = math.inf, None
        for _ in range(2):
            field = None                        # (the peak is one field's, not two)
            t = time.perf_counter()
            field = ivx.distance_field(shape, res, norm=norm, band=band,
                                       check_suitability=False, workers=workers)
            seconds = min(seconds, time.perf_counter() - t)
        out = {"seconds": seconds, "peak": tables.peak_bytes(), "samples": field.count,
               "kind": field.kind, "bound": field.max_error / min(field.grid.voxel_size),
               "workers": field.metadata["workers"]}
        coords, values, _ = field.band_values()
        rng = np.random.default_rng(0)
        pick = rng.choice(len(coords), min(500, len(coords)), replace=False)
        p = field.grid.centers(coords[pick])
        h = min(field.grid.voxel_size)
        if model == "bunny":
            from implicitvox.linf.euclidean import triangle_distance as euclidean
            from implicitvox.linf.polyhedron import triangle_distance as linf
            tri = shape.tri
            brute = np.array([(linf if norm == "linf" else euclidean)(
                np.repeat(q[None], len(tri), 0), tri).min() for q in p])
            out["error"] = float(np.abs(np.abs(values[pick]) - brute).max()) / h
        elif model == "torus":
            out["error"] = float(np.abs(values[pick] - shape.euclidean_distance(p)).max()) / h
        grid = field.grid
        np.savez(_cache(name, res), coords=coords, values=values,
                 bounds=np.asarray(grid.bounds, dtype=np.float64),
                 voxel_size=np.asarray(grid.voxel_size, dtype=np.float64))
        return out
    # the baseline, on the field's grid (its bounds reach past the surface by the
    # band), timed from the voxelization on
    from implicitvox.fields.suitability import solid_voxels
    cached = np.load(_cache(name, res))
    grid = {"bounds": tuple(map(tuple, cached["bounds"])),
            "voxel_size": tuple(cached["voxel_size"])}
    t = time.perf_counter()
    if model == "bunny":
        triangles = (shape.tri.reshape(-1, 3), np.arange(3 * len(shape.tri)).reshape(-1, 3))
        vox = ivx.voxelize_mesh(triangles, **grid)
        dense = vox.to_dense(interior=False)
        signed = ndimage.distance_transform_cdt(~dense, metric="chessboard").astype(
            np.float64) if norm == "linf" else ndimage.distance_transform_edt(~dense)
    else:
        vox = ivx.voxelize(shape, interior=True, **grid)
        solid = solid_voxels(vox, shape)
        signed = ndimage.distance_transform_edt(~solid) - ndimage.distance_transform_edt(solid)
    seconds = time.perf_counter() - t
    out = {"seconds": seconds, "peak": tables.peak_bytes(), "samples": int(signed.size)}
    c, ours = cached["coords"], cached["values"]
    h = min(vox.grid.voxel_size)
    theirs = signed[c[:, 0], c[:, 1], c[:, 2]]
    truth = np.abs(ours) / h if model == "bunny" else ours / h
    out["error"] = float(np.abs(theirs - truth).max())
    out["mean_error"] = float(np.abs(theirs - truth).mean())
    return out


def _cache(name: str, res: int) -> str:
    return os.path.join(os.environ.get("TMPDIR", "/tmp"), f"implicitvox-bench-{name}-{res}.npz")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--quick", action="store_true", help="small resolutions (a smoke run)")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if tables.answer_child(args.child, child):
        return
    load = tables.load_average()
    print(f"load average before: {load}")
    rows = []
    for name in args.cases:
        _, res, norm, band, _ = CASES[name]
        res = QUICK[name] if args.quick else res
        for method in ("field", "baseline"):
            r = tables.run_child(__file__, name, str(res), method)
            what = ("implicitvox " + r.get("kind", "")) if method == "field" else \
                ("scipy distance_transform_cdt" if norm == "linf" else
                 "scipy distance_transform_edt")
            row = [name, f"{res}³", norm, band, what.strip(), r.get("workers", 1),
                   "-" if "seconds" not in r else f"{r['seconds']:.2f}",
                   "-" if "samples" not in r else f"{r['samples']:,}",
                   "-" if "peak" not in r else f"{r['peak'] / 2**20:,.0f}",
                   "-" if "error" not in r else f"{r['error']:.2g}",
                   "-" if "bound" not in r else f"{r['bound']:.2g}",
                   r.get("error_text", "")]
            print(" | ".join(str(c) for c in row), flush=True)
            rows.append(row)
    header = ["case", "N", "norm", "band", "method", "workers", "seconds", "samples", "peak MiB",
              "max error (voxels)", "stored bound (voxels)", "note"]
    tables.write("fields", header, rows, "python tests/benchmarks/bench_fields.py "
                 + " ".join(sys.argv[1:]), load)


if __name__ == "__main__":
    main()
