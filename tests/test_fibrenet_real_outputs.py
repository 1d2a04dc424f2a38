"""fibrelmp run vs the real FibreNet program (tests/data/real-outputs/fibrenet).

Tolerances are FibreNet's own precision (see that folder's README): its pair and spring
distances use single-precision native_sqrt, and its files hold 5 decimals (xyz) or 6
significant digits (restart).
"""

import numpy as np
import pytest

from fibrelmp.pipeline.run_model import run_fibrenet
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.translate.fibrenet.writer import XYZ_SUFFIX, read_restart, read_xyz

from .conftest import data_path

CASES = ["network_pbc_hs", "lambda_07_damped", "st_pairs_network", "lj_two_types_minimize",
         "restart_continue", "restart_continue/first_run"]
TOL = {"position": 2e-5, "velocity": 3e-5, "force": 1e-3}


@pytest.mark.parametrize("case", CASES)
def test_matches_real_fibrenet(case, tmp_path):
    folder = data_path("real-outputs", "fibrenet", case)
    model = read_fibrenet(folder / "input.txt")
    base = model.plan.output.basename
    run_fibrenet(model, out=tmp_path, progress=False)
    for field, suffix in XYZ_SUFFIX.items():
        mine, ref = read_xyz(tmp_path / f"{base}{suffix}"), read_xyz(folder / f"{base}{suffix}")
        assert [f.step for f in mine] == [f.step for f in ref]
        for a, b in zip(mine, ref):
            assert a.names == b.names
            assert a.dt == b.dt and np.array_equal(a.lengths, b.lengths)
            err = np.abs(a.values - b.values).max()
            assert err <= TOL[field], f"{field} frame {a.step}: max error {err:.2e}"
    names_a, mine = read_restart(tmp_path / f"{base}_restart.res")
    names_b, ref = read_restart(folder / f"{base}_restart.res")
    assert names_a == names_b
    pos_rel = np.abs(mine[:, :6] - ref[:, :6]) / np.maximum(np.abs(ref[:, :6]), 1.0)
    assert pos_rel.max() <= 1e-5
    assert np.abs(mine[:, 6:9] - ref[:, 6:9]).max() <= TOL["velocity"]
    assert np.abs(mine[:, 9:] - ref[:, 9:]).max() <= TOL["force"]
    head_a = (tmp_path / f"{base}_restart.res").read_text().splitlines()[:2]
    head_b = (folder / f"{base}_restart.res").read_text().splitlines()[:2]
    assert head_a == head_b
