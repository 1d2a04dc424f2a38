"""MUSEN text reader, result writer and cmusen script parser, against MUSEN's own files."""

import os
import gzip
import math
import shutil

import numpy as np
import pytest

from fibrelmp.granmodel import GranularFrame
from fibrelmp.translate.musen.writer import MusenResultWriter
from fibrelmp.translate.musen import scene as musen
from fibrelmp.translate.musen import script as ms

from .conftest import REPO, data_path

EX = REPO / "examples" / "musen"
SINGLE = EX / "SingelParticle_text.txt"
AGGLO = EX / "SphericalAgglomerate_text.txt"


@pytest.fixture(scope="module")
def agglo_result(tmp_path_factory):
    """The real 12-time-point MUSEN result, unpacked once (64 MB)."""
    src = data_path("real-outputs", "musen", "agglomerate", "agglo_result.txt.gz")
    dst = tmp_path_factory.mktemp("musen") / "agglo_result.txt"
    with gzip.open(src, "rb") as fi, open(dst, "wb") as fo:
        shutil.copyfileobj(fi, fo, 1 << 22)
    return dst


def raw_fields(line: str, tag: int, size: int) -> list[list[float]]:
    """Independent reading of one object line: every `tag` field's values, in order."""
    tok = line.split()
    start = tok.index("2")
    out, i = [], start
    sizes = musen.TD_SIZE
    while i < len(tok):
        t = int(tok[i])
        if t == tag:
            out.append([float(x) for x in tok[i + 1:i + 1 + size]])
        i += 1 + sizes[t]
    return out


# ------------------------------------------------------------------ real scenes

def test_single_particle_scene():
    m = musen.read(SINGLE)
    assert m.kind == "musen"
    assert m.triangles.ids.tolist() == list(range(12))
    assert m.spheres.ids.tolist() == [12]
    assert m.spheres.velocity[0].tolist() == [0.0, 0.0, -0.5]
    assert m.spheres.position[0].tolist() == [0.0, 0.0, 0.005]
    assert m.spheres.mass[0] == pytest.approx(2500 * 4 / 3 * math.pi * 0.0005 ** 3, rel=1e-15)
    # old vertex encoding: 12 = V1, 31 = V2 (x y z 0), 16 = V3 (first wall line of the file)
    assert m.triangles.vertices[0].tolist() == [[0.00598675, 0.00594779, -0.002],
                                                [-0.00598675, 0.00594779, -0.002],
                                                [-0.00598675, 0.00594779, -0.001]]
    glass, steel = (m.materials[[x.name for x in m.materials].index(n)] for n in ("Glass", "Steel"))
    assert (glass.density, glass.youngs, glass.poisson) == (2500, 5e10, 0.22)
    assert glass.props[1] == 1000 and glass.props[3] == 0.5      # DefinesMDB.h defaults
    law = m.contact(m.spheres.material[0], m.triangles.material[0])
    e_star = 1 / ((1 - 0.22 ** 2) / 5e10 + (1 - 0.3 ** 2) / 2e11)
    assert law.youngs_eff == pytest.approx(e_star, rel=1e-14)
    assert (law.restitution, law.friction, law.rolling_friction) == (0.8, 0.6, 0.05)
    (g,) = m.geometries
    assert (g.name, g.rotate_around_centre, g.motion_type) == ("Plate", None, 0)
    assert sorted(m.triangles.ids[g.triangle_rows].tolist()) == list(range(12))
    lo, hi = m.plan.domain
    assert lo.tolist() == [-0.00748344, -0.00743473, -0.0029375] and hi[2] == 0.0264375
    assert math.isnan(m.plan.dt) and math.isnan(m.plan.t_end) and m.plan.t_start == 0
    assert not m.plan.gravity.any()
    assert m.spheres.active_end[0] == math.inf
    assert m.warnings == []


