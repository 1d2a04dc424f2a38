"""The checks every registered format gets, one base class per registry role (like
MDAnalysis's ``BaseReaderTest``/``BaseWriterTest``): a format's test module subclasses the
base class of each of its roles, sets ``format`` (its registry name) and gives its reference
samples; the base class's ``test_*`` methods then run for it.  The base classes' names do not
start with ``Test``, so pytest collects only the subclasses.

* ``InputConformance``    (``input``): detected as itself, read, checked, translated into a
  job; a bad or empty file is an InputError ``path: message`` with nothing written.
* ``ResultConformance``   (``result``, ``run``'s native results): atomic write and abort.
* ``TargetConformance``   (``target``, ``post --to``): round trip within the printed
  precision, bad input, atomic write, streaming, force policy.
* ``FramesConformance``   (``frames``, ``post``'s readers): streaming reads and bad files.
* ``MeshConformance``     (``mesh``): written, read, written again, read: equal; bad files.
* ``DocumentConformance`` (``document``, ``fibrelmp convert``): conversions reach a fixed
  point through every document format; existing outputs kept; bad files write nothing.
* ``MotionConformance``   (``motion``): the frames a hand-made file holds, one at a time;
  bad files.
* ``AlsoConformance``     (``also``, ``run --also``): from a granular run's frames, every file
  written is one the format declared beforehand, atomically; abort and a full disk leave
  nothing.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path
from typing import Any, Callable, ClassVar

import numpy as np
import pytest

from fibrelmp import python_api, registry
from fibrelmp.errors import InputError, RunError
from fibrelmp.python_api import convert
from fibrelmp.registry import ALSO, DOCUMENT, FRAMES, INPUT, MESH, MOTION, RESULT, TARGET

from ..conftest import REPO, copy_example

ENOSPC = os.strerror(errno.ENOSPC)


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


def listing(folder: Path) -> dict[str, bytes]:
    """Every file below ``folder`` (hidden temp files included) with its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def every_file(folder: Path) -> set[Path]:
    return set(folder.rglob("*"))


class Conformance:
    """What every role's base class has: the format's registry name and the role it tests."""

    format: ClassVar[str]                  # the registry name; set by the subclass
    role: ClassVar[str]

    @classmethod
    def registered(cls) -> registry.Format:
        return registry.get(cls.format)

    @classmethod
    def hook(cls) -> Any:
        return cls.registered().load(cls.role)


# -- INPUT --------------------------------------------------------------------------------------
class InputConformance(Conformance):
    """``sample``: the format's small reference input (relative to the repository); its
    folder is copied, so the files it names come along."""

    role = INPUT
    sample: ClassVar[str]

    @pytest.fixture
    def example(self, tmp_path: Path) -> Path:
        source = REPO / self.sample
        copy_example(source.parent.relative_to(REPO), tmp_path / "in")
        return tmp_path / "in" / source.name

    def test_hook_and_example(self):
        from fibrelmp.inputformat import InputFormat

        fmt = self.registered()
        assert (REPO / fmt.example).is_file(), fmt.name       # the example help texts show
        hook = self.hook()
        assert issubclass(hook, InputFormat) and hook.name == fmt.name

    def test_detect_read_check_translate(self, example, tmp_path):
        from fibrelmp.translate.cardioproof.case import SphCase
        from fibrelmp.granmodel import GranularModel
        from fibrelmp.model import Model

        assert registry.detect(example).name == self.format
        hook = self.hook()()
        assert python_api.read(example) is not None
        assert isinstance(hook.model(example), (Model, GranularModel, SphCase))

        report = python_api.check(example)
        assert report.format == self.format
        assert report.lines[0].startswith("input") and report.lines[-1].startswith("results")

        job = python_api.write_job(example, tmp_path / "job")
        assert job.script == tmp_path / "job" / "in.lammps" and job.script.is_file()
        assert job.data.parent == tmp_path / "job" and job.data.is_file()
        assert not hook.has_checkpoint(example)

    @pytest.mark.parametrize("content", ["", "garbage"])
    def test_bad_or_empty_input_is_an_input_error_and_writes_nothing(self, example, tmp_path, content):
        bad = example.with_name("bad" + example.suffix)
        if content and self.registered().binary:    # the sample, spoilt after its headers
            data = bytearray(example.read_bytes())
            data[2200:2300] = b"@" * 100
            bad.write_bytes(bytes(data))
            assert registry.detect(bad).name == self.format
        elif content:    # spoilt after its first line (detected as the same format)
            lines = example.read_text().splitlines(keepends=True)
            bad.write_text(lines[0] + "@@@ not a line of any input @@@ ]]\n" + "".join(lines[1:]))
            assert registry.detect(bad).name == self.format
        else:
            bad.write_text("")
        before = every_file(tmp_path)
        for call in (lambda: python_api.check(bad),
                     lambda: python_api.write_job(bad, tmp_path / "job"),
                     lambda: python_api.run(bad, tmp_path / "out", work=tmp_path / "work")):
            with pytest.raises(InputError) as err:
                call()
            assert Path(err.value.path) == bad and str(err.value).startswith(f"{bad}"), str(err.value)
        assert every_file(tmp_path) == before


