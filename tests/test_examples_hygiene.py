"""Running the examples leaves the clone clean, and the tests never see what running them
left there (issue 24: the README's main job, then pytest, failed two tests)."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

import fibrelmp

from .conftest import REPO, copy_example


def _git(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["git", "-C", str(REPO), *args], capture_output=True, text=True,
                          timeout=30)


@pytest.fixture(autouse=True)
def _needs_git():
    if _git("rev-parse", "--git-dir").returncode != 0:
        pytest.skip("not a git checkout")


@pytest.mark.parametrize("folder, name", [("examples/fibre_network", "input.txt"),
                                          ("examples/demdf", "head_on.json")])
def test_what_an_example_run_writes_is_ignored_by_git(tmp_path, folder, name):
    """Run the example in a copy; every file and folder it added, placed in examples/, is
    one git ignores (so `git status` stays clean after the README's jobs)."""
    copy = copy_example(folder, tmp_path / "copy")
    before = {p.relative_to(copy) for p in copy.rglob("*")}
    fibrelmp.run(copy / name)
    added = {p.relative_to(copy) for p in copy.rglob("*")} - before
    tops = sorted({Path(p.parts[0]) for p in added})
    assert tops
    names = [f"{folder}/{p}" + ("/" if (copy / p).is_dir() else "") for p in tops]
    ignored = _git("check-ignore", "--no-index", *names).stdout.split()
    assert sorted(ignored) == sorted(names)


def test_tests_copy_only_tracked_example_files():
    """No test copies an examples folder wholesale (results of earlier runs would come
    along): they use conftest.copy_example; and no build product is tracked."""
    wholesale = re.compile(r"copytree\(\s*(REPO\s*/\s*[\"']examples|EXAMPLES?\b|source\.parent)")
    offenders = [p.name for p in (REPO / "tests").glob("*.py") if wholesale.search(p.read_text())]
    assert offenders == []
    tracked = _git("ls-files", "fibrelmp").stdout.split()
    assert not [p for p in tracked if p.endswith((".so", ".dylib", ".pyd"))]
