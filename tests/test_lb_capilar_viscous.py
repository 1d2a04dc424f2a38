"""ModelLBCapilarViscous and liquid bonds (translate/granular/models/lb_capilar_viscous.py,
translate/musen/liquid_bonds.py), against the real cmusen 1.74.2
(tests/data/real-outputs/musen/models/lb_capilar_viscous/README.md):

* MUSEN e0ff360's law is commented out: liquid bonds exert no force; fibrelmp's spheres are
  cmusen's at every saved time, with a warning that the law is a no-op;
* the liquid bonds' result records and activity ends are cmusen's, in the text result and in
  the .mdem (a bond active at the start ends at the last save; one inactive at the start is
  an object of type 0, left out of the text export);
* a job with no PP model runs without sphere-sphere contacts, with a warning, as cmusen does;
* snapshots draw the liquid bonds active at a frame's time.
"""

from __future__ import annotations

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.translate.musen import scene as musen_scene
from fibrelmp.translate.musen.liquid_bonds import LiquidBondActivity
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_reference_is_cmusens_output,
                                 check_resume_is_bitwise, model_job, needs_cmusen, styles_or_skip)

LB = data_path("real-outputs/musen/models/lb_capilar_viscous")
FORCE = 20                      # MUSEN text tag of the saved force


def _object_lines(path, ids) -> dict[int, str]:
    """The text result's object lines of ``ids`` (object id -> line)."""
    out = {}
    for line in path.read_text().splitlines():
        tok = line.split(maxsplit=2)
        if len(tok) == 3 and tok[0] == "0" and int(tok[1]) in ids:
            out[int(tok[1])] = line
    return out


def _run(tmp_path, prefix):
    job = model_job(tmp_path, LB, prefix, "")
    result = python_api.run(job, work=tmp_path / "work")
    return result, read_time_points(tmp_path / f"{prefix}_result_prec17.txt"), \
        read_time_points(LB / f"cmusen_{prefix}_result_prec17.txt")


def _spheres_are_cmusens(ours, theirs) -> None:
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    assert np.array_equal(ours.ids, theirs.ids)
    for tag in (COORD, VEL, ANGVEL, FORCE):
        a, b = ours.fields[tag][:, :2], theirs.fields[tag][:, :2]     # the two spheres
        scale = np.abs(b).max()
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * scale)   # measured: 0


@needs_cmusen
@pytest.mark.parametrize("prefix", ["lb", "nopp", "dom"])
def test_reference_is_cmusens_output(tmp_path, prefix):
    check_reference_is_cmusens_output(tmp_path, LB, prefix)


def test_liquid_bonds_exert_no_force_as_in_cmusen(tmp_path):
    styles_or_skip()
    result, ours, theirs = _run(tmp_path, "lb")
    # the spheres collide (Hertz-Mindlin acts), the bonds add nothing: cmusen's spheres
    v = theirs.fields[VEL]
    assert np.linalg.norm(v[-1, :2] - v[0, :2], axis=1).min() > 0.05
    _spheres_are_cmusens(ours, theirs)
    kinds = [k for k, _ in result.warnings]
    assert "musen-liquid-bond-no-op" in kinds and "musen-liquid-bonds" in kinds
    text = dict(result.warnings)["musen-liquid-bond-no-op"]
    assert "job_lb.txt:11: ModelLBCapilarViscous: its law is a no-op" in text   # its PARAMS line
    # the bonds' records (times only) and activity ends, character for character: bond 2
    # (scene end 3e-5) ends at the last save, 4 keeps 1e+300, 3 (from 1e-5) is left out
    ours_lines = _object_lines(tmp_path / "lb_result_prec17.txt", {2, 3, 4})
    theirs_lines = _object_lines(LB / "cmusen_lb_result_prec17.txt", {2, 3, 4})
    assert sorted(theirs_lines) == [2, 4]
    assert ours_lines == theirs_lines
    assert " 24 0 6e-05 2 0 2 1.0000000000000004e-06 " in theirs_lines[2]


def test_mdem_result_holds_cmusens_liquid_bonds(tmp_path):
    """The .mdem's objects as cmusen's result holds them (read from its protobuf): types and
    exact activity ends; the expected end of bond 2 is cmusen's last saved time."""
    styles_or_skip()
    from fibrelmp.translate.musen.mdem.document import MdemFile

    _run(tmp_path, "lb")
    last = float(read_time_points(LB / "cmusen_lb_result_prec17.txt").times[-1])
    with MdemFile(tmp_path / "lb_result.mdem") as mdem:
        p = mdem.storage.info.particles
        got = [(p[i].type, p[i].activity_start, p[i].activity_end) for i in range(len(p))]
    assert got == [(1, 0.0, 1e300), (1, 0.0, 1e300), (13, 0.0, last), (0, 1e-5, 2e-5),
                   (13, 0.0, 1e300)]


