"""Runs that cannot finish are refused before anything is written (issue 24): exit 2 with
the figures, nothing created.  Each run is a subprocess under a memory limit and a timeout,
so a regression (a job rendered with billions of pieces) fails instead of eating the machine."""

from __future__ import annotations

import json
import resource
import shutil
import subprocess
import sys

import pytest

from fibrelmp.sanity import LONGEST_RUN_SECONDS, run_budget

from .conftest import REPO, copy_example

MEMORY = 2 * 1024 ** 3


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def _refused(folder, *args: str) -> str:
    before = sorted(p.name for p in folder.rglob("*"))
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", *args], cwd=folder,
                          capture_output=True, text=True, timeout=120, preexec_fn=_limited)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in folder.rglob("*")) == before        # nothing written
    return proc.stderr


def _fibrenet(tmp_path, **settings: str):
    folder = copy_example("examples/fibre_network", tmp_path / "fn")
    text = (folder / "input.txt").read_text()
    for key, value in settings.items():
        lines = [ln for ln in text.splitlines() if ln.split()[:1] != [key]]
        text = "\n".join(lines + [f"{key}\t{value}"]) + "\n"
    (folder / "input.txt").write_text(text)
    return folder


def test_fibrenet_frame_every_step_for_2e9_steps_is_refused_for_disk_space(tmp_path):
    """2e9 steps with a frame each: 2e9+1 frames of 128 beads, >= 16 TB of work dump."""
    folder = _fibrenet(tmp_path, run="2000000000", output_freq="1")
    err = _refused(folder, "input.txt")
    assert "the run would write about 16.7 TB (2000000001 saved frames)" in err
    assert "free" in err and "--yes-i-mean-it" in err


def test_fibrenet_2e9_minimisation_chunks_are_refused_for_time(tmp_path):
    """minimize_steps 2e18 in chunks of 1e9 (2e9 chunks): 2e18 steps, decades at any speed
    (this job was once rendered as 1e9 LAMMPS run pieces: 23 GB and no end)."""
    folder = _fibrenet(tmp_path, minimize_steps="2000000000000000000",
                       minimize_substeps="1000000000")
    err = _refused(folder, "input.txt", "--yes-i-mean-it")        # not even with the override
    assert "the run has 2000000000000002000 time steps" in err and "years" in err


def test_demdf_1e9_saves_are_refused_for_disk_space(tmp_path):
    """1e9 saves: 1e9 snapshot files (a disk block each) and 1e9 dump frames, > 4 TB."""
    spec = json.loads((REPO / "examples" / "demdf" / "head_on.json").read_text())
    spec["output"]["snapshot"]["savePeriodInTime"] = spec["timeEnd"] / 1e9
    (tmp_path / "many.json").write_text(json.dumps(spec))
    err = _refused(tmp_path, "many.json")
    assert "the run would write about 4.37 TB (1000000001 saved frames)" in err


def test_step_counts_lammps_cannot_hold_are_refused(tmp_path):
    """More steps than LAMMPS's 64-bit counter (relaxation + production, each within 64
    bits); a loop of more than 2^31-1 frames (DEMDF,
    3e9 saves: 'variable ... loop 3000000000' is not a LAMMPS integer)."""
    folder = _fibrenet(tmp_path, run="9000000000000000000", minimize_steps="9000000000000000000",
                       minimize_substeps="1000000000")
    err = _refused(folder, "input.txt", "--yes-i-mean-it")
    assert "the run has 18000000000000000000 time steps; LAMMPS counts at most 9223372036854775807" in err
    spec = json.loads((REPO / "examples" / "demdf" / "head_on.json").read_text())
    spec["output"]["snapshot"]["savePeriodInTime"] = spec["timeEnd"] / 3e9
    (tmp_path / "loop.json").write_text(json.dumps(spec))
    err = _refused(tmp_path, "loop.json", "--yes-i-mean-it")
    assert "more than the 2147483647 (2^31-1) LAMMPS takes there" in err


def test_the_override_skips_the_estimates_only(tmp_path):
    """run_budget with allow_huge: no disk or time refusal (the same job is refused without)."""
    import fibrelmp
    from fibrelmp.errors import InputError
    from fibrelmp.translate.fibrenet.plan import render
    from fibrelmp.translate.fibrenet.input import fibrenet_outputs

    folder = _fibrenet(tmp_path, run="2000000000", output_freq="1")
    model = fibrelmp.read(folder / "input.txt")
    outputs, _, _ = fibrenet_outputs(model, None, None)
    job = render(model)(outputs.work, False)
    run_budget([(model, job)], outputs, 1, allow_huge=True)
    try:
        run_budget([(model, job)], outputs, 1, allow_huge=False)
    except InputError as exc:
        assert "16.7 TB" in str(exc)
    else:
        raise AssertionError("not refused")
    assert LONGEST_RUN_SECONDS == 30 * 86400
    assert shutil.disk_usage(tmp_path).free < 16.7e12        # the refusal above is real


def test_one_step_minimisation_chunks_are_warned_or_refused_by_their_run_count(tmp_path):
    """2e9 minimisation chunks of one step each: every chunk is a LAMMPS 'run' that sets the
    system up again (0.44 ms measured here), so 2e9 of them take days however few steps they
    hold.  Was: accepted silently (a progress ETA of 10 days).  Now warned ('long run') above a
    day at 1e4 runs/s, refused above 30 days unless --yes-i-mean-it."""
    import fibrelmp
    from fibrelmp.errors import InputError
    from fibrelmp.sanity import check_steps, long_run_check, planned_runs

    folder = _fibrenet(tmp_path, minimize_steps="2000000000", minimize_substeps="1",
                       minimize_reset="yes")
    model = fibrelmp.read(folder / "input.txt")
    assert planned_runs(model) == 2_000_000_000 + -(-model.plan.stages[-1].steps // model.plan.stages[-1].chunk)
    check_steps(model, folder / "input.txt", allow_huge=False)          # 2.3 days: runs
    long_run_check(model)
    assert [k for k, _ in model.warnings].count("long run") == 1
    said = dict(model.warnings)["long run"]
    assert f"in {planned_runs(model)} LAMMPS runs (chunks): at least 2.34 days" in said
    folder = _fibrenet(tmp_path / "b", minimize_steps="40000000000", minimize_substeps="1")
    model = fibrelmp.read(folder / "input.txt")
    with pytest.raises(InputError, match="46.8 days even at 1e\\+06 steps/s and 1e\\+04 LAMMPS runs"):
        check_steps(model, folder / "input.txt", allow_huge=False)
    check_steps(model, folder / "input.txt", allow_huge=True)
