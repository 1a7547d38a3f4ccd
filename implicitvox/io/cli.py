"""The ``implicitvox`` command.

::

    implicitvox examples
    implicitvox voxelize --example sinsin34 --resolution 256 --render sinsin.png
    implicitvox voxelize model.py --resolution 512 --bounds -1 -1 -1 1 1 1 --out model.npz
    implicitvox voxelize bunny.obj --resolution 256 --interior --render bunny.png
    implicitvox voxelize bracket.csg --resolution 256 --out bracket.npz   # OpenSCAD's facets
    implicitvox voxelize bracket.csg --facets true --resolution 256      # true curves
    implicitvox voxelize knob.scad --render knob.png      # through the installed OpenSCAD
    implicitvox mesh --example gear --tolerance 0.01 --out gear.stl --render gear.png
    implicitvox field --example gear --resolution 256 --band 4 --out gear-sdf.vti
    implicitvox field bunny.obj --norm linf --resolution 256 --check-suitability

A model file is Python that defines ``shape`` (an expression or a shape);
errors inside it are reported with the model's own file and line. OpenSCAD
``.csg`` files and JSON scenes are read by ``csg`` (registered as loaders), and
``.scad`` files too when OpenSCAD is installed (it evaluates them). A mesh
file (``.stl``, ``.ply``, ``.obj``, ``.vtk``, ``.vtp``) is voxelized exactly
(:func:`implicitvox.voxelize_mesh`; ``--interior`` fills closed meshes).
``mesh`` triangulates a model within a guaranteed Hausdorff distance
(:func:`implicitvox.mesh`) and writes ``.stl``, ``.ply``, ``.obj``, ``.vtp`` or
``.vtk``. ``field`` samples the signed distance in a narrow band
(:func:`implicitvox.distance_field`) and writes ``.npz`` or ``.vti``;
``--check-suitability`` (on ``voxelize`` and ``field``) prints Bærentzen's
criterion at the resolution (:func:`implicitvox.suitability`).
"""
from __future__ import annotations

import argparse
import contextlib
import os
import runpy
import sys
import time
import traceback
import warnings
from typing import Any, Iterator, Optional, Sequence

from .. import validate
from ..expr.examples import EXAMPLES, example
from ..triangles.inputs import MESH_SUFFIXES
from ..parallel import WorkerError
from ..octree.subdivide import RECHECK
from ..voxelizers.implicit import voxelize
from ..voxelizers.mesh import voxelize_mesh
from ..meshing.mesher import REFINE, mesh
from ..fields.field import DTYPES
from ..fields.sampled import distance_field
from ..fields.suitability import suitability
from .files import MESH_FORMATS, save_mesh
from .field_files import FIELD_FORMATS
from .rendering import render_mesh

__all__ = ["main", "ProgressBar", "load_model"]


class ProgressBar:
    """A one-line progress bar on a stream (stderr by default), for ``progress=``:
    the share done, the time so far, and (from 1% and a second on) the time left
    at the pace so far.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> bar = ProgressBar("distances", out, width=10)
    >>> bar.start -= 30.0                      # as if it had run for 30 s
    >>> bar(0.25)
    >>> out.getvalue().split("]")[1].split()
    ['25.0%', '30.0s,', 'about', '1m30s', 'left']
    """

    def __init__(self, label: str = "voxelizing", stream: Any = None, width: int = 30):
        self.label, self.stream, self.width = label, stream or sys.stderr, width
        self.start = time.perf_counter()
        self._last = -1

    def __call__(self, share: float) -> None:
        step = int(share * 1000)
        if step == self._last:
            return
        self._last = step
        filled = int(share * self.width)
        bar = "#" * filled + "-" * (self.width - filled)
        elapsed = time.perf_counter() - self.start
        left = f", about {_duration(elapsed * (1.0 - share) / share)} left" \
            if 0.01 <= share < 1.0 and elapsed >= 1.0 else ""
        self.stream.write(f"\r{self.label} [{bar}] {share * 100:5.1f}% {elapsed:6.1f}s"
                          f"{left:<22}")
        self.stream.flush()

    def close(self) -> None:
        self(1.0)
        self.stream.write("\n")
        self.stream.flush()


def _duration(seconds: float) -> str:
    """``42s``, ``3m05s``, ``1h02m``."""
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds}s"
    if seconds < 3600:
        return f"{seconds // 60}m{seconds % 60:02d}s"
    return f"{seconds // 3600}h{seconds % 3600 // 60:02d}m"


class ModelError(Exception):
    """A model file could not be loaded."""