def test_agglomerate_scene():
    m = musen.read(AGGLO)
    assert (m.spheres.count, m.bonds.count, m.triangles) == (5696, 18802, None)
    # last line of the file: 0 24497 1 9 5 5683 5688 0.0005999... 0.001273409999...
    assert m.bonds.ids[-1] == 24497
    assert m.spheres.ids[m.bonds.pair[-1]].tolist() == [5683, 5688]
    assert m.bonds.length0[-1] == 0.001273409999999999993314237
    assert m.bonds.diameter[-1] == 0.0006
    assert m.bonds.force is None and m.bonds.active_end[-1] == math.inf
    kinds = [w[0] for w in m.warnings]
    assert "musen-outside-domain" in kinds            # the scene's own 1 mm domain


# ------------------------------------------------------------------ real results

def test_real_result_time_points(agglo_result):
    tp = musen.read_time_points(agglo_result)
    assert len(tp.times) == 12
    assert tp.times[0] == 0 and tp.times[-1] == 2.0001e-4
    assert np.allclose(tp.times[1:11], np.arange(1, 11) * 2e-5, rtol=0, atol=1e-12)
    assert len(tp.ids) == 5696 + 18802 and tp.ids[0] == 0 and tp.ids[-1] == 24497
    sph = tp.types == 1
    # README: mean sphere vz at the end -0.0019617 m/s (= -g t)
    assert np.mean(tp.fields[15][-1, sph, 2]) == pytest.approx(-0.0019617, abs=5e-7)
    assert not np.isnan(tp.fields[12][:, sph]).any()
    assert np.isnan(tp.fields[45][:, sph]).all()           # bonds-only field
    # independent check on one line
    with open(agglo_result) as fh:
        first = fh.readline()
    pos = raw_fields(first, 12, 3)
    assert np.array_equal(tp.fields[12][:, 0], np.array(pos))


def test_real_result_as_scene(agglo_result):
    m = musen.read(agglo_result)
    assert m.plan.t_start == 2.0001e-4
    assert m.plan.domain[0].tolist() == [-0.02] * 3          # the job's domain was stored
    with open(agglo_result) as fh:
        first = fh.readline()
    assert m.spheres.position[0].tolist() == raw_fields(first, 12, 3)[-1]
    assert m.spheres.velocity[0].tolist() == raw_fields(first, 15, 3)[-1]
    assert m.bonds.force is not None and np.abs(m.bonds.force).max() < 0.2   # README: max 0.11 N
    assert np.isinf(m.bonds.active_end).all()                # no bond broke
    assert not [w for w in m.warnings if w[0] == "musen-outside-domain"]


@pytest.mark.tier2    # long reference comparison: second tier (pytest -m tier2; .ci/run runs it)
def test_real_prec17_agrees_with_prec6(agglo_result, tmp_path):
    src = data_path("real-outputs", "musen", "agglomerate", "agglo_result_final_prec17.txt.gz")
    dst = tmp_path / "prec17.txt"
    dst.write_bytes(gzip.decompress(src.read_bytes()))
    fine = musen.read_time_points(dst, types=(1,), tags=(12,))
    coarse = musen.read_time_points(agglo_result, types=(1,), tags=(12,))
    assert len(fine.times) == 2 and fine.times[0] == pytest.approx(2e-4, rel=1e-9)
    assert np.array_equal(fine.ids, coarse.ids)
    # the 6-digit file is the 17-digit one rounded
    assert np.allclose(fine.fields[12], coarse.fields[12][-2:], rtol=6e-6, atol=0)


# ------------------------------------------------------------------ writer

def frames_from(model, times, shift=1e-7, drop_sphere_at=None, break_bond_at=None):
    sp = model.spheres
    for k, t in enumerate(times):
        rows = np.arange(sp.count)
        if drop_sphere_at is not None and t >= drop_sphere_at[1]:
            rows = rows[rows != drop_sphere_at[0]]
        f = GranularFrame(time=t, step=k, sphere_rows=rows,
                          position=sp.position[rows] + k * shift * np.array([1, 2, 3]),
                          velocity=sp.velocity[rows] + k * 1e-3, omega=sp.omega[rows] - k * 0.5,
                          force=np.tile([k * 1e-3, 2e-3, -k / 3], (len(rows), 1)),
                          quaternion=np.tile([1.0, 0, 0, 0], (len(rows), 1)))
        if model.bonds is not None:
            nb = model.bonds.count
            f.bond_alive = np.ones(nb, bool)
            f.bond_end_time = np.full(nb, np.inf)
            if break_bond_at is not None and t >= break_bond_at[1]:
                f.bond_alive[break_bond_at[0]] = False
                f.bond_end_time[break_bond_at[0]] = break_bond_at[1] - 1e-9
            f.bond_force = np.tile([0.1, -0.2, k / 7], (nb, 1))
            f.bond_torque = np.full(nb, 1e-6 * k)
            f.bond_tangential_overlap = np.tile([1e-10, 0, k * 1e-11], (nb, 1))
        if model.triangles is not None:
            f.triangle_force = np.tile([0, 0, k * 0.25], (model.triangles.count, 1))
            f.triangle_vertices = model.triangles.vertices + k * 1e-4
        yield f


