"""Several particle-particle and particle-wall models acting together, as cmusen runs them
(CCPUSimulator::CalculateForcesPP / CalculateForcesPW: each active model in turn over every
collision, its force and moments added; a Hertz-Mindlin-shaped model reads the collision's
tangential overlap the previous model of the step left and writes its own).  References: the
real cmusen 1.74.2 on an oblique spinning two-sphere impact under ModelPPHertzMindlin then
ModelPPLinearElastic, the same the other way round, Hertz-Mindlin named twice in the script
(cmusen keeps one) and twice in a .mdem's model list (cmusen runs both), Hertz-Mindlin and
linear elastic twice in a .mdem with a script's MODEL_PARAMS (the first takes them), and a
spinning sphere on a plate under ModelPWHertzMindlin then ModelPWSimpleViscoElastic
(tests/data/real-outputs/musen/several_models/README.md)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.granmodel import ModelChoice
from fibrelmp.registry import INPUT, detect
from fibrelmp.translate.musen.scene_record import scene_record
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_refused_without_styles,
                                 check_resume_is_bitwise, needs_cmusen, styles_or_skip)

DATA = data_path("real-outputs/musen/several_models")
# each case's source: a text scene, or a .mdem whose model list names a model twice (MUSEN
# loads both; a job's MODEL_PARAMS go to the first)
SCENES = {"hm_le": "pp_scene.txt", "le_hm": "pp_scene.txt", "hm_hm": "pp_scene.txt",
          "pw_hm_sve": "pw_scene.txt", "hm_twice": "hm_twice_init.mdem",
          "le_twice": "le_twice_init.mdem", "pw_twice": "pw_twice_init.mdem"}
# what fibrelmp's LAMMPS script says for each case
LAMMPS_LINES = {
    "hm_le": "pair_style      musen/hm then linear/elastic 500000.0 400000.0",
    "le_hm": "pair_style      musen/linear 500000.0 400000.0 then hertz/mindlin",
    "hm_hm": "pair_style      musen/hm\n",   # cmusen keeps one model of a name: musen/hm alone
    "pw_hm_sve": "musen/wall/mesh walls.mesh law hertz/mindlin law simple/viscoelastic "
                 "500000.0 0.02\n",
    "hm_twice": "pair_style      musen/hm then hertz/mindlin\n",
    "le_twice": "pair_style      musen/hm then linear/elastic 200000.0 400000.0 then "
                "linear/elastic 500000.0 400000.0\n",
    "pw_twice": "musen/wall/mesh walls.mesh law hertz/mindlin law hertz/mindlin\n",
}
# the job of a case with a .mdem source is job 1 (no import)
JOB_FOLDER = {"hm_twice": "job1", "le_twice": "job1", "pw_twice": "job1"}
TOLERANCE = 1e-9    # of each quantity's scale (measured: < 2e-16)


def _staged(tmp_path: Path, case: str) -> Path:
    shutil.copy(DATA / SCENES[case], tmp_path)
    shutil.copy(DATA / f"job_{case}.txt", tmp_path)
    return tmp_path / f"job_{case}.txt"


def _scaled_differences(ours_path: Path, theirs_path: Path) -> dict[int, float]:
    """The largest difference of position, velocity and spin over every saved time point, as
    a fraction of the largest magnitude of that quantity in ``theirs``."""
    ours, theirs = read_time_points(ours_path), read_time_points(theirs_path)
    # cmusen's saved times are sums of steps, fibrelmp's step * dt
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    assert np.array_equal(ours.ids, theirs.ids)
    out = {}
    for tag in (COORD, VEL, ANGVEL):
        a, b = ours.fields[tag], theirs.fields[tag]
        known = np.isfinite(b)           # walls have no position, velocity or spin
        assert np.array_equal(known, np.isfinite(a))
        out[tag] = float(np.abs(a - b)[known].max() / np.abs(b[known]).max())
    return out


@pytest.mark.parametrize("case", sorted(SCENES))
def test_several_models_act_as_in_cmusen(tmp_path, case):
    styles_or_skip()
    job = _staged(tmp_path, case)
    python_api.run(job, work=tmp_path / "work")
    script = (tmp_path / "work" / JOB_FOLDER.get(case, "job2") / "in.lammps").read_text()
    assert LAMMPS_LINES[case] in script
    diffs = _scaled_differences(tmp_path / f"{case}_result_prec17.txt",
                                DATA / f"cmusen_{case}_result_prec17.txt")
    assert max(diffs.values()) < TOLERANCE, diffs


# checkpointed in the middle of the contact (the PP contact starts near step 1500, the PW one
# near 1250): the law lists and the shared tangential overlap survive the restart
@pytest.mark.parametrize("case,every", [("hm_le", 1560), ("pw_hm_sve", 1300)])
def test_checkpointed_and_resumed_run_is_bitwise_the_same(tmp_path, monkeypatch, case, every):
    check_resume_is_bitwise(tmp_path, monkeypatch, lambda at: _staged(at, case), f"{case}_result_prec17.txt",
                            every)


def test_the_references_tell_the_laws_and_their_order_apart():
    """Each model changes the result far beyond the tolerance, and so does their order (the
    second law continues the tangential overlap the first advanced this step)."""
    def ref(case):
        return DATA / f"cmusen_{case}_result_prec17.txt"
    hm_alone = ref("hm_hm")
    for a, b in ((ref("hm_le"), hm_alone), (ref("hm_le"), ref("le_hm")),
                 (ref("hm_twice"), hm_alone), (ref("le_twice"), ref("hm_le")),
                 (ref("pw_twice"), ref("pw_hm_sve"))):
        diffs = _scaled_differences(a, b)
        assert diffs[VEL] > 1e-5 and diffs[ANGVEL] > 1e-5, diffs
    # the wall case: the sphere bounced (velocity reversed) and Hertz-Mindlin's friction
    # slowed its spin (the viscoelastic law has no torque)
    theirs = read_time_points(ref("pw_hm_sve"))
    assert theirs.fields[VEL][0][0][2] < 0 < theirs.fields[VEL][-1][0][2]
    assert theirs.fields[ANGVEL][-1][0][1] < 0.8 * theirs.fields[ANGVEL][0][0][1]


def test_cmusen_lists_both_models_and_one_of_a_name_given_twice():
    log = (DATA / "cmusen_hm_le.log").read_text()
    assert ("Particle-particle:                     Hertz-Mindlin\n"
            "Particle-particle:                     Linear Elastic\n") in log
    assert (DATA / "cmusen_hm_hm.log").read_text().count("Particle-particle:") == 1
    # a .mdem's list is loaded as it is; the script's parameters go to the first of a name
    assert (DATA / "cmusen_hm_twice.log").read_text().count("Hertz-Mindlin") == 2
    assert ("Linear Elastic\n\tKn 200000 Kt 400000 \nParticle-particle:                     "
            "Linear Elastic\n\tKn 500000 Kt 400000") in (DATA / "cmusen_le_twice.log").read_text()


def test_the_result_keeps_both_models_in_order(tmp_path):
    styles_or_skip()
    python_api.run(_staged(tmp_path, "le_hm"), work=tmp_path / "work")
    result = tmp_path / "le_hm_result.mdem"
    model = detect(result).load(INPUT)().model(result)
    assert [(m.name, m.params.split()) for m in scene_record(model).file_models] == [
        ("ModelPPLinearElastic", ["Kn", "500000", "Kt", "400000"]), ("ModelPPHertzMindlin", [])]


def test_check_bounds_the_joint_contact_time(tmp_path):
    """Hertz and a linear spring together: the shorter duration over sqrt(2) (stiffnesses
    add), named so."""
    from fibrelmp.sanity import hertz_contact_time
    lines = python_api.check(_staged(tmp_path, "hm_le")).lines
    line = next(t for t in lines if t.startswith("contact time"))
    assert "(Hertz + linear elastic: shortest / sqrt(2), a lower bound, Glass-Glass" in line, line
    m_eff = 2500.0 * 4.0 / 3.0 * np.pi * 1e-3 ** 3 / 2
    linear = np.pi * np.sqrt(m_eff / 5e5)
    # the fastest approach: the two speeds (0.3 and |(-0.3, 0, 0.05)|) added
    hertz = hertz_contact_time(m_eff, 5e-4, 5e10 / (2 * (1 - 0.22 ** 2)), 0.3 + np.hypot(0.3, 0.05))
    assert line.startswith(f"contact time {min(linear, hertz) / np.sqrt(2):.3g} "), line


def test_a_later_models_parameters_are_checked_at_its_line(tmp_path):
    job = _staged(tmp_path, "hm_le")
    job.write_text(job.read_text().replace("Kn 500000", "Kn -1"))
    with pytest.raises(InputError, match="ModelPPLinearElastic parameter Kn must be a stiffness"):
        python_api.run(job)


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_staged(tmp_path, "pw_hm_sve"), "ModelPWSimpleViscoElastic", 12,
                                 tmp_path / "pw_hm_sve_init.mdem")


def test_a_files_model_twice_is_refused_without_fibrelmps_styles(tmp_path):
    """Hertz-Mindlin alone runs on stock LAMMPS; twice it needs pair musen/hm's law list."""
    from fibrelmp import lammps_styles
    job = _staged(tmp_path, "hm_twice")
    with lammps_styles.stock(True), pytest.raises(InputError) as err:
        python_api.run(job)
    assert err.value.line is None and err.value.path.endswith("hm_twice_init.mdem")
    assert err.value.message.startswith("ModelPPHertzMindlin after ModelPPHertzMindlin: several "
                                        "PP models acting together need fibrelmp's LAMMPS styles")
    assert not (tmp_path / "hm_twice_result.mdem").exists()