# -- RESULT -------------------------------------------------------------------------------------
class ResultConformance(Conformance):
    """``case(folder)``: (a factory of the format's result writer into ``folder``, three
    frames it takes)."""

    role = RESULT

    def case(self, folder: Path) -> tuple[Callable[[], Any], list]:
        raise NotImplementedError

    def test_result_writer_atomic_and_abort(self, tmp_path, monkeypatch):
        kind = self.hook()
        make, frames = self.case(tmp_path)
        writer = make()
        for f in frames:
            writer.add(f)
        written = writer.close()
        assert written and all(p.exists() for p in written)
        assert writer.close() == []                                   # twice: harmless
        before = listing(tmp_path)
        assert not [p for p in before if p.startswith(".")]
        writer = make()                    # abort after frames: the earlier output stays as it was
        for f in frames:
            writer.add(f)
        writer.abort()
        assert listing(tmp_path) == before
        with pytest.raises(KeyError):      # ``with`` aborts on an exception
            with make() as writer:
                writer.add(frames[0])
                raise KeyError("failure")
        assert listing(tmp_path) == before
        real, calls = kind.write, []

        def failing(self, frame):          # a full disk at the 2nd frame
            calls.append(1)
            if len(calls) == 2:
                raise OSError(errno.ENOSPC, ENOSPC)
            real(self, frame)
        monkeypatch.setattr(kind, "write", failing)
        writer = make()
        with pytest.raises(RunError, match=f"cannot write output: {ENOSPC}"):
            for f in frames:
                writer.add(f)
        writer.abort()                     # what callers do next: harmless
        assert listing(tmp_path) == before


def granular_frames(model, count: int) -> list:
    """``count`` frames of a granular model's spheres, moved a little each frame."""
    from fibrelmp.granmodel import GranularFrame

    s = model.spheres
    return [GranularFrame(time=0.001 * k, step=10 * k, sphere_rows=np.arange(s.count),
                          position=s.position + 0.01 * k, velocity=s.velocity, omega=s.omega,
                          force=np.zeros((s.count, 3)), quaternion=s.quaternion)
            for k in range(count)]


def two_glass_spheres():
    """A granular model of two glass spheres (tests/granular_models.py)."""
    from ..granular_models import GLASS, material, model, spheres

    mats = [material("glass", **GLASS)]
    return model(spheres([[0, 0, 0], [0.01, 0, 0]], 0.004, 0, mats), mats, {}, 1e-5, 1e-3)


