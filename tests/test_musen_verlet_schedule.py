"""MUSEN's contact-list updates decide when a broken bond's spheres may touch (fix
musen/verlet; docs/musen.md, *Broken bonds and MUSEN's contact list*), against the real cmusen
(tests/data/real-outputs/musen/verlet_schedule/README.md): two overlapping bonded pairs with
contacts between bonded spheres off, one bond breaking at t = 0, one at step 120, and a far
sphere at 9.7 m/s whose displacement makes cmusen update its list; VERLET_COEF 0.01, with
and without auto-adjustment.  The expected update steps are computed here from MUSEN's rule
and the reference's own positions."""

from __future__ import annotations

import gzip
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (CMUSEN, bond_ends, check_translated_job_replays_bitwise,
                                 needs_cmusen, run_cut_and_resumed, styles_or_skip)

DATA = data_path("real-outputs/musen/verlet_schedule")
COORD, VEL = 12, 15
PAIR_A, PAIR_B, MOVER = (0, 1), (2, 3), 4      # sphere ids (rows: ids are 0..4)
RADIUS, COEF, DT = 1e-3, 0.01, 1e-8


def _reference(auto: int, folder: Path) -> Path:
    out = folder / f"cmusen_auto{auto}_prec17.txt"
    with gzip.open(DATA / f"cmusen_auto{auto}_prec17.txt.gz", "rb") as src:
        out.write_bytes(src.read())
    return out


def _case(folder: Path, auto: int) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("verlet_scene.txt", f"job_auto{auto}.txt"):
        shutil.copy(DATA / name, folder)
    return folder / f"job_auto{auto}.txt"


def musen_updates(z: np.ndarray, auto: bool) -> list[int]:
    """The steps at which MUSEN updates its contact list (CVerletList::IsNeedToBeUpdated with
    no walls: 2 x the largest displacement since the last update >= the Verlet distance;
    AutoAdjustVerletDistance: x 1.1 at the 2nd and 3rd update), from the mover's positions
    at every step (z[k]: at step k); the prediction at step 0 always updates."""
    distance, updates, last = COEF * RADIUS, [0], z[0]
    for k in range(1, len(z)):
        moved = abs(z[k] - last)
        if moved + moved >= distance:
            updates.append(k)
            if auto and len(updates) in (2, 3):
                distance *= 1.1
            last = z[k]
    return updates


def contact_starts(tp, sphere: int, after: int) -> int:
    """The first step >= ``after`` whose force evaluation changed the sphere's velocity (the
    velocity saved at step k + 1 is the one that evaluation gave)."""
    v = tp.fields[VEL][:, list(tp.ids).index(sphere), 0]
    changed = np.nonzero(np.diff(v[after:]))[0]
    return after + int(changed[0])


@pytest.mark.parametrize("auto", [0, 1])
def test_broken_pairs_touch_at_cmusens_list_update(tmp_path, auto):
    """The contact of each broken pair starts at the step of MUSEN's next list update after
    its break (pair A: update 2 at step 52; pair B, broken at step 120: step 156 every 52
    steps, or 172 with the distance grown 10 % at updates 2 and 3), in cmusen and in
    fibrelmp; every position and velocity equals cmusen's (measured: bit for bit)."""
    styles_or_skip()
    ref = read_time_points(_reference(auto, tmp_path), tags=(COORD, VEL))
    mover = list(ref.ids).index(MOVER)
    updates = musen_updates(ref.fields[COORD][:-1, mover, 2], bool(auto))
    broken_b = 120                              # the reference's bond 6 end: 1.2e-6 s
    expect_a = next(k for k in updates if k > 0)
    expect_b = next(k for k in updates if k > broken_b)
    assert (expect_a, expect_b) == ((52, 156) if auto == 0 else (52, 172))
    assert contact_starts(ref, PAIR_A[1], 0) == expect_a
    assert contact_starts(ref, PAIR_B[0], broken_b + 1) == expect_b

    job = _case(tmp_path / "case", auto)
    python_api.run(job, work=tmp_path / "work")
    ours = read_time_points(job.parent / f"cmusen_auto{auto}_prec17.txt", tags=(COORD, VEL))
    assert ours.times.tolist() == ref.times.tolist()
    assert contact_starts(ours, PAIR_A[1], 0) == expect_a
    assert contact_starts(ours, PAIR_B[0], broken_b + 1) == expect_b
    for tag in (COORD, VEL):
        x0 = ref.fields[COORD][0] if tag == COORD else 0.0
        scale = np.abs(ref.fields[tag] - x0).max()
        assert np.abs(ours.fields[tag] - ref.fields[tag]).max() <= 1e-12 * scale
    assert bond_ends(job.parent / f"cmusen_auto{auto}_prec17.txt") == {"5": 0.0, "6": 1.2e-6}