def test_two_models_of_a_kind_fibrelmp_does_not_combine_are_refused_at_the_second():
    from fibrelmp.translate.musen.script_settings import _first_and_later
    script = Path("job.txt")
    first = ModelChoice("ModelLBOne", "LB", {}, script, 3)
    second = ModelChoice("ModelLBTwo", "LB", {}, script, 4)
    with pytest.raises(InputError) as err:
        _first_and_later([first, second], script)
    assert err.value.line == 4
    assert err.value.message == (
        "ModelLBTwo (line 4) and ModelLBOne (line 3) are both LB models: cmusen runs every "
        "selected model, both acting on each liquid bond in turn; fibrelmp runs several models "
        "of a kind only for PP, PW, SB, EF and not two liquid-bond models together: remove one "
        "of the two MODEL_ lines")


@needs_cmusen
@pytest.mark.parametrize("case", sorted(SCENES))
def test_reference_is_cmusens_output(tmp_path, case):
    _staged(tmp_path, case)
    done = subprocess.run([os.environ["FIBRELMP_CMUSEN"], "-t=1", f"-s=job_{case}.txt"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    assert (tmp_path / f"{case}_result_prec17.txt").read_bytes() == \
        (DATA / f"cmusen_{case}_result_prec17.txt").read_bytes()
