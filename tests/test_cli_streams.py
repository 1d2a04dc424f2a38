"""What goes where (issue 24): results, wrote lines and the run summary on stdout (so
``fibrelmp run ... > log`` keeps them), progress and warnings on stderr; a numbered series
of result files is one ``wrote`` line; ``-v`` lists every warning the summary counts; the
MPI rank advice says "1 sphere" and never "0 per rank"."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys

from typer.testing import CliRunner

import fibrelmp
from fibrelmp import python_api
from fibrelmp.cli import app
from fibrelmp.sanity import rank_check

from .conftest import REPO

EXAMPLE = REPO / "examples" / "demdf" / "head_on.json"


def test_run_prints_results_on_stdout_and_progress_on_stderr(tmp_path):
    """head_on.json saves 9 snapshots head_on_0..8.json: one wrote line for them."""
    shutil.copy(EXAMPLE, tmp_path)
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", str(tmp_path / "head_on.json"),
                           "--log-every", "50%"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    snapshots = sorted(tmp_path.glob("head_on_*.json"), key=lambda p: int(p.stem.split("_")[-1]))
    assert len(snapshots) == 9
    wrote = [ln for ln in proc.stdout.splitlines() if ln.startswith("wrote ")]
    assert wrote == [f"wrote {snapshots[0]} .. {snapshots[-1].name} (9 files)"]
    assert "summary of" in proc.stdout and "done in" in proc.stdout
    assert "progress:" in proc.stderr and "progress:" not in proc.stdout
    for said in ("wrote ", "summary of", "done in"):
        assert said not in proc.stderr


def test_post_and_check_report_on_stdout(tmp_path):
    folder = tmp_path / "run"
    done = python_api.run(EXAMPLE, folder)
    runner = CliRunner()
    post = runner.invoke(app, ["post", str(done.dumps[0]), "--to", "xyz", "-o", str(tmp_path / "a")])
    assert post.exit_code == 0, post.stderr
    assert re.search(r"(?m)^wrote .*a_coord\.xyz$", post.stdout) and "wrote" not in post.stderr
    check = runner.invoke(app, ["check", str(EXAMPLE)])
    assert check.exit_code == 0 and "warnings     " in check.stdout


def test_verbose_lists_every_warning_the_summary_counts(tmp_path, monkeypatch):
    """Two warnings of one kind: the summary says '(2)'; -v shows both texts."""
    done = python_api.run(EXAMPLE, tmp_path)
    texts = ["first of the kind", "second of the kind"]
    done.warnings = [("demo", t) for t in texts]
    done.summaries[0]["warnings"] = {"demo": 2}
    monkeypatch.setattr(python_api, "run", lambda *a, **k: done)
    plain = CliRunner().invoke(app, ["run", str(EXAMPLE)])
    assert plain.exit_code == 0, plain.stderr
    assert "demo (2)" in plain.stdout and texts[1] not in plain.stdout
    verbose = CliRunner().invoke(app, ["run", str(EXAMPLE), "-v"])
    assert verbose.exit_code == 0, verbose.stderr
    assert all(f"  [demo] {t}" in verbose.stdout for t in texts)


def test_rank_advice_grammar():
    model = fibrelmp.read(REPO / "examples" / "demdf" / "drop_on_wall.json")
    assert model.spheres.count == 1
    rank_check(model, 2)
    text = [t for kind, t in model.warnings if kind == "ranks"][0]
    assert "2 MPI ranks for 1 sphere (fewer than one per rank)" in text
    assert "0 per rank" not in text and "1 spheres" not in text