def write(model, path, frames, **kw):
    w = MusenResultWriter(model, path, **kw)
    for f in frames:
        w.add(f)
    w.close()
    return path


def test_round_trip_single_particle_exact(tmp_path):
    m = musen.read(SINGLE)
    times = [0.0, 1 / 3 * 1e-3, 2e-3]
    frames = list(frames_from(m, times))
    out = write(m, tmp_path / "r.txt", frames, precision=17)
    assert not list(tmp_path.glob(".*"))                        # spool and temp file removed
    back = musen.read(out)
    assert back.plan.t_start == times[-1]
    assert back.spheres.ids.tolist() == [12] and back.triangles.ids.tolist() == list(range(12))
    assert np.array_equal(back.spheres.position, frames[-1].position)
    assert np.array_equal(back.spheres.velocity, frames[-1].velocity)
    assert np.array_equal(back.spheres.omega, frames[-1].omega)
    assert np.array_equal(back.triangles.vertices, frames[-1].triangle_vertices)   # now `44`
    assert [x.key for x in back.materials] == [x.key for x in m.materials]
    assert [x.props for x in back.materials] == [x.props for x in m.materials]
    assert back.contacts == m.contacts
    assert [g.name for g in back.geometries] == ["Plate"]
    assert back.geometries[0].rotate_around_centre is False          # now the 7-field line
    assert np.array_equal(back.geometries[0].triangle_rows, m.geometries[0].triangle_rows)
    assert all(np.array_equal(a, b) for a, b in zip(back.plan.domain, m.plan.domain))
    tp = musen.read_time_points(out)
    assert tp.times.tolist() == times
    s = list(tp.ids).index(12)
    # MUSEN's result carries the force cmusen saves: the previous evaluation's (docs/musen.md)
    saved = [f.force[0] if f.saved_force is None else f.saved_force[0] for f in frames]
    assert np.array_equal(tp.fields[20][:, s], np.array(saved))
    # |F| is computed, not copied: allow the last bit (numpy's SIMD paths differ between builds)
    np.testing.assert_allclose(tp.fields[18][:, s, 0], [np.linalg.norm(f) for f in saved],
                               rtol=4e-16, atol=0)
    assert np.array_equal(tp.fields[20][:, 0], np.array([f.triangle_force[0] for f in frames]))
    text = out.read_text().splitlines()
    assert text[0].startswith("0 0 1 14 5  23 KYDX71DJATPLUTAHNBZX 24 0 1e+300 2 0 44 ")
    i = next(k for k, x in enumerate(text) if x.startswith("22 "))
    assert text[i:i + 9] == [
        "22 -0.00748344 -0.00743473 -0.0029375 0.00748344 0.00743473 0.0264375 ",
        "28 0 0 0 0 0 0 0 0 0 0 ", "29 0 ", "30 0 ",
        "25 Plate F83J03ZGKK1IJUBXR4IJ 0 0 0 0 0 ", "26 0 0  ",
        "27 12 0 1 2 3 4 5 6 7 8 9 10 11 ",
        "32 KYDX71DJATPLUTAHNBZX Steel 0 7750 1 1000 2 1e+40 3 0.5 7 2e+11 8 4e+09 9 4e+09 "
        "10 0.3 11 1 12 2e-05 13 0.7 14 1.7e-05 15 2e+10 ",
        "32 KF6843H84OPHH3017U3D Glass 0 2500 1 1000 2 1e+40 3 0.5 7 5e+10 8 5e+07 9 5e+07 "
        "10 0.22 11 1 12 2e-05 13 0.7 14 1.7e-05 15 2e+10 "]
    assert text[i + 9:] == ["33 KYDX71DJATPLUTAHNBZX KYDX71DJATPLUTAHNBZX 200 0.6 201 0.7 202 0.05 ",
                            "33 KF6843H84OPHH3017U3D KYDX71DJATPLUTAHNBZX 200 0.8 201 0.6 202 0.05 ",
                            "33 KF6843H84OPHH3017U3D KF6843H84OPHH3017U3D 200 0.9 201 0.45 202 0.05 ",
                            "40 1 2 "]


