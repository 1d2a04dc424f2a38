"""The architecture's rules (docs/architecture.md), checked on the source:

- the CLI and the Python API name no format, not even as an option (``--vtk``): every format
  choice comes from the registry;
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
import importlib
import re
from pathlib import Path

import pytest

from fibrelmp import registry
from fibrelmp.registry import ALSO, DOCUMENT, FRAMES, INPUT, MESH, MOTION, RESULT, TARGET

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "fibrelmp"

# what a reader of the code would recognise as a format's name (registry names + spellings)
FORMAT_WORDS = sorted({f.name for f in registry.formats()} |
                      {"fibrenet", "musen", "cmusen", "demdf", "mercury", "mercurydpm", "vtk",
                       "vtu", "pvd", "paraview", "xyz", "mdem", "openCARP"}, key=str.lower)


@pytest.mark.parametrize("module", ["cli.py", "python_api.py"])
def test_cli_and_python_api_name_no_format(module):
    text = (PACKAGE / module).read_text()
    # words, not substrings: "results" is not "res", "fibrelmp" is not a format; "--vtk" is
    # (grep -w); the MDAnalysis library, which RunResult.universe uses, is not the format
    found = sorted({w for w in FORMAT_WORDS
                    if re.search(rf"(?<!\w){re.escape(w)}(?!\w)", text,
                                 0 if w == "mdanalysis" else re.I)})
    assert not found, f"{module} names formats: {found}"


def _type_checking_only(tree: ast.Module) -> set[int]:
    """Ids of the nodes under ``if TYPE_CHECKING:``: those imports never run."""
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip.update(id(n) for stmt in node.body for n in ast.walk(stmt))
    return skip


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


class ImportGraph:
    """Which modules of a package tree import which, read with ``ast`` (nothing is imported)."""

    def __init__(self, root: Path, exceptions: set[tuple[str, str]] = frozenset(),
                 units: tuple[str, ...] = ()):
        self.top = root.name
        self.units = units          # deeper packages that are parts of the root of their own
        self.modules: dict[str, Path] = {}
        for path in sorted(root.rglob("*.py")):
            parts = path.relative_to(root.parent).with_suffix("").parts
            self.modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
        self.base = root.parent
        self.imports = {m: {t: line for t, line in self._imports(m).items()
                            if (m, t) not in exceptions} for m in self.modules}

    def _module_of(self, name: str) -> str | None:
        """The module ``name`` executes: itself, else its nearest existing parent."""
        while name and name not in self.modules:
            name = name.rpartition(".")[0]
        return name or None

    def _imports(self, module: str) -> dict[str, int]:
        """The modules ``module`` imports at run time (function-level imports too), with the
        line of the first such import.  Importing ``a.b.c`` also runs the packages ``a.b`` and
        ``a`` (not the root, whose lazy exports import nothing when it loads)."""
        path = self.modules[module]
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
                names = [f"{base}.{a.name}" if f"{base}.{a.name}" in self.modules else base
                         for a in node.names]
            else:
                continue
            for name in names:
                ours = name == self.top or name.startswith(self.top + ".")
                target = self._module_of(name) if ours else None
                while target and target != self.top:
                    if target != module:
                        out[target] = min(out.get(target, node.lineno), node.lineno)
                    target = target.rpartition(".")[0]
        return out

    def where(self, module: str, target: str) -> str:
        line = self.imports[module][target]
        return f"{self.modules[module].relative_to(self.base)}:{line} imports {target}"

    def part_of(self, package: str, module: str) -> str | None:
        """Which part of ``package`` holds ``module``: one of its plain modules (the package's
        own ``__init__`` included) or the whole of one of its subpackages (``name/``)."""
        if module == package:
            return module
        if not module.startswith(package + "."):
            return None
        if package == self.top:
            for unit in self.units:
                if module == unit or module.startswith(unit + "."):
                    return unit + "/"
        child = package + "." + module[len(package) + 1:].split(".")[0]
        return child + "/" if self.modules[child].name == "__init__.py" else child

    def packages(self) -> list[str]:
        return sorted(m for m, p in self.modules.items() if p.name == "__init__.py")

    def subpackage_cycles(self, package: str) -> list[str]:
        """Inside ``package``: the import cycles that run through one of its subpackages (each
        taken whole), with the imports that make them.  Plain modules of one package may need
        each other; two subpackages, or a subpackage and a module beside it, may not."""
        graph: dict[str, set[str]] = {}
        edges: dict[tuple[str, str], list[str]] = {}
        for module, targets in self.imports.items():
            a = self.part_of(package, module)
            if a is None:
                continue
            graph.setdefault(a, set())
            for target in targets:
                b = self.part_of(package, target)
                if b is not None and b != a:
                    graph[a].add(b)
                    graph.setdefault(b, set())
                    edges.setdefault((a, b), []).append(self.where(module, target))
        found = []
        for component in _cycles(graph):
            if any(part.endswith("/") for part in component):
                members = set(component)
                found.append("cycle " + " <-> ".join(component) + ":\n  " + "\n  ".join(
                    w for (a, b), where in sorted(edges.items()) if a in members and b in members
                    for w in where))
        return found


# The one upward import: ``fibrelmp.translate`` is callable as the API's
# ``translate(path, folder)`` and imports ``python_api`` only when called.
# The format homes under translate/ are parts of fibrelmp of their own (a layer above post and
# pictures, LAYERS): translate/ (the shared job code) and each home are taken whole apart.
HOMES = ("fibrelmp.translate.fibrenet", "fibrelmp.translate.demdf", "fibrelmp.translate.musen",
         "fibrelmp.translate.cardioproof")
GRAPH = ImportGraph(PACKAGE, {("fibrelmp.translate", "fibrelmp.python_api")}, HOMES)
MODULES, IMPORTS = GRAPH.modules, GRAPH.imports


@pytest.mark.parametrize("package", GRAPH.packages())
def test_no_import_cycle_between_subpackages(package):
    bad = GRAPH.subpackage_cycles(package)
    assert not bad, "\n".join(bad)


def _toy_tree(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    return root / "pkg"


def test_the_cycle_check_sees_function_level_imports_and_skips_type_checking_ones(tmp_path):
    """The check itself, on a toy package: ``pkg.a`` and ``pkg.b`` import each other, one of
    them inside a function (a cycle), or under ``if TYPE_CHECKING:`` (none)."""
    files = {"pkg/__init__.py": "", "pkg/a/__init__.py": "", "pkg/b/__init__.py": "",
             "pkg/a/x.py": "from pkg.b.y import g\n",
             "pkg/b/y.py": "def g():\n    from ..a import x\n    return x\n",
             "pkg/b/z.py": "import pkg.b.y\n", "pkg/m.py": "from pkg.a import x\n"}
    cyclic = ImportGraph(_toy_tree(tmp_path / "one", files))
    assert cyclic.imports["pkg.b.y"] == {"pkg.a.x": 2, "pkg.a": 2}
    [found] = cyclic.subpackage_cycles("pkg")
    assert found.startswith("cycle pkg.a/ <-> pkg.b/:") and "pkg/b/y.py:2 imports pkg.a.x" in found
    assert cyclic.subpackage_cycles("pkg.b") == []          # y and z inside b: no cycle there

    files["pkg/b/y.py"] = ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                           "    from pkg.a import x\n")
    assert ImportGraph(_toy_tree(tmp_path / "two", files)).subpackage_cycles("pkg") == []


# The layers, lowest first (docs/architecture.md draws them).  A module imports its own layer
# and the layers below; an import upwards fails, and so does a module no layer names.
LAYERS = [
    ("base", ["errors", "textio", "units", "registry", "formatbase", "lammps_text", "_lammps",
              "lammps_log", "numtext/", "lammps_styles/"]),
    ("core", ["particles", "model", "granmodel", "sanity", "record", "runner", "lammps_flow", "checkpoint",
              "outputs", "inputformat", "runplan", "also", "finite"]),
    ("mesh", ["mesh/"]),
    ("translate", ["translate/"]),
    ("post", ["post/"]),
    # what the granular formats' homes share: the check summary, the run request and frames
    ("cases", ["granular_check", "granular_run/"]),
    ("pictures", ["pictures/"]),
    # a format's home: reader, writers, input hook, post target, picture source; it uses the
    # shared translate code, post's and pictures' bases, never the pipeline
    ("homes", [h[len("fibrelmp."):].replace(".", "/") + "/" for h in HOMES]),
    ("pipeline", ["pipeline/"]),
    ("api", ["__init__", "python_api", "cli"]),
]
LAYER_OF = {unit: rank for rank, (_, units) in enumerate(LAYERS) for unit in units}


def _unit(module: str) -> str:
    """The part of fibrelmp that holds ``module`` (as LAYERS names it: a format home,
    ``translate/fibrenet/``, or a top-level module or package)."""
    part = GRAPH.part_of("fibrelmp", module)
    return "__init__" if part == "fibrelmp" else part[len("fibrelmp."):].replace(".", "/")


def test_every_module_has_a_layer():
    missing = sorted({_unit(m) for m in MODULES} - set(LAYER_OF))
    assert not missing, f"not in test_architecture.LAYERS (and the picture in docs/architecture.md): {missing}"


def test_imports_point_down_the_layers():
    bad = []
    for module, targets in IMPORTS.items():
        for target in targets:
            a, b = _unit(module), _unit(target)
            if LAYER_OF.get(b, -1) > LAYER_OF.get(a, len(LAYERS)):
                bad.append(f"{GRAPH.where(module, target)} ({LAYERS[LAYER_OF[a]][0]} -> "
                           f"{LAYERS[LAYER_OF[b]][0]})")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("unit", ["numtext/", "lammps_styles/"])
def test_built_parts_import_nothing_of_fibrelmp(unit):
    """The C fast path and the LAMMPS plugin build on their own."""
    bad = [GRAPH.where(m, t) for m, targets in IMPORTS.items() if _unit(m) == unit
           for t in targets if _unit(t) != unit]
    assert not bad, "\n".join(bad)


# The particle model's families (fibrelmp/particles.py) and their homes: only there may code
# switch on a family; a shared module asks the model (docs/architecture.md, "The particle model")
FAMILY_HOMES = {"Model": "fibrelmp.model", "GranularModel": "fibrelmp.granmodel",
                "SphCase": "fibrelmp.translate.cardioproof"}


def family_switches(tree: ast.Module) -> list[tuple[int, str]]:
    """(line, family) of every switch on a model family in ``tree``: ``isinstance`` /
    ``issubclass`` naming a family class, or ``type(x) is/== Family``."""
    def families(node: ast.AST) -> set[str]:
        names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
        names |= {n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute)}
        return names & set(FAMILY_HOMES)

    found = []
    for node in ast.walk(tree):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in ("isinstance", "issubclass") and len(node.args) == 2):
            found += [(node.lineno, name) for name in families(node.args[1])]
        elif isinstance(node, ast.Compare) and any(
                isinstance(side, ast.Call) and isinstance(side.func, ast.Name) and side.func.id == "type"
                for side in [node.left, *node.comparators]):
            found += [(node.lineno, name) for side in [node.left, *node.comparators]
                      for name in families(side) if not isinstance(side, ast.Call)]
    return sorted(found)


def test_family_switches_are_found():
    tree = ast.parse("import fibrelmp.granmodel as g\n"
                     "def f(m):\n"
                     "    if isinstance(m, (g.GranularModel, int)):\n"
                     "        return 1\n"
                     "    return type(m) is SphCase or isinstance(m, ParticleModel)\n")
    assert family_switches(tree) == [(3, "GranularModel"), (5, "SphCase")]


def test_no_module_switches_on_a_model_family_outside_its_home():
    """sanity, record, the pipeline, the API ... ask a ``ParticleModel`` (its ``kind``,
    ``time_scale``, ``summary_figures`` ...) instead of testing which family it is."""
    bad = []
    for module, path in MODULES.items():
        for line, family in family_switches(ast.parse(path.read_text())):
            home = FAMILY_HOMES[family]
            if module != home and not module.startswith(home + "."):
                bad.append(f"{path.relative_to(REPO)}:{line}: switches on {family}")
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
    bad = [GRAPH.where(m, t) for m, targets in IMPORTS.items() if _unit(m) in shared
           for t in targets if any(t == c or t.startswith(c + ".") for c in code)]
    assert not bad, "\n".join(bad)


BASES = {
    INPUT: ("fibrelmp.inputformat", "InputFormat"),
    RESULT: ("fibrelmp.formatbase", "Writer"),
    TARGET: ("fibrelmp.post.target", "DumpTarget"),
    FRAMES: ("fibrelmp.formatbase", "Reader"),
    DOCUMENT: ("fibrelmp.formatbase", "DocumentFormat"),
    MESH: ("fibrelmp.mesh.model", "MeshFormat"),
    MOTION: ("fibrelmp.formatbase", "Reader"),
    ALSO: ("fibrelmp.also", "RunOutput"),
}


@pytest.mark.parametrize("fmt, role", [(f, r) for f in registry.formats() for r in f.roles],
                         ids=lambda v: v.name if isinstance(v, registry.Format) else v)
def test_every_hook_loads_and_derives_from_its_role_base(fmt, role):
    module, name = BASES[role]
    base = getattr(importlib.import_module(module), name)
    hook = fmt.load(role)
    assert isinstance(hook, type) and issubclass(hook, base), f"{fmt.name} {role}: {hook}"


def test_every_result_format_names_a_picture_source():
    """``plot``/``snapshot`` draw a result through the source its registry record names (no
    second table of formats in ``pictures``): each result format names one, and it loads."""
    from fibrelmp.pictures.sources import Source

    for fmt in registry.formats(RESULT):
        assert fmt.pictures, f"{fmt.name}: no picture source"
    for fmt in registry.formats():
        if fmt.pictures:
            source = fmt.load_pictures()
            assert isinstance(source, type) and issubclass(source, Source), f"{fmt.name}: {source}"
    assert not hasattr(importlib.import_module("fibrelmp.pictures.sources"), "_SOURCES")


def test_architecture_doc_lists_every_format():
    doc = (REPO / "docs" / "architecture.md").read_text()
    for fmt in registry.formats():
        assert f"`{fmt.name}`" in doc, fmt.name


def test_input_hooks_pick_no_run_output_writer():
    """``run --also``'s writers come from the registry (``pipeline.also``): no input hook
    imports the module of a format's ALSO hook."""
    homes = {f.hooks[ALSO].partition(":")[0] for f in registry.formats(ALSO)}
    hooks = {f.hooks[INPUT].partition(":")[0] for f in registry.formats(INPUT)}
    bad = [f"{module} imports {name}" for module, imports in sorted(GRAPH.imports.items())
           if module in hooks
           for name in imports if name in homes]
    assert homes and not bad, "\n".join(bad)


