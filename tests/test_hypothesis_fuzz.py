"""Fuzzing the readers with random byte mutations of real and valid files: whatever the bytes,
the only exception that may escape is fibrelmp's own InputError (naming a file), and no numpy
warning may reach the user's terminal.  ``fibrelmp check``'s every-error mode
(``textio.collect_errors``) is fuzzed the same way: it must end, with InputErrors only.

Examples are bounded (``PROFILE``) so CI stays fast; ``FIBRELMP_HYPOTHESIS_EXAMPLES=2000``
explores more, ``FIBRELMP_HYPOTHESIS_RANDOM=1`` draws new examples on every run.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import warnings
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fibrelmp.errors import InputError
from fibrelmp.post.complete import Completer
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.textio import collect_errors
from fibrelmp.translate.demdf import reader as demdf
from fibrelmp.translate.fibrenet import reader as fibrenet
from fibrelmp.translate.musen import scene as musen
from fibrelmp.translate.musen import script as ms

PROFILE = settings(max_examples=int(os.environ.get("FIBRELMP_HYPOTHESIS_EXAMPLES", "300")),
                   deadline=None, database=None,
                   derandomize=not os.environ.get("FIBRELMP_HYPOTHESIS_RANDOM"),
                   suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
CORPUS = REPO / "tests" / "bad_inputs"

# tokens that stress number parsing, line structure, encodings and each format's keywords
TOKENS = [b"nan", b"inf", b"-inf", b"-1", b"0", b"-0", b"1e400", b"1e-400", b"1.5", b"2", b"12",
          b"23", b"24", b"99999999999999999999", b"x", b"\t", b"\r\n", b"\r", b"\n", b" ",
          b"\x00", b"\xff", b"\xef\xbb\xbf", b"#", b"BEAD", b"SPRING", b"ANGLE", b"type",
          b"pair", b"JOB", b"COMPONENT", b"ITEM:", b"ITEM: ATOMS", b"{", b"}", b"[", b"]", b",",
          b'"', b"null", b"true"]


@st.composite
def mutations(draw, base: bytes) -> bytes:
    """1 to 4 edits: a byte changed, a span deleted, a token inserted or put in place of a
    token, a line duplicated or dropped, or the file cut short."""
    data = bytearray(base)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["byte", "delete", "insert", "token", "dup", "drop", "cut"]))
        at = draw(st.integers(0, max(len(data) - 1, 0)))
        if op == "byte" and data:
            data[at] = draw(st.integers(0, 255))
        elif op == "delete":
            del data[at:at + draw(st.integers(1, 40))]
        elif op == "insert":
            data[at:at] = draw(st.sampled_from(TOKENS))
        elif op == "token":
            start = end = at
            while start > 0 and data[start - 1] not in b" \t\n":
                start -= 1
            while end < len(data) and data[end] not in b" \t\n":
                end += 1
            data[start:end] = draw(st.sampled_from(TOKENS))
        elif op in ("dup", "drop"):
            lines = bytes(data).split(b"\n")
            k = draw(st.integers(0, len(lines) - 1))
            if op == "dup":
                lines.insert(draw(st.integers(0, len(lines))), lines[k])
            else:
                del lines[k]
            data = bytearray(b"\n".join(lines))
        elif op == "cut":
            del data[at:]
    return bytes(data)


@contextmanager
def only_input_errors() -> Iterator[None]:
    """Readers may raise InputError (naming a file) and nothing else, and print no warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # a RuntimeWarning would reach the terminal
        try:
            yield
        except InputError as exc:
            assert exc.path is not None, f"InputError without a file: {exc}"


def _check_mode(read: Callable[[], object], patch) -> None:
    """``fibrelmp check``: all errors of the file; must end and raise nothing itself."""
    try:
        read()
    except InputError as first:
        errors = collect_errors(read, first, patch)
        assert errors and all(isinstance(e, InputError) for e in errors)


def _copy(folder: Path, *files: Path) -> None:
    for f in files:
        shutil.copy(f, folder / f.name)


