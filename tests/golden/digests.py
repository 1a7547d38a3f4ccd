"""The golden digests: what a user computes, hashed, so a refactor can prove it changed nothing.

:func:`compute` voxelizes every built-in example at 64³ and 128³ under each
option set, the OpenSCAD fixtures (both facet modes), their STL meshes, the
Utah teapot and a tilted torus; it hashes the voxels, interior octants,
normals, the interval enclosures of fixed boxes, the tape listings of the
examples and the interval outputs of every opcode in float64 and float32.
``python -m tests.golden.digests`` rewrites ``golden.json`` and this CPU's set
in ``golden_simd.json`` (do that only when a change of results is intended,
and say which digests changed and why).

The opcode outputs and box enclosures depend, in their last bits, on which of
numpy's SIMD kernels run (AVX-512 and AVX2 machines differ by an ulp in
``sin``, ``exp``, ``**``, ...; every one is still enclosed, outward rounded).
They are kept per dispatch target (:func:`simd_target`); the voxels, interior
and normals are the same on all and kept once.

Every grid here is cubic and its bounds explicit, so the digests do not depend
on the rule for default bounds.
"""
from __future__ import annotations

import hashlib
import json
import pathlib

import numpy as np

HERE = pathlib.Path(__file__).parent
GOLDEN = HERE / "golden.json"
#: the digests that depend on numpy's SIMD code paths (its libm-like kernels and
#: ``**`` differ by an ulp between, say, AVX-512 and AVX2 machines): one set per
#: dispatch target, see :func:`simd_target`
GOLDEN_SIMD = HERE / "golden_simd.json"
#: the digest names that depend on the SIMD target
SIMD_DEPENDENT = ("opcode/", "boxes/")
FIXTURES = HERE.parent / "openscad"

#: option sets for the expression examples
OPTIONS = {
    "default": {},
    "interior+normals": {"interior": True, "normals": True},
    "recheck=0": {"recheck": 0.0},
    "mean_value": {"mean_value": True},
    "subvoxel=1": {"subvoxel": 1},
}


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:24]


def voxel_digests(vox) -> dict[str, str]:
    out = {"count": str(vox.count), "voxels": _digest(vox.coords())}
    if vox.interior:
        out["interior"] = _digest(*[np.asarray(lvl) for lvl in sorted(vox.interior)],
                                  *[vox.interior[lvl] for lvl in sorted(vox.interior)])
    if vox.normals is not None:
        out["normals"] = _digest(vox.normals)
    return out


def _cube(bounds, pad: float = 1.0) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The cube about the bounds' centre holding them (times ``pad``)."""
    lo, hi = np.asarray(bounds, dtype=np.float64)
    c, half = (lo + hi) / 2, float(np.max(hi - lo)) / 2 * pad
    return tuple((c - half).tolist()), tuple((c + half).tolist())


def _boxes(bounds, n: int = 512, seed: int = 7):
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(bounds)
    a = lo + rng.random((n, 3)) * (hi - lo)
    w = rng.random((n, 3)) * (hi - lo) * rng.choice([1e-3, 1e-2, 0.1], (n, 1))
    return a, a + w


def _examples(out: dict) -> None:
    import implicitvox as iv
    from implicitvox.expr.examples import EXAMPLES, example
    from implicitvox.eval.tape import build_tape
    for name in sorted(EXAMPLES):
        shape = example(name)
        bounds = _cube(shape.bounds)
        tape = build_tape(shape.expr)
        out[f"tape/{name}"] = hashlib.sha256(_listing(tape).encode()).hexdigest()[:24]
        lo, hi = _boxes(bounds)
        out[f"boxes/{name}"] = _digest(*iv.compile(shape.expr).interval(lo, hi))
        for res in (64, 128):
            for label, opts in OPTIONS.items():
                vox = iv.voxelize(shape.expr, bounds=bounds, resolution=res, **opts)
                for k, v in voxel_digests(vox).items():
                    out[f"voxelize/{name}/{res}/{label}/{k}"] = v


def _listing(tape) -> str:
    rows = [f"{c.register}={c.value!r}[{c.lo!r},{c.hi!r}]" for c in tape.constants]
    for ins in tape.instructions:
        param = ins.param if ins.op.name not in ("repeat", "repeat_polar") else "sweep"
        rows.append(f"{ins.out}<-{ins.op.name}{ins.args};{param!r}")
    rows.append(f"out={tape.output};inputs={sorted(tape.inputs.items())}")
    return "\n".join(rows)


