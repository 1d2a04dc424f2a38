"""Progress of ``fibrelmp run`` (fibrelmp.runner.Progress, tqdm): a bar on a terminal, lines on
stderr without one (``--log-every``), both ending at 100 % and N/N, and after ``--resume`` a
count that starts where the checkpoint was with an ETA from this session's steps only.

The terminal is a pseudo-terminal (``pty.openpty``); runs are the CLI in a subprocess on
examples/fibre_network (2000 steps).  A run is stopped at a checkpoint deterministically by a
driver that makes ``Checkpointing.stop_requested`` report SIGTERM at its Nth call.
"""

from __future__ import annotations

import io
import json
import os
import pty
import re
import select
import subprocess
import sys
import time

import pytest

from fibrelmp.runner import LogEvery, Progress, parse_log_every

from .conftest import REPO, copy_example

CLI = [sys.executable, "-m", "fibrelmp.cli"]
EXAMPLE = REPO / "examples" / "fibre_network"
LINE = re.compile(r"^\[[\d-]+ [\d:]+\] progress: +([\d.]+)% step (\d+)/(\d+), elapsed (\S+), "
                  r"ETA (\S+), +(\S+) step/s$")
STOP_AT = """
import signal, sys
from fibrelmp.checkpoint import Checkpointing
calls = [0]
def stop(self, size):
    calls[0] += 1
    return signal.SIGTERM if calls[0] == {n} else 0
Checkpointing.stop_requested = stop
from fibrelmp.cli import main
sys.argv = ["fibrelmp"] + {args!r}
main()
"""


def _example(tmp_path):
    copy_example(EXAMPLE.relative_to(REPO), tmp_path / "in")
    return tmp_path / "in" / "input.txt"