# ------------------------------------------------------------------ FibreNet
FIBRENET = [(EXAMPLES / "fibrenet_readme" / "input.txt", EXAMPLES / "fibrenet_readme" / "test_model.txt"),
            (EXAMPLES / "fibre_network" / "input.txt", EXAMPLES / "fibre_network" / "model.txt"),
            (CORPUS / "fibrenet" / "good.txt", CORPUS / "fibrenet" / "model.txt")]


@st.composite
def fibrenet_mutants(draw):
    inp, model = draw(st.sampled_from(FIBRENET))
    which = draw(st.sampled_from(["input", "model"]))
    data = draw(mutations((inp if which == "input" else model).read_bytes()))
    return inp, model, which, data


@PROFILE
@given(fibrenet_mutants(), st.booleans())
def test_fuzz_fibrenet(case, check_mode):
    inp, model, which, data = case
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        _copy(folder, inp, model)
        (folder / (inp.name if which == "input" else model.name)).write_bytes(data)
        with only_input_errors():
            if check_mode:
                _check_mode(lambda: fibrenet.read(folder / inp.name),
                            fibrenet.check_patch(folder / inp.name))
            else:
                fibrenet.read(folder / inp.name)


# ------------------------------------------------------------------ MUSEN scenes and scripts
SCENES = [EXAMPLES / "musen" / "SingelParticle_text.txt", CORPUS / "musen" / "good.txt"]


@PROFILE
@given(st.sampled_from(SCENES).flatmap(lambda p: mutations(p.read_bytes())), st.booleans())
def test_fuzz_musen_scene(data, check_mode):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.txt"
        path.write_bytes(data)
        with only_input_errors():
            if check_mode:
                _check_mode(lambda: musen.read(path), musen.check_patch)
            else:
                musen.read(path)
        with only_input_errors():
            musen.read_time_points(path)


SCRIPT = CORPUS / "musen_script" / "good.txt"


def _simulate_settings(script: Path) -> None:
    for job in ms.read_script(script):
        if job.component == "SIMULATOR":
            ms.apply_simulator_settings(musen.read(script.parent / "scene.txt"), job)


@PROFILE
@given(mutations(SCRIPT.read_bytes()), st.booleans())
def test_fuzz_cmusen_script(data, check_mode):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        _copy(folder, CORPUS / "musen_script" / "scene.txt")
        script = folder / "job.txt"
        script.write_bytes(data)
        with only_input_errors():
            if check_mode:
                _check_mode(lambda: _simulate_settings(script), ms.check_patch)
            else:
                _simulate_settings(script)


# ------------------------------------------------------------------ DEMDF
DOCUMENTS = sorted((EXAMPLES / "demdf").glob("*.json")) + [CORPUS / "demdf" / "good.json"]


@PROFILE
@given(st.sampled_from(DOCUMENTS).flatmap(lambda p: mutations(p.read_bytes())))
def test_fuzz_demdf(data):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "case.json"
        path.write_bytes(data)
        with only_input_errors():
            demdf.read(path)


# ------------------------------------------------------------------ LAMMPS dumps
RICH = "".join(
    f"ITEM: TIME\n{0.1 * s}\nITEM: TIMESTEP\n{s}\nITEM: NUMBER OF ATOMS\n4\n"
    "ITEM: BOX BOUNDS xy xz yz pp pp ff\n0 10 0.5\n0 10 0\n0 10 0\n"
    "ITEM: ATOMS id type xs ys zs ix iy iz vx vy vz fx fy fz radius mass\n"
    + "".join(f"{i} {1 + i % 2} 0.{i}1 0.{i}2 0.{i}3 {i - 2} 0 1 0.1 0.2 0.3 1 2 3 0.5 1\n"
              for i in (4, 1, 3, 2))
    for s in (0, 10, 20)).encode()
DUMPS = [CORPUS / "dump" / "good.dump", None]


@PROFILE
@given(st.sampled_from(DUMPS).flatmap(lambda p: mutations(RICH if p is None else p.read_bytes())))
def test_fuzz_dump(data):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "frames.dump"
        path.write_bytes(data)
        complete = Completer(None, None, {}, [])
        with only_input_errors():
            for frame in iter_frames(path, []):
                complete(frame).wrapped()
