"""``post`` conversion, whatever the target: a FIFO is refused, warnings reach the caller."""

from __future__ import annotations

import os
import re

import pytest

from fibrelmp import registry
from fibrelmp.errors import InputError
from fibrelmp.python_api import convert
from fibrelmp.registry import TARGET

from .base import dump_text


def test_fifo_trajectory_is_refused_not_waited_for(tmp_path):
    fifo = tmp_path / "frames.dump"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        convert(fifo, registry.names(TARGET)[0], tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_convert_reports_warnings_to_the_caller(tmp_path):
    text, _ = dump_text()
    dump = tmp_path / "notime.dump"
    dump.write_text(re.sub(r"ITEM: TIME\n[^\n]*\n", "", text))
    got: list = []
    convert(dump, "vtk", tmp_path / "out" / "run", warn=got.extend)
    assert any(kind == "no times" for kind, _ in got), got
