"""The contact heat models (fix musen/heat with pair musen/hm's heat/conduction, fix
musen/wall/mesh's heat/transfer and bond musen/elastic's heat) on 2 MPI ranks: the ghosts'
temperatures are sent before every evaluation (forward communication in fix musen/heat's
pre_force), a bond's flux into a ghost goes back to its owner (reverse communication in
post_force), pair musen/hm's half list is newton off (each rank adds only to its own sphere),
and a sphere that changes rank takes its temperature along (fix property/atom).

Case (tests/data/real-outputs/musen/models/heat_mpi, README.md): a bonded chain on a plate and a
colliding pair, both across the ranks' boundary z = 0, and a sphere that changes rank.  Serial
and 2-rank runs write the same bytes: each sphere's flux has at most two terms summed before
the reverse communication adds the ghost's (a + b = b + a in floating point), so here the order
does not matter; a sphere with three or more contributions split over ranks may differ in the
last bit (summation order).  Both equal cmusen's temperatures bit for bit."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.translate.musen.scene import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_reference_is_cmusens_output,
                                 needs_cmusen, styles_or_skip)
from .test_mpi import assert_ran, assert_same_files, pytestmark, serial_and_mpi  # noqa: F401

TEMPERATURE = 37
CASE = data_path("real-outputs/musen/models/heat_mpi")
SPHERES = 7


@pytest.fixture(scope="module")
def heat_runs(tmp_path_factory):
    styles_or_skip()

    def populate(case: Path) -> None:
        for name in ("hmpi_scene.txt", "job_hmpi.txt"):
            shutil.copy(CASE / name, case)

    return serial_and_mpi(tmp_path_factory.mktemp("heat"), populate, ["run", "job_hmpi.txt"])


def test_two_ranks_write_the_serial_result_bitwise(heat_runs):
    assert_ran(heat_runs)
    assert_same_files(heat_runs)
    ser, mpi = heat_runs["serial"][0], heat_runs["mpi"][0]
    log = (mpi / "job_hmpi_work" / "job2" / "log.lammps").read_text()
    assert "1 by 1 by 2 MPI processor grid" in log       # the split the scene was made for
    assert (mpi / "hmpi_result_prec17.txt").read_bytes() == (ser / "hmpi_result_prec17.txt").read_bytes()


def test_the_case_crosses_the_ranks(heat_runs):
    """Bond 1-2, the colliding pair and the sliding sphere's path cross z = 0; every sphere that
    touches something changed its temperature."""
    ours = read_time_points(heat_runs["mpi"][0] / "hmpi_result_prec17.txt")
    z = ours.fields[COORD][:, :SPHERES, 2]
    assert z[0, 1] < 0 < z[0, 2] and z[0, 4] < 0 < z[0, 5]
    assert z[0, 6] < 0 < z[-1, 6]
    temp = ours.fields[TEMPERATURE][:, :SPHERES, 0]
    assert np.all(np.abs(temp[-1] - temp[0]) > 0.2)
    assert np.abs(temp[-1, :4] - temp[0, :4]).min() > 50


@pytest.mark.parametrize("run", ["serial", "mpi"])
def test_both_are_cmusens(heat_runs, run):
    """Every saved time: temperatures (measured: bit for bit), positions' displacements,
    velocities and angular velocities (3e-17 of scale) within 1e-6 of scale."""
    ours = read_time_points(heat_runs[run][0] / "hmpi_result_prec17.txt")
    theirs = read_time_points(CASE / "cmusen_hmpi_result_prec17.txt")
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    x0 = theirs.fields[COORD][0, :SPHERES]
    for tag in (COORD, VEL, ANGVEL, TEMPERATURE):
        a, b = ours.fields[tag][:, :SPHERES], theirs.fields[tag][:, :SPHERES]
        if tag == COORD:
            a, b = a - x0, b - x0
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.abs(b).max(), err_msg=str(tag))


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, CASE, "hmpi")
