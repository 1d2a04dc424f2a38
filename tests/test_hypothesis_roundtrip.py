"""Property-based round trips: generate a valid model, write it in the format's text (with any
of the spacings, number spellings and line ends the format allows), read it back, compare.

* FibreNet input + model text -> ``translate.fibrenet.read``
* MUSEN scene text -> ``musen.read`` -> ``translate.musen.writer.MusenResultWriter`` -> ``musen.read``
* DEMDF JSON -> ``demdf.read`` -> ``translate.demdf.writer.DemdfSnapshotWriter`` -> ``demdf.read_snapshot``
* LAMMPS dump text (plain and gzip) -> ``post.lammps_dump.iter_frames``

Examples are bounded (``PROFILE``) so CI stays fast; ``FIBRELMP_HYPOTHESIS_EXAMPLES=2000``
explores more, ``FIBRELMP_HYPOTHESIS_RANDOM=1`` draws new examples on every run.
"""

from __future__ import annotations

import gzip
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fibrelmp.granmodel import GranularFrame
from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.translate.musen.writer import MusenResultWriter
from fibrelmp.translate.demdf import reader as demdf
from fibrelmp.translate.fibrenet import reader as fibrenet
from fibrelmp.translate.musen import scene as musen

PROFILE = settings(max_examples=int(os.environ.get("FIBRELMP_HYPOTHESIS_EXAMPLES", "100")),
                   deadline=None, database=None,
                   derandomize=not os.environ.get("FIBRELMP_HYPOTHESIS_RANDOM"),
                   suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

# every spelling is exact: the readers must give back the very same doubles
SPELL = st.sampled_from([repr, lambda x: "%.17g" % x, lambda x: "%.16e" % x])
SEP = st.sampled_from([" ", "\t", "  ", " \t "])
EOL = st.sampled_from(["\n", "\r\n"])


def unit(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False, allow_subnormal=False)


# ------------------------------------------------------------------ FibreNet
NAME = st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,5}", fullmatch=True).filter(lambda s: s != "all")


@st.composite
def fibrenet_cases(draw):
    types = draw(st.lists(NAME, min_size=1, max_size=3, unique=True))
    size = np.array(draw(st.lists(unit(2.0, 50.0), min_size=3, max_size=3)))
    n = draw(st.integers(3, 10))
    frac = draw(st.lists(st.tuples(unit(0, 1), unit(0, 1), unit(0, 1)), min_size=n, max_size=n,
                         unique=True))
    pos = np.array(frac) * size                     # f * L <= L in floating point for f <= 1
    floats = lambda lo, hi, k: np.array(draw(st.lists(unit(lo, hi), min_size=k, max_size=k)))  # noqa: E731
    beads = {"type": draw(st.lists(st.integers(0, len(types) - 1), min_size=n, max_size=n)),
             "tag": draw(st.lists(st.integers(-5, 5), min_size=n, max_size=n)),
             "radius": floats(0, 2, n), "mass": floats(0, 10, n), "pos": pos,
             "vel": floats(-5, 5, 3 * n).reshape(n, 3), "force": floats(-1e3, 1e3, 3 * n).reshape(n, 3)}
    index = st.integers(0, n - 1)
    springs = draw(st.lists(st.tuples(index, index, unit(0, 5), unit(0, 1e4),
                                      st.one_of(st.none(), st.tuples(st.integers(-9, 9),
                                                                     st.integers(-9, 9))))
                            .filter(lambda s: s[0] != s[1]), max_size=8))
    angles = draw(st.lists(st.tuples(index, index, index, unit(0, math.pi), unit(0, 100))
                           .filter(lambda a: len(set(a[:3])) == 3), max_size=6))
    pairs = {}
    for i in range(len(types)):
        for j in range(i, len(types)):
            kind = draw(st.sampled_from(["hs", "st", "lj"]))
            need = {"hs": 1, "st": 4, "lj": 3}[kind]
            values = draw(st.lists(unit(0.01, 100), min_size=need, max_size=need))
            pairs[(i, j)] = (kind, values)
    run = draw(st.integers(1, 10 ** 6))
    plan = {"box_type": draw(st.sampled_from(["pbc", "finite"])), "wall": draw(unit(0, 1e3)),
            "dt": draw(unit(1e-6, 1e-2)), "lambda": draw(unit(0.01, 1)),
            "damping": draw(unit(0, 1)), "cutoff": draw(unit(0.5, 3)),
            "gravity": draw(st.lists(unit(-10, 10), min_size=3, max_size=3)),
            "run": run, "freq": draw(st.integers(1, run))}
    style = {"spell": draw(SPELL), "sep": draw(SEP), "eol": draw(EOL)}
    # a periodic box needs every spring and angle leg shorter than half the box (FibreNet does
    # not take the minimum image, LAMMPS does: such inputs are refused); otherwise walls
    legs = [(i, j) for i, j, *_ in springs] + [(a, b) for a, b, *_ in angles] + \
        [(b, c) for _, b, c, *_ in angles]
    if any((np.abs(pos[j] - pos[i]) >= 0.5 * size).any() for i, j in legs):
        plan["box_type"] = "finite"
    return types, size, beads, springs, angles, pairs, plan, style