# -- TARGET -------------------------------------------------------------------------------------
class TargetConformance(Conformance):
    """Needs nothing but ``format``: the frames are a synthetic LAMMPS dump (``dump_text``);
    the target class gives ``files``, ``write_frame`` and ``read_back``."""

    role = TARGET

    def test_target_write_read(self, tmp_path):
        to = self.format
        dump, truth = write_dump(tmp_path)
        kind = self.hook()
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

    @pytest.mark.parametrize("defect", ["missing column", "non-finite position"])
    def test_target_bad_input_writes_nothing(self, tmp_path, defect):
        kw = {"drop": "z"} if defect == "missing column" else {"bad": (2, 3)}
        dump, _ = write_dump(tmp_path, **kw)
        with pytest.raises(InputError) as err:
            convert(dump, self.format, tmp_path / "out" / "run", frames="0:")    # every frame, also for res
        assert err.value.path == str(dump) and err.value.line is not None, str(err.value)
        assert not (tmp_path / "out").exists()                          # nothing, not even the folder

    def test_target_failure_mid_way_leaves_earlier_output(self, tmp_path, monkeypatch):
        to, kind = self.format, self.hook()
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

    def test_target_failure_while_closing_leaves_earlier_output(self, tmp_path, monkeypatch):
        """Every frame written, then the renames fail: the earlier output stays complete (no
        old frame file removed before the new ones are in place)."""
        from fibrelmp import formatbase

        to = self.format
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

    def test_target_force_replaces_the_earlier_output_completely(self, tmp_path):
        """A --force conversion with fewer frames leaves no file of the earlier one behind."""
        to = self.format
        first, _ = write_dump(tmp_path, "first.dump", seed=2, frames=4)
        convert(first, to, tmp_path / "out" / "run", frames="0:")
        dump, _ = write_dump(tmp_path, frames=1)
        written = convert(dump, to, tmp_path / "out" / "run", force=True, frames="0:")
        assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(p.name for p in written)

    def test_target_streaming(self, tmp_path):
        from fibrelmp.post.target import PostContext

        kind = self.hook()
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

    def test_target_force_policy(self, tmp_path):
        from fibrelmp.post.target import PostContext

        to = self.format
        dump, _ = write_dump(tmp_path)
        convert(dump, to, tmp_path / "out" / "run")
        before = listing(tmp_path / "out")
        with pytest.raises(InputError, match="output exists; use --force to overwrite"):
            convert(dump, to, tmp_path / "out" / "run")
        with pytest.raises(InputError, match="output exists; use --force to overwrite"):
            self.hook()(tmp_path / "out" / "run", PostContext(dump), force=False)
        assert listing(tmp_path / "out") == before
        assert convert(dump, to, tmp_path / "out" / "run", force=True)


def completed_frames(dump: Path) -> list:
    from fibrelmp.post.complete import Completer
    from fibrelmp.post.lammps_dump import iter_frames

    complete = Completer(None, None, {}, [])
    return [complete(f) for f in iter_frames(dump)]


# -- FRAMES -------------------------------------------------------------------------------------
class FramesConformance(Conformance):
    """``sample(folder)``: (a 3-frame trajectory of ``atoms`` atoms, a file the reader
    cannot read)."""

    role = FRAMES
    atoms: ClassVar[int]

    def sample(self, folder: Path) -> tuple[Path, Path]:
        raise NotImplementedError

    @pytest.mark.filterwarnings("ignore:Reader has no dt information")
    def test_frames_reader_streams(self, tmp_path):
        from fibrelmp.post.convert import open_frames

        kind = self.hook()
        good, bad = self.sample(tmp_path)
        assert type(open_frames(good, None, [])) is kind          # the pipeline picks this reader
        reader = kind(good)
        it = iter(reader)
        first = next(it)                                         # one frame, not the whole file
        assert first.count == self.atoms
        assert len([first, *it]) == reader.count() == 3
        assert [f.step for f in reader.frames(lambda i: i != 1)] == \
            [f.step for k, f in enumerate(kind(good)) if k != 1]
        assert reader.last().step == list(kind(good))[-1].step
        with pytest.raises(InputError) as err:
            list(kind(bad))
        assert err.value.path == str(bad)


# -- MESH ---------------------------------------------------------------------------------------
def mixed_mesh():
    """A tetra, a prism and two triangles (mixed kinds, element order kept) in µm."""
    from fibrelmp.mesh.model import CellBlock, Mesh

    rng = np.random.default_rng(3)
    points = rng.random((9, 3)) * 1000.0          # µm, arbitrary doubles
    points[0] = (10.34, -15.0023, 12.023)
    cells = [CellBlock("tetra", [[0, 1, 2, 3]], [1]),
             CellBlock("wedge", [[1, 2, 3, 4, 5, 6]], [2]),
             CellBlock("triangle", [[6, 7, 8], [0, 7, 8]], [3, 3]),
             CellBlock("tetra", [[2, 3, 4, 5]], [1])]
    return Mesh(points.astype(np.float32).astype(np.float64), cells, unit=1e-6)