def _opcodes(out: dict) -> None:
    from implicitvox.eval.interval import apply_op
    from implicitvox.eval.opcodes import OPCODES
    params = {"powi": 3, "powr": 1.5, "addc": 0.3, "rsubc": -1.25, "mulc": 2.5, "divc": 3.0,
              "periodic_angle": ("sin", 3.0, 0.5), "distance": (0.1, -0.2, 0.3)}
    for name in sorted(OPCODES):
        if name in ("repeat", "repeat_polar"):
            continue           # driven by their compiled sweeps: covered by the examples
        op = OPCODES[name]
        for single in (False, True):
            rng = np.random.default_rng(11)
            n = 3000
            los, his = [], []
            for _ in range(op.arity):
                a = rng.uniform(-4, 4, n) * 10.0 ** rng.integers(-3, 2, n)
                b = a + rng.random(n) * 10.0 ** rng.integers(-6, 1, n)
                dt = np.float32 if single else np.float64
                los.append(a.astype(dt))
                his.append(np.maximum(b.astype(dt), a.astype(dt)))
            with np.errstate(all="ignore"):
                result = apply_op(op, params.get(name), tuple(los), tuple(his), single)
            arrays = [np.broadcast_to(np.asarray(r), (n,)) for r in result]
            out[f"opcode/{name}/{'float32' if single else 'float64'}"] = _digest(*arrays)


def _openscad(out: dict) -> None:
    import implicitvox as iv
    from csg import read_openscad
    for path in sorted(FIXTURES.glob("*.csg")):
        for facets in ("true", "openscad"):
            solid = read_openscad(path, facets=facets)
            bounds = _cube(solid.bounds, 1.04)
            vox = iv.voxelize(solid, bounds=bounds, resolution=64, interior=True)
            for k, v in voxel_digests(vox).items():
                out[f"openscad/{path.stem}/{facets}/64/{k}"] = v
        stl = path.with_suffix(".stl")
        for res in (64, 128):
            vox = iv.voxelize_mesh(str(stl), bounds=_cube(iv_mesh_bounds(stl), 1.04),
                                   resolution=res, interior=True)
            for k, v in voxel_digests(vox).items():
                out[f"mesh/{stl.stem}/{res}/{k}"] = v


def iv_mesh_bounds(stl):
    import pyvista as pv
    b = pv.read(str(stl)).bounds
    return (b[0], b[2], b[4]), (b[1], b[3], b[5])


def _teapot_and_torus(out: dict) -> None:
    import implicitvox as iv
    from csg import Torus
    for res in (64, 128):
        teapot = iv.utah_teapot()
        vox = iv.voxelize_bezier(teapot, bounds=((-3.5, -3.5, -0.5), (3.5, 3.5, 6.5)),
                                 resolution=res)
        for k, v in voxel_digests(vox).items():
            out[f"bezier/teapot/{res}/{k}"] = v
    tilted = Torus(1.0, 0.3).rotate((1, 2, 0.5), 35).translate((0.05, -0.02, 0.03))
    for res in (64, 128):
        vox = iv.voxelize(tilted, bounds=((-1.5,) * 3, (1.5,) * 3), resolution=res,
                          interior=True)
        for k, v in voxel_digests(vox).items():
            out[f"csg/tilted-torus/{res}/{k}"] = v


def simd_target() -> str:
    """The best of numpy's dispatch targets this CPU has (``X86_V4`` on AVX-512
    machines, ``X86_V3`` on AVX2 ones, ...), which picks its transcendental kernels."""
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    import platform
    found = [t for t in __cpu_dispatch__ if __cpu_features__.get(t)]
    levels = [t for t in found if t.startswith("X86_V")] or found   # AVX512_ICL/SPR: X86_V4's
    return f"{platform.machine()}:{levels[-1] if levels else 'baseline'}"


def split(digests: dict[str, str]) -> tuple[dict[str, str], dict[str, str]]:
    """``(portable, simd_dependent)`` digests."""
    dependent = {k: v for k, v in digests.items() if k.startswith(SIMD_DEPENDENT)}
    return {k: v for k, v in digests.items() if k not in dependent}, dependent


def compute() -> dict[str, str]:
    """Every digest, by name."""
    out: dict[str, str] = {}
    _opcodes(out)
    _examples(out)
    _openscad(out)
    _teapot_and_torus(out)
    return out


if __name__ == "__main__":
    portable, dependent = split(compute())
    GOLDEN.write_text(json.dumps(portable, indent=1, sort_keys=True) + "\n")
    sets = json.loads(GOLDEN_SIMD.read_text()) if GOLDEN_SIMD.exists() else {}
    sets[simd_target()] = dependent
    GOLDEN_SIMD.write_text(json.dumps(sets, indent=1, sort_keys=True) + "\n")
    print(f"wrote {GOLDEN} and the {simd_target()} set of {GOLDEN_SIMD}")