def write_fibrenet(folder: Path, case) -> Path:
    types, size, beads, springs, angles, pairs, plan, style = case
    f, sep, eol = style["spell"], style["sep"], style["eol"]
    rows = []
    for k in range(len(beads["pos"])):
        p = beads["pos"][k]
        values = [beads["radius"][k], beads["mass"][k], *p, *beads["vel"][k], *beads["force"][k], *p]
        rows.append(sep.join(["BEAD", types[beads["type"][k]], str(beads["tag"][k]), "0"]
                             + [f(float(v)) for v in values]))
    for k, (i, j, r0, stiff, fl) in enumerate(springs):
        tail = [] if fl is None else [str(fl[0]), str(fl[1])]
        rows.append(sep.join(["SPRING", "HR" if fl is None else "HR_FL", str(k), str(i), str(j),
                              f(r0), f(stiff)] + tail))
    for k, (a, b, c, theta, coef) in enumerate(angles):
        rows.append(sep.join(["ANGLE", "HR", str(k), str(a), str(b), str(c), "0", "0", f(theta),
                              f(coef)]))
    (folder / "model.txt").write_bytes(eol.join(rows).encode() + eol.encode())
    lines = ["model_file model.txt", "output_file out", *(f"type{sep}{t}" for t in types)]
    for (i, j), (kind, values) in pairs.items():
        lines.append(sep.join(["pair", kind, types[i], types[j]] + [f(v) for v in values]))
    lines += [f"box_size{sep}" + sep.join(f(float(v)) for v in size),
              f"box_type {plan['box_type']}", f"box_wall_rep {f(plan['wall'])}",
              "box_unit_cell 0.5", f"cutoff {f(plan['cutoff'])}", f"step {f(plan['dt'])}",
              f"lambda {f(plan['lambda'])}", f"damping {f(plan['damping'])}",
              "gravity " + " ".join(f(v) for v in plan["gravity"]), f"run {plan['run']}",
              f"output_freq {plan['freq']}", "output_data all", "output_type all"]
    (folder / "input.txt").write_bytes(eol.join(lines).encode() + eol.encode())
    return folder / "input.txt"


