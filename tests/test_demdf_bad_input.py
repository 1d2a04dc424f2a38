"""Bad DEMDF input: every problem is an InputError naming the file and the JSON location."""

from __future__ import annotations

import copy
import json
import random
from pathlib import Path

import pytest
from typer.testing import CliRunner

from fibrelmp.cli import app
from fibrelmp.errors import InputError
from fibrelmp.translate.demdf import reader as demdf

GOOD = {
    "fileFormat": "demdf", "fileFormatVersion": 0.01, "dimensionality": 3, "time": 0.0,
    "timeEnd": 1.0, "timeStep": 0.001, "timeStepCount": 0, "timeStepCountEnd": 100,
    "output": {"snapshot": {"name": "demdf", "filename": "out", "saveCount": 0,
                            "savePeriodInTimeSteps": 10, "savePeriodInTime": 0.01}},
    "domain": [[0, 0, 0], [5, 5, 5]], "bodyForce": [0, 0, -1],
    "objectTypes": [{"id": 0, "type": "particle", "radius": 0.5, "mass": 1.0,
                     "restitutionCoefficient": 0.9},
                    {"id": 1, "type": "wall", "restitutionCoefficient": 0.9}],
    "objects": {"particles": [[1, 1, 1, 1, 0, 0, 0], [3, 1, 1, -1, 0, 0, 0],
                              [1, 3, 1, 0, 0, 0, 0], [3, 3, 3, 0, 0, 0, 0]],
                "walls": [{"normal": [0, 0, 1], "point": [0, 0, 0], "objectType": 1}]},
    "interactions": [{"name": "particleInelastic", "objectTypes": [0, 0]},
                     {"name": "wallInelastic", "objectTypes": [0, 1]}],
}


def put(doc: dict, where: str, value) -> dict:
    """Set doc[a][b][3]... from "a.b[3]" (a copy)."""
    doc = copy.deepcopy(doc)
    keys = [int(k) if k.isdigit() else k for k in where.replace("[", ".").replace("]", "").split(".")]
    target = doc
    for k in keys[:-1]:
        target = target[k]
    target[keys[-1]] = value
    return doc


def expect_error(tmp_path: Path, text: str | bytes, *fragments: str) -> str:
    path = tmp_path / "bad.json"
    path.write_bytes(text.encode() if isinstance(text, str) else text)
    with pytest.raises(InputError) as exc:
        demdf.read(path)
    message = str(exc.value)
    assert message.startswith(f"{path}:"), message
    for fragment in fragments:
        assert fragment in message, message
    return message


def test_good_document_reads(tmp_path):
    path = tmp_path / "good.json"
    path.write_text(json.dumps(GOOD))
    assert demdf.read(path).spheres.count == 4


def test_not_json_names_line_and_column(tmp_path):
    text = '{\n  "fileFormat": "demdf",\n  "time": 0.0,,\n}'
    msg = expect_error(tmp_path, text, "not valid JSON", "line 3, column 15")
    assert msg.startswith(f"{tmp_path / 'bad.json'}:3: ")


@pytest.mark.parametrize("text, fragments", [
    ("", ["not valid JSON", "line 1, column 1"]),
    ("[1, 2]", ["a DEMDF document is a JSON object"]),
    ('{"fileFormat": "demdf", "time": NaN}', ["NaN is not valid JSON"]),
    ('{"fileFormat": "demdf", "time": 1e999}', ["too large"]),
    ('{"fileFormat": "demdf", "time": 0, "time": 1}', ["'time' appears twice"]),
    ('{"time": 0}', ["fileFormat: missing"]),
])
def test_malformed_documents(tmp_path, text, fragments):
    expect_error(tmp_path, text, *fragments)


def test_utf16_file(tmp_path):
    expect_error(tmp_path, json.dumps(GOOD).encode("utf-16"), "UTF-16")