def _loaders() -> dict[str, Any]:
    """Model loaders registered by other packages (``csg`` registers ``csg`` and ``json``)."""
    from importlib.metadata import entry_points
    found = {}
    for ep in entry_points(group="implicitvox.loaders"):
        found[ep.name] = ep
    return {name: _LazyLoader(ep) for name, ep in found.items()}


class _LazyLoader:
    def __init__(self, ep: Any):
        self.ep = ep

    def __call__(self, path: str, **options: Any) -> Any:
        return self.ep.load()(path, **options)


def load_model(path: str, **options: Any) -> Any:
    """Run a model file and return its ``shape``.

    ``.py`` files run as Python (they are the user's own code); the error of
    a failing model names the model's line. Other suffixes go to the loaders
    registered under the entry-point group ``implicitvox.loaders`` (``csg``
    registers ``.csg``, ``.scad`` and ``.json``); ``options`` are passed to them.
    """
    if not os.path.isfile(path):
        raise ModelError(f"no such model file: {path}")
    ext = os.path.splitext(path)[1].lower()
    if ext != ".py":
        loader = _loaders().get(ext.lstrip("."))
        if loader is None:
            known = ", ".join(["py"] + sorted(_loaders()))
            raise ModelError(f"unsupported model type {ext!r} for {path} (model files: {known}; "
                             "meshes: stl, ply, obj, vtk, vtp)")
        return loader(path, **options)
    try:
        namespace = runpy.run_path(path, run_name="__implicitvox_model__")
    except SyntaxError as err:
        raise ModelError(f"{path}:{err.lineno}:{err.offset or 0}: syntax error: {err.msg}") from None
    except Exception as err:  # the model's own exception: point at its line
        frames = [f for f in traceback.extract_tb(err.__traceback__)
                  if os.path.abspath(f.filename) == os.path.abspath(path)]
        where = f"{path}:{frames[-1].lineno}" if frames else path
        line = f"\n    {frames[-1].line}" if frames and frames[-1].line else ""
        raise ModelError(f"{where}: {type(err).__name__}: {err}{line}") from None
    if "shape" not in namespace:
        raise ModelError(f"{path} defines no `shape` (assign the solid to a variable named shape)")
    return namespace["shape"]