@PROFILE
@given(fibrenet_cases())
def test_fibrenet_roundtrip(case):
    types, size, beads, springs, angles, pairs, plan, _ = case
    with tempfile.TemporaryDirectory() as tmp:
        model = fibrenet.read(write_fibrenet(Path(tmp), case))
    p = model.particles
    assert model.units == "lj"
    assert p.type_names == types
    np.testing.assert_array_equal(p.types, beads["type"])
    np.testing.assert_array_equal(p.molecules, beads["tag"])
    np.testing.assert_array_equal(p.positions, beads["pos"])
    np.testing.assert_array_equal(p.unwrapped, beads["pos"])
    np.testing.assert_array_equal(p.masses, beads["mass"])
    np.testing.assert_array_equal(p.radii, beads["radius"])
    np.testing.assert_array_equal(p.display_velocities, beads["vel"])
    np.testing.assert_array_equal(p.velocities, np.repeat(beads["vel"][:, :1], 3, axis=1))  # FibreNet's quirk
    np.testing.assert_array_equal(p.initial_forces, beads["force"])
    b = model.bonds
    np.testing.assert_array_equal(b.atoms.reshape(-1, 2), np.array([s[:2] for s in springs]).reshape(-1, 2))
    np.testing.assert_array_equal(b.r0, [s[2] for s in springs])
    np.testing.assert_array_equal(b.k, [s[3] for s in springs])
    for k, (_, _, r0, _, fl) in enumerate(springs):
        if fl is None:
            assert math.isnan(b.break_length[k])
        else:
            want = r0 * fl[0] / (fl[0] - fl[1]) if fl[0] > fl[1] else math.inf
            assert b.break_length[k] == want
    a = model.angles
    np.testing.assert_array_equal(a.atoms.reshape(-1, 3), np.array([x[:3] for x in angles]).reshape(-1, 3))
    np.testing.assert_array_equal(a.theta0, np.float32([x[3] for x in angles]).astype(float))  # std::stof
    np.testing.assert_array_equal(a.c, [x[4] for x in angles])
    np.testing.assert_array_equal(model.box.lengths, size)
    assert all(model.box.periodic) == (plan["box_type"] == "pbc")
    d = model.dynamics
    assert (d.dt, d.lambda_, d.damping, d.pair_cutoff) == (plan["dt"], plan["lambda"], plan["damping"],
                                                           plan["cutoff"])
    np.testing.assert_array_equal(d.gravity, plan["gravity"])
    (prod,) = model.plan.stages
    assert (prod.steps, prod.chunk) == (plan["run"], plan["freq"])
    got = {(law.type_i, law.type_j): law for law in model.pairs}
    assert set(got) == set(pairs)
    for key, (kind, values) in pairs.items():
        law = got[key]
        assert law.kind == kind
        names = {"hs": ("K",), "st": ("Krep", "Katt", "l0", "rc"), "lj": ("sigma", "epsilon", "shift")}
        assert [law.params[n] for n in names[kind]] == values


# ------------------------------------------------------------------ MUSEN
KEY = st.from_regex(r"[A-Z][A-Z0-9]{3,9}", fullmatch=True)


