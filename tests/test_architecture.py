"""The architecture's rules (docs/architecture.md), checked on the source:

- the CLI and the Python API name no format, not even as an option (``--vtk``): every format
  choice comes from the registry;
- ``fibrelmp.translate`` (the formats' homes and the job renderers) imports neither
  ``fibrelmp.post`` nor ``fibrelmp.pipeline``, ``post`` does not import the pipeline and
  ``pictures`` (which reads results through both) neither the pipeline nor the API, so the
  packages form no cycle;
- every registry hook loads and derives from its role's base class;
- docs/architecture.md lists every registered format.
"""

from __future__ import annotations

import ast
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


def _imports(path: Path) -> set[str]:
    """Every module ``path`` imports, at any level (function-level imports too)."""
    tree = ast.parse(path.read_text())
    package = ".".join(path.relative_to(REPO).with_suffix("").parts[:-1])
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                out.add(".".join(base + ([node.module] if node.module else [])))
            else:
                out.add(node.module or "")
    return out


@pytest.mark.parametrize("package, forbidden", [
    ("translate", ("fibrelmp.post", "fibrelmp.pipeline", "fibrelmp.python_api", "fibrelmp.cli")),
    ("post", ("fibrelmp.pipeline", "fibrelmp.cli")),
    ("pictures", ("fibrelmp.pipeline", "fibrelmp.cli", "fibrelmp.python_api")),
    ("numtext", ("fibrelmp.",)),
])
def test_packages_form_no_cycle(package, forbidden):
    bad = []
    for path in sorted((PACKAGE / package).rglob("*.py")):
        for name in _imports(path):
            own = name == f"fibrelmp.{package}" or name.startswith(f"fibrelmp.{package}.")
            if name.startswith(forbidden) and not own:       # its own modules are fine
                bad.append(f"{path.relative_to(REPO)} imports {name}")
    # the callable-module shim of fibrelmp.translate defers to the API only when called
    bad = [b for b in bad if not b.startswith("fibrelmp/translate/__init__.py imports fibrelmp.python_api")]
    assert not bad, "\n".join(bad)


BASES = {
    INPUT: ("fibrelmp.pipeline.inputs", "InputFormat"),
    RESULT: ("fibrelmp.formatbase", "Writer"),
    TARGET: ("fibrelmp.post.target", "DumpTarget"),
    FRAMES: ("fibrelmp.formatbase", "Reader"),
    DOCUMENT: ("fibrelmp.formatbase", "DocumentFormat"),
    MESH: ("fibrelmp.mesh.model", "MeshFormat"),
    MOTION: ("fibrelmp.formatbase", "Reader"),
    ALSO: ("fibrelmp.pipeline.also", "RunOutput"),
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


def test_input_hooks_pick_no_run_output_writer():
    """``run --also``'s writers come from the registry (``pipeline.also``): no input hook
    imports the module of a format's ALSO hook."""
    homes = {f.hooks[ALSO].partition(":")[0] for f in registry.formats(ALSO)}
    bad = [f"{path.relative_to(REPO)} imports {name}"
           for path in sorted((PACKAGE / "pipeline" / "inputs").rglob("*.py"))
           for name in _imports(path) if name in homes]
    assert homes and not bad, "\n".join(bad)
