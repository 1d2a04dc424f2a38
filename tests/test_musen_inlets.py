"""MUSEN's dynamic generators (inlets) against the real cmusen's inlet-into-a-box run
(tests/data/real-outputs/musen/inlet/README.md): settings, generation times and counts, ids,
activity starts, radii per mixture fraction, positions and velocities at generation, for
cmusen's stored result and for fibrelmp's run of the same job (fix musen/inlet); the heap at
the end against cmusen's spread over four runs; the fix's own statistics, seeding and ranks.
cmusen seeds its random positions with the wall clock, so positions are compared as
statistics (inside the volume, no overlap), not value by value."""

from __future__ import annotations

import gzip
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.mdem import generators as gen
from fibrelmp.translate.musen.mdem.document import MdemFile, MdemWriter

from .conftest import data_path
from .musen_model_checks import CMUSEN, needs_cmusen

DATA = data_path("real-outputs", "musen", "inlet")
SCENE = DATA / "inlet_scene.mdem"
DT, END = 1e-6, 0.02                                   # job_inlet.txt
VOLUME_LO, VOLUME_HI = np.array([-0.004, -0.004, 0.007]), np.array([0.004, 0.004, 0.011])


def _storage():
    with MdemFile(SCENE) as f:
        return f.storage


_WIDTH = {16: 3, 12: 3, 20: 3, 18: 1, 31: 4, 42: 3, 36: 9, 37: 1, 15: 3}   # sphere tags


def _records(tok: list[str]) -> list[tuple[float, dict[int, list[float]]]]:
    """The time records of an object line from its first ``2``: (time, tag -> values)."""
    out, k = [], 12
    while k < len(tok):
        assert tok[k] == "2"
        rec: dict[int, list[float]] = {}
        t, k = float(tok[k + 1]), k + 2
        while k < len(tok) and tok[k] != "2":
            tag = int(tok[k])
            rec[tag] = [float(x) for x in tok[k + 1:k + 1 + _WIDTH[tag]]]
            k += 1 + _WIDTH[tag]
        out.append((t, rec))
    return out


def _spheres(text: str) -> dict:
    """Per sphere of a cmusen text result: id, radius, compound, activity start (6 digits, as
    MUSEN writes it) and its first saved time point at or after it (time, coord, velocity);
    ``saves``: every saved time."""
    out: dict = {"id": [], "r": [], "mat": [], "start": [], "first": [], "saves": None}
    for line in text.splitlines():
        tok = line.split()
        if len(tok) < 12 or tok[0] != "0" or tok[3] != "1":
            continue
        records = _records(tok)
        out["saves"] = np.array([t for t, _ in records])
        out["id"].append(int(tok[1]))
        out["r"].append(float(tok[5]))
        out["mat"].append(tok[8])
        out["start"].append(tok[10])
        t, rec = next((t, rec) for t, rec in records if "%g" % t >= tok[10] and t >= float(tok[10]))
        out["first"].append((t, rec[12], rec[15], rec[20]))
    return out


@pytest.fixture(scope="module")
def cmusen_result() -> dict:
    with gzip.open(DATA / "inlet_result_prec17.txt.gz", "rt") as fh:
        return _spheres(fh.read())


@pytest.fixture(scope="module")
def fibrelmp_run(tmp_path_factory) -> Path:
    """fibrelmp's run of cmusen's job (the .mdem scene, its generators, END_TIME 0.02 s)."""
    folder = tmp_path_factory.mktemp("inlet")
    for name in ("inlet_scene.mdem", "job_inlet.txt"):
        shutil.copy(DATA / name, folder)
    python_api.run(folder / "job_inlet.txt")
    return folder


@pytest.fixture(scope="module")
def fibrelmp_result(fibrelmp_run) -> dict:
    return _spheres((fibrelmp_run / "inlet_result_prec17.txt").read_text())


@pytest.fixture(params=["cmusen", "fibrelmp"])
def result(request) -> dict:
    return request.getfixturevalue(f"{request.param}_result")


