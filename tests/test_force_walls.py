"""Force-controlled and free-moving geometries (fix musen/wall/mesh's stepped geometries)
against the real cmusen (tests/data/real-outputs/musen/force_walls/README.md): a plate pressing
a glass sphere until the force on it passes a limit (motion from the scene's `26 2` line, and
from a script's GEOMETRY_MOTION_FORCE lines, and with constant-force motion), and a free lid with a mass falling onto the
spheres under gravity."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.scene import read
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (check_reference_is_cmusens_output, check_resume_is_bitwise,
                                 model_job, needs_cmusen, styles_or_skip)

DATA = data_path("real-outputs/musen/force_walls")
COORD, VEL, FORCE, WALL = 12, 15, 20, 44       # MUSEN text tags
SPHERES, WALLS = slice(0, 3), slice(3, 7)      # object ids 0-2 spheres, 3-6 wall triangles
DT = 2e-7


def _run(tmp_path: Path, prefix: str, **changes: str):
    shutil.copy(DATA / f"{prefix}_scene.txt", tmp_path)
    job = (DATA / f"job_{prefix}.txt").read_text()
    for old, new in changes.items():
        job = job.replace(old, new)
    (tmp_path / f"job_{prefix}.txt").write_text(job)
    python_api.run(tmp_path / f"job_{prefix}.txt", work=tmp_path / "work")
    ours = read_time_points(tmp_path / f"{prefix}_result_prec17.txt")
    theirs = read_time_points(DATA / f"cmusen_{prefix}_result_prec17.txt")
    return ours, theirs


def _within(ours, theirs, tag: str, objects: slice, rel: float, n: int | None = None) -> float:
    """Largest difference at every common time point, as a fraction of the quantity's scale
    (its largest change over the run in cmusen's result); asserts it is below ``rel``."""
    key = {"coord": COORD, "vel": VEL, "wall": WALL, "force": FORCE}[tag]
    a, b = ours.fields[key][:n, objects], theirs.fields[key][:n, objects]
    scale = float(np.max(np.abs(b - b[:1])))
    worst = float(np.max(np.abs(a - b))) / scale
    assert worst <= rel, (tag, worst)
    return worst


def _same_times(ours, theirs) -> int:
    # cmusen adds a last time point after END_TIME (docs/musen.md): compare the common ones
    n = len(ours.times)
    assert len(theirs.times) in (n, n + 1)
    np.testing.assert_allclose(ours.times, theirs.times[:n], rtol=0, atol=1e-15)
    assert np.array_equal(ours.ids, theirs.ids)
    return n


@pytest.mark.parametrize("prefix", ["press", "script", "const", "rot"])
def test_force_controlled_plate_is_cmusens(tmp_path, prefix):
    """press, script: the plate moves down until the force on it passes the first limit, up
    until it falls below the second, then stops (keeping its last velocity in the contact law,
    as MUSEN); const (`26 3`, constant force): it moves down while the force is below 3 N and
    up while above, step by step; rot: the first interval also turns the plate about y.  Walls, wall velocities and sphere positions as cmusen's at
    every saved time."""
    styles_or_skip()
    ours, theirs = _run(tmp_path, prefix)
    n = _same_times(ours, theirs)
    plate_vz = theirs.fields[VEL][:n, 5, 2]
    assert plate_vz[1] == -0.05 and plate_vz[-1] > 0        # it switched on the force
    for tag, objects in (("wall", WALLS), ("vel", WALLS), ("coord", SPHERES)):
        _within(ours, theirs, tag, objects, 1e-6, n)
    if prefix == "const":
        return          # the plate turns every step: the force of one step before differs most
    # cmusen saves the wall force of the step before each saved time (the opt-in test shows
    # it equal to fibrelmp's force one step earlier): here within one step's change
    force = theirs.fields[FORCE][:n, 5:7, 2].sum(1)
    per_step = np.max(np.abs(np.diff(force))) / (1e-5 / DT)
    assert force.max() > 1                     # the plate pressed (not a trivial zero)
    assert np.max(np.abs(ours.fields[FORCE][:n, 5:7, 2].sum(1) - force)) <= 3 * per_step


def test_free_lid_is_cmusens(tmp_path):
    """A lid of 2 g, free along z, falls under gravity onto the spheres, bounces and falls
    again: its walls and velocity as cmusen's (the spheres differ by the integrators'
    start-up under gravity, docs/granular.md, 7e-5 of their small displacement)."""
    styles_or_skip()
    ours, theirs = _run(tmp_path, "free")
    n = _same_times(ours, theirs)
    lid_vz = theirs.fields[VEL][:n, 5, 2]
    assert lid_vz.min() < -0.03 and lid_vz.max() > 0.03     # fell and bounced
    _within(ours, theirs, "wall", WALLS, 1e-6, n)
    _within(ours, theirs, "vel", WALLS, 1e-6, n)
    _within(ours, theirs, "coord", SPHERES, 2e-4, n)


def test_scene_force_intervals_are_read():
    model = read(DATA / "press_scene.txt")
    press = model.geometries[1]
    assert (press.name, press.motion_type, len(press.force_motion)) == ("Press", 2, 3)
    first, second, last = press.force_motion
    assert (first.limit, first.limit_max, list(first.velocity)) == (3.0, True, [0, 0, -0.05])
    assert (second.limit, second.limit_max, list(second.velocity)) == (0.1, False, [0, 0, 0.02])
    assert (last.limit, list(last.velocity)) == (1e9, [0, 0, 0])
    lid = read(DATA / "free_scene.txt").geometries[1]
    assert (lid.mass, lid.free) == (0.002, (False, False, True))


def test_written_motion_line_is_cmusens(tmp_path):
    """The result's `26` line (from the scene, or from the script's lines) as cmusen writes it."""
    styles_or_skip()
    for prefix in ("press", "script"):
        folder = tmp_path / prefix
        folder.mkdir()
        _run(folder, prefix, **{"SAVING_STEP          1e-5": "SAVING_STEP 3e-4",
                                "END_TIME             6e-4": "END_TIME 3e-4"})
        line = [s for s in (folder / f"{prefix}_result_prec17.txt").read_text().splitlines()
                if s.startswith("26 2")]
        theirs = [s for s in (DATA / f"cmusen_{prefix}_result_prec17.txt").read_text().splitlines()
                  if s.startswith("26 2")]
        assert line == theirs and len(line) == 1


def test_refused_without_fibrelmps_styles(tmp_path):
    shutil.copy(DATA / "press_scene.txt", tmp_path)
    shutil.copy(DATA / "job_press.txt", tmp_path)
    with lammps_styles.stock(True), pytest.raises(
            InputError, match="geometry 'Press': force-dependent geometry motion needs fibrelmp's LAMMPS styles"):
        python_api.run(tmp_path / "job_press.txt")
    assert not (tmp_path / "press_result.mdem").exists()


@needs_cmusen
@pytest.mark.parametrize("prefix", ["press", "script", "free", "const", "pack", "packg", "rot"])
def test_reference_is_cmusens_output(tmp_path, prefix):
    check_reference_is_cmusens_output(tmp_path, DATA, prefix)


@needs_cmusen
def test_saved_wall_force_is_the_previous_steps(tmp_path):
    """Saving every step (7 s): at each of cmusen's saved times fibrelmp's saved wall force is
    cmusen's, bit for bit: the previous evaluation's, from the contacts dumped one step before
    the frame (here the previous frame's step: with_presaves splits no run)."""
    styles_or_skip()
    ours, _ = _run(tmp_path, "press", **{"SAVING_STEP          1e-5": f"SAVING_STEP {DT}"})
    theirs = read_time_points(DATA / "cmusen_press_result_prec17.txt")
    force = theirs.fields[FORCE][:, 6, 2]
    steps = np.rint(theirs.times / DT).astype(int)[1:len(theirs.times) - 1]
    assert np.abs(force).max() > 1.0
    np.testing.assert_array_equal(ours.fields[FORCE][steps, 6, 2], force[1:len(steps) + 1])


def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch):
    """The stepped state (interval, velocities, vertices) goes through LAMMPS's restart file:
    a run stopped after a checkpoint taken while the plate presses, then resumed, writes the
    uninterrupted run's result byte for byte."""
    check_resume_is_bitwise(tmp_path, monkeypatch, lambda at: model_job(at, DATA, "press", ""),
                            "press_result_prec17.txt", 2290)