def _in_pty(args: list[str], cwd) -> tuple[int, str]:
    """Run with stderr (and stdout) on a pseudo-terminal; (exit code, everything it showed)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(args, cwd=cwd, stdin=subprocess.DEVNULL, stdout=slave, stderr=slave)
    os.close(slave)
    chunks = []
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.5)
        if ready:
            try:
                data = os.read(master, 65536)
            except OSError:          # EIO: the child closed the terminal
                break
            if not data:
                break
            chunks.append(data)
        elif proc.poll() is not None:
            break
    os.close(master)
    return proc.wait(timeout=60), b"".join(chunks).decode(errors="replace")


def _lines(stderr: str) -> list[tuple[float, int, int, str, str, str]]:
    found = []
    for line in stderr.splitlines():
        m = LINE.match(line)
        if m:
            pct, n, total, elapsed, eta, rate = m.groups()
            found.append((float(pct), int(n), int(total), elapsed, eta, rate))
    return found


def _stop(tmp_path, inp, out, n: int) -> int:
    """Run to the ``n``th checkpoint test and stop there (SIGTERM's path); the steps done."""
    args = ["-q", "run", str(inp), "-o", str(out)]
    proc = subprocess.run([sys.executable, "-c", STOP_AT.format(n=n, args=args)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 128 + 15, proc.stderr
    return json.loads((out / "fibre_network_work" / "checkpoint.json").read_text())["steps"]


def test_bar_on_a_terminal(tmp_path):
    inp = _example(tmp_path)
    rc, shown = _in_pty(CLI + ["run", str(inp), "-o", str(tmp_path / "out")], tmp_path)
    assert rc == 0, shown
    bars = [s for s in shown.split("\r") if "step/s" in s]
    print(f"\nlast bar: {bars[-1].strip()!r}")
    assert bars and "100%|" in bars[-1] and "2000/2000" in bars[-1]
    assert "1999/2000" not in shown and "progress:" not in shown   # a bar, not lines
    assert "summary of" in shown and "warnings   none" in shown


def test_lines_without_a_terminal(tmp_path):
    inp = _example(tmp_path)
    proc = subprocess.run(CLI + ["run", str(inp), "-o", str(tmp_path / "out"), "--log-every", "25%"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = _lines(proc.stderr)
    print("\n" + "\n".join(ln for ln in proc.stderr.splitlines() if "progress:" in ln))
    assert "\r" not in proc.stderr
    assert lines[0][:3] == (0.0, 0, 2000) and lines[-1][:3] == (100.0, 2000, 2000)
    # a line each time a quarter is passed (the steps advance 40 at a time)
    assert [int(pct // 25) for pct, *_ in lines] == [0, 1, 2, 3, 4]
    assert [n for _, n, *_ in lines] == sorted(n for _, n, *_ in lines)
    assert proc.stdout.count("summary of") == 1 and "summary of" not in proc.stderr
    quiet = subprocess.run(CLI + ["-q", "run", str(inp), "-o", str(tmp_path / "out"), "--force"],
                           cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert quiet.returncode == 0 and quiet.stderr == ""


def test_resumed_run_without_a_terminal(tmp_path):
    inp = _example(tmp_path)
    out = tmp_path / "out"
    done = _stop(tmp_path, inp, out, 4)
    assert 0 < done < 2000
    proc = subprocess.run(CLI + ["run", str(inp), "-o", str(out), "--resume", "--log-every", "10%"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = _lines(proc.stderr)
    print("\n" + "\n".join(ln for ln in proc.stderr.splitlines() if "progress:" in ln))
    assert lines[0][1:3] == (done, 2000) and lines[0][4] == "?"      # no rate yet this session
    assert lines[-1][:3] == (100.0, 2000, 2000)
    summary = json.loads((out / "fibre_network_work" / "summary.json").read_text())
    assert summary["steps"] == {"total": 2000, "this_session": 2000 - done, "resumed_from": done}


def test_resumed_run_on_a_terminal(tmp_path):
    inp = _example(tmp_path)
    out = tmp_path / "out"
    done = _stop(tmp_path, inp, out, 6)
    rc, shown = _in_pty(CLI + ["run", str(inp), "-o", str(out), "--resume"], tmp_path)
    assert rc == 0, shown
    bars = [s.strip() for s in shown.split("\r") if "step/s" in s]
    print(f"\nfirst bar {bars[0]!r}\nlast bar {bars[-1]!r}")
    assert f"{done}/2000" in bars[0]
    assert "100%|" in bars[-1] and "2000/2000" in bars[-1] and "1999/2000" not in shown


def test_eta_after_resume_counts_this_session_only(monkeypatch):
    """1000 of 2000 steps done before; 100 more in 10 s: 10 steps/s, so 900 steps take 90 s
    (counting the resumed steps as done in 10 s would say 110 steps/s and 8 s)."""
    clock = [0.0]
    monkeypatch.setattr("fibrelmp.runner.time.monotonic", lambda: clock[0])
    stream = io.StringIO()
    bar = Progress(2000, True, done=1000, every=LogEvery(percent=None, seconds=10.0), stream=stream)
    clock[0] = 10.0
    bar.advance(100)
    clock[0] = 100.0
    bar.advance(900)
    bar.close()
    lines = _lines(stream.getvalue())
    print("\n" + stream.getvalue())
    assert [ln[:3] for ln in lines] == [(50.0, 1000, 2000), (55.0, 1100, 2000), (100.0, 2000, 2000)]
    assert lines[1][3:] == ("00:10", "01:30", "10.00")
    assert lines[2][3:5] == ("01:40", "00:00")


def test_eta_after_resume_on_a_terminal(monkeypatch):
    """The same on a pseudo-terminal, through tqdm's bar."""
    import tqdm.std

    clock = [0.0]
    monkeypatch.setattr(tqdm.std, "time", lambda: clock[0])
    master, slave = pty.openpty()
    with os.fdopen(slave, "w") as stream:
        bar = Progress(2000, True, done=1000, stream=stream)
        clock[0] = 10.0
        bar.advance(100)
        clock[0] = 100.0
        bar.advance(900)
        bar.close()
    shown = b""
    while select.select([master], [], [], 0.2)[0]:
        try:
            shown += os.read(master, 65536)
        except OSError:              # EIO: everything written was read
            break
    os.close(master)
    bars = [s.strip() for s in shown.decode().split("\r") if "step/s" in s]
    print("\n" + "\n".join(bars))
    assert bars[0].startswith("50%|") and "1000/2000 [00:00<?" in bars[0]
    assert "1100/2000 [00:10<01:30" in bars[1]
    assert bars[-1].startswith("100%|") and "2000/2000 [01:40<00:00" in bars[-1]


@pytest.mark.parametrize("text,want", [("10%", LogEvery(10.0, None)), ("60", LogEvery(None, 60.0)),
                                       ("90s", LogEvery(None, 90.0)), ("5m", LogEvery(None, 300.0)),
                                       ("1h, 2.5%", LogEvery(2.5, 3600.0))])
def test_log_every_values(text, want):
    assert parse_log_every(text) == want


def test_log_every_refuses_nonsense(tmp_path):
    inp = _example(tmp_path)
    for bad in ("0%", "soon", "-5", "10%,20%", "150%"):
        proc = subprocess.run(CLI + ["run", str(inp), "--log-every", bad], cwd=tmp_path,
                              capture_output=True, text=True, timeout=60)
        assert proc.returncode == 2 and ": --log-every" in proc.stderr, (bad, proc.stderr)
        assert "Traceback" not in proc.stderr
    assert not (tmp_path / "in" / "fibre_network_work").exists()       # nothing written