class MeshConformance(Conformance):
    """``suffix``: what the name the writer takes ends with ("" for a base name);
    ``needs``: modules the format needs (skipped without them); ``bad_sample(folder)``: a
    file the reader must refuse with an InputError naming it."""

    role = MESH
    suffix: ClassVar[str]
    needs: ClassVar[tuple[str, ...]] = ()

    def bad_sample(self, folder: Path) -> Path:
        raise NotImplementedError

    @pytest.fixture(autouse=True)
    def _needs(self):
        for module in self.needs:
            pytest.importorskip(module)

    def test_mesh_round_trips(self, tmp_path):
        """Written, read, written again, read: equal."""
        hook = self.hook()
        with hook.writer(tmp_path / f"first{self.suffix}") as w:
            w.add(mixed_mesh())
        first = hook.reader(w.outputs()[0]).read()
        with hook.writer(tmp_path / f"second{self.suffix}") as w2:
            w2.add(first)
        assert hook.reader(w2.outputs()[0]).read().equals(first)

    def test_existing_mesh_kept_without_force(self, tmp_path):
        hook = self.hook()
        with hook.writer(tmp_path / f"m{self.suffix}") as w:
            w.add(mixed_mesh())
        before = listing(tmp_path)
        with pytest.raises(InputError, match="output exists"):
            hook.writer(tmp_path / f"m{self.suffix}", force=False)
        assert listing(tmp_path) == before

    def test_bad_mesh_is_an_input_error(self, tmp_path):
        bad = self.bad_sample(tmp_path)
        with pytest.raises(InputError) as err:
            self.hook().reader(bad).read()
        assert err.value.path == str(bad), str(err.value)


# -- DOCUMENT -----------------------------------------------------------------------------------
class DocumentConformance(Conformance):
    """``sample``: a reference file of the format (relative to the repository);
    ``cut``: a length at which the sample, cut off, is no longer a valid file (mid-record)."""

    role = DOCUMENT
    sample: ClassVar[str]
    cut: ClassVar[int]

    def _name(self, folder: Path, stem: str, fmt: str | None = None) -> Path:
        hook = registry.get(fmt or self.format).load(DOCUMENT)
        return folder / (stem + hook.suffixes[0])

    @staticmethod
    def time_points(fmt: str, path: Path) -> list[tuple[float, np.ndarray]]:
        doc = registry.get(fmt).load(DOCUMENT).open(path)
        try:
            return [(time, values) for time, values, _ in doc.points()]
        finally:
            doc.close()

    def assert_same_time_points(self, fmt: str, path: Path) -> None:
        """``path`` (a ``fmt`` file) holds the sample's time points: same times, values to the
        6 significant digits text is written with."""
        want, got = self.time_points(self.format, REPO / self.sample), self.time_points(fmt, path)
        assert [t for t, _ in got] == [t for t, _ in want], path.name
        for (_, values), (_, expected) in zip(got, want):
            np.testing.assert_allclose(values, expected, rtol=1e-5, atol=0, equal_nan=True,
                                       err_msg=path.name)

    def test_conversions_reach_a_fixed_point(self, tmp_path):
        """Into this format, then through itself and every document format and back: the
        sample's time points in every form, and one pass changes nothing more."""
        first = self._name(tmp_path, "first")
        assert python_api.convert_file(REPO / self.sample, first, to=self.format) == [first]
        self.assert_same_time_points(self.format, first)
        itself = self._name(tmp_path, "itself")
        python_api.convert_file(first, itself, to=self.format)
        assert itself.read_bytes() == first.read_bytes()
        for other in registry.names(DOCUMENT):
            passes = [first]
            for k in range(2):
                middle = self._name(tmp_path, f"{other}_{k}", other)
                python_api.convert_file(passes[-1], middle, to=other)
                self.assert_same_time_points(other, middle)
                passes.append(self._name(tmp_path, f"back_{other}_{k}"))
                python_api.convert_file(middle, passes[-1], to=self.format)
            assert passes[1].read_bytes() == passes[2].read_bytes(), other

    def test_existing_output_kept_without_force(self, tmp_path, monkeypatch):
        out = self._name(tmp_path, "out")
        python_api.convert_file(REPO / self.sample, out, to=self.format)
        before = listing(tmp_path)
        with pytest.raises(InputError, match="output exists"):
            python_api.convert_file(REPO / self.sample, out, to=self.format)
        assert listing(tmp_path) == before
        probe = self.hook().writer(tmp_path / "probe")
        probe.abort()                      # only its class is wanted
        writer = type(probe)

        def failing(self, doc):            # a full disk while writing
            raise OSError(errno.ENOSPC, ENOSPC)
        monkeypatch.setattr(writer, "write", failing)
        with pytest.raises((RunError, InputError), match=ENOSPC):
            python_api.convert_file(REPO / self.sample, out, to=self.format, force=True)
        assert listing(tmp_path) == before

    def test_truncated_file_is_an_input_error_and_writes_nothing(self, tmp_path):
        source = REPO / self.sample
        bad = tmp_path / ("bad" + source.suffix)
        data = source.read_bytes()
        assert 0 < self.cut < len(data)
        bad.write_bytes(data[:self.cut])
        before = every_file(tmp_path)
        with pytest.raises(InputError) as err:
            python_api.convert_file(bad, self._name(tmp_path, "out"), to=self.format)
        assert Path(err.value.path) == bad, str(err.value)
        assert every_file(tmp_path) == before


