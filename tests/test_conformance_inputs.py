"""Every INPUT format of the registry behaves the same through its hook and the Python API:
detected as itself, read into a model, checked, translated into a stock LAMMPS job, and a
bad or empty file is an InputError ``path: message`` with nothing written.

One small example per format: the registry's ``example`` (a file in examples/)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fibrelmp import python_api
from fibrelmp.cardioproof.case import SphCase
from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.model import Model
from fibrelmp.pipeline.inputs import InputFormat
from fibrelmp.registry import INPUT, detect, formats

from .conftest import REPO, copy_example

FORMATS = formats(INPUT)


@pytest.fixture(params=FORMATS, ids=[f.name for f in FORMATS])
def example(request, tmp_path):
    """(format, a copy of its example: the example's folder, so the files it names come along)."""
    fmt = request.param
    source = REPO / fmt.example
    copy_example(source.parent.relative_to(REPO), tmp_path / "in")
    return fmt, tmp_path / "in" / source.name


def _files(folder: Path) -> set[Path]:
    return {p for p in folder.rglob("*")}


def test_every_input_format_has_a_hook_and_an_example():
    assert [f.name for f in FORMATS] == ["fibrenet", "musen-script", "mdem", "musen", "cardioproof", "demdf"]
    for fmt in FORMATS:
        assert (REPO / fmt.example).is_file(), fmt.name
        hook = fmt.load(INPUT)
        assert issubclass(hook, InputFormat) and hook.name == fmt.name


def test_detect_read_check_translate(example, tmp_path):
    fmt, path = example
    assert detect(path).name == fmt.name
    hook = fmt.load(INPUT)()
    assert python_api.read(path) is not None
    model = hook.model(path)
    assert isinstance(model, (Model, GranularModel, SphCase))

    report = python_api.check(path)
    assert report.format == fmt.name
    assert report.lines[0].startswith("input") and report.lines[-1].startswith("results")

    job = python_api.write_job(path, tmp_path / "job")
    assert job.script == tmp_path / "job" / "in.lammps" and job.script.is_file()
    assert job.data.parent == tmp_path / "job" and job.data.is_file()
    assert not hook.has_checkpoint(path)


@pytest.mark.parametrize("content", ["", "garbage"])
def test_bad_or_empty_input_is_an_input_error_and_writes_nothing(example, tmp_path, content):
    fmt, path = example
    bad = path.with_name("bad" + path.suffix)
    if content and fmt.binary:     # the example, spoilt after its headers (same signature)
        data = bytearray(path.read_bytes())
        data[2200:2300] = b"@" * 100
        bad.write_bytes(bytes(data))
        assert detect(bad).name == fmt.name
    elif content:    # the example, spoilt after its first line (detected as the same format)
        lines = path.read_text().splitlines(keepends=True)
        bad.write_text(lines[0] + "@@@ not a line of any input @@@ ]]\n" + "".join(lines[1:]))
        assert detect(bad).name == fmt.name
    else:
        bad.write_text("")
    before = _files(tmp_path)
    for call in (lambda: python_api.check(bad),
                 lambda: python_api.write_job(bad, tmp_path / "job"),
                 lambda: python_api.run(bad, tmp_path / "out", work=tmp_path / "work")):
        with pytest.raises(InputError) as err:
            call()
        assert Path(err.value.path) == bad and str(err.value).startswith(f"{bad}"), str(err.value)
    assert _files(tmp_path) == before
