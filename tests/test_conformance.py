"""Conformance tests every registered format gets (like MDAnalysis's BaseReaderTest /
BaseWriterTest and meshio's write_read): parametrised over ``registry.formats(role)``.

* TARGET (``post --to``): round trip (a synthetic dump -> target -> the target's
  ``read_back`` -> the dump's values within the format's printed precision), bad input (an
  error ``path:line``, nothing written), atomic write (a failure at the 2nd frame leaves no
  file and an earlier output untouched), streaming (add/close/abort, ``with``), force policy.
  A new target gets these for free: it needs ``files``, ``write_frame`` and ``read_back``.
* RESULT (``run``'s native results): atomic write and abort through a small model; the
  fixtures are the one per-format table here (``RESULT_CASES``), checked to cover every
  registered RESULT format.
* FRAMES (``post``'s readers): streaming reads and bad files; sample files per format in
  ``FRAMES_SAMPLES``.
* A toy target registered at run time (tests/csv_target.py) converts through the Python API.
"""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import registry
from fibrelmp.errors import InputError, RunError
from fibrelmp.python_api import convert
from fibrelmp.registry import FRAMES, RESULT, TARGET

ENOSPC = os.strerror(errno.ENOSPC)
TARGETS = [f.name for f in registry.formats(TARGET)]
RESULTS = [f.name for f in registry.formats(RESULT)]
READERS = [f.name for f in registry.formats(FRAMES)]


# -- a synthetic LAMMPS dump ------------------------------------------------------------------
def dump_text(frames: int = 3, n: int = 6, seed: int = 1, drop: str | None = None,
              bad: tuple[int, int] | None = None) -> tuple[str, list[dict]]:
    """A dump with ids (not in order), types, x y z, v, f, radius, mass and ITEM: TIME;
    ``drop`` leaves a column out, ``bad`` = (frame, atom) gets a non-finite position.
    Returns the text and, per frame, the columns in atom-id order."""
    rng = np.random.default_rng(seed)
    ids = rng.permutation(np.arange(1, n + 1))
    types = 1 + ids % 2
    cols = ["id", "type", "x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz", "radius", "mass"]
    if drop:
        cols.remove(drop)
    text, truth = [], []
    for k in range(frames):
        data = {"id": ids.astype(float), "type": types.astype(float),
                "radius": 0.1 * types, "mass": 0.5 * types}
        x = rng.uniform(0.5, 9.5, (n, 3))
        if bad is not None and bad[0] == k:
            x[bad[1], 0] = np.nan
        for j, c in enumerate("xyz"):
            data[c] = x[:, j]
            data["v" + c] = rng.normal(size=n)
            data["f" + c] = rng.normal(size=n)
        text.append(f"ITEM: TIME\n{0.001 * 10 * k!r}\nITEM: TIMESTEP\n{10 * k}\nITEM: NUMBER OF ATOMS\n{n}\n"
                    "ITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\n"
                    f"ITEM: ATOMS {' '.join(cols)}\n")
        text += [" ".join(repr(float(data[c][i])) if c not in ("id", "type") else str(int(data[c][i]))
                          for c in cols) + "\n" for i in range(n)]
        order = np.argsort(ids)
        truth.append({c: v[order] for c, v in data.items()})
    return "".join(text), truth


def write_dump(folder: Path, name: str = "d.dump", **kw) -> tuple[Path, list[dict]]:
    text, truth = dump_text(**kw)
    path = folder / name
    path.write_text(text)
    return path, truth


def target_class(name: str):
    return registry.get(name).load(TARGET)