def _facets_option(command: argparse.ArgumentParser) -> None:
    """The one ``--facets`` option of the commands that read models."""
    command.add_argument("--facets", choices=["openscad", "true"], default="openscad",
                         help=".csg and .scad models: OpenSCAD's own facets (default), or "
                              "true curves")


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="implicitvox",
                                     description="Robust voxelization of implicit solids.",
                                     epilog="A .py model file is Python and is executed: run "
                                            "only model files you trust. A .scad file is "
                                            "evaluated by the installed OpenSCAD. Every other "
                                            "format (.csg, .json, meshes, voxel files) is read "
                                            "as data.")
    parser.add_argument("--debug", action="store_true",
                        help="show the traceback of an error (for bug reports)")
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("examples", help="list the built-in example models")
    vox = sub.add_parser("voxelize", help="voxelize a model")
    vox.add_argument("model", nargs="?",
                     help="a .py file that defines `shape`, a .csg, .scad or .json model, or "
                          "a mesh (.stl .ply .obj .vtk .vtp)")
    vox.add_argument("--example", help="a built-in example instead of a model file")
    size = vox.add_mutually_exclusive_group()
    size.add_argument("--resolution", type=int, help="voxels along the longest side (default 256)")
    size.add_argument("--voxel-size", type=float, metavar="H", help="the voxels' edge length")
    vox.add_argument("--bounds", type=float, nargs=6, metavar=("X0", "Y0", "Z0", "X1", "Y1", "Z1"))
    vox.add_argument("--interior", action="store_true", help="also find interior octants")
    _facets_option(vox)
    vox.add_argument("--normals", action="store_true", help="store normals")
    vox.add_argument("--mean-value", action="store_true",
                     help="tighter: mean value form on ambiguous octants (about 3x the time)")
    vox.add_argument("--subvoxel", type=int, default=0, metavar="K",
                     help="tighter: keep a voxel only if a sub-voxel K levels down is ambiguous")
    vox.add_argument("--recheck", type=float, default=RECHECK, metavar="STRENGTH",
                     help="recheck on sub-voxels the voxels predicted to be false "
                          f"(default {RECHECK}; 0 = off, up to 4 = nearly all)")
    vox.add_argument("--no-prune", dest="prune", action="store_false",
                     help="evaluate the whole expression everywhere (the same voxels, slower "
                          "on models of many parts; for comparison)")
    vox.add_argument("--out", help="write .npz, .vti or .binvox")
    vox.add_argument("--render", metavar="PNG", help="render a picture")
    vox.add_argument("--max-memory", type=float, metavar="GIB", help="refuse runs estimated above")
    _parallel_options(vox)
    vox.add_argument("--quiet", action="store_true", help="no progress bar")
    vox.add_argument("--check-suitability", action="store_true",
                     help="print whether the solid is S_r-open and closed with r > sqrt(6) "
                          "voxels (Baerentzen's criterion) and the predicted error")
    fld = sub.add_parser("field", help="signed distances in a narrow band, with their error")
    fld.add_argument("model", nargs="?", help="a .py, .csg, .scad or .json model, or a "
                                                  "mesh")
    fld.add_argument("--example", help="a built-in example instead of a model file")
    size = fld.add_mutually_exclusive_group()
    size.add_argument("--resolution", type=int, help="voxels along the longest side (default 256)")
    size.add_argument("--voxel-size", type=float, metavar="H", help="the voxels' edge length")
    fld.add_argument("--bounds", type=float, nargs=6, metavar=("X0", "Y0", "Z0", "X1", "Y1", "Z1"))
    fld.add_argument("--norm", choices=["euclidean", "linf"], default="euclidean")
    fld.add_argument("--band", type=int, default=4,
                     help="voxels around the surface (default 4; 0: every voxel)")
    fld.add_argument("--tolerance", type=float, metavar="E",
                     help="error target of certified distances (default 1e-3 voxel)")
    fld.add_argument("--dtype", choices=DTYPES, default="float64",
                     help="the float type stored (float32: half the size; each error bound "
                          "then includes the rounding)")
    _facets_option(fld)
    fld.add_argument("--out", help="write .npz (lossless) or .vti")
    fld.add_argument("--render", metavar="PNG", help="render the 0-isosurface")
    fld.add_argument("--check-suitability", action="store_true",
                     help="print Baerentzen's suitability criterion at this resolution")
    fld.add_argument("--max-memory", type=float, metavar="GIB", help="refuse runs estimated above")
    _parallel_options(fld)
    fld.add_argument("--quiet", action="store_true", help="no progress bar")
    msh = sub.add_parser("mesh", help="triangulate a model within a guaranteed Hausdorff "
                                      "distance")
    msh.add_argument("model", nargs="?", help="a .py file that defines `shape`, or a .csg, "
                                              ".scad or .json model")
    msh.add_argument("--example", help="a built-in example instead of a model file")
    size = msh.add_mutually_exclusive_group(required=True)
    size.add_argument("--tolerance", type=float, metavar="E",
                      help="the Hausdorff bound, world units (cells of edge E/sqrt(3))")
    size.add_argument("--resolution", type=int,
                      help="cells along the longest side (the bound is sqrt(3) cells)")
    msh.add_argument("--bounds", type=float, nargs=6, metavar=("X0", "Y0", "Z0", "X1", "Y1", "Z1"))
    _facets_option(msh)
    msh.add_argument("--refine", type=int, default=REFINE, metavar="K",
                     help=f"levels complex cells may be split below the largest (default {REFINE})")
    msh.add_argument("--no-prune", dest="prune", action="store_false",
                     help="evaluate the whole expression everywhere (for comparison)")
    msh.add_argument("--out", help=f"write {', '.join(MESH_FORMATS)}")
    msh.add_argument("--render", metavar="PNG", help="render a picture (edges shown)")
    msh.add_argument("--max-memory", type=float, metavar="GIB", help="refuse runs estimated above")
    _parallel_options(msh)
    msh.add_argument("--quiet", action="store_true", help="no progress bar")
    return parser


#: seconds ``--scheduler`` waits to reach the Dask scheduler
SCHEDULER_TIMEOUT = 30


def _parallel_options(command: argparse.ArgumentParser) -> None:
    command.add_argument("--workers", type=int, metavar="N",
                         help="processes to run on (default: every core, one for small runs)")
    command.add_argument("--scheduler", metavar="ADDRESS",
                         help="run on a Dask cluster (e.g. tcp://host:8786; needs "
                              "dask.distributed)")


