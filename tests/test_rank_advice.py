"""The "too many MPI ranks" advice (``sanity.rank_check``, issue 17): ``fibrelmp run`` warns
when the ranks leave fewer particles per rank than the family's ``min_per_rank`` (measured crossovers,
docs/performance.md).  That the line is printed once, by rank 0, under ``mpiexec -n 2`` and
not in a serial run: tests/test_mpi.py::test_messages_are_printed_by_rank_0_only."""

from __future__ import annotations

import pytest

import fibrelmp
from fibrelmp import sanity
from fibrelmp.granmodel import GranularModel
from fibrelmp.model import Model

from .conftest import REPO


def _ranks_warnings(model) -> list[str]:
    return [text for kind, text in model.warnings if kind == "ranks"]


@pytest.fixture
def network():
    return fibrelmp.read(REPO / "examples" / "fibre_network" / "input.txt")      # 128 beads


def test_serial_run_is_never_warned(network):
    sanity.rank_check(network, 1)
    assert _ranks_warnings(network) == []


def test_small_network_on_two_ranks_is_warned_once(network):
    assert network.particles.count == 128
    sanity.rank_check(network, 2)
    (text,) = _ranks_warnings(network)
    assert "2 MPI ranks for 128 beads (64 per rank)" in text
    assert f"~{Model.min_per_rank} beads per rank" in text and "1 (no mpiexec)" in text


@pytest.mark.parametrize("ranks, warned, advice", [(2, False, None), (3, True, "mpiexec -n 2"),
                                                    (4, True, "mpiexec -n 2")])
def test_limit_is_particles_per_rank(network, monkeypatch, ranks, warned, advice):
    """128 beads with a limit of 64 per rank: 2 ranks are fine (exactly 64 each), 3 or 4 are
    too many, and 128 // 64 = 2 is the advice."""
    monkeypatch.setattr(Model, "min_per_rank", 64)
    sanity.rank_check(network, ranks)
    found = _ranks_warnings(network)
    assert bool(found) == warned
    if warned:
        assert advice in found[0] and f"{ranks} MPI ranks for 128 beads ({128 // ranks} per rank)" in found[0]


def test_granular_scenes_count_spheres(monkeypatch):
    scene = fibrelmp.read(REPO / "examples" / "musen" / "SphericalAgglomerate_text.txt")
    n = scene.spheres.count
    assert n == 5696
    monkeypatch.setattr(GranularModel, "min_per_rank", n // 2)
    sanity.rank_check(scene, 2)
    assert _ranks_warnings(scene) == []                  # 2848 per rank: at the limit
    sanity.rank_check(scene, 3)
    (text,) = _ranks_warnings(scene)
    assert f"3 MPI ranks for {n} spheres ({n // 3} per rank)" in text and "mpiexec -n 2" in text
