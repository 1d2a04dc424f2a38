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


# what a build, an editable install, a test run or an example run leaves behind
BUILD_PRODUCT = re.compile(r"(\.(so|dylib|pyd|dll|o|obj|a|pyc|pyo|whl)$|(^|/)(__pycache__|build|dist|"
                           r"\.pytest_cache|\.venv|\.ci-venv|_lib)/|\.egg-info/|_work/)")


def test_no_build_product_is_tracked_and_gitignore_names_them():
    """Issue 25: the numtext C extension was tracked, under a path .gitignore no longer named."""
    tracked = _git("ls-files", "-z").stdout.split("\0")
    assert [p for p in tracked if BUILD_PRODUCT.search(p)] == []
    samples = ["fibrelmp/numtext/_fastparse_c.cpython-311-x86_64-linux-gnu.so",
               "fibrelmp/lammps_styles/_lib/fibrelmp_styles.so", "fibrelmp/__pycache__/cli.cpython-311.pyc",
               "build/lib/fibrelmp/cli.py", "fibrelmp.egg-info/PKG-INFO", "x_work/in.lammps"]
    ignored = _git("check-ignore", "--no-index", *samples).stdout.split()
    assert ignored == samples


def test_no_data_file_is_stored_twice():
    """Issue 25: examples/musen kept a second copy of a 4 MB test scene; the example links to
    the one in tests/data.  Files of 64 kB or more with the same content are duplicates (small
    ones may repeat where a folder must stand alone: a licence beside the files it covers, the
    5 kB model.txt of each run of a real FibreNet case)."""
    entries = _git("ls-files", "-s", "-z").stdout.split("\0")
    by_blob: dict[str, list[str]] = {}
    for entry in filter(None, entries):
        meta, path = entry.split("\t", 1)
        mode, blob = meta.split()[:2]
        if mode != "120000" and (REPO / path).stat().st_size >= 65536:     # 120000: a link
            by_blob.setdefault(blob, []).append(path)
    assert [paths for paths in by_blob.values() if len(paths) > 1] == []
