"""The bad-input corpus (tests/bad_inputs/, docs/errors.md): every malformed input exits with
code 2 and one ``error: path[:line]: message`` without a traceback, writes nothing and leaves
existing outputs alone; inputs accepted on purpose check cleanly; the documented messages are
the real ones."""

from __future__ import annotations

import hashlib
import re
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest

from tests.bad_inputs.corpus import (CASES, CORPUS, Case, doc_rows, row, run_case,
                                     unreadable_possible)

# files that are part of a case without being one (a case's model file, a script's scene)
HELPERS = re.compile(r"(fibrenet_model/model_\w+|fibrenet/model|musen_script/(scene|broken_scene))"
                     r"\.txt$|\.py$")
LOCATION = re.compile(r"^(<tmp>|<corpus>)?[\w./-]+(:\d+)?: \S")


def _snapshot(folder: Path) -> dict[str, str]:
    out = {}
    for p in sorted(folder.rglob("*")):
        if "__pycache__" in p.parts:
            continue
        try:
            out[str(p.relative_to(folder))] = hashlib.sha1(p.read_bytes()).hexdigest() \
                if p.is_file() else "dir"
        except OSError:
            out[str(p.relative_to(folder))] = "unreadable"
    return out


def test_corpus_size_and_every_file_is_a_case():
    rejected = Counter(c.fmt for c in CASES if not c.accept)
    assert sum(rejected.values()) >= 40, rejected
    for fmt in ("FibreNet input", "FibreNet model", "MUSEN scene", "cmusen script", "DEMDF",
                "LAMMPS dump"):
        assert rejected[fmt] >= 5, (fmt, rejected)
    used = {c.path for c in CASES if c.path}
    files = {str(p.relative_to(CORPUS)) for p in CORPUS.rglob("*")
             if p.is_file() and "__pycache__" not in p.parts}
    orphans = {f for f in files - used if not HELPERS.search(f)}
    assert not orphans, f"corpus files no case uses: {sorted(orphans)}"
    missing = {p for p in used - files if not p.startswith("generic/missing")}
    assert not missing, missing
    assert len({c.name for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_case(case: Case, tmp_path):
    if case.needs_unreadable and not unreadable_possible(tmp_path):
        pytest.skip("running as root (or with CAP_DAC_OVERRIDE): chmod 000 does not stop "
                    "reading, so an unreadable file cannot be made")
    before_corpus = _snapshot(CORPUS)
    args = case.args(tmp_path)
    before_tmp = _snapshot(tmp_path)
    outcome = run_case(case, tmp_path, args)
    assert outcome.exception is None, f"{type(outcome.exception).__name__}: {outcome.exception}"
    assert "Traceback" not in outcome.stdout + outcome.stderr
    if case.accept:
        assert outcome.exit_code == 0, outcome.stderr
        assert outcome.errors == []
    else:
        assert outcome.exit_code == 2, outcome.stderr
        assert len(outcome.errors) == 1, outcome.errors
        assert LOCATION.match(outcome.errors[0]), outcome.errors[0]
        # nothing written, existing outputs untouched (accepted post cases write into tmp)
        assert _snapshot(tmp_path) == before_tmp
    assert _snapshot(CORPUS) == before_corpus
    documented = doc_rows()
    assert case.name in documented, f"{case.name} is not in docs/errors.md: run make_table.py"
    assert documented[case.name] == row(case, outcome), \
        "docs/errors.md differs from the real message: run tests/bad_inputs/make_table.py"


def test_doc_table_lists_exactly_the_cases():
    assert set(doc_rows()) == {c.name for c in CASES}


def test_readme_troubleshooting_quotes_real_messages():
    """Every message quoted in README's Troubleshooting table is (a part of) a message the
    corpus produces, so the section cannot drift from what fibrelmp prints."""
    readme = (CORPUS.parents[1] / "README.md").read_text()
    section = readme.split("## Troubleshooting", 1)[1].split("\n## ", 1)[0]
    messages = [r.split(" | ")[-1] for r in doc_rows().values()]      # "message |"
    quoted = 0
    for line in section.splitlines():
        if not line.startswith("| ") or line.startswith(("| message", "|---")):
            continue
        cell = line.split(" | ")[0][2:]
        for span in re.findall(r"``(.+?)``|`([^`]+)`", cell):
            text = span[0] or span[1]
            if text.startswith("run failed:"):
                continue                          # a LAMMPS failure, not a corpus case
            parts = [p.strip() for p in re.split(r"…|\.\.\.", text) if p.strip()]
            assert any(all(p in m for p in parts) for m in messages), text
            quoted += 1
    assert quoted >= 20


# ------------------------------------------------------------------ through real processes
def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fibrelmp.cli", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def _bad_run(proc: subprocess.CompletedProcess) -> str:
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 1, proc.stderr
    return errors[0]


SENTINEL = "an earlier result: must survive\n"


@pytest.mark.parametrize("case, copies, outputs, extra", [
    ("fibrenet/unknown_keyword.txt", ["fibrenet/model.txt"],
     ["out_coord.xyz", "out_vel.xyz", "out_force.xyz", "out_restart.res"], []),
    ("fibrenet_model/zero_length_spring.txt", ["fibrenet_model/model_zero_length_spring.txt"],
     ["out_coord.xyz", "out_restart.res"], []),
    ("musen/negative_radius.txt", [], ["result.txt"],
     ["-o", "result.txt", "--end-time", "1e-3", "--step", "1e-7", "--save-step", "1e-4"]),
    ("musen_script/model_typo.txt", ["musen_script/scene.txt"], ["result.txt"], []),
    ("demdf/outside_domain.json", [], ["out_0.json", "out_1.json"], []),
], ids=["fibrenet-input", "fibrenet-model", "musen-scene", "cmusen-script", "demdf"])
def test_run_writes_nothing_and_keeps_outputs(tmp_path, case, copies, outputs, extra):
    for rel in [case] + copies:
        shutil.copy(CORPUS / rel, tmp_path / Path(rel).name)
    for name in outputs:
        (tmp_path / name).write_text(SENTINEL)
    before = _snapshot(tmp_path)
    message = _bad_run(_cli("run", Path(case).name, *extra, cwd=tmp_path))
    assert message.startswith(f"error: {Path(case).name}:") or "model_" in message, message
    assert _snapshot(tmp_path) == before         # no new file or folder, outputs untouched


@pytest.mark.parametrize("to, outputs", [
    ("xyz", ["out_coord.xyz"]), ("vtk", ["out.pvd", "out_000000.vtp", "out_000001.vtp"]),
    ("demdf", ["out_0.json", "out_1.json"]), ("res", ["out_restart.res"]),
])
def test_post_force_keeps_outputs_when_a_later_frame_is_bad(tmp_path, to, outputs):
    """--force replaces outputs only once the whole conversion has succeeded."""
    for name in outputs:
        (tmp_path / name).write_text(SENTINEL)
    before = _snapshot(tmp_path)
    dump = CORPUS / "dump" / "not_a_number.dump"          # the second frame is bad
    message = _bad_run(_cli("post", str(dump), "--to", to, "-o", str(tmp_path / "out"),
                            "--force", cwd=tmp_path))
    assert "not_a_number.dump:23: column 'y'" in message
    assert _snapshot(tmp_path) == before


def test_post_force_replaces_outputs_after_success(tmp_path):
    (tmp_path / "out_000007.vtp").write_text(SENTINEL)      # frames of an earlier conversion
    (tmp_path / "out_000003.vtu").write_text(SENTINEL)      # (as fibrelmp wrote them before)
    (tmp_path / "out.pvd").write_text(SENTINEL)
    proc = _cli("post", str(CORPUS / "dump" / "good.dump"), "--to", "vtk", "-o",
                str(tmp_path / "out"), "--force", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.pvd", "out_000000.vtp",
                                                           "out_000001.vtp"]
    assert (tmp_path / "out.pvd").read_text() != SENTINEL
