"""Bad MUSEN scenes and cmusen scripts: a `path:line: message` InputError or a named warning,
never another exception."""

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.translate.musen import scene as musen
from fibrelmp.translate.musen import script as ms

BASE = """\
0 0 1 14 5  23 STEEL 24 0 1e+300 2 0 44 0 0 0 1 0 0 0 1 0 15 0 0 0
0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0 0.01 15 0 0 0 31 1 0 0 0
0 2 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0 0.012 15 0 0 0 31 1 0 0 0
0 3 1 9 5 1 2 0.001 0.002 23 GLASS 24 0 1e+300 2 0 12 0 0 0 20 0 0 0
22 -1 -1 -1 1 1 1
28 0 0 0 0 0 0 0 0 0 0
25 Plate GEOKEY 0 0 0 0 0
26 0 0
27 1 0
32 STEEL Steel 0 7800 7 2e11 10 0.3
32 GLASS Glass 0 2500 7 5e10 10 0.2
33 STEEL STEEL 200 0.5 201 0.3 202 0.01
33 GLASS STEEL 200 0.5 201 0.3 202 0.01
33 GLASS GLASS 200 0.5 201 0.3 202 0.01
"""


def scene(tmp_path, text, name="scene.txt"):
    p = tmp_path / name
    p.write_text(text)
    return p


def replace_line(n, new):
    lines = BASE.splitlines()
    lines[n - 1] = new
    return "\n".join(lines) + "\n"


def test_base_scene_is_clean(tmp_path):
    m = musen.read(scene(tmp_path, BASE))
    assert (m.spheres.count, m.bonds.count, m.triangles.count) == (2, 1, 1)
    assert m.warnings == []