@pytest.mark.parametrize("where, value, fragments", [
    ("fileFormat", "mercury", ['fileFormat: must be "demdf"', "'mercury'"]),
    ("objects.particles[1]", [3, 1, 1, -1, 0, 0], ["objects.particles[1]: expected 7 entries",
                                                   "[x, y, z, vx, vy, vz, type]", "got 6"]),
    ("objects.particles[3][6]", 2, ["objects.particles[3][6]: objectType 2 does not exist",
                                    "1 particle objectType"]),
    ("objects.particles[3][6]", 0.5, ["objects.particles[3][6]: the objectType index must be an integer"]),
    ("objects.particles[2][4]", "fast", ["objects.particles[2][4]: expected a number", "'fast'"]),
    ("objects.particles[2][4]", True, ["objects.particles[2][4]: expected a number, got true"]),
    ("objects.particles[2]", {"x": 1}, ["objects.particles[2]: a row is an array"]),
    ("objects.particles", "missing.json", ["objects.particles: particles file 'missing.json' not found"]),
    ("objects.particles", 7, ["objects.particles: expected an array of particles or a particles file"]),
    ("objects.particles", [], ["objects.particles: no particles"]),
    ("time", "zero", ["time: expected a number, got the string 'zero'"]),
    ("timeStep", -1, ["timeStep: must be at least 0"]),
    ("timeStepCountEnd", 1.5, ["timeStepCountEnd: expected an integer"]),
    ("dimensionality", 4, ["dimensionality: must be 2 or 3"]),
    ("domain", [[0, 0, 0]], ["domain: expected two opposite corners"]),
    ("domain", [[0, 0, 0], [5, 5]], ["domain[1]: expected 3 numbers"]),
    ("domain", [[0, 0, 0], [5, 5, 0]], ["domain: the two corners have the same z"]),
    ("domain", [[0, 0, 0], [5, 5, [5]]], ["domain[1][2]: expected a number, got an array of 1"]),
    ("bodyForce", {"z": -1}, ["bodyForce: expected an array"]),
    ("objectTypes", {"0": {}}, ["objectTypes: expected an array"]),
    ("objectTypes[0].mass", "1", ["objectTypes[0].mass: expected a number"]),
    ("objectTypes[0].mass", 0, ["objectTypes[0].mass: must be positive"]),
    ("objectTypes[0].radius", -0.5, ["objectTypes[0].radius: must be positive"]),
    ("objectTypes[0].restitutionCoefficient", 1.5, ["objectTypes[0].restitutionCoefficient: "
                                                    "a restitution coefficient must be in (0, 1]"]),
    ("objectTypes[0].restitutionCoefficient", None, ["restitutionCoefficient: expected a number, got null"]),
    ("objectTypes[0].id", "zero", ["objectTypes[0].id: expected an integer"]),
    ("objectTypes[0].type", 3, ["objectTypes[0].type: expected a string"]),
    ("objects.walls[0].normal", [0, 0, 0], ["objects.walls[0].normal: the normal's length is 0"]),
    ("objects.walls[0].normal", [0, 0], ["objects.walls[0].normal: expected 3 numbers"]),
    ("objects.walls[0].point", None, ["objects.walls[0].point: expected an array"]),
    ("objects.walls[0].objectType", 0, ["objects.walls[0].objectType: 0 is not a wall entry"]),
    ("objects.walls[0]", [0, 0, 1], ["objects.walls[0]: expected an object"]),
    ("objects.walls[0].normal", [0, 0, -1], ["objects.particles[0] is behind objects.walls[0]"]),
    ("objects.particles[0][0]", 9.0, ["objects.particles[0]: the centre", "outside the domain"]),
    ("objects", [], ["objects: expected an object"]),
    ("interactions", {"name": "x"}, ["interactions: expected an array"]),
    ("interactions[0].name", None, ["interactions[0].name: expected a string"]),
    ("output", "out", ["output: expected"]),
    ("output.snapshot.filename", "/tmp/x", ["output.snapshot.filename: must be a non-empty relative name"]),
    ("output.snapshot.savePeriodInTime", 0, ["output.snapshot.savePeriodInTime: must be positive"]),
    ("output.snapshot.saveCount", -1, ["output.snapshot.saveCount: must be at least 0"]),
    ("fibrelmp", {"youngsModulus": "stiff"}, ["fibrelmp.youngsModulus: expected a number"]),
    ("fibrelmp", {"poissonRatio": 0.7}, ["fibrelmp.poissonRatio: must be below 0.5"]),
    ("timeEnd", 0.0, ["timeEnd: 0 is not after time 0: nothing to simulate"]),
])
def test_bad_values_name_the_json_location(tmp_path, where, value, fragments):
    expect_error(tmp_path, json.dumps(put(GOOD, where, value)), *fragments)