def test_free_lid_starts_with_its_walls_velocity(tmp_path):
    """Analytic (numpy) reference of MUSEN's MoveWalls rule for a free geometry without
    contacts: v_k = mean wall velocity + dt (g m) / m, then x += v_k dt, once for the
    prediction and once per step; the lid's walls start at 0.01 m/s upwards (their `15`)."""
    styles_or_skip()
    scene = (DATA / "free_scene.txt").read_text().splitlines()
    for i in (5, 6):      # the lid's two triangles (lines 6 and 7): stored velocity 0.01 m/s up
        assert scene[i].startswith(f"0 {i} 1 14 ") and scene[i].endswith("15 0 0 0")
        scene[i] = scene[i][:-len("15 0 0 0")] + "15 0 0 0.01"
    (tmp_path / "free_scene.txt").write_text("\n".join(scene) + "\n")
    job = (DATA / "job_free.txt").read_text().replace("END_TIME             1.2e-3", "END_TIME 1e-4")
    (tmp_path / "job_free.txt").write_text(job)
    python_api.run(tmp_path / "job_free.txt", work=tmp_path / "work")
    ours = read_time_points(tmp_path / "free_result_prec17.txt")
    g, mass, z0 = -100.0, 0.002, 0.002005
    vz, z, expect_z, expect_v = 0.01, z0, {0: z0}, {0: 0.01}
    for k in range(501):        # k = 0: the prediction update
        vz = (vz / 2 + vz / 2) + DT * (g * mass) / mass     # mean of the two walls' velocities
        z += vz * DT
        expect_z[k + 1], expect_v[k + 1] = z, vz
    steps = np.rint(ours.times / DT).astype(int)
    want_z = [expect_z[s + 1] if s else z0 for s in steps]    # walls one update ahead
    want_v = [expect_v[s + 1] if s else 0.01 for s in steps]
    np.testing.assert_allclose(ours.fields[WALL][:, 5, 2], want_z, rtol=0, atol=1e-18)
    np.testing.assert_allclose(ours.fields[VEL][:, 5, 2], want_v, rtol=0, atol=1e-17)
    assert ours.fields[VEL][-1, 5, 2] < 0.01 - 0.009      # gravity slowed it