def test_settings_read_as_musen_loads_them():
    a, b = gen.read_generators(_storage())
    assert (a.name, a.volume_key, a.mixture_key, a.objects) == ("InletA", "VINLET", "MIXONE", 1)
    assert a.random_velocity and a.velocity_magnitude == 0.5 and a.rate == 10000.0
    assert (a.start, a.end, a.update_step, a.max_iterations) == (0.0, 0.015, 1e-3, 30)
    assert b.init_velocity == (0.0, 0.0, -0.5) and not b.random_velocity
    assert b.rate_type == gen.RATE_PER_UPDATE and b.rate == pytest.approx(1500.0, rel=1e-15)


def test_schedule_gives_cmusens_generation_times(cmusen_result):
    """Every generation cmusen made happened at a scheduled event, each event made something,
    in the schedule's order (ids ascending with the events), never more than requested."""
    events = gen.generation_schedule(gen.read_generators(_storage()), DT, END)
    assert len(events) == 20
    starts = cmusen_result["start"]
    ids = np.array(cmusen_result["id"])
    assert (ids == np.arange(10, 10 + len(ids))).all()        # after the 10 walls, compact
    labels = ["%g" % e.time for e in events]
    made = [starts.count(lab) for lab in labels]
    assert sum(made) == len(starts) == 183
    order = [labels.index(s) for s in starts]
    assert order == sorted(order)
    assert all(1 <= m <= e.requested for m, e in zip(made, events))
    # uncrowded at first: exactly the requested numbers; InletB's first 12 (not 2 dt 1500 = 3
    # per update step) is MUSEN's start-time arithmetic, floor((t - (0 - 0.004)) 1500)
    assert [e.requested for e in events[:4]] == made[:4] == [10, 10, 10, 12]
    assert [e.generator for e in events[:4]] == [0, 0, 0, 1]
    assert events[1].step == 2001 and events[3].step == 4000      # drift of the summed time


def test_radii_follow_the_mixture_fractions(result):
    cmusen_result = result
    events = gen.generation_schedule(gen.read_generators(_storage()), DT, END)
    labels = ["%g" % e.time for e in events]
    radii = np.array(cmusen_result["r"])
    which = np.array([events[labels.index(s)].generator for s in cmusen_result["start"]])
    assert (radii[which == 0] == 0.0005).all()
    made = [0, 0]
    expected = []
    for _ in range(int((which == 1).sum())):
        i = gen.next_fraction(made, [0.5, 0.5])
        made[i] += 1
        expected.append([0.0004, 0.0006][i])
    np.testing.assert_allclose(radii[which == 1], expected, rtol=1e-15)
    assert set(cmusen_result["mat"]) == {"MGLASS"}


def test_objects_at_a_save_of_their_generation_step(result):
    cmusen_result = result
    """Spheres generated on a saving step are saved as generated: totally inside the volume,
    free of each other, with the generator's velocity (|v| = 0.5 for the random one) and a
    zero force."""
    saves = cmusen_result["saves"]
    events = gen.generation_schedule(gen.read_generators(_storage()), DT, END)
    on_save = {"%g" % e.time: e for e in events if np.isin(e.time, saves)}
    assert sorted(on_save) == ["0.001", "0.004", "0.006", "0.008"]
    for label, event in on_save.items():
        rows = [k for k, s in enumerate(cmusen_result["start"]) if s == label]
        pos = np.array([cmusen_result["first"][k][1] for k in rows])
        vel = np.array([cmusen_result["first"][k][2] for k in rows])
        r = np.array([cmusen_result["r"][k] for k in rows])
        assert all(cmusen_result["first"][k][0] == event.time for k in rows)
        assert ((pos - r[:, None] >= VOLUME_LO) & (pos + r[:, None] <= VOLUME_HI)).all()
        d = np.linalg.norm(pos[:, None] - pos[None], axis=2) + np.eye(len(r))
        assert (d >= r[:, None] + r[None] - 1e-15).all()
        # MUSEN saves the previous step's force: none yet for a sphere made on this step
        assert all(cmusen_result["first"][k][3] == [0.0, 0.0, 0.0] for k in rows)
        if event.generator == 0:
            np.testing.assert_allclose(np.linalg.norm(vel, axis=1), 0.5, rtol=1e-14)
            assert len({tuple(v) for v in vel}) == len(vel)        # one random draw each
        else:
            assert (vel == [0.0, 0.0, -0.5]).all()