@contextlib.contextmanager
def _parallel(args: argparse.Namespace) -> Iterator[dict]:
    """``workers`` and ``executor`` of a command: a Dask client while it runs."""
    workers = validate.workers(args.workers, "--workers")
    if args.scheduler is None:
        yield {"workers": workers, "executor": None}
        return
    try:
        from distributed import Client
    except ImportError:
        raise ModelError("--scheduler needs dask.distributed: pip install "
                         "'implicitvox[dask]'") from None
    try:
        client = Client(args.scheduler, timeout=SCHEDULER_TIMEOUT)
    except (OSError, TimeoutError) as err:
        raise ModelError(f"--scheduler {args.scheduler}: cannot reach it ({err})") from None
    with client:
        yield {"workers": workers, "executor": client}


def _shape(args: argparse.Namespace) -> Any:
    """The model of a command: a built-in example or a model file."""
    if (args.model is None) == (args.example is None):
        raise ModelError("give a model file or --example NAME (one of them)")
    if args.example:
        return example(args.example)
    options = {"facets": args.facets} if not args.model.endswith(".py") else {}
    return load_model(args.model, **options)


def _common(args: argparse.Namespace) -> tuple[Any, Any]:
    """``(bounds, max_memory)`` of a command, checked; the output paths checked."""
    for path, flag in ((args.out, "--out"), (args.render, "--render")):
        if path is not None:
            validate.writable_path(path, flag)
    bounds = None
    if args.bounds:
        bounds = (tuple(args.bounds[:3]), tuple(args.bounds[3:]))
    max_memory = None if args.max_memory is None else \
        validate.max_memory(validate.positive_number(args.max_memory, "--max-memory") * 2**30,
                             "--max-memory (bytes)")
    return bounds, max_memory


def _mesh(args: argparse.Namespace) -> int:
    if args.model is not None and args.model.lower().endswith(MESH_SUFFIXES):
        raise ModelError(f"{args.model} is already a triangle mesh; `mesh` triangulates "
                         "implicit and csg models")
    if args.out is not None and os.path.splitext(args.out)[1].lower() not in MESH_FORMATS:
        raise ModelError(f"--out {args.out}: a mesh is written as one of "
                         f"{', '.join(MESH_FORMATS)}")
    shape = _shape(args)
    bounds, max_memory = _common(args)
    bar = None if args.quiet else ProgressBar("meshing")
    with _parallel(args) as parallel:
        result = mesh(shape, args.tolerance, args.resolution, bounds=bounds, refine=args.refine,
                      progress=bar, max_memory=max_memory, prune=args.prune, **parallel)
    if bar:
        bar.close()
    data = result.field_data
    print(f"{result.n_cells:,} triangles, {result.n_points:,} vertices in "
          f"{float(data['seconds'][0]):.2f} s; Hausdorff distance <= "
          f"{float(data['hausdorff_bound'][0]):.4g} (max norm {float(data['linf_bound'][0]):.4g})")
    if int(data["uncertified_cells"][0]):
        print(f"{int(data['uncertified_cells'][0]):,} cells are not covered by the bound "
              "(raise --refine)")
    if args.out:
        print(f"wrote {save_mesh(result, args.out)}")
    if args.render:
        print(f"rendered {render_mesh(result, args.render, title=_model_name(args))}")
    return 0


def _suitability(shape: Any, args: argparse.Namespace, bounds: Any, max_memory: Any) -> None:
    """Print Bærentzen's criterion for the model at the command's grid."""
    if shape is None:
        raise ModelError("--check-suitability needs an implicit or csg model (a mesh has no "
                         "inside to open and close)")
    answer = suitability(shape, args.resolution, bounds=bounds, voxel_size=args.voxel_size,
                         max_memory=max_memory)
    print(f"suitability: {answer}")


def _model_name(args: argparse.Namespace) -> str:
    """The model's name for a picture's title: the example, or the file's name."""
    return args.example or os.path.basename(args.model)


def _is_mesh(args: argparse.Namespace) -> bool:
    """Whether the command's model is a triangle mesh file."""
    return args.model is not None and args.example is None and \
        args.model.lower().endswith(MESH_SUFFIXES)