def test_inelastic_needs_restitution(tmp_path):
    doc = copy.deepcopy(GOOD)
    del doc["objectTypes"][0]["restitutionCoefficient"]
    expect_error(tmp_path, json.dumps(doc), "objectTypes[0]: no restitutionCoefficient",
                 "particleInelastic")


def test_bad_external_particles_file_names_that_file(tmp_path):
    rows = copy.deepcopy(GOOD["objects"]["particles"])
    rows[3] = [3, 3, 3, 0, 0, "0", 0]
    (tmp_path / "p.json").write_text(json.dumps({"particles": rows}))
    with pytest.raises(InputError) as exc:
        demdf.read(_with_file(tmp_path, "p.json"))
    assert str(exc.value).startswith(f"{tmp_path / 'p.json'}: particles[3][5]: expected a number")
    (tmp_path / "p.json").write_text('{"particles": [[1, 2, 3,]]}')
    with pytest.raises(InputError, match=r"p\.json:1: DEMDF particles file is not valid JSON"):
        demdf.read(_with_file(tmp_path, "p.json"))
    (tmp_path / "p.json").write_text('[[1, 1, 1, 0, 0, 0, 0]]')
    with pytest.raises(InputError, match=r'is an object \{"particles"'):
        demdf.read(_with_file(tmp_path, "p.json"))


def _with_file(folder: Path, name: str) -> Path:
    path = folder / "spec.json"
    path.write_text(json.dumps(put(GOOD, "objects.particles", name)))
    return path


def test_bad_overrides(tmp_path):
    path = tmp_path / "good.json"
    path.write_text(json.dumps(GOOD))
    for kwargs, fragment in [({"time_end": -1.0}, "--time-end -1 is not after"),
                             ({"steps": 0}, "--steps must be a positive integer"),
                             ({"save_every": 0.0}, "--save-every must be positive"),
                             ({"save_every": "often"}, "--save-every must be a number")]:
        with pytest.raises(InputError, match=fragment):
            demdf.read(path, **kwargs)


def _mutations(doc, rng: random.Random, where=()):
    """Every location in the document, to be replaced by a value of a wrong kind."""
    yield where
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _mutations(v, rng, where + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _mutations(v, rng, where + (i,))


@pytest.mark.filterwarnings("error")
def test_wrong_kinds_anywhere_give_input_errors(tmp_path):
    rng = random.Random(3)
    weird = ["", "1.0", None, True, [], {}, [[1]], -1, 0, 1e308, -1e308, 1e-300, 10 ** 400,
             [None] * 7, {"a": []}]
    path = tmp_path / "fuzz.json"
    count = 0
    for where in _mutations(GOOD, rng):
        if not where:
            continue
        for value in rng.sample(weird, 4):
            doc = copy.deepcopy(GOOD)
            target = doc
            for k in where[:-1]:
                target = target[k]
            target[where[-1]] = value
            path.write_text(json.dumps(doc))
            try:
                demdf.read(path)
            except InputError as exc:
                assert str(exc).startswith(str(path))
            count += 1
    assert count > 300


# ------------------------------------------------------------------ through the CLI
@pytest.mark.parametrize("where, value, fragment", [
    ("fileFormat", "demdf2", 'fileFormat: must be "demdf"'),
    ("objects.particles[3]", [1, 2, 3], "objects.particles[3]: expected 7 entries"),
    ("objects.particles", "nowhere.json", "objects.particles: particles file 'nowhere.json' not found"),
])
def test_cli_reports_bad_input(tmp_path, where, value, fragment):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(put(GOOD, where, value)))
    result = CliRunner().invoke(app, ["run", str(path)])
    assert result.exit_code == 2
    output = result.output + (result.stderr if result.stderr_bytes is not None else "")
    assert fragment in output
    assert "Traceback" not in output


def test_cli_reports_broken_json(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text('{"fileFormat": "demdf",\n "time": }')
    result = CliRunner().invoke(app, ["run", str(path)])
    assert result.exit_code == 2
    output = result.output + (result.stderr if result.stderr_bytes is not None else "")
    assert "bad.json:2:" in output and "column 10" in output
