"""The run pipeline's own rules, without LAMMPS: writers are closed on success and aborted on
failure, the frame schedule is enforced, and the Python API leaves every format choice to
the registry's INPUT hooks."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from fibrelmp.errors import RunError
from fibrelmp.runplan import Rendered
from fibrelmp.pipeline.run import _EXTRA, _scheduled
from fibrelmp.runplan import feed
from fibrelmp.registry import formats

from .conftest import REPO


class Writer:
    def __init__(self, fail_at: int | None = None):
        self.frames, self.state, self.fail_at = [], "open", fail_at

    def add(self, frame) -> None:
        if frame == self.fail_at:
            raise OSError("disk full")
        self.frames.append(frame)

    def close(self) -> Path:
        self.state = "closed"
        return Path("result.txt")

    def abort(self) -> None:
        self.state = "aborted"


class Source:
    def is_frame(self, words):
        return words[0] == "write_dump"

    def read(self, step):
        return step

    def close(self):
        pass


def _rendered(schedule):
    class Job:
        script = Path("in.lammps")
    return Rendered(Job(), "", schedule, [])


def test_feed_closes_on_success_and_aborts_everything_on_failure():
    a, b = Writer(), Writer()
    assert feed([a, b])(iter([1, 2])) == [Path("result.txt"), Path("result.txt")]
    assert (a.state, b.state, b.frames) == ("closed", "closed", [1, 2])
    a, b = Writer(), Writer(fail_at=2)
    with pytest.raises(OSError):
        feed([a, b])(iter([1, 2, 3]))
    assert (a.state, b.state) == ("aborted", "aborted")


def test_frame_schedule_missing_and_extra_frames_are_run_errors():
    # the schedule is what the tokens (one per frame LAMMPS wrote) did not take
    assert list(_scheduled(iter([0, 10]), Source(), iter([]), _rendered([0, 10]))) == [0, 10]
    writer = Writer()
    with pytest.raises(RunError, match="without the frame of step 10"):
        feed([writer])(_scheduled(iter([0]), Source(), iter([10]), _rendered([0, 10])))
    assert writer.state == "aborted"
    with pytest.raises(RunError, match="more frames than the 1 scheduled"):
        list(_scheduled(iter([0, _EXTRA]), Source(), iter([]), _rendered([0])))


def test_python_api_has_no_format_branches():
    tree = ast.parse((REPO / "fibrelmp" / "python_api.py").read_text())
    names = {f.name for f in formats()}
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            assert not any(isinstance(c, ast.Constant) and c.value in names for c in node.comparators)
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            assert node.value not in names, node.value


def test_a_writer_failing_at_the_end_leaves_no_output_of_the_others(tmp_path):
    """``feed`` prepares every writer (their last files written) before renaming any file into
    place: the last writer failing in ``finish`` leaves nothing of the first one."""
    from fibrelmp.formatbase import Writer
    from fibrelmp.runplan import feed

    class Lines(Writer):
        def write(self, frame) -> None:
            self.put(self.target, f"{frame}\n".encode())

    class FailsAtTheEnd(Lines):
        def finish(self) -> None:
            raise ValueError("cannot finish")

    first, second = Lines(tmp_path / "a.txt"), FailsAtTheEnd(tmp_path / "b.txt")
    with pytest.raises(ValueError, match="cannot finish"):
        feed([first, second])(iter([1, 2, 3]))
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    ok = Lines(tmp_path / "c.txt")
    assert feed([ok])(iter([1, 2])) == [tmp_path / "c.txt"]
    assert (tmp_path / "c.txt").read_text() == "1\n2\n"
