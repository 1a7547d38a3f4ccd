"""The house: layers import only downward, no cycles, no private names across modules.

The import graph is read from the source (the AST), every import counted,
also those inside functions: a module-level cycle hidden behind a late import
is still a cycle. ``from package import module`` is an edge to that module;
``from module import name`` an edge to the module.
"""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("implicitvox", "csg")

#: the kernel's layers, bottom first: a module may import its own layer and those below
LAYERS = [
    ("implicitvox.validate", "implicitvox.lazy", "implicitvox.version", "implicitvox.batches"),
    ("implicitvox.parallel",),
    ("implicitvox.expr",),
    ("implicitvox.interval",),
    ("implicitvox.eval",),
    ("implicitvox.octree",),
    ("implicitvox.triangles",),
    ("implicitvox.linf",),
    ("implicitvox.meshing",),
    ("implicitvox.voxelizers",),
    ("implicitvox.fields",),
    ("implicitvox.io",),
    ("implicitvox",),
]

#: the public names, as before the house move (issue 16: they stay)
IMPLICITVOX_ALL = [
    "Expr", "constant", "wrap", "x", "y", "z", "Function", "compile",
    "r", "rho", "theta", "phi", "spherical", "cylindrical", "Spherical", "Cylindrical",
    "radius", "elevation", "repeat", "repeat_polar",
    "voxelize", "voxelize_mesh", "winding_numbers", "BezierPatch", "voxelize_bezier",
    "utah_teapot", "linf", "linf_distance", "Voxels", "Grid", "Octree", "PointerOctree", "load",
    "mesh", "Shape", "EMPTY", "FULL", "AMBIGUOUS", "distance_field", "DistanceField", "load_field",
    "suitability", "Suitability",
    "abs", "acos", "affine", "asin", "atan", "atan2", "clip", "cos", "exp", "floor", "hypot",
    "log", "max", "min", "sin", "sqrt", "square", "tan",
]
CSG_ALL = [
    "Solid", "Union", "Intersection", "Difference", "Complement", "Transformed", "ExprSolid",
    "rotation_matrix", "Sphere", "Box", "Cylinder", "Torus", "Ellipsoid", "Capsule", "HalfSpace",
    "ConvexPolyhedron", "Polyhedron", "Circle", "Rectangle", "Polygon", "linear_extrude",
    "rotate_extrude", "smooth_union", "smooth_intersection", "smooth_difference", "Blobby",
    "read_openscad", "OpenSCADError", "OpenSCADWarning", "OpenSCADNotFound", "load_json",
    "SceneError",
    "hull", "minkowski", "NotAPolytope",
]


def _shown(path: Path) -> str:
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def _modules() -> dict[str, Path]:
    out = {}
    for pkg in PACKAGES:
        for f in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(f.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = f
    return out


MODULES = _modules()


def _imports(name: str, path: Path) -> list[tuple[str, list[str], int]]:
    """(target module, imported names, line) of every import in a module."""
    tree = ast.parse(path.read_text())
    is_pkg = path.name == "__init__.py"
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                found.append((alias.name, [], node.lineno))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_pkg else name.split(".")[:-1]
                base = base[:len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            names = [a.name for a in node.names]
            subs = [n for n in names if f"{module}.{n}" in MODULES]
            if subs:      # a submodule: the edge goes to it, and its own name counts too
                found.extend((f"{module}.{n}", [n], node.lineno) for n in subs)
                rest = [n for n in names if f"{module}.{n}" not in MODULES]
                if rest:
                    found.append((module, rest, node.lineno))
            else:
                found.append((module, names, node.lineno))
    return found


def _graph() -> dict[str, set[str]]:
    graph = {}
    for name, path in MODULES.items():
        graph[name] = {target for target, _, _ in _imports(name, path) if target in MODULES}
    return graph


def _layer(module: str) -> int:
    best = None
    for i, group in enumerate(LAYERS):
        for prefix in group:
            if module == prefix or module.startswith(prefix + "."):
                if best is None or len(prefix) > best[1]:
                    best = (i, len(prefix))
    assert best is not None, f"{module} is in no layer: add it to LAYERS"
    return best[0]


def test_no_import_cycles():
    graph = _graph()
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)


def test_layers_import_only_downward_and_the_kernel_never_imports_csg():
    wrong = []
    for name, targets in _graph().items():
        if not name.startswith("implicitvox"):
            continue
        for target in targets:
            if target.startswith("csg"):
                wrong.append(f"{name} imports {target} (the kernel never imports csg)")
            elif target == "implicitvox" and name != "implicitvox":
                wrong.append(f"{name} imports the package root (import its subpackages)")
            elif _layer(target) > _layer(name):
                wrong.append(f"{name} (layer {_layer(name)}) imports {target} "
                             f"(layer {_layer(target)})")
    assert not wrong, "\n".join(sorted(wrong))


def test_no_private_name_is_imported_across_modules():
    wrong = []
    for name, path in MODULES.items():
        for target, names, line in _imports(name, path):
            if target == "__future__":
                continue
            for n in names:
                if n.startswith("_") and not n.startswith("__"):
                    wrong.append(f"{_shown(path)}:{line} imports {n} from {target}")
    assert not wrong, "\n".join(wrong)


def test_no_private_attribute_of_an_imported_module_is_used():
    wrong = []
    for name, path in MODULES.items():
        tree = ast.parse(path.read_text())
        aliases = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                for a in node.names:
                    target = f"{node.module}.{a.name}" if node.module else a.name
                    if target in MODULES or node.level:
                        aliases.add(a.asname or a.name)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] in PACKAGES:
                        aliases.add(a.asname or a.name.split(".")[0])
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                    and node.value.id in aliases and node.attr.startswith("_") \
                    and not node.attr.startswith("__"):
                wrong.append(f"{_shown(path)}:{node.lineno} uses "
                             f"{node.value.id}.{node.attr}")
    assert not wrong, "\n".join(wrong)