def test_next_fraction_is_musens_rule():
    assert gen.next_fraction([0, 0, 0], [0.2, 0.3, 0.5]) == 0
    assert gen.next_fraction([1, 0, 0], [0.2, 0.3, 0.5]) == 1
    assert gen.next_fraction([1, 1, 0], [0.2, 0.3, 0.5]) == 2
    assert gen.next_fraction([2, 3, 5], [0.2, 0.3, 0.5]) == 0     # all at target: the first


def test_fibrelmp_generates_at_cmusens_times_and_ids(fibrelmp_run, fibrelmp_result, cmusen_result):
    """fibrelmp's run: generation events, counts and ids as cmusen's (exact while the volume
    is uncrowded), every activity start bit-identical to cmusen's summed time of its event."""
    events = gen.generation_schedule(gen.read_generators(_storage()), DT, END)
    labels = ["%g" % e.time for e in events]
    starts = fibrelmp_result["start"]
    made = [starts.count(lab) for lab in labels]
    assert fibrelmp_result["id"] == list(range(10, 10 + len(starts)))
    assert sum(made) == len(starts)
    assert [labels.index(s) for s in starts] == sorted(labels.index(s) for s in starts)
    assert all(1 <= m <= e.requested for m, e in zip(made, events))
    cm = [cmusen_result["start"].count(lab) for lab in labels]
    assert made[:4] == cm[:4] == [10, 10, 10, 12]
    with MdemFile(fibrelmp_run / "inlet_result.mdem") as f:
        info = f.storage.info.particles
    exact = [info[i].activity_start for i in fibrelmp_result["id"]]
    assert exact == [events[labels.index(s)].time for s in starts]
    assert exact[0] == 0.0010000000000000152 and exact[30] == 0.0040000000000002065   # README


# cmusen's own spread: four runs of job_inlet.txt (README: the stored one and three reruns)
CMUSEN_COUNTS = (183, 178, 187, 186)
CMUSEN_Z_CENTRE = (0.006769615662088993, 0.00701519015460296, 0.006947915411370733,
                   0.006895959351739143)


def _spread_check(value: float, runs: tuple) -> None:
    mean, half = float(np.mean(runs)), 0.5 * (max(runs) - min(runs))
    assert abs(value - mean) <= 3 * half, (value, mean, half)


def test_heap_at_the_end_within_three_cmusen_spreads(fibrelmp_run):
    """At 0.02 s: the sphere count and the z centre of mass of the heap (volume-weighted: one
    material) against cmusen's four runs, within 3x their half range."""
    with MdemFile(fibrelmp_run / "inlet_result.mdem") as f:
        info = f.storage.info.particles
        t, values, masks = list(f.time_points())[-1]
    ids = [i for i, p in enumerate(info) if p.type == 1]
    r = np.array([np.frombuffer(info[i].encoded_properties, "<f8")[0] for i in ids])
    z = values[ids, 2]
    assert t == pytest.approx(0.020001, abs=1e-12) and (masks[ids] != 0).all()
    _spread_check(len(ids), CMUSEN_COUNTS)
    _spread_check(float((z * r ** 3).sum() / (r ** 3).sum()), CMUSEN_Z_CENTRE)


def test_generated_spheres_touch_from_the_start(fibrelmp_run):
    """Every pair of spheres that overlaps at a saved time point pushes apart: the contact
    law's neighbour cutoff is sized for the inlet's spheres too (pair musen/hm asks fix
    musen/inlet for their radii; once a run starting with no spheres missed their contacts
    until a checkpoint's re-initialisation)."""
    from fibrelmp.post.lammps_dump.reader import iter_frames

    checked = 0
    for frame in iter_frames(fibrelmp_run / "job_inlet_work" / "job1" / "frames.dump"):
        if frame.count < 2:
            continue
        x = np.c_[frame.column("x"), frame.column("y"), frame.column("z")]
        r = frame.column("radius")
        d = np.linalg.norm(x[:, None] - x[None], axis=2) + np.eye(len(r)) * 1e9
        touching = np.argwhere(np.triu(d < r[:, None] + r[None]))
        checked += len(touching)
        force = np.c_[frame.column("fx"), frame.column("fy"), frame.column("fz")]
        # the step's contact forces are in f (gravity alone would be m g along -z)
        for i, j in touching:
            assert np.abs(force[i, :2]).max() > 0 or np.abs(force[j, :2]).max() > 0, (frame.step, i, j)
    assert checked > 20


