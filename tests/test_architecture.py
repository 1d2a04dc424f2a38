"""The architecture's rules (docs/architecture.md), checked on the source:

- the CLI and the Python API name no format: every format choice comes from the registry;
- every module of fibrelmp sits in one layer (``LAYERS``) and imports only its own layer and
  those below (function-level imports count; ``if TYPE_CHECKING:`` ones never run);
- no import cycle runs through two subpackages, or a subpackage and a module beside it, at
  any depth of the package tree;
- the API and the shared layers below the formats reach a format only through the registry;
- every registry hook loads and derives from its role's base class;
- docs/architecture.md lists every registered format.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from fibrelmp import registry
from fibrelmp.registry import DOCUMENT, FRAMES, INPUT, MESH, MOTION, RESULT, TARGET

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "fibrelmp"

# what a reader of the code would recognise as a format's name (registry names + spellings)
FORMAT_WORDS = sorted({f.name for f in registry.formats()} |
                      {"fibrenet", "musen", "cmusen", "demdf", "mercury", "mercurydpm", "vtk",
                       "vtu", "pvd", "paraview", "xyz", "mdem", "openCARP"}, key=str.lower)


@pytest.mark.parametrize("module", ["cli.py", "python_api.py"])
def test_cli_and_python_api_name_no_format(module):
    text = (PACKAGE / module).read_text()
    # words, not substrings: "results" is not "res", "fibrelmp" is not a format
    # (the MDAnalysis library, which RunResult.universe uses, is not the "mdanalysis" format)
    found = sorted({w for w in FORMAT_WORDS
                    if re.search(rf"(?<![\w-]){re.escape(w)}(?![\w-])", text,
                                 0 if w == "mdanalysis" else re.I)})
    assert not found, f"{module} names formats: {found}"


def _modules() -> dict[str, Path]:
    """Every module of fibrelmp by dotted name (a package is its ``__init__.py``)."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(REPO).with_suffix("").parts
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


MODULES = _modules()


def _type_checking_only(tree: ast.Module) -> set[int]:
    """Ids of the import nodes under ``if TYPE_CHECKING:``: they never run."""
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip.update(id(n) for stmt in node.body for n in ast.walk(stmt))
    return skip


