"""Trust, round 3 (issue 24), physics: singular inputs are refused or guarded, a run whose
results would hold nan/inf does not exit 0, and nothing is written then."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fibrelmp.translate.cardioproof.results import SphFrame
from fibrelmp.errors import RunError
from fibrelmp.granmodel import GranularFrame
from fibrelmp import finite

from .test_musen_bad_input import BASE

CLI = [sys.executable, "-m", "fibrelmp.cli"]

# two glass spheres (ids 1, 2) and a solid bond (id 3) between them, on a steel triangle
SCENE = BASE
COINCIDENT = SCENE.replace("12 0 0 0.012 15", "12 0 0 0.01 15")    # sphere 2 onto sphere 1
SHORT = ["--end-time", "1e-5", "--step", "1e-7", "--save-step", "1e-6"]


def cli(args, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(CLI + [str(a) for a in args], cwd=cwd, capture_output=True, text=True,
                          timeout=300)


@pytest.mark.parametrize("styles", [[], ["--stock-styles"]], ids=["musen-elastic", "stock-bpm"])
def test_bond_between_coincident_spheres_is_an_input_error(tmp_path, styles):
    """Was: 252 nan tokens in the MUSEN result, exit 0.  The real cmusen 1.74.2 gives nan for
    every value of both spheres and the bond from the first step on, so the scene is refused:
    `path:line` of the bond, exit 2, nothing written."""
    scene = tmp_path / "scene.txt"
    scene.write_text(COINCIDENT)
    res = cli(["run", scene, "-o", tmp_path / "result.txt", *SHORT, *styles], tmp_path)
    assert res.returncode == 2, res.stderr
    assert f"error: {scene}:4: solid bond 3 joins spheres 1 and 2, which are at the same position" \
        in res.stderr
    assert "Traceback" not in res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.txt"]      # not even a work folder


UNBONDED_COINCIDENT = "".join(ln + "\n" for ln in COINCIDENT.splitlines()    # no bond, no wall
                              if ln.split()[:2] not in (["0", "3"], ["0", "0"])
                              and ln[:3] not in ("25 ", "26 ", "27 "))


def test_unbonded_spheres_at_one_position_are_an_input_error(tmp_path):
    """Was: exit 0, the two spheres overlapping for ever with no force (musen/hm skips a pair at
    zero distance), where MUSEN gives nan."""
    scene = tmp_path / "scene.txt"
    scene.write_text(UNBONDED_COINCIDENT)
    for command in (["check", scene], ["run", scene, "-o", tmp_path / "result.txt", *SHORT]):
        res = cli(command, tmp_path)
        assert res.returncode == 2, res.stderr
        assert f"error: {scene}: spheres 1 and 2 are at the same position (0, 0, 0.01)" \
            in res.stderr and "Traceback" not in res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.txt"]


def test_non_finite_frame_is_a_run_error_and_keeps_the_old_result(tmp_path, monkeypatch):
    """Two unbonded spheres at one position (let through here: the input check refuses them)
    under stock pair granular: LAMMPS divides by their zero distance and writes nan forces.
    Was: exit 0 with nan in the result; now a RunError naming the sphere, the quantity and the
    time, and the earlier result is untouched."""
    import fibrelmp
    from fibrelmp.translate.granular import spheres

    monkeypatch.setattr(spheres, "check_distinct_positions", lambda model: None)
    scene = tmp_path / "scene.txt"
    scene.write_text(UNBONDED_COINCIDENT)
    result = tmp_path / "result.txt"
    result.write_text("an earlier result\n")
    with pytest.raises(RunError, match=r"the simulation produced nan in the force of sphere 1 at "
                       r"t = 0 \(step 0\)"):
        fibrelmp.run(scene, result, force=True, stock_styles=True, end_time=1e-5, step=1e-7,
                     save_step=1e-6)
    assert result.read_text() == "an earlier result\n"
    assert not [p.name for p in tmp_path.iterdir() if ".tmp" in p.name]


def _granular_frame(**changes) -> GranularFrame:
    n = 3
    values = dict(time=0.25, step=250, sphere_rows=np.array([0, 2, 3]), position=np.zeros((n, 3)),
                  velocity=np.zeros((n, 3)), omega=np.zeros((n, 3)), force=np.zeros((n, 3)),
                  quaternion=np.tile([1.0, 0, 0, 0], (n, 1)),
                  bond_alive=np.array([False, True]), bond_end_time=np.array([0.1, np.inf]),
                  bond_force=np.array([[np.nan] * 3, [0.0] * 3]),
                  triangle_force=np.zeros((2, 3)))
    values.update(changes)
    return GranularFrame(**values)


MODEL = SimpleNamespace(spheres=SimpleNamespace(ids=np.array([10, 11, 12, 13])),
                        bonds=SimpleNamespace(ids=np.array([20, 21])),
                        triangles=SimpleNamespace(ids=np.array([30, 31])))


def test_guard_names_the_first_non_finite_value():
    finite.check(_granular_frame(), MODEL)     # a broken bond's nan force is its "absent" mark
    omega = np.zeros((3, 3))
    omega[2, 1] = -np.inf
    omega[1, 0] = np.inf
    with pytest.raises(RunError, match=r"inf in the angular velocity of sphere 12 at t = 0.25 \(step 250\)"):
        finite.check(_granular_frame(omega=omega), MODEL)
    bond_force = np.array([[np.nan] * 3, [0, np.nan, 0]])
    with pytest.raises(RunError, match="nan in the force of bond 21"):
        finite.check(_granular_frame(bond_force=bond_force), MODEL)
    tri = np.zeros((2, 3))
    tri[1, 2] = np.nan
    with pytest.raises(RunError, match="nan in the force of triangle 31"):
        finite.check(_granular_frame(triangle_force=tri), MODEL)
    with pytest.raises(RunError, match="nan in the force of triangle row 1"):
        finite.check(_granular_frame(triangle_force=tri))
    sph = SphFrame(step=4, time=0.5, ids=np.array([7, 8]), positions=np.zeros((2, 3)),
                   velocities=np.zeros((2, 3)), density=np.array([1000.0, np.nan]), pressure=np.zeros(2))
    with pytest.raises(RunError, match="nan in the density of particle 8 at t = 0.5"):
        finite.check(sph)
    dump = SimpleNamespace(step=9, time=None, columns={"id": np.array([5.0, 6.0]),
                                                       "x": np.array([0.0, 1.0]),
                                                       "fx": np.array([np.inf, 0.0])})
    with pytest.raises(RunError, match=r"inf in the dump column 'fx' of atom 5 at \(step 9\)"):
        finite.check(dump)
    finite.check(17)                    # a FibreNet frame counter: nothing to check


def test_guard_scans_result_text_files(tmp_path):
    """Results a LAMMPS style wrote itself (FibreNet's files): a nan/inf value is found by its
    line; a type named like a number word is not a value."""
    good = tmp_path / "a_coord.xyz"
    good.write_text("2\nFRAME\t0\t0.001\t8\t7\t8\ninf\t1.5\t3.5\t5\nNanofibre\t1\t2\t3\n")
    finite.scan_text_files([good])
    bad = tmp_path / "b_vel.xyz"
    row = "N1\t1.5\t3.5\t5\n"                    # 70,000 rows: the value is in the second MiB
    bad.write_text("2\nFRAME\t0\t0.001\t8\t7\t8\n" + row * 70000 + "N1\t1\t-nan\t3\n")
    with pytest.raises(RunError, match=rf"{bad}:70003: the simulation produced -nan"):
        finite.scan_text_files([good, bad])


# two touching A beads (R 0.3, 0.5 apart: overlap 0.1) of different fibres, a B bead far away
FIBRE_MODEL = ("BEAD\tA\t0\t0\t0.3\t1.0\t1.0\t1.0\t1.0\t0\t0\t0\t0\t0\t0\t1.0\t1.0\t1.0\n"
               "BEAD\tA\t1\t0\t0.3\t1.0\t1.5\t1.0\t1.0\t0\t0\t0\t0\t0\t0\t1.5\t1.0\t1.0\n"
               "BEAD\tB\t2\t0\t0.2\t1.0\t3.0\t3.0\t3.0\t0\t0\t0\t0\t0\t0\t3.0\t3.0\t3.0\n")
FIBRE_INPUT = ("model_file model.txt\noutput_file out\ntype A\ntype B\npair hs A A 100\n"
               "pair hs B B 100\npair hs A B 100\nbox_size 5 5 5\nbox_type finite\nbox_wall_rep 100\n"
               "box_unit_cell 1.0\ncutoff 1.0\nstep 0.001\nlambda 0.5\nrun 20\noutput_freq 10\noutput_data all\n"
               "output_type all\n")


@pytest.mark.parametrize("skin,kind,listed", [
    ("0.1", "skin radius below the bead radius", "0.4"),   # lists r < 0.3 + 0.1: misses 0.5
    ("0.3", "skin radius", None),                          # lists r < 0.6: every contact
])
def test_skin_radius_below_the_radius_warns_how_fibrenet_differs(tmp_path, skin, kind, listed):
    """Was: skin_radius below the bead radius was said to have 'no effect', yet the real
    FibreNet lists an hs pair only when r < max(R_i, R_j) + min(skin_i, skin_j) at its list
    builds (kernel.cl) and so misses overlapping pairs (forces up to 328 different).  That
    depends on when its list was built (an artefact, no cut-off LAMMPS could express):
    fibrelmp keeps every contact and warns, naming the listing distance."""
    from fibrelmp.translate.fibrenet.reader import read as read_fibrenet

    (tmp_path / "model.txt").write_text(FIBRE_MODEL)
    (tmp_path / "input.txt").write_text(FIBRE_INPUT + f"modif_bead type A skin_radius {skin}\n")
    model = read_fibrenet(tmp_path / "input.txt")
    notes = [msg for k, msg in model.warnings if k.startswith("skin radius")]
    assert [k for k, _ in model.warnings if k.startswith("skin radius")] == [kind]
    assert notes[0].startswith(f"{tmp_path / 'input.txt'}:19: skin_radius {skin} ")
    if listed:
        assert f"(here {listed})" in notes[0] and f"{listed} <= r < 0.6" in notes[0]
    else:
        assert "no effect" in notes[0]


# ------------------------------------------------------------------ DEMDF keys
DROP = (Path(__file__).resolve().parents[1] / "examples" / "demdf" / "drop_on_wall.json").read_text()


@pytest.mark.parametrize("old,new,line,where,hint", [
    ('"bodyForce"', '"bodyforce"', 17, "", "did you mean 'bodyForce'?"),
    ('"radius"', '"raduis"', 22, "objectTypes[0]: ", "did you mean 'radius'?"),
    ('"type": "wall",\n            "restitutionCoefficient"', '"type": "wall",\n            "restitution"',
     29, "objectTypes[1]: ", "did you mean 'restitutionCoefficient'?"),
    ('"particles": [\n', '"particle": [\n', 33, "objects: ", "did you mean 'particles'?"),
    ('"normal"', '"norma1"', 38, "objects.walls[0]: ", "did you mean 'normal'?"),
    ('"name": "wallInelastic",\n            "objectTypes"', '"name": "wallInelastic",\n            "objecttypes"',
     51, "interactions[1]: ", "did you mean 'objectTypes'?"),
    ('"savePeriodInTime"', '"savePeriodInTim"', 13, "output.snapshot: ", "did you mean 'savePeriodInTime'?"),
    ('"snapshot"', '"snapshots"', 9, "output: ", "did you mean 'snapshot'?"),
    ('"dimensionality": 3,', '"dimensionality": 3, "fibrelmp": {"maxOverlapp": 0.02},', 5, "fibrelmp: ",
     "did you mean 'maxOverlap'?"),
    ('"dimensionality": 3,', '"dimensionality": 3, "colour": "red",', 5, "", "unknown key 'colour';"),
], ids=["top", "particle-type", "wall-type", "objects", "wall", "interaction", "snapshot", "output",
        "extension", "no-match"])
def test_demdf_unknown_key_is_an_input_error_at_its_line(tmp_path, old, new, line, where, hint):
    """Was: "bodyforce" ran with gravity 0 and "raduis" with the default radius (a mere
    warning), exit 0.  Now every object level refuses keys it does not read, at the key's line,
    with the key it most resembles."""
    from fibrelmp.errors import InputError
    from fibrelmp.translate.demdf.reader import read

    assert DROP.count(old) == 1
    path = tmp_path / "drop.json"
    path.write_text(DROP.replace(old, new))
    with pytest.raises(InputError) as exc:
        read(path)
    assert str(exc.value).startswith(f"{path}:{line}: {where}unknown key"), str(exc.value)
    assert hint in str(exc.value)


def test_demdf_unknown_key_in_a_particles_file_and_other_outputs(tmp_path):
    """The particles file is checked too; an output routine other than the snapshot (one
    that does not resemble it) stays a warning: DEMDF's output holds any routines."""
    from fibrelmp.errors import InputError
    from fibrelmp.translate.demdf.reader import read

    (tmp_path / "parts.json").write_text('{\n "particles": [[2, 2, 2, 0, 0, 0, 0]],\n "particels": []\n}\n')
    path = tmp_path / "drop.json"
    path.write_text(DROP.replace('"particles": [\n            [2.0, 2.0, 2.0, 0.0, 0.0, 0.0, 0]\n        ]',
                                 '"particles": "parts.json"'))
    with pytest.raises(InputError) as exc:
        read(path)
    assert str(exc.value).startswith(f"{tmp_path / 'parts.json'}:3: unknown key 'particels' "
                                     "(did you mean 'particles'?)"), str(exc.value)
    path.write_text(DROP.replace('"snapshot": {', '"energyMeasurement": {"every": 1}, "snapshot": {'))
    kinds = [msg for _, msg in read(path).warnings]
    assert "output.energyMeasurement is not an output fibrelmp writes; ignored" in kinds


# ------------------------------------------------------------------ packages and the plugin
def _header_packages(script: str) -> list[str]:
    line = next(ln for ln in script.splitlines() if "Needs package" in ln)
    return [p.strip() for p in line.split("Needs package")[1].lstrip("s ").split("(")[0]
            .rstrip(".").split(",")]


def test_demdf_job_loads_no_plugin_and_names_its_packages(tmp_path):
    """Was: the DEMDF job loaded fibrelmp's plugin (it uses stock styles only) while its header
    said 'Needs packages GRANULAR and BPM'.  Now a job loads the plugin only for a style of
    its own and its header lists what the script uses."""
    from fibrelmp import lammps_styles
    from fibrelmp.translate.demdf.reader import read
    from fibrelmp.translate.granular_job import build_granular_job

    if not lammps_styles.plugin().available:
        pytest.skip("fibrelmp's LAMMPS styles are not available here: nothing to leave out")
    model = read(Path(__file__).resolve().parents[1] / "examples" / "demdf" / "drop_on_wall.json")
    _, script, _ = build_granular_job(model, tmp_path)
    assert "plugin" not in script.split("Needs package")[1].split("\n", 1)[1]
    assert _header_packages(script) == ["GRANULAR", "BPM"]
    words = {ln.split()[0] for ln in script.splitlines() if ln.strip() and not ln.startswith("#")}
    assert "plugin" not in words


def test_musen_jobs_name_plugin_only_when_loaded(tmp_path):
    """A MUSEN scene with the plugin loads it and says PLUGIN; with stock styles neither."""
    from fibrelmp import lammps_styles
    from fibrelmp.translate.granular_job import build_granular_job
    from fibrelmp.translate.musen import scene as musen

    path = tmp_path / "scene.txt"
    path.write_text(SCENE)
    model = musen.read(path)
    model.plan.dt, model.plan.t_end, model.plan.save_every_time = 1e-7, 1e-5, 1e-6
    previous = lammps_styles.request_stock(True)
    try:
        _, stock, _ = build_granular_job(model, tmp_path / "stock")
    finally:
        lammps_styles.request_stock(previous)
    assert "plugin          load" not in stock and "PLUGIN" not in _header_packages(stock)
    assert _header_packages(stock)[:2] == ["GRANULAR", "BPM"]
    if lammps_styles.plugin().available:
        _, exact, _ = build_granular_job(model, tmp_path / "exact")
        assert "plugin          load" in exact and _header_packages(exact)[-1] == "PLUGIN"


# ------------------------------------------------------------------ the real codes (opt-in)
# What the deviations above rest on, run through the real programs (built as described in
# shared/oracles/README.md): FIBRELMP_FIBRENET=/path/to/FibreNet (kernel.cl beside it, an
# OpenCL CPU device), FIBRELMP_CMUSEN=/path/to/CMUSEN.
FIBRENET_BIN = os.environ.get("FIBRELMP_FIBRENET")
CMUSEN_BIN = os.environ.get("FIBRELMP_CMUSEN")
TWO_A_BEADS = FIBRE_MODEL + ("BEAD\tB\t2\t0\t0.2\t1.0\t3.5\t3.0\t3.0\t0\t0\t0\t0\t0\t0\t3.5\t3.0\t3.0\n"
                             "SPRING\tHR\t2\t2\t3\t0.5\t100\n")       # FibreNet needs a spring


@pytest.mark.skipif(not FIBRENET_BIN, reason="set FIBRELMP_FIBRENET to the real FibreNet")
def test_real_fibrenet_misses_the_contact_a_short_skin_hides(tmp_path):
    """The two A beads overlap by 0.1 but their skin 0.1 lists them only below r = 0.4: the real
    FibreNet leaves them where they are for 20 steps; fibrelmp pushes them apart with
    K (R_i + R_j - r) = 10 (x 0.998107 and 1.501893 after 20 steps) and warns."""
    from fibrelmp.translate.fibrenet.writer import read_xyz

    (tmp_path / "model.txt").write_text(TWO_A_BEADS)
    (tmp_path / "input.txt").write_text(FIBRE_INPUT + "modif_bead type A skin_radius 0.1\n")
    (tmp_path / "kernel.cl").write_bytes((Path(FIBRENET_BIN).parent / "kernel.cl").read_bytes())
    subprocess.run([FIBRENET_BIN], input="1\n1\ninput.txt\n", cwd=tmp_path, capture_output=True,
                   text=True, timeout=300, env={**os.environ, "POCL_MAX_PTHREAD_COUNT": "1"})
    real = read_xyz(tmp_path / "out_coord.xyz")[-1].values
    assert real[:2, 0].tolist() == [1.0, 1.5]             # no hs force: the contact is missed
    res = cli(["-q", "run", tmp_path / "input.txt", "-o", tmp_path / "ours"], tmp_path)
    assert res.returncode == 0 and "skin radius below the bead radius" in res.stderr, res.stderr
    ours = read_xyz(tmp_path / "ours" / "out_coord.xyz")[-1].values
    assert ours[0, 0] < 0.999 and ours[1, 0] > 1.501


def _cmusen(folder: Path, scene: str) -> str:
    """cmusen's 17-digit text export of ``scene`` after three 1e-7 s steps."""
    (folder / "scene.txt").write_text(scene)
    (folder / "job.txt").write_text(
        "JOB\nSOURCE_FILE scene.txt\nRESULT_FILE ./init.mdem\nCOMPONENT IMPORT_FROM_TEXT\n"
        "JOB\nSOURCE_FILE ./init.mdem\nRESULT_FILE ./res.mdem\nCOMPONENT SIMULATOR\n"
        "SIMULATOR_TYPE CPU\nMODEL_PP ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\n"
        "MODEL_SB ModelSBElastic\nSIMULATION_STEP 1e-7\nSAVING_STEP 1e-7\nEND_TIME 3e-7\n"
        "EXT_ACCEL 0 0 0\nJOB\nSOURCE_FILE ./res.mdem\nRESULT_FILE ./res.txt\n"
        "COMPONENT EXPORT_TO_TEXT\nTEXT_EXPORT_PRECISION 17\n")
    subprocess.run([CMUSEN_BIN, "-t=1", "-s=job.txt"], cwd=folder, capture_output=True, timeout=300)
    return (folder / "res.txt").read_text()


@pytest.mark.skipif(not CMUSEN_BIN, reason="set FIBRELMP_CMUSEN to the real cmusen")
@pytest.mark.parametrize("case", ["centre-on-face", "coincident-bond"])
def test_real_cmusen_gives_nan_where_fibrelmp_deviates_or_refuses(tmp_path, case):
    """A sphere centre on a wall face (fibrelmp: the face normal, warned) and a bond between
    coincident spheres (fibrelmp: an input error): the real cmusen 1.74.2 writes nan."""
    scene = (Path(__file__).resolve().parents[1] / "examples" / "musen" / "SingelParticle_text.txt").read_text()
    if case == "centre-on-face":
        scene = scene.replace("12 0 0 0.005 15 0 0 -0.5", "12 0.002 -0.001 -0.001 15 0 0 0")
        sphere = 12
    else:
        line = next(ln for ln in scene.splitlines() if ln.startswith("0 12 "))
        line = line.replace("15 0 0 -0.5", "15 0 0 0")
        bond = "0 14 1 9 5 12 13 0.0002 0.001 23 KF6843H84OPHH3017U3D 24 0 1e+300 2 0 12 0 0 0.005 20 0 0 0"
        scene = scene.replace(line_of(scene, 12), "\n".join([line, line.replace("0 12 ", "0 13 ", 1), bond]))
        sphere = 13
    text = _cmusen(tmp_path, scene)
    row = next(ln for ln in text.splitlines() if ln.startswith(f"0 {sphere} "))
    start = row.split()
    assert start[start.index("12") + 1:start.index("12") + 4] != ["nan"] * 3    # t = 0 is finite
    assert sum(tok.lstrip("-") == "nan" for tok in start) >= 9             # every later point: nan


def line_of(scene: str, ident: int) -> str:
    return next(ln for ln in scene.splitlines() if ln.startswith(f"0 {ident} "))