def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch, fibrelmp_run):
    """Stopped after the checkpoint at step 2420 (between generations, spheres in contact),
    then resumed: the result is the uninterrupted run's byte for byte (the inlet's state and
    the generated spheres' contacts go through the restart file)."""
    from .musen_model_checks import run_cut_and_resumed

    for name in ("inlet_scene.mdem", "job_inlet.txt"):
        shutil.copy(DATA / name, tmp_path)
    run_cut_and_resumed(monkeypatch, tmp_path / "job_inlet.txt", tmp_path / "work", 2400)
    assert (tmp_path / "inlet_result_prec17.txt").read_bytes() == \
        (fibrelmp_run / "inlet_result_prec17.txt").read_bytes()


def test_summary_counts_the_generated_spheres(fibrelmp_run, fibrelmp_result):
    import json
    summary = json.loads((fibrelmp_run / "job_inlet_work" / "job1" / "summary.json").read_text())
    p = summary["particles"]
    assert (p["start"], p["generated"], p["end"]) == (0, len(fibrelmp_result["id"]), len(fibrelmp_result["id"]))


def _periodic_x(storage) -> None:
    info = storage.info
    info.periodic_conditions_enabled = info.periodic_conditions_x = True
    info.periodic_conditions_min.x, info.periodic_conditions_max.x = -0.005, 0.005
    info.periodic_conditions_min.y, info.periodic_conditions_max.y = -0.005, 0.005
    info.periodic_conditions_min.z, info.periodic_conditions_max.z = 0.0, 0.012


def _changed_scene(folder: Path, change) -> Path:
    """The stored inlet scene with ``change(storage)`` applied, written into ``folder``."""
    scene = folder / "inlet_scene.mdem"
    with MdemFile(SCENE) as f:
        storage = f.storage
        points = list(f.time_points())
    change(storage)
    with open(scene, "wb") as fh:
        writer = MdemWriter(fh)
        for t, values, masks in points:
            writer.add(t, values, masks)
        writer.finish(storage)
    return scene