def test_mdem_scene_keeps_the_force_intervals(tmp_path):
    """A `.mdem` scene (MUSEN's text import of the press scene) runs with the same force-
    dependent motion as the text scene: its motion message read back field by field."""
    from fibrelmp.translate.musen.mdem.model import read_scene
    python_api.convert_file(DATA / "press_scene.txt", tmp_path / "press.mdem")
    press = read_scene(tmp_path / "press.mdem").geometries[1]
    text = read(DATA / "press_scene.txt").geometries[1]
    assert press.motion_type == text.motion_type == 2
    assert [(f.limit, f.limit_max, list(f.velocity)) for f in press.force_motion] == \
        [(f.limit, f.limit_max, list(f.velocity)) for f in text.force_motion]


def test_pressed_packing_within_cmusens_spread(tmp_path):
    """A packing of 48 spheres pressed by the force-controlled plate (chaotic): at every saved
    time sphere positions and wall vertices within 3 x cmusen's own spread (cmusen rerun with
    the plate speed x (1 + 1e-8); no gravity here), or 1e-6 of scale where that is larger."""
    styles_or_skip()
    ours, theirs = _run(tmp_path, "pack")
    spread = read_time_points(DATA / "cmusen_packg_result_prec17.txt")
    n = _same_times(ours, theirs)
    assert np.max(theirs.fields[VEL][:n, 50, 2]) == 0.02           # it reached 20 N and turned
    box = 8.4e-3

    def deviation(a, b, periodic):
        d = a - b
        if periodic:               # the same sphere, wrapped by the other code one step apart
            d[..., :2] -= box * np.round(d[..., :2] / box)
        return np.abs(d).reshape(len(d), -1).max(1)
    for tag, objects, periodic in ((COORD, slice(0, 48), True), (WALL, slice(48, 52), False)):
        a, b, c = (tp.fields[tag][:n, objects] for tp in (ours, theirs, spread))
        scale = np.max(deviation(b, b[:1], periodic))
        d, s = deviation(a, b, periodic), deviation(c, b, periodic)
        assert np.all(d <= np.maximum(3 * s, 1e-6 * scale)), (tag, d / scale, s / scale)
