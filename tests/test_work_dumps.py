"""fibrelmp's own work files: ``fibrelmp post`` of a run's work dump (with ``--data`` of its
work folder) writes the run's own files, and the data files are ones MDAnalysis reads.

Each example runs once (module fixtures); the comparisons are byte for byte where the post
output can hold everything the run's does, and say precisely what differs where it cannot
(a MUSEN result's walls, material properties and interactions are not in a dump).
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

import fibrelmp
from fibrelmp.errors import InputError, RunError

from . import granular_models as gm
from .conftest import DATA, REPO

EXAMPLES = REPO / "examples"


def _copy(folder: Path, *files: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for f in files:
        shutil.copy(f, folder)
    return folder


def _dump_times(dump: Path) -> list[tuple[int, float]]:
    """(step, ITEM: TIME) of every frame, read from the text (not with fibrelmp's reader)."""
    text = dump.read_text()
    return [(int(s), float(t)) for t, s in re.findall(r"ITEM: TIME\n(\S+)\nITEM: TIMESTEP\n(\d+)", text)]


# ---------------------------------------------------------------------------------------------
# FibreNet


@pytest.fixture(scope="module")
def fibrenet_run(tmp_path_factory):
    folder = _copy(tmp_path_factory.mktemp("fn"), EXAMPLES / "fibre_network" / "input.txt",
                   EXAMPLES / "fibre_network" / "model.txt")
    result = fibrelmp.run(folder / "input.txt")
    return folder, result


def test_fibrenet_post_of_work_dump_is_the_run(fibrenet_run, tmp_path):
    folder, result = fibrenet_run
    work = folder / "fibre_network_work"
    out = tmp_path / "fibre_network"
    said: list = []
    written = fibrelmp.convert(work / "frames.dump", "xyz", out, data=work / "data.lammps", warn=said.extend)
    written += fibrelmp.convert(work / "frames.dump", "res", out, data=work / "data.lammps", warn=said.extend)
    assert said == []
    assert sorted(p.name for p in written) == sorted(p.name for p in result.outputs)
    for path in result.outputs:
        assert (tmp_path / path.name).read_bytes() == path.read_bytes(), path.name


def test_fibrenet_work_dump_columns_time_radius_mass(fibrenet_run):
    """ITEM: TIME = step * dt; standard column names; radius and mass per bead as the model
    file gives them (R and m columns of BEAD lines), read from the text."""
    folder, result = fibrenet_run
    dump = folder / "fibre_network_work" / "frames.dump"
    text = dump.read_text()
    assert text.startswith("ITEM: TIME\n0\nITEM: TIMESTEP\n0\n")
    header = re.search(r"ITEM: ATOMS (.*)\n", text).group(1).split()
    assert header == "id type x y z ix iy iz vx vy vz fx fy fz radius mass".split()
    times = _dump_times(dump)
    assert [s for s, _ in times] == list(range(0, 2001, 400))
    for step, t in times:
        assert t == pytest.approx(step * 0.0005, rel=1e-13, abs=1e-15)
    beads = [ln.split() for ln in (folder / "model.txt").read_text().splitlines() if ln.startswith("BEAD")]
    first = text.split("ITEM: ATOMS")[1].splitlines()[1:1 + len(beads)]
    rows = np.array([ln.split() for ln in first], float)
    rows = rows[np.argsort(rows[:, 0])]
    np.testing.assert_array_equal(rows[:, 14], [float(b[4]) for b in beads])      # R
    np.testing.assert_array_equal(rows[:, 15], [float(b[5]) for b in beads])      # m


def test_fibrenet_post_without_data_names_types_by_number_and_hints(fibrenet_run, tmp_path):
    folder, _ = fibrenet_run
    said: list = []
    fibrelmp.convert(folder / "fibre_network_work" / "frames.dump", "xyz", tmp_path / "n", warn=said.extend)
    assert "FRAME\t0\t0.00050\t" in (tmp_path / "n_coord.xyz").read_text()     # dt from ITEM: TIME
    assert (tmp_path / "n_coord.xyz").read_text().splitlines()[2].startswith("1\t")
    assert [k for k, _ in said] == ["work folder"]
    assert "--data" in said[0][1] and "data.lammps" in said[0][1]


def test_result_universe_reads_the_timed_dump(fibrenet_run):
    """MDAnalysis's own LAMMPSDUMP reader cannot read a dump with ITEM: TIME;
    RunResult.universe can: frames, times, positions as the dump has them."""
    folder, result = fibrenet_run
    dump = result.dumps[-1]
    times = _dump_times(dump)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        u = result.universe()
        assert len(u.atoms) == 128 and len(u.trajectory) == len(times)
        text = dump.read_text().split("ITEM: TIME\n")[1:]
        for k in (0, 3, len(times) - 1):
            ts = u.trajectory[k]
            assert ts.time == times[k][1] and ts.data["step"] == times[k][0]
            rows = np.array([ln.split() for ln in text[k].splitlines()[10:138]], float)
            np.testing.assert_allclose(ts.positions, rows[np.argsort(rows[:, 0]), 2:5], rtol=1e-6)
            np.testing.assert_allclose(ts.velocities, rows[np.argsort(rows[:, 0]), 8:11], rtol=1e-6, atol=1e-6)


def _model_counts(model_txt: Path) -> dict[str, int]:
    kinds = [ln.split()[0] for ln in model_txt.read_text().splitlines() if ln.strip()]
    return {k: kinds.count(k) for k in ("BEAD", "SPRING", "ANGLE")}


def test_fibrenet_data_file_reads_in_mdanalysis(tmp_path):
    """The FibreNet state lives beside the data file (fibrenet_state.txt), so MDAnalysis reads
    data.lammps: atoms, bonds and angles as the model file has them, positions its unwrapped ones."""
    import MDAnalysis

    folder = _copy(tmp_path / "in", EXAMPLES / "fibre_network" / "input.txt", EXAMPLES / "fibre_network" / "model.txt")
    job = fibrelmp.python_api.write_job(folder / "input.txt", tmp_path / "job")
    counts = _model_counts(folder / "model.txt")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        u = MDAnalysis.Universe(str(job.data), format="DATA", atom_style="id resid type x y z")
    assert (len(u.atoms), len(u.bonds), len(u.angles)) == (counts["BEAD"], counts["SPRING"], counts["ANGLE"])
    beads = np.array([ln.split()[15:18] for ln in (folder / "model.txt").read_text().splitlines()
                      if ln.startswith("BEAD")], float)
    np.testing.assert_allclose(u.atoms.positions, beads, rtol=1e-6)
    assert "FibreNetState" not in job.data.read_text()


def test_fibrenet_state_reaches_lammps_exactly(tmp_path):
    """A restart with forces and velocities: LAMMPS's fix fn_state holds the restart file's
    values bit for bit after the script's atomfile commands (read with numpy here)."""
    src = DATA / "real-outputs" / "fibrenet" / "restart_continue"
    folder = tmp_path / "case"
    shutil.copytree(src, folder)
    with open(folder / "input.txt", "a") as fh:
        fh.write("restart_data\tforce\n")
    job = fibrelmp.python_api.write_job(folder / "input.txt", tmp_path / "job")
    res = folder / "first_run" / "restart_continue_first_restart.res"
    rows = np.loadtxt(res, skiprows=2, usecols=range(1, 13))
    script = job.script.read_text().splitlines()
    end = script.index("variable        fn_state delete")
    lmp = fibrelmp.lammps_instance(["-log", "none", "-screen", "none", "-nocite"])
    cwd = os.getcwd()
    try:
        os.chdir(job.folder)
        for line in script[:end + 1]:
            lmp.command(line)
        ids = lmp.numpy.extract_atom("id")[: lmp.get_natoms()].copy()
        got = {c: lmp.numpy.extract_atom(c)[: len(ids)].copy() for c in
               ("d_fox", "d_foy", "d_foz", "d_vtx", "d_vty", "d_vtz")}
    finally:
        os.chdir(cwd)
        lmp.close()
    order = ids - 1
    for k, c in enumerate(("d_fox", "d_foy", "d_foz")):
        np.testing.assert_array_equal(got[c], rows[order, 9 + k])
    for k, c in enumerate(("d_vtx", "d_vty", "d_vtz")):
        np.testing.assert_array_equal(got[c], rows[order, 6 + k])
    assert np.count_nonzero(rows[:, 6:12]) > 6 * len(rows) - 10      # a real state, not zeros


# ---------------------------------------------------------------------------------------------
# MUSEN


@pytest.fixture(scope="module")
def musen_run(tmp_path_factory):
    folder = _copy(tmp_path_factory.mktemp("mu"), EXAMPLES / "musen" / "single_particle_job.txt",
                   EXAMPLES / "musen" / "SingelParticle_text.txt")
    result = fibrelmp.run(folder / "single_particle_job.txt")
    return folder, result


def _lines_by_tag(path: Path) -> dict[str, list[str]]:
    """A MUSEN text file's lines: objects by their type (tag 1), scene lines by their tag."""
    out: dict[str, list[str]] = {}
    for line in path.read_text().splitlines():
        w = line.split()
        key = f"object type {w[3]}" if w[0] == "0" else w[0]
        out.setdefault(key, []).append(line)
    return out


def test_musen_post_of_work_dump_has_the_runs_spheres(musen_run, tmp_path):
    """The sphere's line (id, radii, material key, activity, every time point) is the run's
    byte for byte but for the stress tensor (42 and 36: from the contacts, which the frames do
    not hold); what a dump cannot hold differs, and only that: the wall triangles (objects of
    type 14) and their geometry (25-27), the PBC box (28), material properties (32: only the
    density, from mass and radius) and interactions (33); a warning says so, naming the walls
    this run had and the stress tensors."""
    folder, result = musen_run
    work = folder / "single_particle_job_work" / "job2"
    run_txt = folder / "single_particle_result.txt"
    post_txt = tmp_path / "result.txt"
    said: list[tuple[str, str]] = []
    fibrelmp.convert(work / "frames.dump", "musen", post_txt, data=work / "data.lammps", warn=said.extend)
    only = [text for kind, text in said if kind == "spheres only"]
    assert len(only) == 1 and "its walls" in only[0] and "bonds" not in only[0] and "stress" in only[0]
    run, post = _lines_by_tag(run_txt), _lines_by_tag(post_txt)
    # the run's line without its stress fields: "42" and 3 values, "36" and 9, before "37"
    no_stress = [re.sub(r" 42 \S+ \S+ \S+ 36( \S+){9}(?= 37 )", "", ln) for ln in run["object type 1"]]
    assert no_stress[0] != run["object type 1"][0]
    assert post["object type 1"] == no_stress and len(run["object type 1"]) == 1
    assert post["object type 1"][0].startswith("0 12 1 1 5 0.0005 0.0005 23 KF6843H84OPHH3017U3D 24 0 1e+300 2 0 ")
    same = {k for k in run if post.get(k) == run[k]} | {"object type 1"}
    assert same == {"object type 1", "22", "29", "30", "40"}
    assert set(run) - same == {"object type 14", "25", "26", "27", "28", "32", "33"}
    assert set(post) - same == {"28", "32"}
    assert [ln.split()[1:3] for ln in post["32"]] == [["KF6843H84OPHH3017U3D", "Glass"]]


def test_musen_post_mdem_time_points_are_the_runs(musen_run, tmp_path):
    """The .mdem result's sphere values at every time point, as stored (doubles), equal, but
    for the run's stress tensor (from the contacts, which the frames do not hold)."""
    from fibrelmp.translate.musen.mdem import timepoints as tp
    from fibrelmp.translate.musen.mdem.document import MdemFile
    from fibrelmp.translate.musen.mdem.objects import SPHERE, read_objects

    folder, result = musen_run
    work = folder / "single_particle_job_work" / "job2"
    post = tmp_path / "result.mdem"
    fibrelmp.convert(work / "frames.dump", "mdem", post, data=work / "data.lammps")

    def spheres(path):
        with MdemFile(path) as mdem:
            obj = read_objects(mdem.info, mdem.version, mdem.path)
            ids = obj.ids[obj.types == SPHERE]
            return ids, [(t, v[ids].copy(), m[ids].copy()) for t, v, m in mdem.time_points()]

    (ids_a, a), (ids_b, b) = spheres(folder / "single_particle_result.mdem"), spheres(post)
    # 200 saves, then cmusen's last time point: its summed time reaches END_TIME one step late
    assert ids_a.tolist() == ids_b.tolist() == [12] and len(a) == len(b) == 202
    stress, bit = tp.columns("stress_tensor"), tp.bit("stress_tensor")
    for (ta, va, ma), (tb, vb, mb) in zip(a, b):
        assert ta == tb
        assert np.all(ma & bit) and not np.any(mb & bit)
        va[:, stress] = 0.0
        np.testing.assert_array_equal(va, vb)
        np.testing.assert_array_equal(ma & ~np.uint32(bit), mb)


def test_musen_work_dump_times_columns(musen_run):
    folder, _ = musen_run
    dump = folder / "single_particle_job_work" / "job2" / "frames.dump"
    header = re.search(r"ITEM: ATOMS (.*)\n", dump.read_text()).group(1).split()
    # sfx sfy sfz: the force cmusen saves (the previous evaluation's, fix musen/leapfrog)
    assert header == ("id type x y z vx vy vz omegax omegay omegaz fx fy fz quatw quati quatj quatk "
                      "radius mass sfx sfy sfz").split()
    times = _dump_times(dump)
    assert [s for s, _ in times] == list(range(0, 200001, 1000)) + [200001]     # cmusen's last point
    for step, t in times:            # LAMMPS's running sum: within rounding of step * dt
        assert t == pytest.approx(step * 1e-7, rel=1e-12, abs=1e-18)
    assert any(t != step * 1e-7 for step, t in times)      # ... and not exactly: post uses the facts


def test_post_frames_equal_run_frames_with_orientation_ids_radii(tmp_path):
    """Spheres with initial orientations, MUSEN ids that are not 0..n-1, sphere radii other
    than their contact radii and a start time other than 0: post's frames (through the job's
    facts) are the run's GranularFrames bit for bit."""
    from fibrelmp.post.lammps_data.reader import read_data
    from fibrelmp.post.lammps_dump.reader import iter_frames
    from fibrelmp.post.to_granular import granular_frame, model_from_frame

    glass = gm.material("Glass", **gm.GLASS)
    contacts = {(0, 0): gm.law_for(glass, glass)}
    q0 = np.array([[math.cos(0.3), math.sin(0.3), 0, 0], [math.cos(1.1), 0, 0, math.sin(1.1)],
                   [0.5, 0.5, 0.5, 0.5]])
    sph = gm.spheres([[0, 0, 0], [0.003, 0, 0], [0, 0.004, 0.001]], 0.0005, [0], [glass],
                     v=[[0.1, 0, 0], [0, 0.2, 0], [0, 0, -0.1]], w=[[0, 0, 50.0], [30.0, 0, 0], [1, 2, 3]], q=q0)
    sph.ids = np.array([7, 3, 42])
    sph.contact_radius = sph.radius * 1.01
    sph.active_start[:] = 0.25
    model = gm.model(sph, [glass], contacts, dt=1e-5, t_end=0.26, save_every_steps=200)
    model.plan.t_start = 0.25
    job, frames = gm.run(model, tmp_path)
    data = read_data(job.data)
    facts = data.facts
    dumped = list(iter_frames(job.frames))
    assert len(dumped) == len(frames) > 3
    first = dumped[0]
    post_model = model_from_frame(first, job.frames, data.type_names, "musen", facts.time(first.step),
                                  1e-5, True, facts)
    assert post_model.spheres.ids.tolist() == [7, 3, 42]
    np.testing.assert_array_equal(post_model.spheres.radius, sph.radius)
    np.testing.assert_array_equal(post_model.spheres.contact_radius, sph.contact_radius)
    assert post_model.materials[0].key == "Glass"
    musen_time = {0: 0.25}              # cmusen's clock: t += dt from the start, step by step
    t = 0.25
    for k in range(1, dumped[-1].step + 1):
        t += 1e-5
        musen_time[k] = t
    for f, run_frame in zip(dumped, frames):
        got = granular_frame(f, facts.time(f.step), post_model, facts)
        assert got.time == run_frame.time == musen_time[f.step]
        for name in ("position", "velocity", "omega", "force", "quaternion"):
            np.testing.assert_array_equal(getattr(got, name), getattr(run_frame, name), err_msg=name)
    # MUSEN turns orientations only with ANISOTROPY (fix musen/leapfrog keeps them): the
    # initial ones come through the facts unchanged, though the spheres spin
    np.testing.assert_array_equal(frames[-1].quaternion, q0)
    assert np.abs(frames[-1].omega).max() > 1


# ---------------------------------------------------------------------------------------------
# DEMDF


def test_demdf_post_of_work_dump_is_the_run(tmp_path):
    folder = _copy(tmp_path / "run", EXAMPLES / "demdf" / "head_on.json")
    result = fibrelmp.run(folder / "head_on.json")
    work = folder / "head_on_work"
    written = fibrelmp.convert(work / "frames.dump", "demdf", tmp_path / "post" / "head_on",
                               data=work / "data.lammps")
    assert sorted(p.name for p in written) == sorted(p.name for p in result.outputs) and len(written) == 9
    for path in result.outputs:
        assert (tmp_path / "post" / path.name).read_bytes() == path.read_bytes(), path.name
    assert json.loads(result.outputs[3].read_text())["time"] == 0.75
    assert dict(_dump_times(work / "frames.dump"))[3 * 1699] != 0.75      # LAMMPS's running sum


# ---------------------------------------------------------------------------------------------
# data files MDAnalysis reads; facts that do not fit


@pytest.mark.parametrize("source, spheres, bonds", [
    (("musen", "single_particle_job.txt", "SingelParticle_text.txt"), 1, 0),
    (("musen", "agglomerate_short_job.txt", "SphericalAgglomerate_text.txt"), None, None),
    (("demdf", "head_on.json"), 2, 0),
])
def test_granular_data_files_read_in_mdanalysis(tmp_path, source, spheres, bonds):
    """Sphere and bond counts as the scene has them (the agglomerate's counted in its text:
    objects of type 1 and 9); fibrelmp's bond geometry lives beside the data file."""
    import MDAnalysis

    kind, *names = source
    folder = _copy(tmp_path / "in", *[EXAMPLES / kind / n for n in names])
    job = fibrelmp.python_api.write_job(folder / names[0], tmp_path / "job")
    if spheres is None:
        types = [ln.split()[3] for ln in (folder / names[1]).read_text().splitlines() if ln.startswith("0 ")]
        spheres, bonds = types.count("1"), types.count("9")
        assert (job.folder / "bond_geometry.txt").is_file()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        u = MDAnalysis.Universe(str(job.data), format="DATA", atom_style="id resid type diameter density x y z")
    assert (len(u.atoms), len(u.bonds)) == (spheres, bonds)
    sections = [ln for ln in job.data.read_text().splitlines()[1:] if ln[:1].isalpha()]
    assert set(sections) <= {"Atoms # bpm/sphere", "Velocities", "Bonds"}


def test_facts_from_another_run_warn_and_dump_times_win(musen_run, tmp_path):
    folder, _ = musen_run
    work = tmp_path / "work"
    shutil.copytree(folder / "single_particle_job_work" / "job2", work)
    facts = json.loads((work / "data.fibrelmp.json").read_text())
    facts["time"]["step"] = 2e-7
    (work / "data.fibrelmp.json").write_text(json.dumps(facts))
    said: list = []
    fibrelmp.convert(work / "frames.dump", "musen", tmp_path / "r.txt", data=work / "data.lammps", warn=said.extend)
    assert [k for k, _ in said] == ["data facts", "spheres only"]     # the latter: no walls in a dump
    times = [float(t) for t in re.findall(r" 2 (\S+) 16 ", (tmp_path / "r.txt").read_text())]
    assert times[1] == pytest.approx(1e-4, rel=1e-12)


def test_damaged_facts_are_an_input_error(musen_run, tmp_path):
    folder, _ = musen_run
    work = tmp_path / "work"
    shutil.copytree(folder / "single_particle_job_work" / "job2", work)
    (work / "data.fibrelmp.json").write_text('{"fibrelmp_work_facts": 1, "kind": "musen"}')
    with pytest.raises(InputError, match=r"damaged fibrelmp work facts"):
        fibrelmp.convert(work / "frames.dump", "musen", tmp_path / "r.txt", data=work / "data.lammps")
    assert not (tmp_path / "r.txt").exists()


def test_runner_follows_atomfile_next_and_still_refuses_unknown_next():
    from fibrelmp.runner import execute, parse_commands

    text = "variable s atomfile f.txt\nset group all d_a v_s\nnext s\nset group all d_b v_s\n"
    commands, labels = parse_commands(text)
    assert [c.words[0] for c in execute(commands, labels)] == ["variable", "set", "next", "set"]
    commands, labels = parse_commands("next q\n")
    with pytest.raises(RunError, match="without a loop variable"):
        list(execute(commands, labels))