def test_round_trip_agglomerate_bonds_and_removals(tmp_path):
    m = musen.read(AGGLO)
    times = [0.0, 1e-6, 2e-6]
    frames = list(frames_from(m, times, drop_sphere_at=(7, 2e-6), break_bond_at=(3, 1e-6)))
    out = write(m, tmp_path / "r.txt", frames, precision=17)
    back = musen.read(out)
    assert np.array_equal(back.spheres.ids, m.spheres.ids)
    assert np.array_equal(back.bonds.ids, m.bonds.ids)
    assert np.array_equal(back.bonds.pair, m.bonds.pair)
    assert np.array_equal(back.bonds.length0, m.bonds.length0)
    assert np.array_equal(back.bonds.diameter, m.bonds.diameter)
    assert back.spheres.active_end[7] == 2e-6 and np.isinf(np.delete(back.spheres.active_end, 7)).all()
    assert back.bonds.active_end[3] == 9.99e-7          # activity always gets 6 digits (MUSEN)
    assert np.isinf(np.delete(back.bonds.active_end, 3)).all()
    # removed sphere: zeros at the later save (MUSEN stores nothing for inactive objects)
    assert back.spheres.position[7].tolist() == [0, 0, 0]
    assert np.array_equal(back.spheres.position[:7], frames[-1].position[:7])
    # broken bond: zero force after the break; the rest as given
    assert back.bonds.force[3].tolist() == [0, 0, 0]
    assert back.bonds.force[4].tolist() == [0.1, -0.2, 2 / 7]
    tp = musen.read_time_points(out, types=(9,), tags=(12, 43))
    j = 0                                                       # first bond: spheres 0 and 236
    a, b = m.bonds.pair[j]
    mid = 0.5 * (frames[1].position[a] + frames[1].position[b])
    assert np.allclose(tp.fields[12][1, j], mid, rtol=1e-15, atol=0)
    assert tp.fields[43][:, 0, 0].tolist() == [0, 1e-6, 2e-6]