def test_public_names_are_unchanged():
    import csg
    import implicitvox
    assert sorted(implicitvox.__all__) == sorted(IMPLICITVOX_ALL)
    assert sorted(csg.__all__) == sorted(CSG_ALL)
    for mod in (implicitvox, csg):
        missing = [n for n in mod.__all__ if not hasattr(mod, n)]
        assert not missing, f"{mod.__name__}.__all__ names what it lacks: {missing}"


def test_every_subpackage_has_a_public_api_and_a_docstring():
    for name, path in MODULES.items():
        if path.name != "__init__.py":
            continue
        tree = ast.parse(path.read_text())
        assert ast.get_docstring(tree), f"{name} has no docstring"


def test_import_loads_neither_scipy_nor_mpmath():
    code = ("import sys, implicitvox; "
            "print(sorted(m for m in ('scipy', 'mpmath', 'pyvista', 'vtk', 'skimage', 'csg') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=ROOT)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr


def test_the_layer_checks_can_fail(tmp_path, monkeypatch):
    """A planted upward import, cycle and private import are caught."""
    fake = {"implicitvox.expr.bad": tmp_path / "bad.py"}
    fake["implicitvox.expr.bad"].write_text(
        "from ..io.cli import main\nfrom ..octree.grid import _whole_voxels\n")
    monkeypatch.setitem(MODULES, "implicitvox.expr.bad", fake["implicitvox.expr.bad"])
    with pytest.raises(AssertionError, match="layer 1"):
        test_layers_import_only_downward_and_the_kernel_never_imports_csg()
    with pytest.raises(AssertionError, match="_whole_voxels"):
        test_no_private_name_is_imported_across_modules()
    cyc = tmp_path / "cyc.py"
    cyc.write_text("from ..io import cli\n")
    monkeypatch.setitem(MODULES, "implicitvox.expr.cyc", cyc)
    monkeypatch.setitem(MODULES, "implicitvox.io.cli2", tmp_path / "cli2.py")
    (tmp_path / "cli2.py").write_text("from ..expr import cyc\n")
    cyc.write_text("from ..io import cli2\n")
    with pytest.raises(pytest.fail.Exception, match="import cycle"):
        test_no_import_cycles()


#: tracked files allowed over ``MAX_TRACKED_BYTES``: test data, each with its size in bytes
LARGE_TEST_DATA = {
    "tests/openscad/lettering.stl": 1154340,   # OpenSCAD's own STL export of lettering.scad
}
MAX_TRACKED_BYTES = 1 << 20
#: endings of archives, wheels and binaries that never belong in the repository
ARCHIVE_ENDINGS = (".whl", ".zip", ".tar", ".tar.gz", ".tgz", ".tar.bz2", ".tar.xz", ".gz",
                   ".bz2", ".xz", ".7z", ".rar", ".egg", ".so", ".dll", ".dylib", ".exe",
                   ".pyc", ".jar")


def _tracked_files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-z"], capture_output=True, check=True, cwd=ROOT)
    return [p for p in out.stdout.decode().split("\0") if p]


def _unwanted(paths: list[str]) -> list[str]:
    wrong = []
    for rel in paths:
        path = ROOT / rel
        if rel.lower().endswith(ARCHIVE_ENDINGS):
            wrong.append(f"{rel} is an archive or binary: it does not belong in the repository")
        elif path.is_file() and path.stat().st_size > MAX_TRACKED_BYTES:
            size = path.stat().st_size
            if LARGE_TEST_DATA.get(rel) != size:
                wrong.append(f"{rel} has {size} bytes, over {MAX_TRACKED_BYTES}: name it in "
                             f"LARGE_TEST_DATA with its size if it is test data")
    return wrong


@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="not a git checkout: nothing is tracked")
def test_no_archive_and_no_large_file_is_tracked():
    wrong = _unwanted(_tracked_files())
    assert not wrong, "\n".join(wrong)


