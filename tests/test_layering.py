"""Dependencies point one way.  ``lut`` is pure Python over numpy,
OpenImageIO and colour-science: it never imports bpy or the add-on.  Inside
``lut`` the layers import only layers before them (models -> colour ->
paint -> LUT files -> polarized -> render -> the top-level faces), and the add-on's
modules import each other without a circle."""

import ast
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
LUT = ROOT / "lut"
ADDON = ROOT / "addon"

#: lut's layers, in the order they may import each other ("" is the top:
#: lut/__init__.py, __main__, examples, bench, figures and the former names).
LAYERS = ("models", "colour", "paint", "lutfiles", "polarized", "render", "")


def _imports(path: pathlib.Path, root: pathlib.Path):
    """(line, absolute module name) of every import in the file at ``path``
    of the package at ``root``, at any depth (function bodies too);
    ``from . import x`` yields the package's ``x``."""
    here = list(path.relative_to(root.parent).parts[:-1])  # the file's package
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[: len(here) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            if node.module is None or node.level and not node.module:
                for alias in node.names:  # from . import x: x may be a module
                    yield node.lineno, f"{module}.{alias.name}"
            else:
                yield node.lineno, module


def _layer(module: str) -> int:
    parts = module.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else len(LAYERS) - 1


def lut_violations(root: pathlib.Path = LUT) -> list[str]:
    """Every import in ``root`` (a ``lut`` tree) that runs back up a layer,
    or out to bpy or the add-on."""
    found = []
    for path in sorted(root.rglob("*.py")):
        own = ".".join(("lut", *path.relative_to(root).with_suffix("").parts))
        for line, module in _imports(path, root):
            head = module.split(".")[0]
            where = f"{path.relative_to(root.parent)}:{line} imports {module}"
            if head in ("bpy", "addon", "mathutils"):
                found.append(where)
            elif head == "lut" and _layer(module) > _layer(own):
                found.append(f"{where} ({LAYERS[_layer(module)] or 'top'} is above {LAYERS[_layer(own)] or 'top'})")
    return found


def addon_cycles(root: pathlib.Path = ADDON) -> list[list[str]]:
    """Circles among the add-on's modules' imports of each other."""
    names = {p.stem for p in root.glob("*.py")}
    graph = {}
    for path in root.glob("*.py"):
        targets = set()
        for _, module in _imports(path, root):
            parts = module.split(".")
            if parts[0] == root.name and len(parts) > 1 and parts[1] in names and parts[1] != path.stem:
                targets.add(parts[1])
        graph[path.stem] = targets
    cycles, state = [], {}

    def visit(node, stack):
        state[node] = "open"
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                cycles.append(stack[stack.index(nxt) :] + [nxt])
            elif nxt not in state:
                visit(nxt, [*stack, nxt])
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    return cycles


def test_lut_imports_point_down_its_layers():
    assert lut_violations() == []


def test_addon_modules_import_each_other_without_a_circle():
    assert addon_cycles() == []


def test_the_checks_catch_what_they_guard(tmp_path):
    """Each check fails on a tree that breaks its rule."""
    lut = tmp_path / "lut"
    (lut / "models").mkdir(parents=True)
    (lut / "paint").mkdir()
    (lut / "models" / "facet.py").write_text("from ..paint import core\n")
    (lut / "paint" / "core.py").write_text("import bpy\nfrom ..models import facet\n")
    assert len(lut_violations(lut)) == 2
    addon = tmp_path / "addon"
    addon.mkdir()
    (addon / "api.py").write_text("from . import properties\n")
    (addon / "properties.py").write_text("def f():\n    from . import api\n")
    assert addon_cycles(addon) == [["api", "properties", "api"]]


@pytest.mark.parametrize("former", ["closures", "fitting", "lutfile", "schema"])
def test_former_module_paths_still_import_with_a_warning(former):
    """A released script's ``import lut.fitting`` gets the module at its new
    path, and is told so."""
    import subprocess
    import sys

    code = (
        "import warnings, lut, importlib\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    warnings.simplefilter('always')\n"
        f"    module = importlib.import_module('lut.{former}')\n"
        "print(module.__name__, [str(w.message) for w in caught if w.category is DeprecationWarning])\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    name = done.stdout.split()[0]
    assert name.startswith("lut.") and name != f"lut.{former}"
    assert f"lut.{former} is deprecated: import {name}" in done.stdout


def test_former_render_names_warn_and_work():
    import lut

    with pytest.warns(DeprecationWarning, match="lut.render.bake.node_inputs"):
        former = lut.render.node_inputs
    assert former is lut.render.bake.node_inputs


def test_the_polarized_package_imports_mitsuba_only_when_a_plugin_is_registered():
    """lut.polarized and its Mitsuba modules import without mitsuba or drjit
    (numpy only until ``register`` or a scene is built)."""
    import subprocess
    import sys

    code = (
        "import sys, lut.polarized, lut.polarized.mitsuba_bsdf, lut.polarized.scenes, lut.polarized.pictures, "
        "lut.polarized.benchmark; print(sorted(m for m in ('mitsuba', 'drjit') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
