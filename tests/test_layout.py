"""The house plan (CONTRIBUTING.md): dependencies flow one way, no import cycles, small modules."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("bem", "fem_reference", "validation")
#: which packages each package may import (validation -> fem_reference -> bem)
ALLOWED = {"bem": {"bem"}, "fem_reference": {"bem", "fem_reference"},
           "validation": {"bem", "fem_reference", "validation"}}
MAX_LINES = 400
#: the layers of ``validation``, lowest first: each imports only the layers below it and the shared
#: modules (``validation.io``, ``units``, ``provenance``, ``compare``, ``extras``: any module of
#: ``validation`` outside these sub-packages), which import no layer
LAYERS = ("scene", "run", "studies", "report", "layer_law", "cli")


def _modules():
    """``{module name: path}`` of every module of the three packages."""
    out = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            parts = path.relative_to(ROOT).with_suffix("").parts
            out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def _imports(name, path, modules, *, top_level_only):
    """Project modules imported by the module ``name`` (relative imports resolved)."""
    is_package = path.name == "__init__.py"
    tree = ast.parse(path.read_text(encoding="utf-8"))
    nodes = tree.body if top_level_only else ast.walk(tree)
    found = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = name.split(".") if is_package else name.split(".")[:-1]
            if node.level:
                base = base[: len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module
            submodules = [f"{module}.{a.name}" for a in node.names]
            # ``from package import submodule`` needs the submodule; the package itself is
            # initialised before any of its submodules runs, so it is no dependency of its own
            targets = submodules if all(t in modules for t in submodules) else [module] + submodules
        else:
            continue
        for target in targets:
            while target and target not in modules:  # a name imported from a module: its module
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


def test_dependencies_flow_one_way():
    modules = _modules()
    wrong = sorted((name, target) for name, path in modules.items()
                   for target in _imports(name, path, modules, top_level_only=False)
                   if target.split(".")[0] not in ALLOWED[name.split(".")[0]])
    assert not wrong, wrong


def _layer(name):
    """Rank of a module of ``validation`` in :data:`LAYERS` (-1: a shared module)."""
    parts = name.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else -1


def upward_imports(modules):
    """``(module, imported module)`` of every import, function-level included, from a layer of
    ``validation`` to a layer above it (or from a shared module to any layer)."""
    return sorted((name, target) for name, path in modules.items() if name.startswith("validation")
                  for target in _imports(name, path, modules, top_level_only=False)
                  if target.startswith("validation.") and _layer(target) > _layer(name))


def test_validation_layers_import_downwards():
    assert not upward_imports(_modules()), upward_imports(_modules())


def test_layer_check_sees_function_level_imports(tmp_path):
    """A scene module importing the report inside a function is an upward import."""
    source = "def sections():\n    from ..report.documents.sections import SECTIONS\n    return SECTIONS\n"
    (tmp_path / "planted.py").write_text(source, encoding="utf-8")
    modules = {**_modules(), "validation.scene.planted": tmp_path / "planted.py"}
    assert ("validation.scene.planted", "validation.report.documents.sections") in upward_imports(modules)


def test_no_import_cycles():
    """No cycle among the modules' top-level imports (a package importing its own submodules and a
    submodule importing names of its package's other submodules are not cycles by themselves)."""
    modules = _modules()
    graph = {name: _imports(name, path, modules, top_level_only=True) for name, path in modules.items()}
    state, cycles = {}, []

    def visit(node, stack):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open" and not nxt.startswith(node + ".") and not node.startswith(nxt + "."):
                cycles.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, stack)
        stack.pop()
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [])
    assert not cycles, cycles


#: the import circles of ``bem`` (function-level imports included) that may remain: small, each inside
#: one concern (the array backend and the argument checks; the layer laws and their series)
KNOWN_CIRCLES = ({"bem.backend", "bem.checks", "bem.fft", "bem.layers.base", "bem.pruned_fft"},
                 {"bem.layers._common", "bem.layers.series"})