def test_architecture_doc_draws_every_layer():
    """The picture of the layers in docs/architecture.md names each layer and what it holds."""
    doc = (REPO / "docs" / "architecture.md").read_text()
    picture = doc[doc.index("### The layers"):].split("```")[1]
    rows = {line.split()[0]: line for line in picture.splitlines() if line[:1] == " " and line.split()
            and line.split()[0].isalpha()}
    assert list(rows) == [name for name, _ in reversed(LAYERS)]
    for name, units in LAYERS:
        text = rows[name] + "".join(ln for ln in picture.splitlines() if ln.startswith("            "))
        for unit in units:
            shown = "fibrelmp/__init__.py" if unit == "__init__" else unit.rstrip("/")
            assert shown in text, f"docs/architecture.md: layer {name} does not show {unit}"


MAX_FUNCTION_LINES = 80
MAX_MODULE_LINES = 600
LONG_MODULE_MARKER = "Longer than 600 lines because"


def test_functions_and_modules_stay_readable():
    """No function or method over 80 lines (``def`` to the last line of its body); no module
    over 600 lines unless its docstring says why (a line starting with LONG_MODULE_MARKER)."""
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text()
        tree = ast.parse(text)
        where = path.relative_to(REPO).as_posix()
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    offenders.append(f"{where}:{node.lineno}: function {node.name} has {length} lines")
        lines = len(text.splitlines())
        if lines > MAX_MODULE_LINES and LONG_MODULE_MARKER not in (ast.get_docstring(tree) or ""):
            offenders.append(f"{where}: {lines} lines and no '{LONG_MODULE_MARKER} ...' in its docstring")
    assert not offenders, "\n".join(offenders)
