"""The one thermo-log reader (fibrelmp/lammps_log.py), which the run record and the pictures
share: logs as fibrelmp's jobs write them, built here line by line."""

import math

import pytest

from fibrelmp.errors import InputError
from fibrelmp.lammps_log import ThermoLog
from fibrelmp.pictures.thermo import read_thermo
from fibrelmp.record import first_state, thermo

# renamed columns (thermo_modify colname), a 'run 0' block, a warning between rows, a nan row,
# a second run repeating the last step, and a log cut short inside its third run
LOG = """\
LAMMPS (2 Aug 2023)
units lj
thermo_modify colname ke KinGravEng norm no
Step Time KinGravEng
0 0 1.5
Loop time of 0 on 1 procs for 0 steps with 2 atoms
Step Time KinGravEng
0 0 1.25
WARNING: Bond/angle/dihedral extent > half of periodic box length (src/domain.cpp:1)
10 0.5 nan
20 1 2.5
Loop time of 0.1 on 1 procs for 20 steps with 2 atoms
run 10
Step Time KinGravEng
20 1 2.625
30 1.5 2.75
40 2.0 2.8125 9
50 2.
"""


@pytest.fixture
def log(tmp_path):
    path = tmp_path / "log.lammps"
    path.write_bytes(LOG.encode() + b"\xff\n")        # a byte that is not UTF-8, as a crash may leave
    return path


def test_blocks_keep_rows_after_warnings_and_of_a_run_cut_short(log):
    reader = ThermoLog(log)
    blocks = list(reader.blocks())
    assert [b.header for b in blocks] == [["Step", "Time", "KinGravEng"]] * 3
    assert [[r[0] for r in b.rows] for b in blocks] == [[0], [0, 10, 20], [20, 30]]
    assert math.isnan(blocks[1].rows[1][2])
    assert (reader.units, reader.norm) == ("lj", False)


def test_record_first_state_is_the_first_advancing_run_despite_a_warning(log):
    """Was: a warning ended the record's block, so the first advancing run looked like a
    one-row block and first_state took the next run's first row (Step 20, energy 2.625)
    for the summary's start energy."""
    assert first_state(log) == {"Step": 0.0, "Time": 0.0, "KinGravEng": 1.25}
    steps = [(r["Step"], r["KinGravEng"]) for r in thermo(log)]
    assert steps[0] == (0, 1.25) and steps[2:] == [(20, 2.625), (30, 2.75)]


def test_pictures_series_from_the_same_reader(log):
    t = read_thermo(log)
    assert t.sections == 3 and not t.per_atom
    assert list(t.columns["Step"]) == [0, 10, 20, 30]
    assert list(t.columns["KinGravEng"])[2:] == [2.625, 2.75]


@pytest.mark.parametrize("line, style", [("------------ Step 0 ----- CPU = 0 (sec) ----", "multi"),
                                         ("keywords: ['Step', 'Temp']", "yaml")])
def test_other_thermo_styles_are_refused_with_the_reason(tmp_path, line, style):
    path = tmp_path / "log.lammps"
    path.write_text(f"units lj\n{line}\n")
    with pytest.raises(InputError, match=style):
        list(ThermoLog(path).blocks())
