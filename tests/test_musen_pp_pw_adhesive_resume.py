"""Checkpoint + resume in the middle of a contact and ``lmp -in`` replay are bitwise for the
laws of pair_style musen/pp (hertz, whose history is MUSEN's tangential force; jkr,
popov/jkr; simple/viscoelastic) and the wall laws jkr, popov/jkr (the references of
tests/test_pp_hertz_simple_viscoelastic.py, test_pp_jkr.py, test_pw_jkr.py)."""

from __future__ import annotations

import pytest

from .conftest import data_path
from .musen_model_checks import check_lmp_replay_is_bitwise, check_resume_is_bitwise, model_job

MODELS = data_path("real-outputs/musen/models")
# (folder, prefix, a checkpoint step inside a contact)
CASES = [("pp_hertz", "hertz", 2010),            # the impact: 1.7e-5 .. 2.6e-5 s, dt 1e-8
         ("pp_simple_viscoelastic", "sve", 310),  # 2.3e-4 .. 3.9e-4 s, dt 1e-6
         ("pp_jkr", "jkr", 15010),                # the slow pair stuck from about 5e-5 s
         ("pp_popov_jkr", "popov", 15010),
         ("pw_jkr", "pwjkr", 5010),               # sphere 0 on the plate from about 2e-5 s
         ("pw_popov_jkr", "pwpopov", 5010)]
IDS = [c[1] for c in CASES]


@pytest.mark.parametrize("folder,prefix,every", CASES, ids=IDS)
def test_checkpointed_and_resumed_run_is_bitwise_the_same(tmp_path, monkeypatch, folder, prefix,
                                                          every):
    check_resume_is_bitwise(tmp_path, monkeypatch, lambda at: model_job(at, MODELS / folder, prefix, ""),
                            f"{prefix}_result_prec17.txt", every)


@pytest.mark.parametrize("folder,prefix,every", CASES, ids=IDS)
def test_lmp_replays_the_run_bitwise(tmp_path, folder, prefix, every):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames."""
    check_lmp_replay_is_bitwise(tmp_path, lambda at: model_job(at, MODELS / folder, prefix, ""))
