"""DEMDF runs on LAMMPS, measured from the written snapshots.

Expected values come from the input documents and closed-form mechanics (restitution,
momentum, energy with the Hertz contact energy 8/15 E* sqrt(R*) delta^(5/2)), never from
fibrelmp's own computations.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.pipeline.run_model import run_granular
from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter
from fibrelmp.translate.demdf import reader as demdf

from .conftest import shared_path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "demdf"


def run(model, tmp_path: Path) -> list[dict]:
    writer = DemdfSnapshotWriter(model, tmp_path / "out")
    run_granular(model, tmp_path / "work", writer.add, progress=False)
    writer.close()
    return [json.loads(p.read_text()) for p in writer.written]


def particles(snapshot: dict) -> np.ndarray:
    return np.array(snapshot["objects"]["particles"], dtype=float)


def test_head_on_restitution_and_momentum(tmp_path):
    source = json.loads((EXAMPLES / "head_on.json").read_text())
    e = source["objectTypes"][0]["restitutionCoefficient"]
    m = source["objectTypes"][0]["mass"]
    snaps = run(demdf.read(EXAMPLES / "head_on.json"), tmp_path)
    assert [s["time"] for s in snaps] == pytest.approx(np.arange(0, 2.01, 0.25).tolist())
    assert [s["output"]["snapshot"]["saveCount"] for s in snaps] == list(range(len(snaps)))
    pre, post = particles(snaps[0]), particles(snaps[-1])
    assert np.array_equal(pre, np.array(source["objects"]["particles"], dtype=float))
    v_pre = pre[0, 3] - pre[1, 3]
    v_post = post[1, 3] - post[0, 3]
    assert post[1, 0] - post[0, 0] > 1.0                      # apart again
    assert v_post / v_pre == pytest.approx(e, rel=0.01)
    p0 = m * pre[:, 3:6].sum(axis=0)
    for snap in snaps:
        p = m * particles(snap)[:, 3:6].sum(axis=0)
        assert np.linalg.norm(p - p0) <= 1e-9 * np.linalg.norm(p0)


def _energy(rows: np.ndarray, model, g: np.ndarray, doc: dict) -> float:
    """Kinetic + body-force potential + Hertz contact energy of a 3D snapshot."""
    m, r = 1.0, 0.5                       # objectType 0 has no mass (BOS: unit), radius 0.5
    x, v = rows[:, 0:3], rows[:, 3:6]
    energy = 0.5 * m * (v * v).sum() - m * (x @ g).sum()
    law = model.contact(0, 0)
    d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
    overlap = np.triu(2 * r - d, 1)
    overlap = overlap[overlap > 0]
    energy += (8 / 15 * law.youngs_eff * math.sqrt(r / 2) * overlap ** 2.5).sum()
    wall = model.contact(0, 1)
    for w in doc["objects"]["walls"]:
        delta = r - (x - np.array(w["point"])) @ np.array(w["normal"], dtype=float)
        delta = delta[delta > 0]
        energy += (8 / 15 * wall.youngs_eff * math.sqrt(r) * delta ** 2.5).sum()
    return float(energy)


def test_elastic_gravity_energy(tmp_path):
    path = shared_path("real-inputs", "demdf", "test_elastic_gravity_100p.json")
    doc = json.loads(path.read_text())
    g = np.array(doc["bodyForce"], dtype=float)
    model = demdf.read(path, steps=10_000, save_every=500)
    snaps = run(model, tmp_path)
    assert len(snaps) == 21
    rows0 = particles(snaps[0])
    n = len(rows0)
    resting = n * 1.0 * np.linalg.norm(g) * 0.5          # everyone resting on the floor z = 0
    e0 = _energy(rows0, model, g, doc)
    available = e0 - resting                               # what can move at all
    assert available > 0.05
    drift = max(abs(_energy(particles(s), model, g, doc) - e0) for s in snaps)
    assert drift <= 0.01 * available
    # the particles did bounce on the floor (otherwise this would test nothing)
    vz = np.array([particles(s)[:, 5] for s in snaps])
    assert (vz > 0.05).any() and (vz < -0.05).any()


def test_drop_on_wall_restitution(tmp_path):
    source = json.loads((EXAMPLES / "drop_on_wall.json").read_text())
    e = source["objectTypes"][0]["restitutionCoefficient"]      # BOS: the particle's value
    g = -source["bodyForce"][2]
    r = source["objectTypes"][0]["radius"]
    snaps = run(demdf.read(EXAMPLES / "drop_on_wall.json"), tmp_path)
    start = particles(snaps[0])[0]
    v_in = math.sqrt(start[5] ** 2 + 2 * g * (start[2] - r))     # speed when touching z = r
    after = [particles(s)[0] for s in snaps if particles(s)[0, 5] > 0]
    assert len(after) >= 2
    for x in after:                                               # in flight after the bounce
        assert x[2] > r
        v_out = math.sqrt(x[5] ** 2 + 2 * g * (x[2] - r))
        assert v_out / v_in == pytest.approx(e, rel=0.01)
        assert x[0:2].tolist() == pytest.approx(start[0:2].tolist(), abs=1e-12)


@pytest.mark.parametrize("name", ["test.json", "test_1pg.json", "test_inelastic_2p.json",
                                  "test_elastic_gravity_100p.json"])
def test_real_files_run(tmp_path, name):
    path = shared_path("real-inputs", "demdf", name)
    doc = json.loads(path.read_text())
    model = demdf.read(path)                  # timeStepCountEnd = 1 step of 0.001
    snaps = run(model, tmp_path)
    assert [s["time"] for s in snaps] == pytest.approx([0.0, 0.001])
    t = 0.001
    g = np.array(doc["bodyForce"], dtype=float)
    start, end = particles(snaps[0]), particles(snaps[-1])
    x0, v0 = start[:, 0:3], start[:, 3:6]
    # no particle can reach a wall within 0.001: momentum changes by the body force only
    assert np.abs(end[:, 3:6].sum(0) - v0.sum(0) - len(start) * g * t).max() <= 1e-9
    # particles nobody can reach fly ballistically (test.json starts with touching pairs)
    d = np.linalg.norm(x0[:, None] - x0[None, :], axis=2) + 2 * np.eye(len(x0))
    free = d.min(axis=1) > 1.0 + 2 * np.abs(v0).sum(1).max() * t
    assert free.all() or name == "test.json"      # there every particle touches another
    assert end[free, 0:3] == pytest.approx(x0[free] + v0[free] * t + 0.5 * g * t * t, abs=1e-9)
    assert end[free, 3:6] == pytest.approx(v0[free] + g * t, abs=1e-9)
    for p in (tmp_path / "out").glob("output_*.json"):
        again = demdf.read_snapshot(p)
        assert again.spheres.count == len(start)


def test_2d_example_runs(tmp_path):
    path = EXAMPLES / "disks_2d.json"
    doc = json.loads(path.read_text())
    model = demdf.read(path, time_end=1.0)
    snaps = run(model, tmp_path)
    lo, hi = np.array(doc["domain"], dtype=float)
    g = np.array(doc["bodyForce"], dtype=float)
    energies = []
    for s in snaps:
        rows = particles(s)
        assert rows.shape == (4, 5)
        assert (rows[:, 0:2] > lo).all() and (rows[:, 0:2] < hi).all()
        energies.append(0.5 * (rows[:, 2:4] ** 2).sum() - (rows[:, 0:2] @ g).sum())
    # inelastic collisions only remove energy: never above the start
    assert max(energies) <= energies[0] * (1 + 1e-6)
    assert energies[-1] < energies[0]
    assert snaps[-1]["time"] == pytest.approx(1.0)