@pytest.mark.tier2    # long reference comparison: second tier (pytest -m tier2; .ci/run runs it)
def test_writer_matches_real_musen_export(agglo_result, tmp_path):
    """Rebuild frames from MUSEN's own result and write them at precision 6: the sphere and
    bond values must come out as MUSEN wrote them (42/36 are not written by fibrelmp)."""
    m = musen.read(agglo_result)
    tp = musen.read_time_points(agglo_result)
    sph = np.flatnonzero(tp.types == 1)
    bnd = np.flatnonzero(tp.types == 9)
    assert np.array_equal(tp.ids[sph], m.spheres.ids) and np.array_equal(tp.ids[bnd], m.bonds.ids)
    frames = []
    for k, t in enumerate(tp.times):
        f = GranularFrame(time=t, step=k, sphere_rows=np.arange(len(sph)),
                          position=tp.fields[12][k, sph], velocity=tp.fields[15][k, sph],
                          omega=tp.fields[16][k, sph], force=tp.fields[20][k, sph],
                          quaternion=tp.fields[31][k, sph],
                          bond_alive=np.ones(len(bnd), bool),
                          bond_end_time=np.full(len(bnd), np.inf),
                          bond_force=tp.fields[20][k, bnd], bond_torque=tp.fields[43][k, bnd, 0],
                          bond_tangential_overlap=tp.fields[45][k, bnd])
        frames.append(f)
    out = write(m, tmp_path / "mine.txt", frames)
    mine = musen.read_time_points(out)
    assert np.array_equal(mine.times, tp.times) and np.array_equal(mine.ids, tp.ids)
    for tag in (16, 12, 20, 31, 37, 15, 45, 43):
        sel = bnd if tag in (45, 43) else sph
        assert np.array_equal(mine.fields[tag][:, sel], tp.fields[tag][:, sel]), tag
    assert 42 not in mine.fields and 36 not in mine.fields
    # recomputed from 6-digit inputs: |F|, bond midpoint and velocity agree to the 6th digit
    assert np.allclose(mine.fields[18], tp.fields[18], rtol=2e-5, atol=1e-12)
    pair = m.bonds.pair
    for tag in (12, 15):
        # bound: 6 significant digits = relative 5e-6 on each sphere value and on each print
        a, b = tp.fields[tag][:, sph][:, pair[:, 0]], tp.fields[tag][:, sph][:, pair[:, 1]]
        mid = tp.fields[tag][:, bnd]
        bound = 5e-6 * 0.5 * (np.abs(a) + np.abs(b)) + 1e-5 * np.abs(mid) + 1e-18
        assert (np.abs(mine.fields[tag][:, bnd] - mid) <= bound).all(), tag
    with open(agglo_result) as fh:
        real_head = [fh.readline() for _ in range(5697)][-1]
        fh.seek(agglo_result.stat().st_size - 2000)
        real_tail = fh.read().splitlines()[-7:]
    mine_lines = out.read_text().splitlines()
    assert mine_lines[5696].split(" 2 ")[0] == real_head.split(" 2 ")[0]   # 0 ID 1 9 5 ... 24 0 1e+300
    assert mine_lines[0].split(" 2 ")[0] == "0 0 1 1 5 0.0004 0.0004 23 KF6843H84OPHH3017U3D 24 0 1e+300"
    assert mine_lines[-7:] == real_tail                                  # 22 28 29 30 32 33 40


def test_writer_time_interval_and_selectors(tmp_path):
    m = musen.read(SINGLE)
    frames = list(frames_from(m, [0.0, 1e-3, 2e-3, 3e-3]))
    sel = {"tdPropsPart": {"stressTensor": False, "force": False},
           "objectTypes": {"walls": False}, "materials": {"interactions": False}}
    out = write(m, tmp_path / "r.txt", frames, time_interval=(0.5e-3, 2e-3), selectors=sel)
    lines = out.read_text().splitlines()
    assert lines[0].startswith("0 12 1 1 5 0.0005 0.0005 ")       # walls filtered out
    tp = musen.read_time_points(out)
    assert tp.times.tolist() == [1e-3, 2e-3]
    assert 20 not in tp.fields and 12 in tp.fields
    assert not any(x.startswith("33 ") for x in lines)


def test_writer_abort_leaves_nothing(tmp_path):
    m = musen.read(SINGLE)
    w = MusenResultWriter(m, tmp_path / "r.txt")
    for f in frames_from(m, [0.0, 1e-3]):
        w.add(f)
    w.abort()
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ job scripts

def test_real_job_script():
    path = data_path("real-outputs", "musen", "agglomerate", "job_agglomerate.txt")
    jobs = ms.read_script(path)
    assert [j.component for j in jobs] == ["IMPORT_FROM_TEXT", "SIMULATOR", "EXPORT_TO_TEXT",
                                           "EXPORT_TO_TEXT"]
    sim = jobs[1]
    assert (sim.source_file, sim.result_file, sim.line) == ("agglo_init.mdem", "agglo_result.mdem", 5)
    assert [x.name for x in sim.models] == ["ModelPPHertzMindlin", "ModelSBElastic"]
    assert (sim.simulation_step, sim.saving_step, sim.end_time) == (1e-8, 2e-5, 2e-4)
    assert sim.ext_accel == (0, 0, -9.81) and sim.simulation_domain == (-0.02,) * 3 + (0.02,) * 3
    assert jobs[3].precision == 17 and jobs[3].time_interval == (1.9e-4, 1.0)
    assert jobs[2].precision == 6 and jobs[2].time_interval is None
    m = musen.read(AGGLO)
    ms.apply_simulator_settings(m, sim)
    p = m.plan
    assert (p.dt, p.t_end, p.save_every_time, p.bond_breakage) == (1e-8, 2e-4, 2e-5, 1)
    assert p.gravity.tolist() == [0, 0, -9.81] and p.domain[1].tolist() == [0.02] * 3
    assert not [w for w in m.warnings if w[0] == "musen-outside-domain"]