def _field(args: argparse.Namespace) -> int:
    is_mesh = _is_mesh(args)
    shape = args.model if is_mesh else _shape(args)
    if args.out is not None and os.path.splitext(args.out)[1].lower() not in FIELD_FORMATS:
        raise ModelError(f"--out {args.out}: a distance field is written as one of "
                         f"{', '.join(FIELD_FORMATS)}")
    bounds, max_memory = _common(args)
    if args.check_suitability:
        _suitability(None if is_mesh else shape, args, bounds, max_memory)
    bar = None if args.quiet else ProgressBar("distances")
    with _parallel(args) as parallel:
        field = distance_field(shape, args.resolution, bounds=bounds,
                               voxel_size=args.voxel_size, norm=args.norm,
                               band=args.band or None, tolerance=args.tolerance,
                               dtype=args.dtype, progress=bar, max_memory=max_memory,
                               **parallel)
    if bar:
        bar.close()
    h = min(field.grid.voxel_size)
    where = "everywhere" if field.band is None else f"in a {field.band}-voxel band"
    print(f"{field.count:,} samples ({field.norm}, {field.kind}) {where} "
          f"at {'x'.join(map(str, field.grid.shape))} in {field.metadata['seconds']:.2f} s; "
          f"{len(field.keys):,} bricks, {field.nbytes:,} bytes; largest error "
          f"{field.max_error:.3g} ({field.max_error / h:.2g} voxel)")
    if args.out:
        print(f"wrote {field.save(args.out)}")
    if args.render:
        picture = render_mesh(field.isosurface(), args.render, title=_model_name(args))
        print(f"rendered {picture}")
    return 0


def _voxelize(args: argparse.Namespace) -> int:
    is_mesh = _is_mesh(args)
    shape = None if is_mesh else _shape(args)
    if args.out is not None and os.path.splitext(args.out)[1].lower() in MESH_FORMATS:
        raise ModelError(f"--out {args.out}: voxels are not triangles; write a mesh with "
                         "`implicitvox mesh MODEL --tolerance E --out X.stl`")
    bounds, max_memory = _common(args)
    if args.check_suitability:
        _suitability(shape, args, bounds, max_memory)
    bar = None if args.quiet else ProgressBar()
    if is_mesh:
        if args.normals or args.mean_value or args.subvoxel:
            raise ModelError("--normals, --mean-value and --subvoxel apply to implicit models, "
                             "not to meshes")
    with _parallel(args) as parallel:
        if is_mesh:
            vox = voxelize_mesh(args.model, args.resolution, bounds=bounds,
                                voxel_size=args.voxel_size, interior=args.interior,
                                progress=bar, max_memory=max_memory, **parallel)
        else:
            vox = voxelize(shape, args.resolution, bounds=bounds, voxel_size=args.voxel_size,
                           interior=args.interior, normals=args.normals or bool(args.render),
                           progress=bar, max_memory=max_memory, mean_value=args.mean_value,
                           subvoxel=args.subvoxel, recheck=args.recheck, prune=args.prune,
                           **parallel)
    if bar:
        bar.close()
    meta = vox.metadata
    print(f"{vox.count:,} surface voxels at {'x'.join(map(str, vox.resolution))} in "
          f"{meta['seconds_total']:.2f} s; octree {vox.octree.nbytes:,} bytes")
    if args.interior:
        print(f"{vox.interior_count:,} interior voxels")
    if args.out:
        print(f"wrote {vox.save(args.out)}")
    if args.render:
        title = f"{_model_name(args)} {'x'.join(map(str, vox.resolution))}"
        print(f"rendered {vox.render(args.render, title=title)}")
    return 0


@contextlib.contextmanager
def _warnings_as_lines(debug: bool) -> Iterator[None]:
    """A warning as one line, ``implicitvox: warning: <message>`` (the message names
    the model's file, line and column), not Python's two lines naming our source;
    ``--debug`` keeps Python's."""
    with warnings.catch_warnings():
        if not debug:
            def show(message: Any, category: type, *_: Any, **__: Any) -> None:
                print(f"implicitvox: warning: {message}", file=sys.stderr)
            warnings.showwarning = show
        yield


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Entry point; returns the exit status: 0, 2 for bad input (one line on stderr,
    naming it), 1 for anything else (one line; ``--debug`` shows the traceback),
    130 when interrupted."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "examples":
            for name, (description, _) in EXAMPLES.items():
                print(f"{name:<14}{description}")
            return 0
        with _warnings_as_lines(args.debug):
            return {"mesh": _mesh, "field": _field, "voxelize": _voxelize}[args.command](args)
    except (ModelError, ValueError, TypeError, MemoryError, OSError) as err:
        if args.debug:
            traceback.print_exc()
        print(f"implicitvox: error: {err}", file=sys.stderr)
        return 2
    except WorkerError as err:
        if args.debug:
            traceback.print_exc()
        print(f"implicitvox: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("implicitvox: interrupted", file=sys.stderr)
        return 130
    except Exception as err:  # noqa: BLE001 - the one place that turns the rest into a line
        if args.debug:
            traceback.print_exc()
        print(f"implicitvox: internal error: {type(err).__name__}: {err} (run with --debug "
              "for the traceback, and please report it)", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