def test_the_tracked_file_check_can_fail(tmp_path, monkeypatch):
    """A wheel and an unlisted large file are caught; listed test data of its size is not."""
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    (tmp_path / "numpy-2.0-cp311.whl").write_bytes(b"PK")
    (tmp_path / "big.bin").write_bytes(b"\0" * (MAX_TRACKED_BYTES + 1))
    (tmp_path / "tests" / "openscad").mkdir(parents=True)
    (tmp_path / "tests/openscad/lettering.stl").write_bytes(b"\0" * 1154340)
    wrong = _unwanted(["numpy-2.0-cp311.whl", "big.bin", "tests/openscad/lettering.stl"])
    assert len(wrong) == 2
    assert "numpy-2.0-cp311.whl is an archive" in wrong[0]
    assert "big.bin has" in wrong[1]


def _layout_section() -> str:
    text = (ROOT / "README.md").read_text()
    return text.split("\n## Layout\n", 1)[1].split("\n## ", 1)[0]


def test_the_readme_layout_names_every_module():
    """A newcomer finds every module (and the data folder) on the README's map."""
    layout = _layout_section()
    def named(name: str) -> bool:
        path = name.replace(".", "/")
        return f"`{name.rsplit('.', 1)[-1]}`" in layout or f"`{path}/`" in layout \
            or f"`{path}`" in layout or f"`{name}`" in layout
    missing = [name for name in MODULES if name not in PACKAGES and not named(name)]
    if not (ROOT / "implicitvox" / "data").is_dir() or "`data/`" not in layout:
        missing.append("implicitvox/data/")
    assert not missing, f"the README's Layout does not name: {missing}"


def _solid_classes() -> list[type]:
    import importlib
    import inspect
    from csg.solid import Solid
    found = []
    for name in MODULES:
        if not name.startswith("csg"):
            continue
        module = importlib.import_module(name)
        found += [obj for obj in vars(module).values()
                  if inspect.isclass(obj) and issubclass(obj, Solid) and obj.__module__ == name]
    return found


def _protocol_faults(classes: list[type]) -> list[str]:
    """What the leaf classes among ``classes`` lack of the leaf protocol (csg.protocol),
    and the optional hooks defined with other parameters than it names."""
    import inspect
    from csg.protocol import OPTIONAL, REQUIRED
    from csg.solid import Solid
    faults = []
    for cls in classes:
        if cls.operation is not None or cls is Solid:
            continue                            # booleans and transforms are no leaves
        missing = [m for m in REQUIRED if getattr(cls, m) is getattr(Solid, m)]
        if missing and not cls.__subclasses__():     # a base of leaves may leave them
            faults.append(f"{cls.__module__}.{cls.__name__} lacks {missing}")
        for hook, wanted in OPTIONAL.items():
            if hook in vars(cls):
                got = tuple(list(inspect.signature(vars(cls)[hook]).parameters)[1:])
                if got != wanted:
                    faults.append(f"{cls.__module__}.{cls.__name__}.{hook} takes {got}, "
                                  f"the protocol {wanted}")
    return faults


def test_every_leaf_class_provides_the_leaf_protocol():
    classes = _solid_classes()
    assert len(classes) > 15
    faults = _protocol_faults(classes)
    assert not faults, "\n".join(faults)


def test_the_leaf_protocol_check_can_fail():
    from csg.solid import Solid

    class NoFunction(Solid):
        @property
        def bounds(self):
            return None

        def closed_mesh(self, matrix):
            return None

    faults = _protocol_faults([NoFunction])
    assert any("lacks ['expr', 'scene_node']" in f for f in faults)
    assert any("closed_mesh takes ('matrix',), the protocol ()" in f for f in faults)