def test_wall_speed_drives_the_updates(tmp_path):
    """No sphere moves; a wall far away moves at 7.3 m/s: MUSEN's check adds 7.3 m/s x dt a
    step (from its step at t = 0 on) and updates at the step where the sum reaches the 10 µm
    distance, 136 (summed here as MUSEN sums it), letting the broken pair touch; cmusen and
    fibrelmp (wallspeed 7.3) bit for bit."""
    styles_or_skip()
    with gzip.open(DATA / "cmusen_wall_prec17.txt.gz", "rb") as src:
        (tmp_path / "ref.txt").write_bytes(src.read())
    ref = read_time_points(tmp_path / "ref.txt", tags=(COORD, VEL))
    wall, expect = 0.0, None
    for k in range(300):
        wall += 7.3 * DT
        if wall >= COEF * RADIUS:
            expect = k
            break
    assert expect == 136 and contact_starts(ref, 1, 0) == expect
    job = tmp_path / "case" / "job_wall.txt"
    job.parent.mkdir()
    for name in ("wall_scene.txt", "job_wall.txt"):
        shutil.copy(DATA / name, job.parent)
    python_api.run(job, work=tmp_path / "work")
    assert "musen/verlet 1e-05 auto no wallspeed 7.3\n" in (tmp_path / "work" / "job2" / "in.lammps").read_text()
    ours = read_time_points(job.parent / "cmusen_wall_prec17.txt", tags=(COORD, VEL))
    assert contact_starts(ours, 1, 0) == expect
    spheres = ref.types == 1
    for tag in (COORD, VEL):
        assert np.array_equal(ours.fields[tag][:, spheres], ref.fields[tag][:, spheres])


@pytest.mark.parametrize("every", [10, 130])
def test_checkpoints_and_resume_keep_the_schedule(tmp_path, monkeypatch, every):
    """A run with a checkpoint every 10 steps (each a LAMMPS set-up and neighbour-list build),
    and one stopped at step 130 (pair A released, pair B broken and waiting) and resumed from
    its restart file: both write the uninterrupted run's result byte for byte."""
    styles_or_skip()
    whole = _case(tmp_path / "whole", 0)
    python_api.run(whole, work=tmp_path / "whole" / "work")
    cut = _case(tmp_path / "cut", 0)
    if every == 10:
        python_api.run(cut, work=cut.parent / "work", checkpoint_every=every)
    else:
        run_cut_and_resumed(monkeypatch, cut, cut.parent / "work", every)
    name = "cmusen_auto0_prec17.txt"
    assert (cut.parent / name).read_bytes() == (whole.parent / name).read_bytes()


def test_job_renders_musens_schedule(tmp_path):
    """The job's fix musen/verlet: distance VERLET_COEF x the smallest contact radius, the
    script's VERLET_AUTO, no wall speed (no walls)."""
    styles_or_skip()
    for auto in (0, 1):
        job = _case(tmp_path / f"a{auto}", auto)
        python_api.translate_job(job, tmp_path / f"job{auto}")
        script = (tmp_path / f"job{auto}" / "in.lammps").read_text()
        assert f"musen/verlet 1e-05 auto {'yes' if auto else 'no'} wallspeed 0.0\n" in script


