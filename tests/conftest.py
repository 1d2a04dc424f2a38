import os
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