@st.composite
def musen_scenes(draw):
    keys = draw(st.lists(KEY, min_size=1, max_size=2, unique=True))
    mats = [(k, draw(st.from_regex(r"[A-Za-z]{1,8}", fullmatch=True)),
             draw(st.integers(100, 20000)), draw(st.integers(1, 999)) * 1e9,
             draw(st.integers(0, 50)) / 100) for k in keys]
    n = draw(st.integers(1, 6))
    ids = draw(st.lists(st.integers(0, 10 ** 6), min_size=n + 4, max_size=n + 4, unique=True))
    f = draw(SPELL)
    spheres = []
    for k in range(n):
        r = draw(unit(1e-4, 1e-2))
        spheres.append({"id": ids[k], "key": draw(st.sampled_from(keys)), "r": r,
                        "x": draw(st.lists(unit(-0.1, 0.1), min_size=3, max_size=3)),
                        "v": draw(st.lists(unit(-1, 1), min_size=3, max_size=3)),
                        "w": draw(st.lists(unit(-10, 10), min_size=3, max_size=3)),
                        "q": draw(st.lists(unit(-1, 1), min_size=4, max_size=4))})
    bonds = []
    if n >= 2:
        for k in range(draw(st.integers(0, 2))):
            i, j = draw(st.lists(st.integers(0, n - 1), min_size=2, max_size=2, unique=True))
            bonds.append({"id": ids[n + k], "ends": (spheres[i]["id"], spheres[j]["id"]),
                          "key": draw(st.sampled_from(keys)), "d": draw(unit(1e-5, 1e-3)),
                          "l0": draw(unit(1e-4, 1e-2))})
    lines = []
    for s in spheres:
        lines.append(f"0 {s['id']} 1 1 5 {f(s['r'])} {f(s['r'])} 23 {s['key']} 24 0 1e+300 2 0 "
                     f"12 {' '.join(map(f, s['x']))} 15 {' '.join(map(f, s['v']))} "
                     f"16 {' '.join(map(f, s['w']))} 31 {' '.join(map(f, s['q']))}")
    for b in bonds:
        lines.append(f"0 {b['id']} 1 9 5 {b['ends'][0]} {b['ends'][1]} {f(b['d'])} {f(b['l0'])} "
                     f"23 {b['key']} 24 0 1e+300 2 0 12 0 0 0")
    lines.append("22 -1 -1 -1 1 1 1")
    for key, name, rho, e, nu in mats:
        lines.append(f"32 {key} {name} 0 {rho} 7 {e:g} 10 {nu:g}")
    for a in range(len(keys)):
        for b in range(a, len(keys)):
            lines.append(f"33 {keys[a]} {keys[b]} 200 0.{draw(st.integers(1, 9))} 201 0.3 202 0.01")
    sep, eol = draw(SEP), draw(EOL)
    text = eol.join(line.replace(" ", sep) for line in lines) + eol
    return text, mats, spheres, bonds


def _initial_frame(model) -> GranularFrame:
    s = model.spheres
    frame = GranularFrame(time=model.plan.t_start, step=0, sphere_rows=np.arange(s.count),
                          position=s.position, velocity=s.velocity, omega=s.omega,
                          force=np.zeros((s.count, 3)), quaternion=s.quaternion)
    if model.bonds is not None:
        frame.bond_alive = np.ones(model.bonds.count, bool)
        frame.bond_end_time = np.full(model.bonds.count, np.inf)
    return frame


@PROFILE
@given(musen_scenes())
def test_musen_scene_roundtrip_through_the_result_writer(scene):
    text, mats, spheres, bonds = scene
    with tempfile.TemporaryDirectory() as tmp:
        first = Path(tmp) / "scene.txt"
        first.write_bytes(text.encode())
        m1 = musen.read(first)
        writer = MusenResultWriter(m1, Path(tmp) / "again.txt", precision=17)
        writer.add(_initial_frame(m1))
        writer.close()
        m2 = musen.read(Path(tmp) / "again.txt")
    # the first read gives what was written
    assert m1.units == "si"
    s1 = m1.spheres
    np.testing.assert_array_equal(s1.ids, [s["id"] for s in spheres])
    np.testing.assert_array_equal(s1.radius, [s["r"] for s in spheres])
    np.testing.assert_array_equal(s1.position, [s["x"] for s in spheres])
    np.testing.assert_array_equal(s1.velocity, [s["v"] for s in spheres])
    np.testing.assert_array_equal(s1.omega, [s["w"] for s in spheres])
    np.testing.assert_array_equal(s1.quaternion, [s["q"] for s in spheres])
    assert [(m.key, m.name, m.density, m.youngs, m.poisson) for m in m1.materials] == \
        [(k, n, float(rho), e, nu) for k, n, rho, e, nu in mats]
    # the written result reads back as the same model (MUSEN writes objects by ascending id)
    s2 = m2.spheres
    order = np.argsort(s1.ids)
    for name in ("ids", "material", "position", "velocity", "omega", "quaternion", "active_start",
                 "active_end"):
        np.testing.assert_array_equal(getattr(s2, name), getattr(s1, name)[order], err_msg=name)
    # radii are written with 16 digits, as MUSEN does; the mass goes with r^3
    for name, rtol in (("radius", 1e-15), ("contact_radius", 1e-15), ("mass", 4e-15)):
        np.testing.assert_allclose(getattr(s2, name), getattr(s1, name)[order], rtol=rtol,
                                   err_msg=name)
    assert [(m.key, m.name, m.density, m.youngs, m.poisson) for m in m2.materials] == \
        [(m.key, m.name, m.density, m.youngs, m.poisson) for m in m1.materials]
    assert m2.contacts == m1.contacts
    if bonds:
        ends = lambda m: m.spheres.ids[m.bonds.pair]                     # noqa: E731
        b_order = np.argsort(m1.bonds.ids)
        np.testing.assert_array_equal(ends(m1), [b["ends"] for b in bonds])
        np.testing.assert_array_equal(ends(m2), ends(m1)[b_order])
        np.testing.assert_allclose(m2.bonds.diameter, np.array([b["d"] for b in bonds])[b_order],
                                   rtol=1e-15)
        np.testing.assert_allclose(m2.bonds.length0, np.array([b["l0"] for b in bonds])[b_order],
                                   rtol=1e-15)
    else:
        assert m1.bonds is None and m2.bonds is None
    for k in (0, 1):
        np.testing.assert_array_equal(m2.plan.domain[k], m1.plan.domain[k])