def _module_of(name: str) -> str | None:
    """The fibrelmp module ``name`` executes: itself, else its nearest existing parent."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _imports(module: str) -> dict[str, int]:
    """The fibrelmp modules ``module`` imports at run time (function-level imports too), with
    the line of the first such import.  Importing ``a.b.c`` also runs the packages ``a.b``
    and ``a`` (not the root ``fibrelmp``, whose lazy exports import nothing when loaded)."""
    path = MODULES[module]
    tree = ast.parse(path.read_text())
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    skip = _type_checking_only(tree)
    out: dict[str, int] = {}
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([node.module] if node.module else []))
            # ``from pkg import sub`` imports the submodule ``pkg.sub``
            names = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base
                     for a in node.names]
        else:
            continue
        for name in names:
            target = _module_of(name) if name.startswith("fibrelmp.") or name == "fibrelmp" else None
            while target and target != "fibrelmp":
                if target != module:
                    out[target] = min(out.get(target, node.lineno), node.lineno)
                target = target.rpartition(".")[0]
    return out


# The one upward import: ``fibrelmp.translate`` is callable as the API's
# ``translate(path, folder)`` and imports ``python_api`` only when called.
UPWARD_EXCEPTIONS = {("fibrelmp.translate", "fibrelmp.python_api")}

IMPORTS = {m: {t: line for t, line in _imports(m).items() if (m, t) not in UPWARD_EXCEPTIONS}
           for m in MODULES}


def _where(module: str, target: str) -> str:
    return f"{MODULES[module].relative_to(REPO)}:{IMPORTS[module][target]} imports {target}"


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            for nxt in edges:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return found


PACKAGES = sorted(m for m, p in MODULES.items() if p.name == "__init__.py")


def _part_of(package: str, module: str) -> str | None:
    """Which part of ``package`` holds ``module``: one of its plain modules (the package's own
    ``__init__`` included) or the whole of one of its subpackages (``name/``)."""
    if module == package:
        return module
    if not module.startswith(package + "."):
        return None
    child = package + "." + module[len(package) + 1:].split(".")[0]
    return child + "/" if MODULES[child].name == "__init__.py" else child


@pytest.mark.parametrize("package", PACKAGES)
def test_no_import_cycle_between_subpackages(package):
    """Inside ``package``, its subpackages (each taken whole) and its plain modules import each
    other without a cycle through a subpackage: modules of one package may need each other,
    two subpackages (or a subpackage and a module beside it) may not."""
    graph: dict[str, set[str]] = {}
    edges: dict[tuple[str, str], list[str]] = {}
    for module, targets in IMPORTS.items():
        a = _part_of(package, module)
        if a is None:
            continue
        graph.setdefault(a, set())
        for target in targets:
            b = _part_of(package, target)
            if b is not None and b != a:
                graph[a].add(b)
                graph.setdefault(b, set())
                edges.setdefault((a, b), []).append(_where(module, target))
    bad = []
    for component in _cycles(graph):
        if any(part.endswith("/") for part in component):
            members = set(component)
            bad.append("cycle " + " <-> ".join(component) + ":\n  " + "\n  ".join(
                w for (a, b), where in sorted(edges.items()) if a in members and b in members
                for w in where))
    assert not bad, "\n".join(bad)


def test_the_cycle_check_sees_a_cycle_through_a_function_level_import():
    """The check itself: two subpackages that import each other, one of them inside a function."""
    graph = {"a/": {"b/"}, "b/": {"a/"}, "c": {"a/"}}
    assert _cycles(graph) == [["a/", "b/"]]
    tree = ast.parse("def f():\n    from fibrelmp.pipeline.run import wrong_frame\n")
    assert [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)] == \
        ["fibrelmp.pipeline.run"]


# The layers, lowest first (docs/architecture.md draws them).  A module imports its own layer
# and the layers below; an import upwards fails, and so does a module no layer names.
LAYERS = [
    ("base", ["errors", "textio", "units", "registry", "formatbase", "lammps_text", "_lammps",
              "numtext/", "lammps_styles/"]),
    ("core", ["model", "granmodel", "sanity", "record", "runner", "checkpoint", "outputs"]),
    ("mesh", ["mesh/"]),
    ("translate", ["translate/"]),
    ("post", ["post/"]),
    ("cases", ["cardioproof/", "granular_check"]),
    ("pictures", ["pictures/"]),
    ("pipeline", ["pipeline/"]),
    ("api", ["__init__", "python_api", "cli"]),
]
LAYER_OF = {unit: rank for rank, (_, units) in enumerate(LAYERS) for unit in units}


def _unit(module: str) -> str:
    """The top-level part of fibrelmp that holds ``module`` (as LAYERS names it)."""
    part = _part_of("fibrelmp", module)
    return "__init__" if part == "fibrelmp" else part[len("fibrelmp."):]


def test_every_module_has_a_layer():
    missing = sorted({_unit(m) for m in MODULES} - set(LAYER_OF))
    assert not missing, f"not in test_architecture.LAYERS (and the picture in docs/architecture.md): {missing}"


def test_imports_point_down_the_layers():
    bad = []
    for module, targets in IMPORTS.items():
        for target in targets:
            a, b = _unit(module), _unit(target)
            if LAYER_OF.get(b, -1) > LAYER_OF.get(a, len(LAYERS)):
                bad.append(f"{_where(module, target)} ({LAYERS[LAYER_OF[a]][0]} -> "
                           f"{LAYERS[LAYER_OF[b]][0]})")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("unit", ["numtext/", "lammps_styles/"])
def test_built_parts_import_nothing_of_fibrelmp(unit):
    """The C fast path and the LAMMPS plugin build on their own."""
    bad = [_where(m, t) for m, targets in IMPORTS.items() if _unit(m) == unit
           for t in targets if _unit(t) != unit]
    assert not bad, "\n".join(bad)


def _format_code() -> list[str]:
    """The packages and modules that are a registered format's code: each home and hook module."""
    code = {f.home for f in registry.formats() if f.home}
    code |= {hook.partition(":")[0] for f in registry.formats() for hook in f.hooks.values()}
    return sorted(code)


def test_shared_layers_reach_formats_only_through_the_registry():
    """The API and the layers below the formats (base, core) import no format's code: they find
    a format through the registry (``Format.load``), which imports its hook when used."""
    code = _format_code()
    shared = {u for name, units in LAYERS if name in ("base", "core", "api") for u in units}
    bad = [_where(m, t) for m, targets in IMPORTS.items() if _unit(m) in shared
           for t in targets if any(t == c or t.startswith(c + ".") for c in code)]
    assert not bad, "\n".join(bad)


BASES = {
    INPUT: ("fibrelmp.pipeline.inputs", "InputFormat"),
    RESULT: ("fibrelmp.formatbase", "Writer"),
    TARGET: ("fibrelmp.post.target", "DumpTarget"),
    FRAMES: ("fibrelmp.formatbase", "Reader"),
    DOCUMENT: ("fibrelmp.formatbase", "DocumentFormat"),
    MESH: ("fibrelmp.mesh.model", "MeshFormat"),
    MOTION: ("fibrelmp.formatbase", "Reader"),
}


@pytest.mark.parametrize("fmt, role", [(f, r) for f in registry.formats() for r in f.roles],
                         ids=lambda v: v.name if isinstance(v, registry.Format) else v)
def test_every_hook_loads_and_derives_from_its_role_base(fmt, role):
    import importlib

    module, name = BASES[role]
    base = getattr(importlib.import_module(module), name)
    hook = fmt.load(role)
    assert isinstance(hook, type) and issubclass(hook, base), f"{fmt.name} {role}: {hook}"


def test_architecture_doc_lists_every_format():
    doc = (REPO / "docs" / "architecture.md").read_text()
    for fmt in registry.formats():
        assert f"`{fmt.name}`" in doc, fmt.name
