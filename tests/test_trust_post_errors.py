"""Errors users can trust: a wrong atom count in the middle of a dump is an error naming the
frame (only the real end of the file truncates), ``--types`` that selects nothing is an
error, control characters in messages are shown escaped, a directory where a file is
expected is said to be one, and a full disk names the output and leaves no temp file."""

from __future__ import annotations

import builtins
import errno
import os
from pathlib import Path

import pytest
from typer.testing import CliRunner

from fibrelmp import textio
from fibrelmp.cli import app
from fibrelmp.errors import InputError, RunError
from fibrelmp.translate.fibrenet.writer import XyzWriter, read_xyz
from fibrelmp.post.lammps_dump.reader import iter_frames, iter_headers

from .test_post_robust import ROWS, frame, write
from .conftest import copy_example

REPO = Path(__file__).resolve().parents[1]
ENOSPC = os.strerror(errno.ENOSPC)          # "No space left on device"


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def errors(result) -> list[str]:
    return [ln for ln in result.stderr.splitlines() if ln.startswith(("error: ", "run failed: "))]


def files(folder: Path) -> list[str]:
    """Every file and folder below ``folder`` (hidden temp files included)."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


# ------------------------------------------------------------- 1. wrong counts, --types
def miscounted(step: int, says: int) -> str:
    """A frame of ROWS (3 atom lines) whose NUMBER OF ATOMS says ``says``."""
    return frame(step, ROWS).replace("NUMBER OF ATOMS\n3\n", f"NUMBER OF ATOMS\n{says}\n")


FRAME_LINES = len(frame(0, ROWS).splitlines())          # 12: 9 header lines + 3 atoms


@pytest.mark.parametrize("says,line,message", [
    # more than the rest of the file holds: was taken for a truncated last frame (exit 0)
    (50, 2 * FRAME_LINES + 1, "frame has 3 atom lines but NUMBER OF ATOMS says 50 "
                              "(frame 1: step 10, from line 13)"),
    # one more than there are: the next frame's ITEM: TIMESTEP fell into the atom block
    (4, 2 * FRAME_LINES + 1, "frame has 3 atom lines but NUMBER OF ATOMS says 4 "
                             "(frame 1: step 10, from line 13)"),
    # one less: the third atom line is met where the next frame should start
    (2, 2 * FRAME_LINES, "(more atom lines than NUMBER OF ATOMS 2 of frame 1: step 10, "
                         "from line 13?)"),
])
def test_wrong_atom_count_in_a_middle_frame_is_an_error_naming_the_frame(tmp_path, says, line,
                                                                         message):
    p = write(tmp_path, frame(0, ROWS) + miscounted(10, says) + frame(20, ROWS) + frame(30, ROWS))
    for read in (lambda w: list(iter_frames(p, w)),                         # parsing every frame
                 lambda w: list(iter_headers(p, w, want=lambda i, h: False))):  # --info, counting
        warnings: list = []
        with pytest.raises(InputError) as err:
            read(warnings)
        assert (err.value.path, err.value.line) == (str(p), line)
        assert message in err.value.message
        assert warnings == []
    out = tmp_path / "out"
    for to, extra in (("xyz", ()), ("xyz", ("--frames", "-1")), ("xyz", ("--info",)),
                      ("res", ())):          # res: every block kept unparsed but the last
        result = invoke("post", p, "--to", to, "-o", out / "o", *extra)
        assert result.exit_code == 2, result.stderr
        (error,) = errors(result)
        assert error.startswith(f"error: {p}:{line}: ") and message in error
        assert "truncated" not in result.stderr
        assert not out.exists()


def test_an_item_line_among_atom_lines_is_named_whatever_the_column_count(tmp_path):
    # two columns: 'ITEM: TIMESTEP' has as many tokens as an atom line
    rows = [(1, 1), (2, 1)]
    text = frame(0, rows, cols="id type").replace("NUMBER OF ATOMS\n2\n", "NUMBER OF ATOMS\n3\n")
    p = write(tmp_path, text + frame(5, rows, cols="id type"))
    with pytest.raises(InputError) as err:
        list(iter_frames(p, []))
    assert err.value.line == 12
    assert err.value.message == ("frame has 2 atom lines but NUMBER OF ATOMS says 3 "
                                 "(frame 0: step 0, from line 1)")


def test_only_the_real_end_of_the_file_truncates(tmp_path):
    # the last frame says 50 and the file ends: truncation, earlier frames kept
    p = write(tmp_path, frame(0, ROWS) + frame(10, ROWS) + miscounted(20, 50))
    warnings: list = []
    assert [f.step for f in iter_frames(p, warnings)] == [0, 10]
    assert [k for k, _ in warnings] == ["truncated dump"]
    result = invoke("post", p, "--to", "xyz", "-o", tmp_path / "o")
    assert result.exit_code == 0, result.stderr
    assert [f.step for f in read_xyz(tmp_path / "o_coord.xyz")] == [0, 10]


def test_types_that_match_no_atom_are_an_error_and_nothing_is_written(tmp_path):
    rows = [r + (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]     # types 1 and 2
    p = write(tmp_path, frame(0, rows, cols="id type x y z vx vy vz fx fy fz radius mass", time=0.0)
              + frame(10, rows, cols="id type x y z vx vy vz fx fy fz radius mass", time=0.1))
    out = tmp_path / "out"
    for to in ("xyz", "res", "vtk", "mercury", "musen", "demdf"):
        result = invoke("post", p, "--to", to, "--types", "7,9", "-o", out / "o")
        assert result.exit_code == 2, (to, result.stderr)
        assert errors(result) == [f"error: {p}: --types 7, 9: no atom of the selected frames has "
                                  "these types (types present: 1, 2); nothing written"], to
        assert not out.exists(), (to, files(tmp_path))
    # a type present in one frame only is fine (the others are written empty)
    p2 = write(tmp_path, frame(0, ROWS) + frame(10, [(4, 3, 1.0, 1.0, 1.0)]), "b.dump")
    result = invoke("post", p2, "--to", "xyz", "--types", "3", "-o", tmp_path / "x")
    assert result.exit_code == 0, result.stderr
    assert [len(f.names) for f in read_xyz(tmp_path / "x_coord.xyz")] == [0, 1]


# ------------------------------------------------------------- 2. control characters
def test_control_characters_in_errors_are_shown_escaped():
    err = InputError("in\rput\x1b[2J.txt", 3, "got 'a\rb' \x1b[31mred\x1b[0m\x07 \u202etxt.exe")
    assert str(err) == ("in\\rput\\x1b[2J.txt:3: got 'a\\rb' \\x1b[31mred\\x1b[0m\\x07 "
                        "\\u202etxt.exe")
    assert err.message == "got 'a\rb' \x1b[31mred\x1b[0m\x07 \u202etxt.exe"      # raw text kept
    assert str(InputError(None, None, "a\nb\x00c\x9b")) == "<input>: a\\nb\\x00c\\x9b"
    # ordinary text is unchanged: tabs, non-ASCII, backslashes of Windows paths
    plain = "C:\\runs\\modèle.txt: 5 µm\tÅ ≥ 0 'x'"
    assert str(InputError(plain, 2, plain)) == f"{plain}:2: {plain}"
    assert str(RunError("out.xyz: \x1b[2Jgone\rover\nline 2")) == \
        "out.xyz: \\x1b[2Jgone\\rover\nline 2"          # a multi-line message keeps its lines


def test_cli_error_line_from_a_file_name_with_control_characters(tmp_path):
    p = write(tmp_path, "hello\n", "bad\rname\x1b[2J.dump")
    result = invoke("post", p, "--to", "xyz", "-o", tmp_path / "o")
    assert result.exit_code == 2
    assert "\r" not in result.stderr and "\x1b" not in result.stderr
    assert "bad\\rname\\x1b[2J.dump:1: not a LAMMPS text dump" in result.stderr


# ------------------------------------------------------------- 3. a directory for a file
def test_read_text_says_a_directory_is_a_directory(tmp_path):
    (tmp_path / "d").mkdir()
    with pytest.raises(InputError) as err:
        textio.read_text(tmp_path / "d", "model file")
    assert err.value.message == "model file is a directory, expected a file"
    with pytest.raises(InputError, match="model file not found"):
        textio.read_text(tmp_path / "nope", "model file")
    (tmp_path / "f").write_text("x")
    with pytest.raises(InputError, match="model file not found"):
        textio.read_text(tmp_path / "f" / "below", "model file")      # a file as a folder


def test_directories_named_by_inputs_are_reported_as_directories(tmp_path):
    # FibreNet: model_file names a directory
    fn = tmp_path / "fn"
    copy_example("examples/fibre_network", fn)
    (fn / "model.txt").unlink()
    (fn / "model.txt").mkdir()
    result = invoke("check", fn / "input.txt")
    assert result.exit_code == 2
    assert errors(result) == [f"error: {fn / 'model.txt'}: FibreNet model file is a directory, "
                              "expected a file"]
    # cmusen script: SOURCE_FILE names a directory
    ms = tmp_path / "ms"
    (ms / "scene.txt").mkdir(parents=True)
    (ms / "job.txt").write_text("JOB\nSOURCE_FILE scene.txt\nRESULT_FILE r.txt\n"
                                "COMPONENT SIMULATOR\nEND_TIME 0.01\n")
    result = invoke("check", ms / "job.txt")
    assert result.exit_code == 2
    assert errors(result) == [f"error: {ms / 'scene.txt'}: MUSEN text file is a directory, "
                              "expected a file"]
    # post: the dump and --data
    (tmp_path / "frames.dump").mkdir()
    result = invoke("post", tmp_path / "frames.dump", "--to", "xyz", "-o", tmp_path / "x")
    assert result.exit_code == 2 and "is a directory, expected a LAMMPS dump file" in result.stderr
    p = write(tmp_path, frame(0, ROWS))
    result = invoke("post", p, "--to", "xyz", "-o", tmp_path / "x", "--data", tmp_path / "fn")
    assert result.exit_code == 2
    assert errors(result) == [f"error: {tmp_path / 'fn'}: LAMMPS data file is a directory, "
                              "expected a file"]


# ------------------------------------------------------------- 4. a full disk
class _FullDisk:
    """A file whose writes fail as on a full disk (the file itself was created)."""

    def __init__(self, fh):
        self.fh = fh

    def write(self, data):
        raise OSError(errno.ENOSPC, ENOSPC)

    def close(self):
        self.fh.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __getattr__(self, name):
        return getattr(self.fh, name)


@pytest.fixture
def full_disk(monkeypatch):
    """Every file opened for writing fails to write; reading works."""
    real_open = builtins.open

    def fake_open(file, mode="r", *args, **kwargs):
        fh = real_open(file, mode, *args, **kwargs)
        return _FullDisk(fh) if any(c in mode for c in "wax+") else fh

    monkeypatch.setattr(builtins, "open", fake_open)


def test_atomic_write_on_a_full_disk_names_the_output_and_leaves_no_temp_file(tmp_path, full_disk):
    target = tmp_path / "out.json"
    for data in ("text", b"bytes"):
        with pytest.raises(RunError) as err:
            textio.atomic_write(target, data)
        assert str(err.value) == f"{target}: cannot write output: {ENOSPC}"
        assert files(tmp_path) == []


def test_atomic_write_failing_rename_leaves_no_temp_file(tmp_path, monkeypatch):
    def no_space(src, dst):
        raise OSError(errno.ENOSPC, ENOSPC)
    monkeypatch.setattr(os, "replace", no_space)
    with pytest.raises(RunError, match=f"out.vtu: cannot write output: {ENOSPC}"):
        textio.atomic_write(tmp_path / "out.vtu", "x")
    assert files(tmp_path) == []


def test_xyz_writer_on_a_full_disk(tmp_path, monkeypatch, full_disk):
    import numpy as np

    from fibrelmp.translate.fibrenet.writer import XyzFrame

    w = XyzWriter(tmp_path / "o", fields=("position",))
    with pytest.raises(RunError) as err:
        w.add(XyzFrame(0, 0.1, np.ones(3), ["a"], np.zeros((1, 3))))
    assert str(err.value) == f"{tmp_path / 'o_coord.xyz'}: cannot write output: {ENOSPC}"
    w.abort()                               # what the callers do next: harmless
    assert files(tmp_path) == []
    monkeypatch.undo()                      # a working disk again ...
    # ... and the rename failing at close
    w = XyzWriter(tmp_path / "o", fields=("velocity",))
    monkeypatch.setattr(os, "replace", lambda a, b: (_ for _ in ()).throw(OSError(errno.ENOSPC, ENOSPC)))
    with pytest.raises(RunError, match=f"o_vel.xyz: cannot write output: {ENOSPC}"):
        w.close()
    assert files(tmp_path) == []


@pytest.mark.parametrize("to,output", [("xyz", "o_coord.xyz"), ("res", "o_restart.res"),
                                       ("vtk", "o_000000.vtp"), ("musen", "o.txt"),
                                       ("demdf", "o_0.json"), ("mercury", "o")])
def test_post_on_a_full_disk_names_the_output_and_leaves_nothing(tmp_path, full_disk, to, output):
    rows = [r + (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]
    cols = "id type x y z vx vy vz fx fy fz radius mass"
    p = write(tmp_path, frame(0, rows, cols=cols, time=0.0) + frame(10, rows, cols=cols, time=0.1))
    out = tmp_path / "out"
    result = invoke("post", p, "--to", to, "-o", out / "o")
    assert result.exit_code == 1, result.stderr
    assert errors(result) == [f"run failed: {out / output}: cannot write output: {ENOSPC}"]
    assert "Errno" not in result.stderr
    assert files(tmp_path) == ["d.dump"]        # no output, temp file, staging or new folder


def test_musen_result_writer_on_a_full_disk(tmp_path, monkeypatch):
    """The writer ``fibrelmp run`` uses: the temp file and the spool are removed."""
    from fibrelmp.translate.musen import writer as musen_out

    from .test_post_roundtrip import post

    rows = [r + (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]
    cols = "id type x y z vx vy vz fx fy fz radius mass"
    p = write(tmp_path, frame(0, rows, cols=cols, time=0.0) + frame(10, rows, cols=cols, time=0.1))
    made = []
    real_finish = musen_out.MusenResultWriter.finish

    def finish(self):                       # the result is written at close, then renamed
        made.append(self)
        monkeypatch.setattr(os, "replace", lambda a, b: (_ for _ in ()).throw(
            OSError(errno.ENOSPC, ENOSPC)))
        return real_finish(self)
    monkeypatch.setattr(musen_out.MusenResultWriter, "finish", finish)
    with pytest.raises(RunError, match=f"/o.txt: cannot write output: {ENOSPC}$"):
        post(p, "musen", tmp_path / "o")
    assert made and not made[0].tmp.exists() and not made[0].spool.exists()
    assert files(tmp_path) == ["d.dump"]