# -- MOTION -------------------------------------------------------------------------------------
class MotionConformance(Conformance):
    """``sample(folder)``: (a file made by hand, the (time, points) frames it holds);
    ``bad_samples(folder)``: files the reader must refuse."""

    role = MOTION

    def sample(self, folder: Path) -> tuple[Path, list[tuple[float, np.ndarray]]]:
        raise NotImplementedError

    def bad_samples(self, folder: Path) -> list[Path]:
        raise NotImplementedError

    def test_frames_as_written_one_at_a_time(self, tmp_path):
        path, want = self.sample(tmp_path)
        reader = self.hook()(path)
        first = next(iter(reader))                  # a frame without reading the rest
        assert first.time == want[0][0] and np.array_equal(first.points, want[0][1])
        for _ in range(2):                          # and again: the reader re-reads
            got = list(reader)
            assert [f.time for f in got] == [t for t, _ in want]
            for f, (_, points) in zip(got, want):
                assert f.points.dtype == np.float64 and np.array_equal(f.points, points)

    def test_bad_files_are_input_errors(self, tmp_path):
        bad_files = self.bad_samples(tmp_path)
        assert bad_files
        for bad in bad_files:
            with pytest.raises(InputError) as err:
                list(self.hook()(bad))
            assert err.value.path == str(bad), str(err.value)


# -- ALSO ---------------------------------------------------------------------------------------
class AlsoConformance(Conformance):
    """A ``run --also`` format: its ``RunOutput`` declares the files of a result base before
    anything is written, and its writer of a granular run's frames writes only declared files
    (named or matching a declared family), through temp files; abort or a full disk leaves
    the folder as it was."""

    role = ALSO

    def _declared(self, tmp_path: Path):
        from fibrelmp.outputs import Outputs

        out = tmp_path / "res"
        out.mkdir()
        outputs = Outputs(source=tmp_path / "in.txt", work=tmp_path / "work")
        self.hook()().declare(outputs, out / "run")
        return outputs, out

    @staticmethod
    def _is_declared(outputs, path: Path) -> bool:
        return path in outputs.files or any(
            folder == path.parent and pattern.fullmatch(path.name) for folder, pattern in outputs.patterns)

    def test_writes_only_declared_files_atomically(self, tmp_path):
        outputs, out = self._declared(tmp_path)
        assert outputs.files or outputs.patterns
        model = two_glass_spheres()
        writer = self.hook()().granular_writer(model, out / "run")
        for frame in granular_frames(model, 3):
            writer.add(frame)
        written = writer.close()
        assert written and all(p.is_file() and p.stat().st_size for p in written)
        assert all(self._is_declared(outputs, p) for p in written), written
        assert not [p for p in listing(out) if p.startswith(".")]          # no temp file left

    def test_abort_and_full_disk_leave_nothing(self, tmp_path, monkeypatch):
        _, out = self._declared(tmp_path)
        model = two_glass_spheres()
        frames = granular_frames(model, 3)
        writer = self.hook()().granular_writer(model, out / "run")
        for frame in frames:
            writer.add(frame)
        writer.abort()
        assert listing(out) == {}
        writer = self.hook()().granular_writer(model, out / "run")
        kind, calls = type(writer), []
        real = kind.write

        def failing(self, frame):          # a full disk at the 2nd frame
            calls.append(1)
            if len(calls) == 2:
                raise OSError(errno.ENOSPC, ENOSPC)
            real(self, frame)
        monkeypatch.setattr(kind, "write", failing)
        with pytest.raises(RunError, match=f"cannot write output: {ENOSPC}"):
            for frame in frames:
                writer.add(frame)
        writer.abort()
        assert listing(out) == {}


BASES = {INPUT: InputConformance, RESULT: ResultConformance, TARGET: TargetConformance,
         FRAMES: FramesConformance, MESH: MeshConformance, DOCUMENT: DocumentConformance,
         MOTION: MotionConformance, ALSO: AlsoConformance}

