"""Two ``fibrelmp.run`` calls in two threads (issue 24): both correct, and the process's
working directory is never the job folder for the caller's other threads."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import fibrelmp
from fibrelmp.runner import Progress

from .conftest import REPO, copy_example


def _inputs(root: Path) -> list[Path]:
    fn = copy_example("examples/fibre_network", root / "fn") / "input.txt"
    demdf = root / "demdf"
    demdf.mkdir()
    (demdf / "head_on.json").write_bytes((REPO / "examples" / "demdf" / "head_on.json").read_bytes())
    return [fn, demdf / "head_on.json"]


def _results(result) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in result.outputs}


def test_two_runs_in_two_threads_are_both_right_and_leave_the_cwd_alone(tmp_path, monkeypatch):
    alone = [fibrelmp.run(path) for path in _inputs(tmp_path / "alone")]      # one at a time
    monkeypatch.chdir(tmp_path)
    cwd = os.getcwd()
    paths = _inputs(tmp_path / "together")
    done: dict[int, object] = {}

    # between two LAMMPS commands of a run, the runner's thread asks a thread of the caller
    # (started before the runs) where it is, and waits for the answer
    ask, answered = threading.Event(), threading.Event()
    views: dict[str, str] = {}
    advance = Progress.advance

    def advance_and_ask(self, steps: int) -> None:
        if not ask.is_set():
            views["run"] = os.getcwd()
            ask.set()
            answered.wait(30)
        advance(self, steps)

    def observe() -> None:
        ask.wait(60)
        views["caller"] = os.getcwd()
        answered.set()

    monkeypatch.setattr(Progress, "advance", advance_and_ask)
    observer = threading.Thread(target=observe)
    observer.start()

    def run(k: int) -> None:
        try:
            done[k] = fibrelmp.run(paths[k])
        except BaseException as exc:        # reported below
            done[k] = exc

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    seen = set()
    while any(t.is_alive() for t in threads):
        seen.add(os.getcwd())               # this thread's view while both runs go on
        time.sleep(0.0005)
    for t in threads + [observer]:
        t.join()
    assert views["run"].endswith("_work") and views["caller"] == cwd, views
    assert seen == {cwd}
    for k in range(2):
        assert not isinstance(done[k], BaseException), repr(done[k])
        assert _results(done[k]) == _results(alone[k])      # byte for byte the lone run's files
    assert os.getcwd() == cwd