def test_no_pp_model_runs_without_contacts_as_cmusen(tmp_path):
    styles_or_skip()
    result, ours, theirs = _run(tmp_path, "nopp")
    # cmusen's spheres pass through each other: their velocities never change
    v = theirs.fields[VEL][:, :2]
    assert np.array_equal(v, np.broadcast_to(v[0], v.shape))
    assert np.abs(theirs.fields[FORCE][:, :2]).max() == 0
    _spheres_are_cmusens(ours, theirs)
    assert "neigh_modify    exclude group spheres spheres" in \
        (tmp_path / "work/job2/in.lammps").read_text()
    text = dict(result.warnings)["musen-no-pp-model"]
    assert "job_nopp.txt:5: job 2: no particle-particle model" in text


def test_activity_follows_musens_save_rule(tmp_path):
    """BaseSimulator::SaveData and CPUSimulator's removal of a sphere leaving the domain,
    worked by hand: a bond active at the start ends at the last save it is active at; a
    sphere's removal ends its bonds at that save; an inactive bond is left as it is."""
    model = musen_scene.read(LB / "lb_scene.txt")
    model.plan.t_start = 0.0
    act = LiquidBondActivity(model)                 # bonds 2 (0..3e-5), 3 (1e-5..2e-5), 4 (0..inf)
    assert act.active.tolist() == [True, False, True] and act.untyped.tolist() == [False, True, False]
    both = np.ones(2, bool)
    for t in (0.0, 1e-5, 2e-5, 4e-5):
        act.save(t, both)
    assert act.end.tolist() == [4e-5, 2e-5, np.inf]      # (the scene reader: 1e+300 is inf)
    # sphere 1 left before the save at 5e-5: bond 4 (active by its interval then) ends there;
    # bond 2's interval, 0..4e-5 by now, does not hold 5e-5: SaveData skips it, its end stays
    act.save(5e-5, np.array([True, False]))
    act.save(6e-5, np.array([True, False]))
    assert act.end.tolist() == [4e-5, 2e-5, 5e-5] and not act.active.any()


def test_snapshots_draw_liquid_bonds(tmp_path):
    styles_or_skip()
    pytest.importorskip("matplotlib")
    from fibrelmp import pictures

    _run(tmp_path, "lb")
    for result in ("lb_result_prec17.txt", "lb_result.mdem"):
        # t = 1e-5: bonds 2 and 4 (3 is not in the result); last save (6.0000000000007e-05,
        # after bond 2's stored end, 6e-05): bond 4 alone
        mid = pictures.snapshot(tmp_path / result, tmp_path / f"{result}.mid.png", frame=10)
        end = pictures.snapshot(tmp_path / result, tmp_path / f"{result}.end.png", frame=-1)
        assert (mid.liquid_bonds, end.liquid_bonds, mid.bonds) == (2, 1, 0), result


@pytest.mark.parametrize("prefix", ["lb", "nopp"])
def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch, prefix):
    """The liquid bonds' activity ends and the excluded contacts survive a resume."""
    check_resume_is_bitwise(tmp_path, monkeypatch, lambda at: model_job(at, LB, prefix, ""),
                            (f"{prefix}_result_prec17.txt", f"{prefix}_result.mdem"), 2500)


def test_a_sphere_leaving_the_domain_ends_its_liquid_bonds(tmp_path):
    """job_dom.txt: sphere 1 leaves the domain at 3.334e-5 s.  cmusen ends bond 4 (0..1e+300)
    at that step's time; bond 2, whose interval had been raised to the save at 3.3e-5 only,
    keeps 3.3e-5.  fibrelmp ends bond 4 at the next save, 3.4e-5, as it ends the sphere (the
    deviation `musen-liquid-bonds` states); every other character is cmusen's."""
    styles_or_skip()
    result, _, _ = _run(tmp_path, "dom")
    assert "the next save's time" in dict(result.warnings)["musen-liquid-bonds"]
    ours = _object_lines(tmp_path / "dom_result_prec17.txt", {1, 2, 4})
    theirs = _object_lines(LB / "cmusen_dom_result_prec17.txt", {1, 2, 4})
    assert ours[2] == theirs[2] and " 24 0 3.3e-05 " in theirs[2]
    assert theirs[4].replace(" 24 0 3.334e-05 ", " 24 0 3.4e-05 ") == ours[4]
    assert " 24 0 3.334e-05 " in theirs[1] and " 24 0 3.4e-05 " in ours[1]
