import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
# Reference files that may be redistributed, copied unchanged into the repository
# (provenance and licences: tests/data/README.md).
DATA = Path(__file__).resolve().parent / "data"
# The developers' folder next to the checkout; FIBRELMP_SHARED points elsewhere (CI, or a
# non-existent path to check what a fresh clone runs).
SHARED = Path(os.environ.get("FIBRELMP_SHARED") or REPO.parent / "shared")


def data_path(*parts: str) -> Path:
    """A reference file kept in tests/data (or, failing that, in the shared folder).

    These files are part of the repository, so a missing one is an error, not a skip."""
    for root in (DATA, SHARED):
        path = root.joinpath(*parts)
        if path.exists():
            return path
    pytest.fail(f"reference data missing: {DATA.joinpath(*parts)} (it belongs to the repository; "
                f"also looked in {SHARED})", pytrace=False)


def shared_path(*parts: str) -> Path:
    """A file that only the shared folder holds because its licence does not allow copying it
    into the repository (the DEMDF examples); skips with the reason when it is absent."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"not in the repository (no licence to redistribute it) and the shared folder "
                    f"does not have it: {path}; set FIBRELMP_SHARED to a folder holding "
                    f"{Path(*parts)}")
    return path


def copy_example(folder: str | Path, dest: Path) -> Path:
    """Copy the example inputs of ``folder`` (relative to the repository, e.g.
    ``examples/fibre_network``) to ``dest``: only the files git tracks there, so results that
    running the examples left in the clone (README's main job) never reach a test."""
    source = REPO / folder
    try:
        listed = subprocess.run(["git", "-C", str(REPO), "ls-files", "-z", "--", str(source)],
                                capture_output=True, check=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        listed = b""
    tracked = [REPO / name for name in listed.decode().split("\0") if name]
    if not tracked:
        # not a git checkout (an unpacked sdist holds the inputs only)
        shutil.copytree(source, dest)
        return dest
    for path in tracked:
        target = dest / path.relative_to(source)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(path, target)
    return dest


def styles_or_skip() -> Path:
    """fibrelmp's compiled LAMMPS styles (the plugin library), else the test is skipped."""
    from fibrelmp import lammps_styles

    found = lammps_styles.plugin()
    if not found.available:
        pytest.skip(f"fibrelmp's LAMMPS styles are not available: {found.how}")
    return found.path


@pytest.fixture(scope="module")
def plugin_path() -> str:
    """styles_or_skip() as a fixture (a str)."""
    return str(styles_or_skip())
