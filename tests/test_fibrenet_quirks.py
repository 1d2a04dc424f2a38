"""FibreNet quirks are reproduced and announced once each."""

import numpy as np

from fibrelmp.pipeline.run_model import run_fibrenet
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.translate.fibrenet.writer import read_xyz

from .test_fibrenet_bad_input import INPUT, MODEL, write_case


def test_velocity_quirk_vx_vx_vx(tmp_path):
    model_text = MODEL.replace("\t1.2\t1.5\t1.0\t0\t0\t0", "\t1.2\t1.5\t1.0\t0.3\t-0.2\t0.1")
    model = read_fibrenet(write_case(tmp_path, model_text, INPUT))
    assert [k for k, _ in model.warnings].count("velocity quirk") == 1
    np.testing.assert_array_equal(model.particles.velocities[2], [0.3, 0.3, 0.3])
    run_fibrenet(model, out=tmp_path, progress=False)
    frame0 = read_xyz(tmp_path / "out_vel.xyz")[0]
    np.testing.assert_allclose(frame0.values[2], [0.3, -0.2, 0.1])     # FibreNet shows v~ buffer


def test_velocity_quirk_silent_when_modif_bead_sets_velocity(tmp_path):
    model_text = MODEL.replace("\t1.2\t1.5\t1.0\t0\t0\t0", "\t1.2\t1.5\t1.0\t0.3\t-0.2\t0.1")
    model = read_fibrenet(write_case(tmp_path, model_text, INPUT + "modif_bead id 2 velocity 0 0 1\n"))
    assert "velocity quirk" not in [k for k, _ in model.warnings]
    np.testing.assert_array_equal(model.particles.velocities[2], [0, 0, 1])


def test_hr_fl_truncation_and_break_length(tmp_path):
    model_text = MODEL.replace("SPRING\tHR\t0\t0\t1\t0.5\t100", "SPRING\tHR_FL\t0\t0\t1\t0.5\t100\t7e6\t2.9")
    model = read_fibrenet(write_case(tmp_path, model_text, INPUT))
    assert "HR_FL integer truncation" in [k for k, _ in model.warnings]
    # stoi: c1 = 7, c2 = 2  ->  Rmax = r0 c1 / (c1 - c2)
    assert model.bonds.break_length[0] == 0.5 * 7 / 5


def test_repeated_keyword_first_wins(tmp_path):
    model = read_fibrenet(write_case(tmp_path, MODEL, INPUT + "step 0.5\n"))
    assert model.dynamics.dt == 0.001
    assert "repeated keyword" in [k for k, _ in model.warnings]


def test_later_pair_line_overrides(tmp_path):
    model = read_fibrenet(write_case(tmp_path, MODEL, INPUT + "pair hs A B 250\n"))
    law = [p for p in model.pairs if (p.type_i, p.type_j) == (0, 1)][0]
    assert law.params["K"] == 250