@pytest.mark.parametrize("change, message", [
    (lambda s: setattr(s.modules_data.objects_generator.generators[0], "inside_geometries", False),
     "dynamic generator 'InletA': inside_geometries: off"),
    (_periodic_x, "dynamic generator 'InletA': generating in a periodic box is not supported"),
])
def test_unsupported_generator_setting_refuses_the_run(tmp_path, change, message):
    scene = _changed_scene(tmp_path, change)
    with pytest.raises(InputError) as err:
        python_api.run(scene)
    assert str(err.value).startswith(f"{scene}: {message}"), str(err.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["inlet_scene.mdem"]


@pytest.mark.parametrize("change, message", [
    (lambda g, s: setattr(g, "obj_type", 3), "obj_type: unknown object type 3"),
    (lambda g, s: (setattr(g, "obj_type", 2), setattr(g, "scaling_factor", 0.0)),
     "scaling_factor: must be > 0"),
    (lambda g, s: setattr(g, "volume_key", "NOPE"), "volume_key: no analysis volume 'NOPE'"),
    (lambda g, s: setattr(s.modules_data.materials_database.mixture[1].fraction[0],
                          "fraction", 0.4), "mixture_key: the fractions of mixture 'MIXTWO' sum"),
    (lambda g, s: setattr(g, "update_time_step", 0.0), "update_time_step: must be > 0"),
])
def test_bad_settings_name_generator_and_field(change, message):
    storage = _storage()
    g = storage.modules_data.objects_generator.generators[1]
    change(g, storage)
    with pytest.raises(InputError, match=f"dynamic generator 'InletB': {message}"):
        gen.read_inlets(storage, SCENE)


def _huge_rate(storage) -> None:
    g = storage.modules_data.objects_generator.generators[0]
    if g.version == 0:
        g.generation_rate = 1e15
    else:
        g.rate_type, g.rate_value = gen.RATE_PER_SECOND, 1e15


def test_a_hostile_rate_is_refused_before_anything_is_reserved(tmp_path):
    """A rate asking for more objects than fibrelmp reserves room for (one atom each, before
    the run) is refused by name, quickly, and nothing is written."""
    import resource
    import time

    scene = _changed_scene(tmp_path, _huge_rate)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.monotonic()
    with pytest.raises(InputError) as err:
        python_api.run(scene)
    assert str(err.value).startswith(f"{scene}: the dynamic generators ask for "), str(err.value)
    assert f"limit of {gen.MAX_GENERATED:,}" in str(err.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["inlet_scene.mdem"]
    assert time.monotonic() - start < 60          # no hang: the schedule stops at the limit
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 500_000    # kB


def test_inactive_generators_are_no_obstacle():
    storage = _storage()
    for g in storage.modules_data.objects_generator.generators:
        g.activity = False
    assert gen.read_inlets(storage, SCENE) == []
    assert gen.generation_schedule(gen.read_generators(storage), DT, END) == []


@needs_cmusen
def test_schedule_holds_for_another_cmusen_seed(tmp_path):
    """cmusen again (another wall-clock seed, other positions): same generation times."""
    for name in ("inlet_scene.mdem", "job_inlet.txt"):
        shutil.copy(DATA / name, tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", "-s=job_inlet.txt"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    starts = _spheres(Path(tmp_path / "inlet_result_prec17.txt").read_text())["start"]
    events = gen.generation_schedule(gen.read_generators(_storage()), DT, END)
    labels = ["%g" % e.time for e in events]
    assert set(starts) <= set(labels) and labels.index(starts[0]) == 0
    # the new run is one more sample of cmusen's spread: the stored four cover it loosely
    _spread_check(len(starts), CMUSEN_COUNTS)


def test_two_ranks_write_the_serial_results(tmp_path):
    """``mpiexec -n 2 fibrelmp run`` of the inlet job: the same result files, byte for byte
    (every rank takes the same insertions; each keeps those it owns)."""
    from .test_mpi import MPIEXEC, assert_ran, serial_and_mpi

    if not MPIEXEC:
        pytest.skip("mpiexec not found (pip install mpich)")

    def populate(case: Path) -> None:
        for name in ("inlet_scene.mdem", "job_inlet.txt"):
            shutil.copy(DATA / name, case)

    runs = serial_and_mpi(tmp_path, populate, ["-q", "run", "job_inlet.txt"])
    assert_ran(runs)
    ser, mpi = runs["serial"][0], runs["mpi"][0]
    for name in ("inlet_result_prec17.txt", "inlet_result.mdem", "job_inlet_work/job1/inlets.log"):
        assert (mpi / name).read_bytes() == (ser / name).read_bytes(), name


def _prism_volume(storage, sides: int = 12, radius: float = 0.004) -> np.ndarray:
    """Replace VINLET's triangles with a closed regular prism about the z axis (the shape of
    MUSEN's cylinder volume) over the same heights; its triangles (n, 3, 3)."""
    z0, z1 = VOLUME_LO[2], VOLUME_HI[2]
    a = 2 * np.pi * np.arange(sides) / sides
    ring = np.c_[radius * np.cos(a), radius * np.sin(a)]
    tri = []
    for i in range(sides):
        p, q = ring[i], ring[(i + 1) % sides]
        tri += [[[*p, z0], [*q, z0], [*q, z1]], [[*p, z0], [*q, z1], [*p, z1]],
                [[0, 0, z0], [*q, z0], [*p, z0]], [[0, 0, z1], [*p, z1], [*q, z1]]]
    tri = np.array(tri, float)
    volume = storage.info.analysis_volume[0]
    del volume.triangles[:]
    for t in tri:
        pt = volume.triangles.add()
        for vert, v in zip((pt.vert1, pt.vert2, pt.vert3), t):
            vert.x, vert.y, vert.z = v
    return tri


def test_triangle_volume_read_and_passed_to_the_fix():
    """A box volume is passed as its box; any other triangle volume as its triangles."""
    storage = _storage()
    assert all(i.triangles is None for i in gen.read_inlets(storage, SCENE))
    tri = _prism_volume(storage)
    inlets = gen.read_inlets(storage, SCENE)
    for inlet in inlets:
        np.testing.assert_array_equal(inlet.triangles, tri)
        np.testing.assert_array_equal(inlet.lo, tri.reshape(-1, 3).min(axis=0))
        np.testing.assert_array_equal(inlet.hi, tri.reshape(-1, 3).max(axis=0))


PRISM = data_path("real-outputs/musen/inlet_prism")
CMUSEN_PRISM_COUNTS = (162, 158)      # the stored run and a rerun (README there)


def _fifteen_points_in_prism(res: dict, events: list) -> int:
    """Assert that every sphere saved on its generation step holds MUSEN's 15 test points
    inside the 12-sided prism of ``_prism_volume`` (its half-planes) and is free of the
    others; the number checked."""
    sides, apothem = 12, 0.004 * np.cos(np.pi / 12)
    face = np.pi * (2 * np.arange(sides) + 1) / sides
    normal = np.c_[np.cos(face), np.sin(face)]
    checked = 0
    for label in {"%g" % e.time for e in events if np.isin(e.time, res["saves"])}:
        rows = [k for k, s in enumerate(res["start"]) if s == label]
        pos = np.array([res["first"][k][1] for k in rows])
        r = np.array([res["r"][k] for k in rows])
        s = r / 1.73205081
        offsets = [np.zeros(3)] + [sign * e * r[:, None] for e in np.eye(3) for sign in (1, -1)]
        offsets += [np.array(d) * s[:, None] for d in ((1, 1, 1), (1, 1, -1), (1, -1, 1), (1, -1, -1),
                                                       (-1, 1, 1), (-1, 1, -1), (-1, -1, 1), (-1, -1, -1))]
        for o in offsets:
            p = pos + o
            assert (p[:, :2] @ normal.T <= apothem * (1 + 1e-12)).all()
            assert ((p[:, 2] >= VOLUME_LO[2]) & (p[:, 2] <= VOLUME_HI[2])).all()
        d = np.linalg.norm(pos[:, None] - pos[None], axis=2) + np.eye(len(r))
        assert (d >= r[:, None] + r[None] - 1e-15).all()
        checked += len(rows)
    return checked


def test_stored_prism_scene_is_the_prism_volume():
    with MdemFile(PRISM / "inlet_prism_scene.mdem") as f:
        stored = gen.read_inlets(f.storage, PRISM / "inlet_prism_scene.mdem")
    storage = _storage()
    tri = _prism_volume(storage)
    for inlet in stored:
        np.testing.assert_array_equal(inlet.triangles, tri)


def test_generation_into_a_prism_volume(tmp_path):
    """cmusen's inlet job with VINLET a 12-sided prism (real cmusen run stored): in cmusen's
    run and in fibrelmp's, the spheres of each generation saved on its step hold MUSEN's 15
    test points inside the prism and are free of each other; the first events make the same
    numbers, the total is within three half-ranges of cmusen's two runs."""
    events = gen.generation_schedule(gen.read_generators(_storage()), DT, END)
    with gzip.open(PRISM / "inlet_prism_result_prec17.txt.gz", "rt") as fh:
        ref = _spheres(fh.read())
    for name in ("inlet_prism_scene.mdem", "job_inlet_prism.txt"):
        shutil.copy(PRISM / name, tmp_path)
    python_api.run(tmp_path / "job_inlet_prism.txt")
    res = _spheres((tmp_path / "inlet_prism_result_prec17.txt").read_text())
    assert len(ref["id"]) == CMUSEN_PRISM_COUNTS[0]
    mid, half = np.mean(CMUSEN_PRISM_COUNTS), np.ptp(CMUSEN_PRISM_COUNTS) / 2
    assert abs(len(res["id"]) - mid) <= 3 * half
    assert res["id"] == list(range(10, 10 + len(res["id"])))
    for out in (ref, res):
        assert _fifteen_points_in_prism(out, events) >= 20
        first = [sum(s == "%g" % e.time for s in out["start"]) for e in events[:3]]
        assert first == [10, 10, 10]
        # activity starts are cmusen's generation times (6 digits in the text)
        assert set(out["start"]) <= {"%g" % e.time for e in events}