# ------------------------------------------------------------------ DEMDF
@st.composite
def demdf_documents(draw):
    dim = draw(st.sampled_from([2, 3]))
    hi = draw(st.lists(unit(4, 20), min_size=dim, max_size=dim))
    ntypes = draw(st.integers(1, 2))
    types = [{"id": k, "type": "particle", "radius": draw(unit(0.05, 0.5)),
              "mass": draw(unit(0.1, 5)), "restitutionCoefficient": draw(unit(0.1, 1))}
             for k in range(ntypes)]
    n = draw(st.integers(1, 6))
    rows = []
    for _ in range(n):
        x = [draw(unit(1.0, h - 1.0)) for h in hi]
        v = [draw(unit(-3, 3)) for _ in range(dim)]
        rows.append(x + v + [draw(st.integers(0, ntypes - 1))])
    doc = {"fileFormat": "demdf", "fileFormatVersion": 0.01, "dimensionality": dim,
           "time": draw(unit(0, 10)), "timeEnd": 1e3,
           "output": {"snapshot": {"name": "demdf", "filename": "snap", "saveCount": 0,
                                   "savePeriodInTime": 1.0}},
           "domain": [[0.0] * dim, hi], "bodyForce": [0.0] * (dim - 1) + [draw(unit(-10, 0))],
           "objectTypes": types, "objects": {"particles": rows},
           "interactions": [{"name": "particleInelastic"}]}
    indent = draw(st.sampled_from([None, 2, "\t"]))
    return doc, json.dumps(doc, indent=indent)


@PROFILE
@given(demdf_documents())
def test_demdf_roundtrip_and_snapshot(case):
    doc, text = case
    dim = doc["dimensionality"]
    rows = np.array(doc["objects"]["particles"], float)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "doc.json"
        path.write_text(text)
        model = demdf.read(path)
        s = model.spheres
        assert model.units == "dimensionless"
        np.testing.assert_array_equal(s.position[:, :dim], rows[:, :dim])
        np.testing.assert_array_equal(s.velocity[:, :dim], rows[:, dim:2 * dim])
        types = rows[:, -1].astype(int)
        np.testing.assert_array_equal(s.radius, [doc["objectTypes"][t]["radius"] for t in types])
        np.testing.assert_array_equal(s.mass, [doc["objectTypes"][t]["mass"] for t in types])
        assert model.plan.t_start == doc["time"]
        np.testing.assert_array_equal(model.plan.gravity[:dim], doc["bodyForce"])
        writer = DemdfSnapshotWriter(model, Path(tmp) / "out")
        snap = writer.add(GranularFrame(time=model.plan.t_start, step=0,
                                        sphere_rows=np.arange(s.count), position=s.position,
                                        velocity=s.velocity, omega=s.omega,
                                        force=np.zeros((s.count, 3)), quaternion=s.quaternion))
        writer.close()
        again = demdf.read_snapshot(snap)
    for name in ("position", "velocity", "radius", "mass", "material"):
        np.testing.assert_array_equal(getattr(again.spheres, name), getattr(s, name), err_msg=name)
    assert again.plan.t_start == model.plan.t_start


