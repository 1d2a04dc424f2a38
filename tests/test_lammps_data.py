"""The one LAMMPS data-file writer (translate/lammps_data.py): layout and row formatting
checked against data files written out by hand."""

import numpy as np

from fibrelmp.translate.lammps_data import DataSection, data_file_text, write_data_file

EXPECTED = """\
LAMMPS data file written by hand

2 atoms
1 bonds
1 atom types
1 bond types

0.0 2.5 xlo xhi
-1.0 1.0 ylo yhi
-1.0 1.0 zlo zhi

Masses

1 0.1  # A m=0.1 R=0.5

Atoms # angle

1 1 1 0.10000000000000001 0 -0
2 1 1 1.0000000000000002 1.0000000000000001e+300 2.5

Bonds

1 1 1 2
"""


def test_data_file_layout_and_rows_as_written_by_hand(tmp_path):
    x = np.array([[0.1, 0.0, -0.0], [1.0000000000000002, 1e300, 2.5]])
    sections = [DataSection("Masses", "%d %s  # %s\n", [np.array([1]), ["0.1"], ["A m=0.1 R=0.5"]]),
                DataSection("Atoms # angle", "%d %d %d %.17g %.17g %.17g\n",
                            [np.array([1, 2]), np.array([1, 1]), np.array([1, 1]), x[:, 0], x[:, 1], x[:, 2]]),
                DataSection("Bonds", "%d %d %d %d\n", [np.array([1]), np.array([1]), np.array([1]), np.array([2])])]
    counts = [(2, "atoms"), (1, "bonds"), (1, "atom types"), (1, "bond types")]
    box = [(0.0, 2.5), (-1.0, 1.0), (-1.0, 1.0)]
    write_data_file(tmp_path / "data.lammps", "LAMMPS data file written by hand", counts, box, sections)
    assert (tmp_path / "data.lammps").read_text() == EXPECTED


def test_no_blank_before_box_and_empty_section_keeps_its_header():
    """CardioProof's layout: the box follows the counts directly; a section without rows is
    still written (its header), as read_data accepts it."""
    text = data_file_text("t", [(0, "atoms")], [(0, 1), (0, 1), (0, 1)],
                          [DataSection("Atoms # sph", "%d %d\n", [np.zeros(0, int), np.zeros(0, int)])],
                          blank_before_box=False)
    assert text == "t\n\n0 atoms\n0.0 1.0 xlo xhi\n0.0 1.0 ylo yhi\n0.0 1.0 zlo zhi\n\nAtoms # sph\n\n"
