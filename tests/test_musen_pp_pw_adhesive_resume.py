"""Checkpoint + resume in the middle of a contact and ``lmp -in`` replay are bitwise for the
laws of pair_style musen/pp (hertz, whose history is MUSEN's tangential force; jkr,
popov/jkr; simple/viscoelastic) and the wall laws jkr, popov/jkr (the references of
tests/test_pp_hertz_simple_viscoelastic.py, test_pp_jkr.py, test_pw_jkr.py)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fibrelmp import python_api
from fibrelmp._lammps import lmp_executable_env

from .conftest import data_path
from .musen_model_checks import model_job, run_cut_and_resumed, styles_or_skip

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
    styles_or_skip()
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    python_api.run(model_job(whole, MODELS / folder, prefix, ""), work=whole / "work")
    run_cut_and_resumed(monkeypatch, model_job(cut, MODELS / folder, prefix, ""), cut / "work",
                        every)
    name = f"{prefix}_result_prec17.txt"
    assert (cut / name).read_bytes() == (whole / name).read_bytes()


@pytest.mark.parametrize("folder,prefix,every", CASES, ids=IDS)
def test_lmp_replays_the_run_bitwise(tmp_path, folder, prefix, every):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames."""
    styles_or_skip()
    lmp = Path(sys.executable).parent / "lmp"
    if not lmp.exists():
        pytest.skip(f"no lmp executable next to {sys.executable}")
    python_api.run(model_job(tmp_path, MODELS / folder, prefix, ""), work=tmp_path / "work")
    ran, replay = tmp_path / "work" / "job2", tmp_path / "replay"
    shutil.copytree(ran, replay)
    (replay / "frames.dump").unlink()
    proc = subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none",
                           "-nocite"], cwd=replay, env=lmp_executable_env(), capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert (replay / "frames.dump").read_bytes() == (ran / "frames.dump").read_bytes()
