"""DEMDF reader on the real files, snapshot round trip, 2D layout, BOS's lookup rules.

Expected numbers are computed here from the JSON (parsed with the standard library) and the
Hertz formulas, not taken from the reader.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularFrame
from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter
from fibrelmp.translate.demdf import reader as demdf

from .conftest import shared_path

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples" / "demdf"
SIMULATIONS = ["test.json", "test_1pg.json", "test_inelastic_2p.json",
               "test_elastic_gravity_100p.json"]


def real(name: str) -> Path:
    return shared_path("real-inputs", "demdf", name)


def hertz_overlap(m_eff, r_eff, e_star, v):
    return (15 * m_eff * v * v / (16 * e_star * math.sqrt(r_eff))) ** 0.4


def write(tmp_path: Path, doc: dict, name: str = "spec.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(doc, indent=2))
    return path


def base_doc(**changes) -> dict:
    doc = {
        "fileFormat": "demdf", "dimensionality": 3, "time": 0.0, "timeEnd": 1.0,
        "output": {"snapshot": {"name": "demdf", "filename": "out", "saveCount": 0,
                                "savePeriodInTime": 0.5}},
        "domain": [[0, 0, 0], [5, 5, 5]], "bodyForce": [0, 0, 0],
        "objectTypes": [{"id": 0, "type": "particle", "radius": 0.5, "mass": 1.0,
                         "restitutionCoefficient": 0.9},
                        {"id": 1, "type": "wall", "restitutionCoefficient": 0.5}],
        "objects": {"particles": [[1, 1, 1, 1, 0, 0, 0], [3, 1, 1, -1, 0, 0, 0]],
                    "walls": [{"normal": [1, 0, 0], "point": [0, 0, 0], "objectType": 1}]},
        "interactions": [{"name": "particleInelastic", "objectTypes": [0, 0]},
                         {"name": "wallInelastic", "objectTypes": [0, 1]}],
    }
    doc.update(changes)
    return doc


# ---------------------------------------------------------------- real files
@pytest.mark.parametrize("name", SIMULATIONS)
def test_real_simulation_reads(name):
    path = real(name)
    doc = json.loads(path.read_text())
    model = demdf.read(path)
    rows = doc["objects"]["particles"]
    if isinstance(rows, str):          # test_elastic_gravity_100p -> config_10p.json
        rows = json.loads((path.parent / rows).read_text())["particles"]
    rows = np.array(rows, dtype=float)
    s = model.spheres
    assert model.kind == "demdf" and s.count == len(rows)
    assert np.array_equal(s.position, rows[:, 0:3]) and np.array_equal(s.velocity, rows[:, 3:6])
    assert np.allclose(s.radius, 0.5) and len(model.planes) == 6
    assert np.array_equal(model.plan.gravity, doc["bodyForce"])
    # every real file ends after timeStepCountEnd=1 step of timeStep=0.001
    assert model.plan.t_end == pytest.approx(0.001, rel=1e-12)
    # the integration step divides the file's step and resolves the contact (>= 50 steps)
    k = doc["timeStep"] / model.plan.dt
    assert k == pytest.approx(round(k), abs=1e-9) and round(k) >= 1
    inelastic = any(i["name"] == "particleInelastic" for i in doc["interactions"])
    for law in model.contacts.values():
        assert law.shear_eff == 0 and law.friction == 0
        assert law.restitution == (0.9 if inelastic else 1.0)
    # peak overlap <= 1% of the radius at the fastest approach the input allows
    lo, hi = map(np.array, doc["domain"])
    g = np.array(doc["bodyForce"], dtype=float)
    gn = np.linalg.norm(g)
    fall = float(np.abs(g) @ (hi - lo) / gn) if gn else 0.0
    speeds = np.sqrt((rows[:, 3:6] ** 2).sum(1) + 2 * gn * fall)
    wall_law = model.contact(0, 1)
    d = hertz_overlap(1.0, 0.5, wall_law.youngs_eff, speeds.max())
    assert d <= 0.005 * (1 + 1e-9)
    t_c = 2.943 * d / speeds.max()
    assert model.plan.dt <= t_c / 50 * (1 + 1e-9)
    if len(rows) > 1:
        top2 = np.sort(speeds)[-2:].sum()
        law = model.contact(0, 0)
        assert hertz_overlap(0.5, 0.25, law.youngs_eff, top2) == pytest.approx(0.005, rel=1e-9)
    kinds = {kind for kind, _ in model.warnings}
    assert "physics" in kinds            # the timeStep 0.001 is refined, and it says so
    assert any("eventCountEnd" in text and "ignored" in text for _, text in model.warnings)


@pytest.mark.parametrize("name, words", [
    ("config_10p.json", ["particles file", "not a stand-alone simulation"]),
    ("output_0.json", ["snapshot", "not a stand-alone simulation", "overwrite"]),
    ("demdfSchema.json", ["JSON Schema"]),
])
def test_real_non_simulations_are_refused(name, words):
    with pytest.raises(InputError) as exc:
        demdf.read(real(name))
    text = str(exc.value)
    assert text.startswith(str(real(name)))
    for word in words:
        assert word in text


def test_bos_snapshot_reads_as_snapshot():
    path = real("output_0.json")
    model = demdf.read_snapshot(path)
    assert model.plan.t_start == 0.7083333333333335
    assert np.array_equal(model.spheres.position, [[2.0, 1.5, 1.5]])
    assert np.array_equal(model.spheres.velocity, [[1.2, 0.0, 0.0]])


def test_copied_snapshot_runs_as_input(tmp_path):
    target = tmp_path / "restart.json"
    target.write_bytes(real("output_0.json").read_bytes())
    model = demdf.read(target, steps=10)
    assert model.plan.t_start == 0.7083333333333335
    assert model.plan.t_end == pytest.approx(0.7083333333333335 + 10 * model.plan.dt)


def test_overrides_are_recorded():
    path = real("test_inelastic_2p.json")
    model = demdf.read(path, time_end=0.5, save_every=0.05)
    assert model.plan.t_end == 0.5 and model.plan.save_every_time == 0.05
    assert model.plan.save_every_steps is None
    notes = [text for kind, text in model.warnings if kind == "override"]
    assert len(notes) == 2 and all(t.startswith("override:") for t in notes)
    model = demdf.read(path, steps=100, save_every=7)
    assert model.plan.t_end == pytest.approx(100 * model.plan.dt)
    assert model.plan.save_every_steps == 7 and model.plan.save_every_time is None
    model = demdf.read(path, time_end=0.5, steps=100)           # the first end reached
    assert model.plan.t_end == pytest.approx(100 * model.plan.dt)


def test_external_particles_file_is_relative_to_the_input(tmp_path, monkeypatch):
    folder = tmp_path / "case"
    folder.mkdir()
    (folder / "p.json").write_text(json.dumps({"particles": [[1, 1, 1, 0, 0, 0.5, 0]]}))
    doc = base_doc()
    doc["objects"]["particles"] = "p.json"
    path = write(folder, doc)
    monkeypatch.chdir(tmp_path)                   # not the input's folder
    model = demdf.read(path)
    assert np.array_equal(model.spheres.position, [[1, 1, 1]])
    assert np.array_equal(model.spheres.velocity, [[0, 0, 0.5]])


# ---------------------------------------------------------------- BOS's rules
def test_types_by_position_among_particle_types(tmp_path):
    doc = base_doc()
    doc["objectTypes"] = [
        {"id": 0, "type": "wall"},
        {"id": 5, "type": "particle", "radius": 0.5, "mass": 2.0, "restitutionCoefficient": 0.6},
        {"id": 7, "type": "particle", "radius": 0.25, "mass": 1.0, "restitutionCoefficient": 1.0},
    ]
    doc["objects"]["particles"] = [[1, 1, 1, 0, 0, 0, 1], [3, 1, 1, 0, 0, 0, 0]]
    doc["objects"]["walls"][0]["objectType"] = 0
    model = demdf.read(write(tmp_path, doc))
    s = model.spheres
    assert s.radius.tolist() == [0.25, 0.5] and s.mass.tolist() == [1.0, 2.0]
    m_small, m_big = int(s.material[0]), int(s.material[1])
    assert model.contact(m_small, m_big).restitution == pytest.approx(0.8)    # mean (BOS)
    assert model.contact(m_big, m_big).restitution == pytest.approx(0.6)
    wall = model.planes[0].material
    assert model.contact(m_small, wall).restitution == 1.0    # the particle's value, not 0 (wall)
    assert model.contact(m_big, wall).restitution == 0.6
    ids = [t for k, t in model.warnings if "id 5" in t or "id 7" in t]
    assert len(ids) == 2 and all("position" in t for t in ids)
    assert len(model.materials) == 3


def test_elastic_interactions_ignore_restitution(tmp_path):
    doc = base_doc(interactions=[{"name": "particleElastic"}, {"name": "wallElastic"},
                                 {"name": "linearViscoelasticSpecies", "stiffness": 1e5}])
    model = demdf.read(write(tmp_path, doc))
    assert {law.restitution for law in model.contacts.values()} == {1.0}
    assert any("linearViscoelasticSpecies" in t for _, t in model.warnings)


def test_legacy_typename_walls(tmp_path):
    doc = base_doc()
    doc["objects"]["walls"] = [{"normal": [0, 0, 2], "point": [0, 0, 0], "typename": "wallElastic"}]
    model = demdf.read(write(tmp_path, doc))
    plane = model.planes[0]
    assert np.array_equal(plane.normal, [0, 0, 1])
    assert model.materials[plane.material].name == "wall wallElastic"
    assert any("normalised" in t for _, t in model.warnings)


def test_stop_rules(tmp_path):
    model = demdf.read(write(tmp_path, base_doc(timeEnd=-1, timeStep=0.01, timeStepCountEnd=30,
                                                timeStepCount=10)))
    assert model.plan.t_end == pytest.approx(0.2)
    model = demdf.read(write(tmp_path, base_doc(timeEnd=0.05, timeStep=0.01, timeStepCountEnd=30)))
    assert model.plan.t_end == 0.05
    with pytest.raises(InputError, match="negative.*needs an end"):
        demdf.read(write(tmp_path, base_doc(timeEnd=-1, eventCountEnd=100)))
    doc = base_doc()
    del doc["timeEnd"]
    with pytest.raises(InputError, match="neither timeEnd nor timeStepCountEnd"):
        demdf.read(write(tmp_path, doc))
    assert demdf.read(write(tmp_path, doc), time_end=2.0).plan.t_end == 2.0
    with pytest.raises(InputError, match="timeStepCountEnd: 5 is not after timeStepCount 5"):
        demdf.read(write(tmp_path, base_doc(timeStepCount=5, timeStepCountEnd=5, timeStep=0.01)))
    model = demdf.read(write(tmp_path, base_doc(eventCount=0, eventCountEnd=10)))
    assert any("eventCountEnd" in t and "ignored" in t for _, t in model.warnings)


def test_save_rules(tmp_path):
    snap = {"name": "demdf", "filename": "o", "savePeriodInTimeSteps": 10}
    model = demdf.read(write(tmp_path, base_doc(timeStep=0.001, output={"snapshot": snap})))
    k = round(0.001 / model.plan.dt)
    assert model.plan.save_every_steps == 10 * k and model.plan.save_every_time is None
    snap["savePeriodInTime"] = 0.02                         # both: time wins (BOS uses it)
    model = demdf.read(write(tmp_path, base_doc(timeStep=0.001, output=[snap])))
    assert model.plan.save_every_time == 0.02 and model.plan.save_every_steps is None
    assert any("disagree" in t for _, t in model.warnings)


def test_no_time_step_gives_contact_time_over_50(tmp_path):
    model = demdf.read(write(tmp_path, base_doc()))          # two spheres at +-1, no gravity
    law = model.contact(0, 0)
    d = hertz_overlap(0.5, 0.25, law.youngs_eff, 2.0)
    assert d == pytest.approx(0.005, rel=1e-9)
    t_c = min(2.943 * d / 2.0, 2.943 * 0.005 / 1.0)
    # the largest step <= t_c/50 that divides the save period 0.5
    assert model.plan.dt == pytest.approx(0.5 / math.ceil(0.5 / (t_c / 50)), rel=1e-12)
    assert any("no timeStep" in t for _, t in model.warnings)
    doc = base_doc()
    del doc["output"]["snapshot"]["savePeriodInTime"]
    model = demdf.read(write(tmp_path, doc))                 # nothing to divide: t_c/50
    assert model.plan.dt == pytest.approx(t_c / 50, rel=1e-9)


def test_extension_modulus(tmp_path):
    doc = base_doc(fibrelmp={"youngsModulus": 1e5, "poissonRatio": 0.25})
    model = demdf.read(write(tmp_path, doc))
    e_star = 1e5 / (2 * (1 - 0.25 ** 2))
    assert all(law.youngs_eff == pytest.approx(e_star) for law in model.contacts.values())
    expect = hertz_overlap(0.5, 0.25, e_star, 2.0) / 0.5
    assert expect > 0.01
    assert any("youngsModulus" in t and f"{100 * expect:.3g}%" in t for _, t in model.warnings)


# ---------------------------------------------------------------- 2D
def test_2d_layout(tmp_path):
    model = demdf.read(EXAMPLES / "disks_2d.json")
    doc = json.loads((EXAMPLES / "disks_2d.json").read_text())
    rows = np.array(doc["objects"]["particles"], dtype=float)
    s = model.spheres
    assert model.plan.dimension == 2
    assert np.array_equal(s.position[:, :2], rows[:, 0:2]) and not s.position[:, 2].any()
    assert np.array_equal(s.velocity[:, :2], rows[:, 2:4]) and not s.velocity[:, 2].any()
    assert np.array_equal(model.plan.gravity, [0, -1, 0])
    assert [p.normal.tolist() for p in model.planes][:2] == [[1, 0, 0], [-1, 0, 0]]
    lo, hi = model.plan.domain
    assert lo.tolist() == [0, 0, -0.5] and hi.tolist() == [6, 4, 0.5]
    bad = dict(doc)
    bad["objects"] = dict(doc["objects"], particles=[[1, 1, 0, 0, 0, 0, 0]])
    with pytest.raises(InputError, match=r"objects\.particles\[0\]: expected 5 entries "
                       r"\[x, y, vx, vy, type\].*3D layout"):
        demdf.read(write(tmp_path, bad))
    bad = dict(doc, bodyForce=[0, -1, 0])
    with pytest.raises(InputError, match=r"bodyForce: expected 2 numbers"):
        demdf.read(write(tmp_path, bad))


# ---------------------------------------------------------------- snapshots
def _frame(model, time, pos, vel, rows=None):
    n = len(pos)
    return GranularFrame(time=time, step=0, sphere_rows=np.arange(n) if rows is None else rows,
                         position=pos, velocity=vel, omega=np.zeros((n, 3)),
                         force=np.zeros((n, 3)), quaternion=np.tile([1.0, 0, 0, 0], (n, 1)))


def test_snapshot_round_trip(tmp_path):
    src = real("test_elastic_gravity_100p.json")
    model = demdf.read(src)
    writer = DemdfSnapshotWriter(model, tmp_path)
    rng = np.random.default_rng(7)
    n = model.spheres.count
    frames = []
    for i, t in enumerate([0.0, 0.1, 1 / 3]):
        pos = model.spheres.position + rng.normal(scale=0.01, size=(n, 3))
        vel = rng.normal(size=(n, 3)) / 3
        frames.append((pos, vel))
        writer.add(_frame(model, t, pos, vel))
    assert not writer.written and not list(tmp_path.glob("output_*.json"))   # staged until close
    writer.close()
    assert [p.name for p in writer.written] == ["output_0.json", "output_1.json", "output_2.json"]
    original = json.loads(src.read_text())
    for i, (path, (pos, vel)) in enumerate(zip(writer.written, frames)):
        again = demdf.read_snapshot(path)
        assert np.array_equal(again.spheres.position, pos)        # bit for bit
        assert np.array_equal(again.spheres.velocity, vel)
        snap = json.loads(path.read_text())
        assert snap["time"] == [0.0, 0.1, 1 / 3][i]
        assert snap["output"]["snapshot"]["saveCount"] == i
        assert snap["timeStepCount"] == round([0.0, 0.1, 1 / 3][i] / 0.001)
        assert isinstance(snap["objects"]["particles"], list)         # the file is inlined
        assert [row[6] for row in snap["objects"]["particles"]] == [0] * n
        for key in original:
            if key not in ("time", "output", "objects", "timeStepCount"):
                assert snap[key] == original[key], key
        assert snap["objects"]["walls"] == original["objects"]["walls"]
    # the last snapshot is refused as an input (running it would overwrite it) ...
    with pytest.raises(InputError, match="snapshot"):
        demdf.read(writer.written[-1])


def test_snapshot_keeps_removed_particles(tmp_path):
    model = demdf.read(EXAMPLES / "head_on.json")
    writer = DemdfSnapshotWriter(model, tmp_path)
    pos, vel = model.spheres.position.copy(), model.spheres.velocity.copy()
    writer.add(_frame(model, 0.0, pos, vel))
    writer.add(_frame(model, 0.5, pos[1:] + 1, vel[1:], rows=np.array([1])))
    writer.close()
    snap = json.loads(writer.written[-1].read_text())["objects"]["particles"]
    assert snap[0] == [3.5, 2.0, 2.0, 1.5, 0.0, 0.0, 0]            # last saved state kept
    assert snap[1][:3] == [7.5, 3.0, 3.0]
    assert writer.removed == {0: 0.5}
    assert any("left the simulation box" in t for _, t in model.warnings)


def test_snapshot_2d_rows(tmp_path):
    model = demdf.read(EXAMPLES / "disks_2d.json")
    writer = DemdfSnapshotWriter(model, tmp_path)
    s = model.spheres
    writer.add(_frame(model, 0.25, s.position + [0.125, 0, 0], s.velocity))
    writer.close()
    rows = json.loads(writer.written[0].read_text())["objects"]["particles"]
    doc = json.loads((EXAMPLES / "disks_2d.json").read_text())["objects"]["particles"]
    assert [len(r) for r in rows] == [5] * len(doc)
    assert [r[0] - 0.125 for r in rows] == [r[0] for r in doc]
    assert [r[1:] for r in rows] == [r[1:] for r in doc]


def test_snapshot_unicode_and_missing_output(tmp_path):
    doc = base_doc(name="Kugeln \u00fc \u2014 \u7403")
    del doc["output"]
    path = write(tmp_path, doc)
    model = demdf.read(path)
    assert any("no output" in t for _, t in model.warnings)
    writer = DemdfSnapshotWriter(model, tmp_path / "out")
    s = model.spheres
    for t in (0.0, 0.5):
        writer.add(_frame(model, t, s.position, s.velocity))
    writer.close()
    assert [p.name for p in writer.written] == ["output_0.json", "output_1.json"]
    snap = json.loads(writer.written[1].read_bytes().decode("utf-8"))
    assert snap["name"] == doc["name"]
    assert snap["output"]["snapshot"]["saveCount"] == 1 and snap["time"] == 0.5
