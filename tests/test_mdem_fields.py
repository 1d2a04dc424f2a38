"""Every field of a `.mdem` file is honoured, refused or declared not simulation data
(fibrelmp/translate/musen/mdem/fields.py); each refused setting, set in MUSEN's example
scene, stops the run with `path: field: why`, exit 2, nothing written."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.mdem import fields as mdem_fields
from fibrelmp.translate.musen.mdem.messages import _SPEC, fields
from fibrelmp.translate.musen.mdem.model import read_scene

from .conftest import REPO
from .mdem_edit import with_edited_scene

SCENE = REPO / "tests" / "data" / "real-inputs" / "musen" / "SingelParticle.mdem"
DOC = REPO / "docs" / "musen.md"


def test_every_field_of_every_message_is_classified():
    """A field the table does not classify would be ignored silently: none may be missing,
    and no row may name a field the messages do not have."""
    missing = [f"{m}.{name}" for m in _SPEC for name, *_ in fields(m)
               if mdem_fields.classify(m, name) is None]
    assert missing == []
    known = {f"{m}.{name}" for m in _SPEC for name, *_ in fields(m)} | {f"{m}.*" for m in _SPEC}
    assert sorted(set(mdem_fields.FIELDS) - known) == []
    classes = {c for c, _ in mdem_fields.FIELDS.values()}
    assert classes <= {mdem_fields.HONOURED, mdem_fields.REFUSED, mdem_fields.WARNED,
                       mdem_fields.NOT_SIMULATION}


def test_docs_table_lists_every_refused_setting():
    text = DOC.read_text()
    assert "## 8. `.mdem` fields" in text
    section = text.split("## 8. `.mdem` fields", 1)[1]
    for setting in mdem_fields.REFUSALS:
        assert setting in section, setting


def _edited(tmp_path: Path, edit, name: str = "edited.mdem") -> Path:
    """MUSEN's example scene with its scene message edited (time points kept as stored)."""
    return with_edited_scene(SCENE, tmp_path / name, edit)


def _ht(s, key):
    s.modules_data.model_manager.ht_pp_model.key = key
    s.modules_data.model_manager.ht_pp_model.path = "ModelPPHeatTransfer" if key else ""


def _keyed_model(s):
    s.modules_data.model_manager.pp_model.key = "B18A46C2786D4D44B925A8A04D0D1008"


REFUSED = [  # (edit, words of the message)
    (lambda s: _ht(s, "ABC"), "modules_data.model_manager.ht_pp_model: the old heat-transfer"),
    (lambda s: s.info.multispheres.add(id=[0]), "info.multispheres: 1 multisphere(s)"),
    (_keyed_model, "modules_data.model_manager.pp_model: a model stored by its key only"),
]


@pytest.mark.parametrize("edit, words", REFUSED)
def test_a_refused_setting_names_the_file_and_the_field(tmp_path, edit, words):
    path = _edited(tmp_path, edit)
    with pytest.raises(InputError) as err:
        read_scene(path)
    assert err.value.path == str(path) and err.value.line is None
    assert words in err.value.message


@pytest.mark.parametrize("edit", [
    lambda s: _ht(s, ""),                                        # empty slot
    lambda s: (_ht(s, "ABC"), setattr(s.modules_data.model_manager, "version", 1)),  # unread
])
def test_settings_at_their_inert_values_are_accepted(tmp_path, edit):
    base = read_scene(SCENE)
    model = read_scene(_edited(tmp_path, edit))
    assert model.spheres.count == base.spheres.count
    assert [k for k, _ in model.warnings] == [k for k, _ in base.warnings]


def test_output_choices_warn_by_name(tmp_path):
    def edit(s):
        s.info.selective_saving = True
        s.modules_data.simulator.save_collisions = True
    model = read_scene(_edited(tmp_path, edit))
    texts = [t for k, t in model.warnings if k == "musen-ignored-setting"]
    assert len(texts) == 2 and "selective_saving" in texts[0] and "save_collisions" in texts[1]


def test_refusal_through_the_cli_exits_2_and_writes_nothing(tmp_path):
    path = _edited(tmp_path, lambda s: s.info.multispheres.add(id=[0]))
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", str(path), "-o", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert f"{path}: info.multispheres: 1 multisphere(s)" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["edited.mdem"]


def test_contacts_between_bonded_particles_are_the_files_setting(tmp_path):
    """CompressionTest.mdem stores 'off' (cmusen honours it: MUSEN's Example 1); a scene
    without a model manager keeps MUSEN's default 'on'; a script's CONNECTED_PP_CONTACT wins."""
    model = read_scene(REPO / "tests" / "data" / "real-inputs" / "musen" / "CompressionTest.mdem")
    assert model.plan.contacts_between_bonded is False
    assert not [t for k, t in model.warnings if "connected_pp_contact" in t]
    on = _edited(tmp_path, lambda s: setattr(s.modules_data.model_manager, "connected_pp_contact", True))
    assert read_scene(on).plan.contacts_between_bonded is True
    bare = _edited(tmp_path, lambda s: s.modules_data.ClearField("model_manager"), "bare.mdem")
    assert read_scene(bare).plan.contacts_between_bonded is True


def test_docs_table_has_every_row():
    section = DOC.read_text().split("## 8. `.mdem` fields", 1)[1]
    for key, (cls, _) in mdem_fields.FIELDS.items():
        assert f"| `{key}` | {cls} |" in section, key


def test_two_stored_models_of_one_kind_both_act(tmp_path):
    """A version-1 model list with two particle-particle models: MUSEN runs both, in order."""
    from fibrelmp.registry import INPUT, detect

    def edit(s):
        manager = s.modules_data.model_manager
        manager.version = 1
        manager.models.add(key="B18A46C2786D4D44B925A8A04D0D1008", path="ModelPPHertzMindlin")
        manager.models.add(key="K2", path="ModelPPLinearElastic", params="Kn 1e5 Kt 1e5")
    path = _edited(tmp_path, edit)
    model = detect(path).load(INPUT)().model(path)
    assert model.models["PP"].name == "ModelPPHertzMindlin"
    assert [(c.name, c.parameters, c.line) for c in model.later_models] == [
        ("ModelPPLinearElastic", {"Kn": 1e5, "Kt": 1e5}, None)]