@needs_cmusen
@pytest.mark.parametrize("case", ["auto0", "auto1", "wall"])
def test_reference_is_cmusens_output(tmp_path, case):
    scene = "wall_scene.txt" if case == "wall" else "verlet_scene.txt"
    for name in (scene, f"job_{case}.txt"):
        shutil.copy(DATA / name, tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", f"-s=job_{case}.txt"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    with gzip.open(DATA / f"cmusen_{case}_prec17.txt.gz", "rb") as ref:
        assert (tmp_path / f"cmusen_{case}_prec17.txt").read_bytes() == ref.read()


def test_lmp_replays_the_schedule_bitwise(tmp_path):
    """``fibrelmp translate`` + the wheel's ``lmp -in``: the same dumps as ``fibrelmp run``
    (the fix's schedule does not depend on fibrelmp's runner)."""
    check_translated_job_replays_bitwise(tmp_path, _case(tmp_path / "case", 1),
                                         ("frames.dump", "breaks.dump", "contacts.dump"))


def test_result_mdem_keeps_the_schedule_settings(tmp_path):
    """The result .mdem stores VERLET_COEF and VERLET_AUTO as MUSEN's SaveConfiguration does
    (with max_cells_number, without which MUSEN's LoadConfiguration skips them): a later job
    on that file gets them back."""
    from fibrelmp.translate.musen.mdem.document import MdemFile
    from fibrelmp.translate.musen.mdem.model import read_scene

    styles_or_skip()
    job = _case(tmp_path, 0)
    python_api.run(job, work=tmp_path / "work")
    with MdemFile(tmp_path / "verlet_auto0_result.mdem") as f:
        sim = f.storage.modules_data.simulator
        assert (sim.max_cells_number, sim.verlet_dist_coeff, sim.verlet_auto_adjust) == (50, 0.01, False)
    plan = read_scene(tmp_path / "verlet_auto0_result.mdem").plan
    assert (plan.verlet_coeff, plan.verlet_auto) == (0.01, False)


def test_two_ranks_write_the_serial_frames(tmp_path):
    """Both pairs straddle the boundary of two ranks' subdomains (x = 5 mm): the released
    pairs leave the special lists of atoms owned by different ranks, and the ranks' pair
    styles ask the same released set; ``mpiexec -n 2 lmp`` writes the serial dumps byte for
    byte, the contacts starting at steps 52 and 172."""
    import os
    import sys

    from fibrelmp._lammps import lmp_executable_env
    bindir = Path(sys.executable).parent
    lmp, mpiexec = bindir / "lmp", bindir / "mpiexec"
    if not lmp.exists() or not mpiexec.exists():
        pytest.skip(f"no lmp and mpiexec next to {sys.executable}")
    styles_or_skip()
    case = tmp_path / "case"
    case.mkdir()
    shutil.copy(DATA / "job_auto1.txt", case)
    scene = (DATA / "verlet_scene.txt").read_text()
    for old, new in (("12 0.0 0 0 ", "12 0.004 0 0 "), ("12 0.00199 0 0 ", "12 0.00599 0 0 "),
                     ("12 0.0 0.005 0 ", "12 0.004 0.005 0 "), ("12 0.00199 0.005 0 ", "12 0.00599 0.005 0 "),
                     ("12 0.01 0 0 ", "12 0.02 0 0 ")):
        assert old in scene
        scene = scene.replace(old, new)
    (case / "verlet_scene.txt").write_text(scene)
    python_api.translate_job(case / "job_auto1.txt", tmp_path / "one")
    shutil.copytree(tmp_path / "one", tmp_path / "two")
    env = {**os.environ, **lmp_executable_env()}
    for folder, prefix in (("one", []), ("two", [str(mpiexec), "-n", "2"])):
        done = subprocess.run([*prefix, str(lmp), "-in", "in.lammps", "-log", "log.lammps", "-screen", "none",
                               "-nocite"], cwd=tmp_path / folder, env=env, capture_output=True, text=True,
                              timeout=300)
        assert done.returncode == 0, done.stdout + done.stderr
    assert "2 by 1 by 1 MPI processor grid" in (tmp_path / "two" / "log.lammps").read_text()
    for dump in ("frames.dump", "breaks.dump"):
        assert (tmp_path / "two" / dump).read_bytes() == (tmp_path / "one" / dump).read_bytes()
    frames = (tmp_path / "one" / "frames.dump").read_text().split("ITEM: TIMESTEP")[1:]
    vx = np.array([[float(line.split()[5]) for line in f.splitlines()[9:14]] for f in frames])
    assert int(np.nonzero(np.diff(vx[:, 1]))[0][0]) == 52            # sphere 1 (id 2)
    assert int(np.nonzero(np.diff(vx[121:, 2]))[0][0]) + 121 == 172  # sphere 2 (id 3)