def test_keywords_before_first_job_form_job_one():
    jobs = ms.read_script(data_path("real-outputs", "musen", "agglomerate",
                                      "job_own_domain_test.txt"))
    assert len(jobs) == 2 and jobs[0].line == 1                 # cmusen: "Number of jobs: 2"
    assert jobs[0].component == "SIMULATOR" and jobs[0].simulation_domain is None
    assert jobs[1].component == "EXPORT_TO_TEXT" and jobs[1].simulation_step == 0


def test_recommended_step_factor_matches_cmusen():
    jobs = ms.read_script(data_path("real-outputs", "musen", "agglomerate",
                                      "job_recommended_step.txt"))
    m = musen.read(AGGLO)
    ms.apply_simulator_settings(m, jobs[0])
    assert m.plan.dt == 3.9e-8                                    # cmusen's log: 3.9e-08
    assert (m.plan.save_every_time, m.plan.t_end) == (1e-7, 2e-7)


def test_example_single_particle_job():
    jobs = ms.read_script(EX / "single_particle_job.txt")
    assert [j.component for j in jobs] == ["IMPORT_FROM_TEXT", "SIMULATOR", "EXPORT_TO_TEXT"]
    assert (EX / jobs[0].source_file).exists()
    m = musen.read(EX / jobs[0].source_file)
    ms.apply_simulator_settings(m, jobs[1])
    p = m.plan
    sp = m.spheres
    law = m.contact(sp.material[0], m.triangles.material[0])
    plate_top = m.triangles.vertices[..., 2].max()
    gap = sp.position[0, 2] - sp.radius[0] - plate_top
    g, v0 = -p.gravity[2], -sp.velocity[0, 2]
    t_hit = (-v0 + math.sqrt(v0 ** 2 + 2 * g * gap)) / g
    v_hit = v0 + g * t_hit
    t_contact = 2.868 * (sp.mass[0] ** 2 / (sp.radius[0] * law.youngs_eff ** 2 * v_hit)) ** 0.2
    assert p.dt <= t_contact / 20
    assert p.t_end > t_hit + 10 * p.save_every_time           # time to see the rebound
    assert p.t_end < t_hit + law.restitution * v_hit / g       # still rising: no second impact
    assert p.save_every_time < 0.01 * law.restitution * v_hit / g
    assert [k for k, _ in m.warnings] == []


def test_example_agglomerate_job():
    jobs = ms.read_script(EX / "agglomerate_short_job.txt")
    m = musen.read(EX / jobs[0].source_file)
    ms.apply_simulator_settings(m, jobs[1])
    assert (m.plan.dt, m.plan.t_end, m.plan.save_every_time) == (1e-8, 2e-6, 5e-7)
    assert m.plan.dt < ms.recommended_time_step(m)
    assert not [w for w in m.warnings if w[0] == "musen-outside-domain"]


def test_overrides_and_defaults(tmp_path):
    script = tmp_path / "job.txt"
    script.write_text("SOURCE_FILE SingelParticle_text.txt\n"
                      "model_pp ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\n"
                      "MATERIAL_PROPERTY DENSITY KF6843H84OPHH3017U3D 3000\n"
                      "INTERACTION_PROPERTY RESTITUTION_COEFFICIENT KYDX71DJATPLUTAHNBZX "
                      "KF6843H84OPHH3017U3D 0.5\nVERLET_COEF 3\nVERLET_AUTO 0\nVERLET_MAX_CELLS 9\n"
                      "CONNECTED_PP_CONTACT 0\n")
    (job,) = ms.read_script(script)
    m = musen.read(SINGLE)
    ms.apply_simulator_settings(m, job)
    assert m.spheres.mass[0] == pytest.approx(3000 * 4 / 3 * math.pi * 0.0005 ** 3, rel=1e-15)
    assert m.contact(0, 1).restitution == 0.5
    assert (m.plan.dt, m.plan.save_every_time, m.plan.t_end) == (1e-6, 1e-3, 1.0)
    assert m.plan.gravity.tolist() == [0, 0, -9.81] and m.plan.contacts_between_bonded is False
    assert (m.plan.verlet_coeff, m.plan.verlet_auto) == (3.0, False)     # fix musen/verlet
    kinds = [k for k, _ in m.warnings]
    assert "musen-default-settings" in kinds and "musen-ignored-keyword" in kinds
    out = write(m, tmp_path / "r.txt", frames_from(m, [0.0]))
    assert "32 KF6843H84OPHH3017U3D Glass 0 3000 " in out.read_text()
    assert "33 KF6843H84OPHH3017U3D KYDX71DJATPLUTAHNBZX 200 0.5 " in out.read_text()