# ------------------------------------------------------------------ LAMMPS dumps
COLUMNS = ["x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz", "mass", "radius", "xu", "q"]


@st.composite
def dumps(draw):
    cols = ["id", "type"] + draw(st.lists(st.sampled_from(COLUMNS), min_size=1, max_size=6,
                                          unique=True))
    cols = draw(st.permutations(cols))
    frames = []
    for k in range(draw(st.integers(1, 3))):
        n = draw(st.integers(0, 6))
        ids = draw(st.lists(st.integers(1, 10 ** 6), min_size=n, max_size=n, unique=True))
        data = {"id": np.array(ids, float), "type": np.array(draw(st.lists(st.integers(1, 4),
                                                                            min_size=n, max_size=n)), float)}
        for c in cols[:]:
            if c not in data:
                data[c] = np.array(draw(st.lists(unit(-1e6, 1e6), min_size=n, max_size=n)))
        lo = np.array(draw(st.lists(unit(-100, 0), min_size=3, max_size=3)))
        hi = lo + np.array(draw(st.lists(unit(0.5, 100), min_size=3, max_size=3)))
        frames.append({"step": draw(st.integers(0, 2 ** 40)) if k == 0 else frames[-1]["step"] + k,
                       "time": draw(st.one_of(st.none(), unit(0, 1e3))), "lo": lo, "hi": hi,
                       "boundary": tuple(draw(st.sampled_from(["pp", "ff", "fm", "ss"])) for _ in range(3)),
                       "data": data})
    style = {"spell": draw(SPELL), "sep": draw(SEP), "eol": draw(EOL), "gzip": draw(st.booleans())}
    return cols, frames, style


def write_dump(path: Path, cols, frames, style) -> None:
    f, sep, eol = style["spell"], style["sep"], style["eol"]
    out = []
    for fr in frames:
        if fr["time"] is not None:
            out += ["ITEM: TIME", f(fr["time"])]
        out += ["ITEM: TIMESTEP", str(fr["step"]), "ITEM: NUMBER OF ATOMS", str(len(fr["data"]["id"])),
                "ITEM: BOX BOUNDS " + " ".join(fr["boundary"])]
        out += [f"{f(float(a))}{sep}{f(float(b))}" for a, b in zip(fr["lo"], fr["hi"])]
        out.append("ITEM: ATOMS " + " ".join(cols))
        for k in range(len(fr["data"]["id"])):
            out.append(sep.join(str(int(fr["data"][c][k])) if c in ("id", "type")
                                else f(float(fr["data"][c][k])) for c in cols))
    raw = (eol.join(out) + eol).encode()
    path.write_bytes(gzip.compress(raw) if style["gzip"] else raw)


@PROFILE
@given(dumps())
def test_lammps_dump_roundtrip(case):
    cols, frames, style = case
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / ("d.dump.gz" if style["gzip"] else "d.dump")
        write_dump(path, cols, frames, style)
        warnings: list = []
        got = list(iter_frames(path, warnings))
    assert warnings == []
    assert len(got) == len(frames)
    for fr, want in zip(got, frames):
        assert fr.step == want["step"] and fr.time == want["time"]
        assert fr.boundary == want["boundary"]
        np.testing.assert_array_equal(fr.lo, want["lo"])
        np.testing.assert_array_equal(fr.hi, want["hi"])
        assert list(fr.columns) == cols
        for c in cols:
            np.testing.assert_array_equal(fr.columns[c], want["data"][c], err_msg=c)