def import_circles(modules, package):
    """The import circles among the modules of ``package``: sets of modules each of which imports, through
    the others, every other one back (strongly connected components of more than one module), with
    function-level imports. Importing a package runs its ``__init__``, so a package depends on the
    submodules it imports; a submodule that imports its own package is no circle by itself."""
    graph = {name: {t for t in _imports(name, path, modules, top_level_only=False)
                    if t.startswith(package) and not name.startswith(t + ".")}
             for name, path in modules.items() if name == package or name.startswith(package + ".")}
    index, low, stack, circles = {}, {}, [], []

    def connect(node):  # Tarjan's algorithm
        index[node] = low[node] = len(index)
        stack.append(node)
        for nxt in sorted(graph[node]):
            if nxt not in graph:
                continue
            if nxt not in index:
                connect(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = set()
            while True:
                member = stack.pop()
                component.add(member)
                if member == node:
                    break
            if len(component) > 1:
                circles.append(component)

    for node in sorted(graph):
        if node not in index:
            connect(node)
    return circles


def test_bem_has_no_import_circles_but_the_known_ones():
    circles = import_circles(_modules(), "bem")
    assert all(c in KNOWN_CIRCLES for c in circles), circles
    assert len(circles) <= 2


def test_circle_check_sees_function_level_imports(tmp_path):
    """A module importing the driver inside a function, imported by the driver: one more circle."""
    (tmp_path / "planted.py").write_text("def run():\n    from .solve import solve\n    return solve\n",
                                         encoding="utf-8")
    (tmp_path / "driver.py").write_text("from .planted import run\n", encoding="utf-8")
    modules = {**_modules(), "bem.planted": tmp_path / "planted.py", "bem.solve": tmp_path / "driver.py"}
    circles = import_circles(modules, "bem")
    assert {"bem.planted", "bem.solve"} in circles
    assert not all(c in KNOWN_CIRCLES for c in circles)


#: private names of ``bem`` imported from a sibling module of the same concern (a gap shape from its
#: readers, a closed form from its base, a surface from its readers); the solver's modules share none
KNOWN_PRIVATE_IMPORTS = {("bem.gaps.measured", "_positive_pair"), ("bem.gaps.measured", "_refuse"),
                         ("bem.gaps.measured", "_axis"), ("bem.reference.layer_limit", "_ClosedForm"),
                         ("bem.rough.instrument_files", "_pair"), ("bem.rough.instrument_files", "_surface"),
                         ("bem.rough.instrument_files", "_surface_topography"), ("bem.rough.patch", "_surface"),
                         ("bem.rough.patch", "_surface_topography"), ("bem.rough.outliers", "_surface_topography"),
                         ("bem.rough.outliers", "_pair")}


def private_imports(modules, package):
    """``(module, name)`` of every private name (``_x``) that a module of ``package`` imports from
    another module, function-level imports included."""
    found = set()
    for name, path in modules.items():
        if name.split(".")[0] != package:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module != "__future__":
                found |= {(name, a.name) for a in node.names if a.name.startswith("_") and not a.name.startswith("__")}
    return found


def test_bem_imports_no_private_name_of_another_module_but_the_known_ones():
    assert private_imports(_modules(), "bem") <= KNOWN_PRIVATE_IMPORTS, private_imports(_modules(), "bem")


def test_private_import_check_sees_function_level_imports(tmp_path):
    (tmp_path / "planted.py").write_text("def run():\n    from ..solve import _run\n    return _run\n",
                                         encoding="utf-8")
    modules = {**_modules(), "bem.periodic.planted": tmp_path / "planted.py"}
    assert ("bem.periodic.planted", "_run") in private_imports(modules, "bem") - KNOWN_PRIVATE_IMPORTS


def test_no_module_over_400_lines():
    long = {str(p.relative_to(ROOT)): n for p in _modules().values()
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, long