def test_text_scan_reused_only_while_the_file_is_unchanged(tmp_path, monkeypatch):
    """A job script reads its scene up to three times: the scan of the same small text is
    shared; a changed text (also one of the same size with its old mtime put back), the other
    mode or a text above the size limit is scanned again."""
    from fibrelmp.translate.musen import text

    path = tmp_path / "scene.txt"
    line = "0 {} 1 1 5 0.0004 0.0004 23 KEY 24 0 1e+300 2 0 12 {} 0 0\n"
    path.write_text(line.format(0, 0.0) + line.format(1, 0.001))
    first = text.scan_text(path)
    assert text.scan_text(path) is first and first.ids == [0, 1]
    assert text.scan_text(path, objects_only=True) is not first
    path.write_text(line.format(0, 0.0) + line.format(1, 0.001) + line.format(2, 0.002))
    again = text.scan_text(path)
    assert again is not first and again.ids == [0, 1, 2]
    same_size = line.format(0, 0.0) + line.format(1, 0.001) + line.format(3, 0.002)
    stat = path.stat()
    path.write_text(same_size)                      # same size, the old mtime put back (cp -p)
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    assert path.stat().st_size == stat.st_size and text.scan_text(path).ids == [0, 1, 3]
    monkeypatch.setattr(text, "_REUSE_BYTES", 10)
    path.write_text(line.format(5, 0.0))
    big = text.scan_text(path)
    assert big.ids == [5] and text.scan_text(path) is not big


@pytest.mark.parametrize("scene", [SINGLE, AGGLO], ids=["walls", "spheres-and-bonds"])
def test_bulk_object_headers_equal_the_line_by_line_ones_under_every_selector(tmp_path, scene):
    """MusenResultWriter._headers (one % for all objects) against object_header called per
    object, as the writer did before: every one of the 32 constProps selections, spheres,
    solid bonds and walls (inactive ends written as MUSEN's 1e+300)."""
    from itertools import product

    from fibrelmp.translate.musen.text_writer import export_selectors, object_header
    from fibrelmp.translate.musen.writer import _g

    m = musen.read(scene)
    w = MusenResultWriter(m, tmp_path / "r.txt")
    ids, types, rows = w._objects()
    flags = ("id", "type", "geometry", "material", "activityInterval")
    seen = set()
    for mask in product([True, False], repeat=5):
        w.sel = export_selectors({"constProps": dict(zip(flags, mask))})
        const = w.sel["constProps"]
        for otype in (1, 9, 14):
            pick = np.flatnonzero(types == otype)[:60]
            if not len(pick):
                continue
            got = w._headers(otype, ids[pick], rows[pick])
            start, end = w._activity(np.full(len(pick), otype), rows[pick])
            obj = {1: m.spheres, 9: m.bonds, 14: m.triangles}[otype]
            want = []
            for j, r in enumerate(rows[pick]):
                if otype == 1:
                    geom = "%.16g %.16g" % (obj.radius[r], obj.contact_radius[r])
                elif otype == 9:
                    pair = m.spheres.ids[obj.pair[r]]
                    geom = "%d %d %.25g %.25g" % (pair[0], pair[1], obj.diameter[r], obj.length0[r])
                else:
                    geom = ""
                key = w._key(obj, otype, r) if const["material"] else ""
                want.append(object_header(const, ids[pick][j], otype, geom, key, _g(start[j]), _g(end[j])))
            assert got == want, (mask, otype)
            seen.add(otype)
    assert seen == ({1, 14} if scene == SINGLE else {1, 9})
    w.abort()