ERRORS = [  # (text, line, words in the message)
    (BASE + "99 1 2\n", 15, "unknown tag `99`"),
    (replace_line(2, BASE.splitlines()[1].replace("15 0 0 0", "19 0 0 0")), 2,
     "19 is not a per-time-point tag"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 12 0 0 0.01 2 0"), 2,
     "per-time-point tag `12` before the first time point"),
    (BASE + "2 0 12 0 0 0\n", 15, "`2` outside an object line"),
    (replace_line(2, "0 1 2 0 12 0 0 0"), 2, "`2` where `1` is expected"),
    (replace_line(2, "0 1 1 1 23 GLASS 5 0.001 0.001 2 0 12 0 0 0"), 2, "`23` where `5`"),
    (BASE + "24 0 1\n", 15, "must begin `0 ID 1 TYPE 5"),
    (BASE.replace("23 GLASS 24 0 1e+300 2 0 12 0 0 0.012", "23 NOPE 24 0 1e+300 2 0 12 0 0 0.012"),
     3, "uses material 'NOPE'"),
    (replace_line(3, "0 2 1 1 5 0.001 0.001 24 0 1e+300 2 0 12 0 0 0.012"), 3, "no `23`"),
    (BASE.replace("5 1 2 0.001", "5 1 7 0.001"), 4, "particle 7, which is no object"),
    (BASE.replace("5 1 2 0.001", "5 1 0 0.001"), 4, "which is a triangular wall"),
    (BASE.replace("5 1 2 0.001", "5 1 1 0.001"), 4, "to itself"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0"), 2,
     "`12` needs 3 value(s) but the line ends after 2"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0 15 0 0 0"), 2,
     "short of values"),
    (replace_line(5, "22 -1 -1 -1 1 1"), 5, "`22` needs 6"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 x 0.01"), 2, "'x'"),
    (replace_line(2, "0 1 1 7 5 0.001 0.001 23 GLASS 2 0 12 0 0 0"), 2, "unknown object type '7'"),
    (BASE + "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0 0.5\n", 15,
     "object id 1 is already used on line 2"),
    (replace_line(2, "0 1 1 1 5 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0 0.01"), 2,
     "a sphere needs `5 RADIUS CONTACT_RADIUS`"),
    (replace_line(11, "32 GLASS Glass 0 2500 7"), 11, "property '7' has no value"),
    (replace_line(11, "32 GLASS Glass beads 0 2500"), 11, "name contains a space"),
    (replace_line(11, "32 GLASS Glass 0 2500 10 0.7"), 11, "Poisson ratio"),
    (BASE.replace("25 Plate GEOKEY 0 0 0 0 0\n", ""), 7, "before any geometry line `25`"),
    (replace_line(9, "27 1 1"), 9, "object 1 is a sphere, not a triangular wall"),
    (replace_line(9, "27 2 0"), 9, "`27` needs 3 value(s), the line has 2"),
    (replace_line(1, "0 0 1 14 5  23 STEEL 24 0 1e+300 2 0 12 0 0 0"), 1, "has no vertices"),
    (replace_line(1, "0 0 1 14 5  23 STEEL 24 0 1e+300 2 0 44 0 0 0 1 0 0 2 0 0"), 1, "zero area"),
    ("0.5 1 1 1\n", 1, "expected a tag, got '0.5'"),
    ("# a comment\n" + BASE, 1, "no comments"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 5 1 2 0 12 0 0 0.01"), 2, "not after the end"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 nan 0.01"), 2, "finite"),
    (replace_line(6, "28 2 0 0 0 0 0 0 0 0 0"), 6, "expected 0 or 1"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 0 1 2 0 12 0 0 0.01"), 2, "one object per line"),
    (replace_line(2, "0 1 1 1 5 -0.001 0.001 23 GLASS 2 0 12 0 0 0.01"), 2, "radius must be positive"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300"), 2, "no time point"),
    (replace_line(2, "0 1.5 1 1 5 0.001 0.001 23 GLASS 2 0 12 0 0 0.01"), 2, "non-negative integer"),
    (replace_line(8, "26 5 0"), 8, "motion type 5"),
    (replace_line(8, "26 1 1 0 1 0 0"), 8, "`26` needs 13 value(s)"),
    (replace_line(8, "26 2 1 5 7 0 0 0 0 0 0 0 0 0"), 8, "limit type 7"),
    (replace_line(5, "22 1 -1 -1 -1 1 1"), 5, "min < max"),
    (replace_line(2, "0"), 2, "object id"),
]


@pytest.mark.parametrize("text,line,words", ERRORS)
def test_bad_scene(tmp_path, text, line, words):
    path = scene(tmp_path, text)
    with pytest.raises(InputError) as exc:
        musen.read(path)
    assert str(exc.value).startswith(f"{path}:{line}: "), str(exc.value)
    assert words in str(exc.value)


@pytest.mark.parametrize("content,name,words", [
    (b"", "scene.txt", "empty"),
    (b"\n  \n\t\n", "scene.txt", "empty"),
    (b"\x08\x01\x12\x00\x00binary", "scene.txt", "COMPONENT EXPORT_TO_TEXT"),
    (b"0 0 1 1 5", "scene.mdem", "EXPORT_TO_TEXT"),
    ("0 1 1 1".encode("utf-16"), "scene.txt", "UTF-16"),
    (b"0 1 1 1 5 \xff\xfe", "scene.txt", "UTF-8"),
])
def test_bad_files(tmp_path, content, name, words):
    p = tmp_path / name
    p.write_bytes(content)
    for fn in (musen.read, musen.read_time_points):
        with pytest.raises(InputError) as exc:
            fn(p)
        assert words in str(exc.value)
    with pytest.raises(InputError):
        musen.read(tmp_path / "missing.txt")


WARNINGS = [  # (text, warning kind)
    (BASE.replace("33 GLASS STEEL 200 0.5 201 0.3 202 0.01\n", ""), "musen-default-interaction"),
    (BASE + "33 GLASS WOOD 200 0.1\n", "musen-unknown-interaction"),
    (BASE + "32 GLASS Glass2 0 10\n", "musen-duplicate-material"),
    (BASE.replace("7 5e10 10 0.2", "7 5e10 10 0.2 77 1"), "musen-unknown-property"),
    (BASE + "38 Vol KEY 0 1 0 0 0 1\n", "musen-not-used"),
    (BASE + "39 Gen 1 V M 0.5 0.1 100 0 0 0 1\n40 1 2\n", "musen-not-used"),
    (BASE.replace("22 -1 -1 -1 1 1 1\n", ""), "musen-default-domain"),
    (BASE.replace("22 -1 -1 -1 1 1 1", "22 -1 -1 -1 1 1 0.011"), "musen-outside-domain"),
    (BASE.replace(" 24 0 1e+300 2 0 12 0 0 0.01", " 2 0 12 0 0 0.01"), "musen-no-activity"),
    (BASE + "0 4 1 13 5 1 2 0.001 0.002 23 GLASS 24 0 1e+300 2 0\n", "musen-liquid-bonds"),
    (BASE.replace("29 0", "") + "29 1\n", "musen-anisotropy"),
    (replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 -1 12 0 0 0.01"),
     "musen-time-mismatch"),
]


@pytest.mark.parametrize("text,kind", WARNINGS)
def test_scene_warnings(tmp_path, text, kind):
    m = musen.read(scene(tmp_path, text))
    assert kind in [k for k, _ in m.warnings]


def test_liquid_bonds_are_simulated_as_cmusen_does(tmp_path):
    """MUSEN e0ff360's liquid-bond law is a no-op: a scene with liquid bonds runs (warned);
    tests/test_lb_capilar_viscous.py compares such a run with cmusen's."""
    text = BASE + "0 4 1 13 5 1 2 0.001 0.002 23 GLASS 24 0 1e+300 2 0\n"
    m = musen.read(scene(tmp_path, text))
    assert m.liquid_bonds[0].id == 4
    musen.check_simulable(m)
    job = tmp_path / "job.txt"
    job.write_text("MODEL_PP ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\n"
                   "MODEL_SB ModelSBElastic\nMODEL_LB ModelLBCapilarViscous\nEND_TIME 1\n")
    ms.apply_simulator_settings(m, ms.read_script(job)[0])
    assert m.models["LB"].name == "ModelLBCapilarViscous"
    assert "musen-liquid-bond-no-op" in [k for k, _ in m.warnings]


def test_time_mismatch_extrapolates_like_musen(tmp_path):
    # sphere 1 has points at t = 0 and 1, the file's last time is 2 (sphere 2):
    # MUSEN extrapolates linearly -> z = 0.01 + 2 * 0.001
    text = replace_line(2, "0 1 1 1 5 0.001 0.001 23 GLASS 24 0 1e+300 2 0 12 0 0 0.01 "
                           "2 1 12 0 0 0.011")
    text = text.replace("2 0 12 0 0 0.012", "2 2 12 0 0 0.012")
    m = musen.read(scene(tmp_path, text))
    assert m.plan.t_start == 2
    assert m.spheres.position[0, 2] == pytest.approx(0.012, abs=1e-15)
    assert m.spheres.quaternion[0].tolist() == [0, 1, 0, 0]     # no `31`: MUSEN's (0,1,0,0)


def mutations():
    """Every line cut short at every token, and every token replaced by odd values."""
    lines = BASE.splitlines()
    for i, line in enumerate(lines):
        tok = line.split()
        for cut in range(len(tok)):
            yield "\n".join(lines[:i] + [" ".join(tok[:cut])] + lines[i + 1:])
        for j in range(len(tok)):
            for bad in ("x", "-1", "1e400", "0.5", "2", "12", "99999999999999999999"):
                yield "\n".join(lines[:i] + [" ".join(tok[:j] + [bad] + tok[j + 1:])]
                                + lines[i + 1:])


def test_no_other_exception_escapes(tmp_path):
    path = tmp_path / "m.txt"
    count = 0
    for text in mutations():
        path.write_text(text)
        for fn in (musen.read, musen.read_time_points):
            try:
                fn(path)
            except InputError as exc:
                assert str(exc).startswith(str(path)), str(exc)
        count += 1
    assert count > 500


# ------------------------------------------------------------------ scripts

SCRIPT_ERRORS = [
    ("SIMULATION_STEPP 1e-8\n", 1, "did you mean SIMULATION_STEP?"),
    ("JOB\nCOMPONENT RESULTS_ANALYZER\n", 2, "not supported"),
    ("JOB\nCOMPONENT SIMULATR\n", 2, "did you mean SIMULATOR?"),
    ("COMPONENT 1\n", 1, "RESULTS_ANALYZER is not supported"),
    ("SIMULATION_STEP abc\n", 1, "expected a number, got 'abc'"),
    ("SIMULATION_STEP -1e-8\n", 1, "positive"),
    ("END_TIME\n", 1, "needs 1 number"),
    ("EXT_ACCEL 0 0\n", 1, "needs 3 number"),
    ("GEOMETRY_MOTION_FORCE Plate 1 MAX 0 0 1\n", 1, "needs 9 number"),
    ("GEOMETRY_MOTION_FORCE Plate\n", 1, "needs GEOMETRY FORCE_LIMIT MIN|MAX"),
    ("LIMIT_PARTICLE_VELOCITY fast\n", 1, "expected a number, got 'fast'"),
    ("MODEL_SB_PARAMS CONSIDER_BREAKAGE 0\n", 1, "no MODEL_SB line before it"),
    ("MODEL_PARAMS ModelSBElastic CONSIDER_BREAKAGE 0\n", 1, "not selected in this job"),
    ("MODEL ModelSBElastic\nMODEL_SB_PARAMS CONSIDER_BREAKAGE 0\n", 2, "no MODEL_SB line before it"),
    ("MATERIAL_PROPERTY DENSTY K 1\n", 1, "did you mean DENSITY?"),
    ("MATERIAL_PROPERTY DENSITY K\n", 1, "needs PROPERTY COMPOUND_KEY VALUE"),
    ("INTERACTION_PROPERTY FRICTION A B 0.1\n", 1, "unknown interaction property"),
    ("TEXT_EXPORT_TD_PART 1 maybe\n", 1, "flag 2 (coord)"),
    ("TEXT_EXPORT_PRECISION 0\n", 1, "1..40"),
    ("PBC_FLAGS 1 0\n", 1, "three flags"),
    ("SIMULATOR_TYPE TPU\n", 1, "expected CPU or GPU"),
    ("STOP_CRITERION SOMETIMES\n", 1, "NONE or BROKEN_BONDS"),
    ("STOP_CRITERION BROKEN_BONDS five\n", 1, "BROKEN_BONDS needs the number of broken bonds"),
    ("CONNECTED_PP_CONTACT maybe\n", 1, "expected 1/0"),
    ("MAX_PART_MOVE -1e-9\n", 1, "expected a value >= 0 (0 keeps the simulator's)"),
    ("STEP_INC_FACTOR -1\n", 1, "expected a value >= 0 (0 keeps the simulator's)"),
    ("GEOMETRY_MOTION_TIME Plate 0 1 0 0\n", 1, "needs 11 number"),
    ("\n\n", None, "empty cmusen job script"),
]


@pytest.mark.parametrize("text,line,words", SCRIPT_ERRORS)
def test_bad_script(tmp_path, text, line, words):
    path = tmp_path / "job.txt"
    path.write_text(text)
    with pytest.raises(InputError) as exc:
        ms.read_script(path)
    where = f"{path}:{line}: " if line else f"{path}: "
    assert str(exc.value).startswith(where), str(exc.value)
    assert words in str(exc.value)


GOOD = ("MODEL_PP ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\nMODEL_SB ModelSBElastic\n"
        "SIMULATION_STEP 1e-7\nSAVING_STEP 1e-4\nEND_TIME 1e-3\n")

APPLY_ERRORS = [  # script, line, words: parsed fine, refused when the job is applied
    # (all 33 of cmusen's models are translated: no untranslated-model case is left)
    (GOOD + "MODEL_EF ModelEFLiquidDiffusion\nMODEL_EF_PARAMS TEMPERATURE 350\n", 8,
     "ModelEFLiquidDiffusion: without FIXED_SEED MUSEN seeds its generators from "
     "std::random_device"),
    (GOOD.replace("ModelPPHertzMindlin", "ModelPPHertzMindlln"), 1, "did you mean ModelPPHertzMindlin?"),
    (GOOD.replace("MODEL_PW ModelPWHertzMindlin", "MODEL_PW ModelPPHertz"), 2,
     "is a PP model, given as MODEL_PW"),
    (GOOD.replace("MODEL_PW ModelPWHertzMindlin\n", "\n"), 1, "has walls but no MODEL_PW"),
    (GOOD.replace("MODEL_SB ModelSBElastic\n", "\n"), 1, "solid bonds but no MODEL_SB"),
    (GOOD + "MODEL_LB ModelLBCapilarViscous\nMODEL_LB_PARAMS CONTACT_ANGLE nan\n", 8,
     "ModelLBCapilarViscous parameter CONTACT_ANGLE must be finite"),
    (GOOD + "MATERIAL_PROPERTY DENSITY Glass 3000\n", 7, "material 'Glass' has key GLASS"),
    (GOOD + "MATERIAL_PROPERTY POISSON_RATIO GLASS 0.6\n", 7, "Poisson ratio"),
    (GOOD + "INTERACTION_PROPERTY SLIDING_FRICTION GLASS WOOD 0.1\n", 7, "no material with key 'WOOD'"),
    (GOOD.replace("END_TIME 1e-3", "END_TIME 1e-8"), 4, "longer than the run"),
    (GOOD + "MODEL_SB_PARAMS CONSIDER_BREAKAGE 3\n", 7, "CONSIDER_BREAKAGE must be 0, 1 or 2"),
    (GOOD + "MODEL_SB_PARAMS CONSIDER_BREAKAGE 1.5\n", 7, "CONSIDER_BREAKAGE must be 0, 1 or 2"),
    (GOOD.replace("ModelSBElastic", "ModelSBKelvin") + "MODEL_SB_PARAMS MAX_DAMP_RATIO -1\n", 7,
     "MAX_DAMP_RATIO must be >= 0"),
    (GOOD + "MODEL_SB_PARAMS CONSIDER_BREAKAGE\n", 3, "expected a number"),
    (GOOD + "GEOMETRY_MOTION_FORCE Lid 1 MAX 0 0 1 0 0 0 0 0 0\n", 7, "no geometry 'Lid'"),
    (GOOD + "GEOMETRY_MOTION_TIME Lid 0 1 0 0 1 0 0 0 0 0 0\n", 7, "no geometry 'Lid'"),
    (GOOD + "COMPONENT EXPORT_TO_TEXT\n", 7, "not a SIMULATOR job"),
]


@pytest.mark.parametrize("text,line,words", APPLY_ERRORS)
def test_bad_job_settings(tmp_path, text, line, words):
    path = tmp_path / "job.txt"
    path.write_text(text)
    (job,) = ms.read_script(path)
    m = musen.read(scene(tmp_path, BASE))
    with pytest.raises(InputError) as exc:
        ms.apply_simulator_settings(m, job)
    assert str(exc.value).startswith(f"{path}:{line}: "), str(exc.value)
    assert words in str(exc.value)


def test_kelvin_bond_needs_the_styles(tmp_path):
    """ModelSBKelvin is translated with fibrelmp's styles (bond_style musen/elastic kelvin);
    with stock styles it is refused, saying why."""
    from fibrelmp import lammps_styles

    path = tmp_path / "job.txt"
    path.write_text(GOOD.replace("ModelSBElastic", "ModelSBKelvin") +
                    "MODEL_SB_PARAMS CONSIDER_BREAKAGE 2 MAX_DAMP_RATIO 0.5\n")
    (job,) = ms.read_script(path)
    with lammps_styles.stock(True):
        m = musen.read(scene(tmp_path, BASE))
        with pytest.raises(InputError) as exc:
            ms.apply_simulator_settings(m, job)
    assert str(exc.value).startswith(f"{path}:3: ")
    assert "ModelSBKelvin needs fibrelmp's LAMMPS styles" in str(exc.value)
    assert "stock LAMMPS has no such solid bond" in str(exc.value)
    if not lammps_styles.plugin().available:
        pytest.skip(f"fibrelmp's LAMMPS styles are unavailable here: {lammps_styles.plugin().how}")
    m = musen.read(scene(tmp_path, BASE))
    ms.apply_simulator_settings(m, job)
    # Kelvin: any non-zero CONSIDER_BREAKAGE is MUSEN's criterion 1
    assert (m.plan.bond_law.form, m.plan.bond_breakage, m.plan.bond_law.max_damp_ratio) == ("kelvin", 1, 0.5)
    assert m.plan.bond_law.model == "ModelSBKelvin" and m.models["SB"].name == "ModelSBKelvin"


def test_job_warnings_and_motion(tmp_path):
    path = tmp_path / "job.txt"
    path.write_text(GOOD + "VERLET_MAX_CELLS 20\nMODEL_SB_PARAMS CONSIDER_BREAKAGE 0 BIMODULARITY 1\n"
                    "GEOMETRY_MOTION_TIME Plate 0 1 0 0 1 0 0 2 5 6 7\n"
                    "PACK_GEN_POROSITY 1 0.3\n# comment\n")
    (job,) = ms.read_script(path)
    m = musen.read(scene(tmp_path, BASE))
    ms.apply_simulator_settings(m, job)
    kinds = [k for k, _ in m.warnings]
    assert "musen-ignored-keyword" in kinds and "musen-unknown-model-parameter" in kinds
    assert "musen-default-settings" in kinds                 # no EXT_ACCEL: MUSEN's -9.81
    assert m.plan.bond_breakage == 0
    (g,) = m.geometries
    assert g.motion_type == 1
    # script order: velocity, rotation velocity, rotation centre
    assert g.motion[0].velocity.tolist() == [0, 0, 1]
    assert g.motion[0].angular_velocity.tolist() == [0, 0, 2]
    assert g.motion[0].centre.tolist() == [5, 6, 7]


def test_reset_bond_length(tmp_path):
    path = tmp_path / "job.txt"
    path.write_text(GOOD + "RESET_INITIAL_BOND_LENGTH 1\n")
    (job,) = ms.read_script(path)
    m = musen.read(scene(tmp_path, BASE))
    assert m.bonds.length0[0] == 0.002
    ms.apply_simulator_settings(m, job)
    assert m.bonds.length0[0] == pytest.approx(0.002, abs=1e-17)   # |0.012 - 0.01|
    assert np.isfinite(m.bonds.length0).all()


def test_script_mutations_only_input_errors(tmp_path):
    path = tmp_path / "job.txt"
    lines = (GOOD + "MATERIAL_PROPERTY DENSITY GLASS 3000\nTEXT_EXPORT_TD_PART 1 1 0\n"
             "TIME_INTERVAL 0 1\nPBC_FLAGS 0 0 0\n").splitlines()
    for i, line in enumerate(lines):
        tok = line.split()
        variants = [" ".join(tok[:c]) for c in range(len(tok))]
        variants += [" ".join(tok[:j] + [b] + tok[j + 1:]) for j in range(len(tok))
                     for b in ("x", "-1", "1e400", "0")]
        for v in variants:
            path.write_text("\n".join(lines[:i] + [v] + lines[i + 1:]) + "\n")
            try:
                for job in ms.read_script(path):
                    ms.apply_simulator_settings(musen.read(scene(tmp_path, BASE)), job)
            except InputError as exc:
                assert str(exc).startswith(str(path)), str(exc)


def test_check_reads_model_params_after_a_refused_model(tmp_path):
    """Issue 24: ``check`` said 'no MODEL_EF line before it' of a MODEL_EF_PARAMS line right
    after a (refused) MODEL_EF line: cmusen gives those parameters to that model, so the one
    error is the model's (now shown with a misspelt MODEL_LB: every LB and EF model is translated); a
    PARAMS line with no model line before it is still an error."""
    from pathlib import Path

    from typer.testing import CliRunner

    from fibrelmp.cli import app

    corpus = Path(__file__).resolve().parent / "bad_inputs" / "musen_script"
    (tmp_path / "scene.txt").write_bytes((corpus / "scene.txt").read_bytes())
    good = (corpus / "good.txt").read_text()
    assert "MODEL_SB" in good and "MODEL_LB" not in good
    # (every MUSEN LB and EF model is translated: a misspelt one is refused)
    extra = ("MODEL_LB ModelLBCapilarViscos\nMODEL_LB_PARAMS MIN_THICKNESS 1e-5\n"
             "MODEL_SB_PARAMS CONSIDER_BREAKAGE 7\n")
    (tmp_path / "job.txt").write_text(good + extra)
    n = good.count("\n")
    result = CliRunner().invoke(app, ["check", str(tmp_path / "job.txt")])
    assert result.exit_code == 2
    errors = [line.split("job.txt", 1)[1] for line in result.stderr.splitlines()
              if line.startswith("error:")]
    assert errors == [
        f":{n + 1}: unknown MUSEN model 'ModelLBCapilarViscos'; did you mean "
        "ModelLBCapilarViscous?",
        f":{n + 3}: CONSIDER_BREAKAGE must be 0, 1 or 2 (got 7)"], result.stderr
    (tmp_path / "orphan.txt").write_text(good + "MODEL_EF_PARAMS MEDIUM_VISCOSITY 1e-5\n")
    with pytest.raises(InputError, match=f":{n + 1}: MODEL_EF_PARAMS: no MODEL_EF line before it"):
        ms.read_script(tmp_path / "orphan.txt")
