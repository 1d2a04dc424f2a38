"""MercuryDPM files written by fibrelmp have the layouts of MercuryDPM's own files
(tests/data/real-inputs/mercurydpm: a 2D run's .data/.ene/.fstat and a 3D .data)."""

from __future__ import annotations

import re

import numpy as np

from fibrelmp.post.mercury import ENE_HEADER, g10, read_data_file, read_ene, read_fstat

from .conftest import data_path
from .test_post_roundtrip import granular, granular2d, post  # noqa: F401  (fixtures)

REAL = ("real-inputs", "mercurydpm")


def _field_ends(line: str) -> list[int]:
    return [m.end() for m in re.finditer(r"\S+", line)]


def _shape(path, dim: int) -> tuple[int, int, set[int]]:
    """(header token count, particle column count, header line endings) of a .data file."""
    lines = path.read_text().splitlines()
    heads, cols, k = set(), set(), 0
    endings = set()
    while k < len(lines):
        h = lines[k].split()
        heads.add(len(h))
        endings.add(lines[k].endswith(" "))
        n = int(h[0])
        cols.update(len(ln.split()) for ln in lines[k + 1:k + 1 + n])
        k += 1 + n
    assert len(heads) == 1 and len(cols) <= 1, (heads, cols)
    return heads.pop(), (cols.pop() if cols else 0), endings


def test_real_files_parse_with_our_readers():
    d2 = read_data_file(data_path(*REAL, "PolydisperseInsertionBoundarySelfTest.data"))
    assert len(d2) == 51 and d2[1].rows.shape == (45, 8)
    d3 = read_data_file(data_path(*REAL, "TwoParticleCollisionInteractionWithLiquidMigrationWilletViscousSelfTest.data"))
    assert len(d3) == 22 and d3[0].rows.shape == (2, 14)
    labels, ene = read_ene(data_path(*REAL, "PolydisperseInsertionBoundarySelfTest.ene"))
    assert labels[0] == "time" and ene.shape == (26, 8)
    fst = read_fstat(data_path(*REAL, "PolydisperseInsertionBoundarySelfTest.fstat"))
    assert len(fst) == 26 and sum(len(f.rows) for f in fst) == 1246 + 217
    walls = np.concatenate([f.rows[f.rows[:, 2] < 0] for f in fst])
    assert len(walls) == 217


def test_data_layout_matches_real_3d(granular, tmp_path):  # noqa: F811
    post(granular / "atoms.dump", "mercury", tmp_path / "run")
    real = _shape(data_path(*REAL, "TwoParticleCollisionInteractionWithLiquidMigrationWilletViscousSelfTest.data"), 3)
    mine = _shape(tmp_path / "run.data", 3)
    assert mine == real == (8, 14, {True})


def test_data_layout_matches_real_2d(granular2d, tmp_path):  # noqa: F811
    post(granular2d / "atoms.dump", "mercury", tmp_path / "run", data=granular2d / "data.lammps")
    real = _shape(data_path(*REAL, "PolydisperseInsertionBoundarySelfTest.data"), 2)
    mine = _shape(tmp_path / "run.data", 2)
    assert mine == real == (6, 8, {True})
    # particles that do not rotate: MercuryDPM prints "-0 -0" for angle and -omega_z
    real_first = data_path(*REAL, "PolydisperseInsertionBoundarySelfTest.data").read_text().splitlines()[2]
    mine_first = (tmp_path / "run.data").read_text().splitlines()[1]
    assert real_first.split()[5:7] == mine_first.split()[5:7] == ["-0", "-0"]


def test_ene_layout_matches_real(granular, tmp_path):  # noqa: F811
    post(granular / "atoms.dump", "mercury", tmp_path / "run", gravity=(0, 0, -9.81))
    real = data_path(*REAL, "PolydisperseInsertionBoundarySelfTest.ene").read_text().splitlines()
    mine = (tmp_path / "run.ene").read_text().splitlines()
    assert mine[0] + "\n" == ENE_HEADER and mine[0] == real[0]      # byte-identical header
    # every row: 8 values right-aligned in 16 characters, one space apart
    ends = [16 + 17 * k for k in range(8)]
    for line in real[1:] + mine[1:]:
        assert len(line) == 135 and _field_ends(line) == ends, line


def test_fstat_layout_matches_real(granular, tmp_path):  # noqa: F811
    post(granular / "atoms.dump", "mercury", tmp_path / "run", local=granular / "contacts.dump")
    for path in (data_path(*REAL, "PolydisperseInsertionBoundarySelfTest.fstat"), tmp_path / "run.fstat"):
        lines = path.read_text().splitlines()
        comment_runs, k = 0, 0
        while k < len(lines):
            if lines[k].startswith("#"):
                assert [len(lines[k + j].split()) for j in range(3)] == [3, 7, 7]
                assert lines[k].split()[2] == "1"                       # fstat version 1
                assert lines[k + 2].split()[3:] == ["0", "0", "0", "0"]
                comment_runs += 1
                k += 3
            else:
                assert len(lines[k].split()) == 16
                k += 1
        assert comment_runs > 5
    mine = read_fstat(tmp_path / "run.fstat")
    assert sum(len(f.rows) for f in mine) > 20


def test_number_format_is_iostream_precision_10():
    assert [g10(v) for v in (0.0, -0.0, 2.060263205e-05, 0.1 + 0.2, 1e16, float("nan"), 123456789012.0)] == \
        ["0", "-0", "2.060263205e-05", "0.3", "1e+16", "nan", "1.23456789e+11"]