def listing(folder: Path) -> dict[str, bytes]:
    """Every file below ``folder`` (hidden temp files included) with its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


# -- TARGET -------------------------------------------------------------------------------------
@pytest.mark.parametrize("to", TARGETS)
def test_target_write_read(tmp_path, to):
    dump, truth = write_dump(tmp_path)
    kind = target_class(to)
    files = convert(dump, to, tmp_path / "out" / "run")
    assert files and all(p.exists() for p in files)
    assert set(files) <= set(kind.files(tmp_path / "out" / "run")) | set(files)
    frames = kind.read_back(files)
    want = truth[-1:] if kind.last_frame_by_default else truth
    assert len(frames) == len(want)
    for got, frame in zip(frames, want):
        x = np.column_stack([frame[c] for c in "xyz"])
        np.testing.assert_allclose(got.positions, x, rtol=got.rtol, atol=got.atol)
        rtol, atol = got.value_tol or (got.rtol, got.atol)
        for cols, values in got.values.items():
            np.testing.assert_allclose(values, np.column_stack([frame[c] for c in cols]),
                                       rtol=rtol, atol=atol, err_msg=str(cols))


@pytest.mark.parametrize("to", TARGETS)
@pytest.mark.parametrize("defect", ["missing column", "non-finite position"])
def test_target_bad_input_writes_nothing(tmp_path, to, defect):
    kw = {"drop": "z"} if defect == "missing column" else {"bad": (2, 3)}
    dump, _ = write_dump(tmp_path, **kw)
    with pytest.raises(InputError) as err:
        convert(dump, to, tmp_path / "out" / "run", frames="0:")    # every frame, also for res
    assert err.value.path == str(dump) and err.value.line is not None, str(err.value)
    assert not (tmp_path / "out").exists()                          # nothing, not even the folder


@pytest.mark.parametrize("to", TARGETS)
def test_target_failure_mid_way_leaves_earlier_output(tmp_path, to, monkeypatch):
    kind = target_class(to)
    first, _ = write_dump(tmp_path, "first.dump", seed=2)
    convert(first, to, tmp_path / "out" / "run")
    before = listing(tmp_path / "out")
    dump, _ = write_dump(tmp_path)
    real = kind.write_frame
    calls = []

    def failing(self, frame):
        calls.append(frame.step)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, ENOSPC)
        real(self, frame)
    monkeypatch.setattr(kind, "write_frame", failing)
    with pytest.raises(RunError, match=f"cannot write output: {ENOSPC}"):
        convert(dump, to, tmp_path / "out" / "run", force=True, frames="0:")
    assert len(calls) == 2
    assert listing(tmp_path / "out") == before          # no temp file, nothing replaced


@pytest.mark.parametrize("to", TARGETS)
def test_target_failure_while_closing_leaves_earlier_output(tmp_path, to, monkeypatch):
    """Every frame written, then the renames fail: the earlier output stays complete (no old
    frame file removed before the new ones are in place)."""
    from fibrelmp import formatbase

    first, _ = write_dump(tmp_path, "first.dump", seed=2, frames=4)
    convert(first, to, tmp_path / "out" / "run", frames="0:")
    before = listing(tmp_path / "out")
    dump, _ = write_dump(tmp_path)

    def failing(self):
        raise OSError(errno.ENOSPC, ENOSPC)
    monkeypatch.setattr(formatbase.Writer, "_commit", failing)
    with pytest.raises((RunError, InputError), match=ENOSPC):
        convert(dump, to, tmp_path / "out" / "run", force=True, frames="0:")
    assert listing(tmp_path / "out") == before


@pytest.mark.parametrize("to", TARGETS)
def test_target_force_replaces_the_earlier_output_completely(tmp_path, to):
    """A --force conversion with fewer frames leaves no file of the earlier one behind."""
    first, _ = write_dump(tmp_path, "first.dump", seed=2, frames=4)
    convert(first, to, tmp_path / "out" / "run", frames="0:")
    dump, _ = write_dump(tmp_path, frames=1)
    written = convert(dump, to, tmp_path / "out" / "run", force=True, frames="0:")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(p.name for p in written)


def test_fifo_trajectory_is_refused_not_waited_for(tmp_path):
    fifo = tmp_path / "frames.dump"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        convert(fifo, TARGETS[0], tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_convert_reports_warnings_to_the_caller(tmp_path):
    text, _ = dump_text()
    dump = tmp_path / "notime.dump"
    dump.write_text(re.sub(r"ITEM: TIME\n[^\n]*\n", "", text))
    got: list = []
    convert(dump, "vtk", tmp_path / "out" / "run", warn=got.extend)
    assert any(kind == "no times" for kind, _ in got), got


def completed_frames(dump: Path) -> list:
    from fibrelmp.post.complete import Completer
    from fibrelmp.post.lammps_dump import iter_frames

    complete = Completer(None, None, {}, [])
    return [complete(f) for f in iter_frames(dump)]


@pytest.mark.parametrize("to", TARGETS)
def test_target_streaming(tmp_path, to):
    from fibrelmp.post.target import PostContext

    kind = target_class(to)
    dump, _ = write_dump(tmp_path)
    frames = completed_frames(dump)
    out = tmp_path / "out"
    out.mkdir()
    target = kind(out / "run", PostContext(dump))
    for f in frames:
        target.add(f)
    target.abort()                                   # after frames: nothing left
    target.abort()
    assert listing(out) == {}
    with pytest.raises(ValueError, match="closed"):
        target.add(frames[0])
    with pytest.raises(KeyError):
        with kind(out / "run", PostContext(dump)) as target:
            target.add(frames[0])
            raise KeyError("a failure while converting")
    assert listing(out) == {}
    with kind(out / "run", PostContext(dump)) as target:
        for f in frames:
            target.add(f)
    written = listing(out)
    assert written and not [p for p in written if p.startswith(".")]
    assert target.close() == []                      # closing twice is harmless
    assert listing(out) == written


@pytest.mark.parametrize("to", TARGETS)
def test_target_force_policy(tmp_path, to):
    from fibrelmp.post.target import PostContext

    dump, _ = write_dump(tmp_path)
    convert(dump, to, tmp_path / "out" / "run")
    before = listing(tmp_path / "out")
    with pytest.raises(InputError, match="output exists; use --force to overwrite"):
        convert(dump, to, tmp_path / "out" / "run")
    with pytest.raises(InputError, match="output exists; use --force to overwrite"):
        target_class(to)(tmp_path / "out" / "run", PostContext(dump), force=False)
    assert listing(tmp_path / "out") == before
    assert convert(dump, to, tmp_path / "out" / "run", force=True)


# -- RESULT -------------------------------------------------------------------------------------
def _granular_frames(model, count: int) -> list:
    from fibrelmp.granmodel import GranularFrame

    s = model.spheres
    return [GranularFrame(time=0.001 * k, step=10 * k, sphere_rows=np.arange(s.count),
                          position=s.position + 0.01 * k, velocity=s.velocity, omega=s.omega,
                          force=np.zeros((s.count, 3)), quaternion=s.quaternion)
            for k in range(count)]


def _musen(folder: Path):
    from fibrelmp.translate.musen.writer import MusenResultWriter

    from .granular_models import GLASS, material, model, spheres

    mats = [material("glass", **GLASS)]
    m = model(spheres([[0, 0, 0], [0.01, 0, 0]], 0.004, 0, mats), mats, {}, 1e-5, 1e-3)
    return (lambda: MusenResultWriter(m, folder / "result.txt")), _granular_frames(m, 3)


def _mdem(folder: Path):
    from fibrelmp.translate.musen.mdem.result import MdemResultWriter

    from .granular_models import GLASS, material, model, spheres

    mats = [material("glass", **GLASS)]
    m = model(spheres([[0, 0, 0], [0.01, 0, 0]], 0.004, 0, mats), mats, {}, 1e-5, 1e-3)
    return (lambda: MdemResultWriter(m, folder / "result.mdem")), _granular_frames(m, 3)


def _demdf(folder: Path):
    from fibrelmp.translate.demdf import reader as demdf
    from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter

    m = demdf.read(Path(__file__).resolve().parents[1] / "examples" / "demdf" / "head_on.json")
    return (lambda: DemdfSnapshotWriter(m, folder)), _granular_frames(m, 3)


def _xyz(folder: Path):
    from fibrelmp.translate.fibrenet.writer import XyzFrame, XyzWriter

    frames = [XyzFrame(10 * k, 0.1, np.ones(3) * 5, ["a", "b"], np.full((2, 3), 0.5 + k)) for k in range(3)]
    return (lambda: XyzWriter(folder / "run", fields=("position",))), frames


def _res(folder: Path):
    from fibrelmp.translate.fibrenet.writer import RestartState, RestartWriter

    z = np.zeros((2, 3))
    frames = [RestartState(10 * k, 0.1, np.ones(3) * 5, np.array([0, 1]), ["a", "b"], z + k, z + k, z, z)
              for k in range(3)]
    return (lambda: RestartWriter(folder / "run_restart.res")), frames


# format -> (folder -> (writer factory, frames)): how to build a writer and its frames
RESULT_CASES = {"musen": _musen, "mdem": _mdem, "demdf": _demdf, "xyz": _xyz, "res": _res}


def test_every_result_format_has_a_case():
    assert set(RESULTS) <= set(RESULT_CASES)


@pytest.mark.parametrize("name", RESULTS)
def test_result_writer_atomic_and_abort(tmp_path, name, monkeypatch):
    kind = registry.get(name).load(RESULT)
    make, frames = RESULT_CASES[name](tmp_path)
    writer = make()
    for f in frames:
        writer.add(f)
    written = writer.close()
    assert written and all(p.exists() for p in written)
    assert writer.close() == []                                   # twice: harmless
    before = listing(tmp_path)
    assert not [p for p in before if p.startswith(".")]
    writer = make()                        # abort after frames: the earlier output stays as it was
    for f in frames:
        writer.add(f)
    writer.abort()
    assert listing(tmp_path) == before
    with pytest.raises(KeyError):          # ``with`` aborts on an exception
        with make() as writer:
            writer.add(frames[0])
            raise KeyError("failure")
    assert listing(tmp_path) == before
    real, calls = kind.write, []

    def failing(self, frame):              # a full disk at the 2nd frame
        calls.append(1)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, ENOSPC)
        real(self, frame)
    monkeypatch.setattr(kind, "write", failing)
    writer = make()
    with pytest.raises(RunError, match=f"cannot write output: {ENOSPC}"):
        for f in frames:
            writer.add(f)
    writer.abort()                         # what callers do next: harmless
    assert listing(tmp_path) == before


# -- FRAMES -------------------------------------------------------------------------------------
def _dump_sample(folder: Path) -> tuple[Path, Path]:
    good, _ = write_dump(folder, frames=3)
    bad = folder / "bad.dump"
    bad.write_text("hello\n")
    return good, bad


def _xyz_sample(folder: Path) -> tuple[Path, Path]:
    pytest.importorskip("MDAnalysis")
    good = folder / "t.xyz"
    good.write_text("".join(f"2\nframe {k}\nC 0 0 {k}\nO 1 0 {k}\n" for k in range(3)))
    bad = folder / "bad.xyz"
    bad.write_text("not a trajectory\n")
    return good, bad


# format -> folder -> (a 3-frame trajectory, a file it cannot read)
FRAMES_SAMPLES = {"lammps-dump": _dump_sample, "mdanalysis": _xyz_sample}


def test_every_frames_format_has_a_sample():
    assert set(READERS) <= set(FRAMES_SAMPLES)


@pytest.mark.filterwarnings("ignore:Reader has no dt information")
@pytest.mark.parametrize("name", READERS)
def test_frames_reader_streams(tmp_path, name):
    from fibrelmp.post.convert import open_frames

    kind = registry.get(name).load(FRAMES)
    good, bad = FRAMES_SAMPLES[name](tmp_path)
    assert type(open_frames(good, None, [])) is kind          # the pipeline picks this reader
    reader = kind(good)
    it = iter(reader)
    first = next(it)                                         # one frame, not the whole file
    assert first.count == 2 or first.count == 6
    assert len([first, *it]) == reader.count() == 3
    assert [f.step for f in reader.frames(lambda i: i != 1)] == \
        [f.step for k, f in enumerate(kind(good)) if k != 1]
    assert reader.last().step == list(kind(good))[-1].step
    with pytest.raises(InputError) as err:
        list(kind(bad))
    assert err.value.path == str(bad)


# -- a new target in one module + one registry entry ------------------------------------------
def test_a_new_target_format_is_one_module_and_one_registry_entry(tmp_path):
    from .csv_target import CSV

    dump, truth = write_dump(tmp_path)
    registry.register_format(CSV)
    try:
        files = convert(dump, "csv", tmp_path / "run")
        assert files == [tmp_path / "run.csv"]
        frames = registry.get("csv").load(TARGET).read_back(files)
        assert len(frames) == 3
        for got, want in zip(frames, truth):
            np.testing.assert_array_equal(got.positions, np.column_stack([want[c] for c in "xyz"]))
        with pytest.raises(InputError, match="output exists"):
            convert(dump, "csv", tmp_path / "run")
    finally:
        registry.unregister_format("csv")
    with pytest.raises(InputError, match="unknown format"):
        convert(dump, "csv", tmp_path / "again")
