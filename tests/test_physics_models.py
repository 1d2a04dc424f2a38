"""The registry of MUSEN physics models (fibrelmp/translate/granular/models/): every module of
the package registers one model, found by its MUSEN name; kinds, parameter names and defaults
are MUSEN's (checked against the real cmusen's own model list when it is here)."""

from __future__ import annotations

import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

from fibrelmp.translate.granular import models as physics
from fibrelmp.translate.musen.script_parse import MUSEN_MODELS

CMUSEN_MODELS = Path("/work/shared/oracles/cmusen_models.txt")   # cmusen's printed model list
MUSEN_GIT = Path("/work/.mirror/msolids+musen/repo")               # MUSEN's source (e0ff360)
ROOT = Path(__file__).resolve().parents[1]


def _registered():
    return [m for kind in physics.KIND_WORDS for m in physics.of_kind(kind)]


def test_every_module_registers_a_model():
    modules = [i.name for i in pkgutil.iter_modules(physics.__path__)]
    owners = sorted(m.__module__.rsplit(".", 1)[1] for m in _registered())
    assert owners == sorted(modules)


def test_names_and_kinds_are_musens():
    for m in _registered():
        assert m.name in MUSEN_MODELS[m.kind], m.name
        assert m.name.startswith(f"Model{m.kind}")
        assert physics.find(m.name) is m
        # MUSEN's keys are mostly 32 upper-case hex digits, but not all (ModelSBPlasticConcrete's
        # "...914SS7D...", ModelEFLiquidDiffusion's 40-digit sha1): test_keys_are_musens
        # compares each with MUSEN's source
        assert re.fullmatch(r"[0-9A-Z]{31,32}|[0-9a-f]{40}", m.mdem_key), m.name


@pytest.mark.skipif(not MUSEN_GIT.exists(), reason="MUSEN's source is not on this machine")
def test_keys_are_musens():
    """Each model's .mdem key is the m_uniqueKey of MUSEN's model of that name (e0ff360)."""
    files = subprocess.run(["git", "-C", str(MUSEN_GIT), "ls-tree", "-r", "--name-only", "HEAD",
                            "Models"], capture_output=True, text=True, check=True).stdout.split()
    for m in _registered():
        [source] = [f for f in files if f.endswith(f"/{m.name}.cpp")]
        text = subprocess.run(["git", "-C", str(MUSEN_GIT), "show", f"HEAD:{source}"],
                              capture_output=True, text=True, check=True).stdout
        keys = re.findall(r'm_uniqueKey\s*=\s*"([^"]*)"', text)
        assert keys == [m.mdem_key], (m.name, keys)


def test_every_model_has_its_current_page():
    """Each registered model has its page docs/models/<module>.md whose generated part is what
    tools/model_pages.py renders from the module now, and every page belongs to a model: a model
    added without its page, or changed without rerunning the tool, fails here."""
    pages = ROOT / physics.MODEL_PAGES
    for m in _registered():
        page = pages / f"{physics.module_name(m)}.md"
        assert page.exists(), f"{m.name}: no {page.relative_to(ROOT)} (python tools/model_pages.py)"
        generated = page.read_text().split(physics.PAGE_END, 1)[0] + physics.PAGE_END + "\n"
        assert generated == physics.model_page(m), f"{page.name} is stale: python tools/model_pages.py"
    modules = {physics.module_name(m) for m in _registered()}
    assert {p.stem for p in pages.glob("*.md")} == modules


def test_every_model_documents_itself():
    """A page's text is the model module's docstring, which starts with MUSEN's name."""
    for m in _registered():
        doc = sys.modules[m.__module__].__doc__ or ""
        assert doc.startswith(m.name) and len(" ".join(physics.model_doc(m))) > 40, m.name


@pytest.mark.skipif(not CMUSEN_MODELS.exists(), reason="the cmusen oracle is not on this machine")
def test_parameters_are_cmusens():
    listed = {}
    for line in CMUSEN_MODELS.read_text().splitlines():
        m = re.match(r"\s+(Model\w+) \([^)]*\)\s*(.*)$", line)
        if m:
            tok = m.group(2).split()
            listed[m.group(1)] = {tok[j]: float(tok[j + 1]) for j in range(0, len(tok), 2)}
    for m in _registered():
        assert m.parameters == listed[m.name], m.name


def test_mdem_key_of_unknown_model_is_empty():
    assert physics.mdem_key("ModelPPNoSuchModel") == ""        # not registered: no key
    assert physics.mdem_key("ModelSBKelvin") == "09405654485642A686561E1FC646DF1E"


def test_laws_name_the_models_that_chose_them():
    """Each law a scene carries names its MUSEN model (issue 25): the contact laws the PP
    model, the solid-bond law the SB model, and ``model.models`` where each was chosen."""
    import fibrelmp

    job = Path(__file__).resolve().parents[1] / "examples" / "musen" / "agglomerate_short_job.txt"
    [model] = [step.model for step in fibrelmp.read(job).steps if step.kind == "simulate"]
    assert {law.model for law in model.contacts.values()} == {"ModelPPHertzMindlin"}
    assert model.plan.bond_law.model == "ModelSBElastic" and model.plan.bond_law.form == "elastic"
    sb = model.models["SB"]
    assert (sb.kind, sb.source, sb.line) == ("SB", job, 11)        # MODEL_SB, line 11
    assert sb.parameters == {"CONSIDER_BREAKAGE": 1.0}
    for kind, choice in model.models.items():
        assert physics.find(choice.name).kind == kind


def test_bead_spring_pair_laws_name_their_law():
    import fibrelmp

    network = Path(__file__).resolve().parents[1] / "examples" / "fibre_network" / "input.txt"
    laws = {law.kind: law.law for law in fibrelmp.read(network).pairs}
    assert laws and all(name for name in laws.values())
    assert laws.get("hs", "harmonic soft-sphere repulsion") == "harmonic soft-sphere repulsion"
