"""The dump reader on awkward and broken input: every defect is an InputError
``path:line: message`` or a warning, never another exception."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.translate.fibrenet.writer import read_xyz
from fibrelmp.post.lammps_dump.reader import iter_frames

from .test_post_roundtrip import post


def frame(step, rows, cols="id type x y z", box="pp pp pp", bounds=((0, 10), (0, 10), (0, 10)), time=None):
    head = "" if time is None else f"ITEM: TIME\n{time}\n"
    head += f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{len(rows)}\nITEM: BOX BOUNDS {box}\n"
    head += "".join(" ".join(map(str, b)) + "\n" for b in bounds)
    return head + f"ITEM: ATOMS {cols}\n" + "".join(" ".join(map(str, r)) + "\n" for r in rows)


ROWS = [(2, 1, 1.5, 2.5, 3.5), (1, 2, 0.25, 9.75, 5.0), (3, 1, 4.0, 4.0, 4.0)]


def write(tmp_path, text: str | bytes, name="d.dump") -> Path:
    p = tmp_path / name
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    return p


def test_truncated_last_frame_is_dropped_with_a_warning(tmp_path):
    text = frame(0, ROWS) + frame(10, ROWS)
    for cut in (len(text) - 5, text.index("ITEM: BOX", len(frame(0, ROWS))), len(frame(0, ROWS)) + 12):
        p = write(tmp_path, text[:cut])
        warnings = []
        frames = list(iter_frames(p, warnings))
        assert [f.step for f in frames] == [0]
        assert warnings and warnings[0][0] == "truncated dump" and f"{p}:" in warnings[0][1]
    said = []
    written = post(p, "xyz", tmp_path / "o", say=said.append)
    assert [f.step for f in read_xyz(written[0])] == [0]
    assert any("truncated dump" in s for s in said)


def test_changing_atom_count_and_unsorted_ids(tmp_path):
    p = write(tmp_path, frame(0, ROWS) + frame(5, ROWS[:2]) + frame(9, ROWS + [(7, 2, 1, 1, 1)]))
    assert [f.count for f in iter_frames(p)] == [3, 2, 4]
    post(p, "xyz", tmp_path / "o")
    frames = read_xyz(tmp_path / "o_coord.xyz")
    assert [len(f.names) for f in frames] == [3, 2, 4]
    np.testing.assert_array_equal(frames[0].values[:, 0], [0.25, 1.5, 4.0])     # sorted by id
    assert frames[0].names == ["2", "1", "1"]


def test_any_column_order_scaled_unwrapped_and_images(tmp_path):
    rows = [(0.5, 1, 0.25, 0.5, 2, -1, 0), (0.1, 2, 0.75, 0.1, 0, 0, 1)]
    p = write(tmp_path, frame(3, rows, cols="ys id xs zs ix iy iz", bounds=((0, 4), (0, 2), (-1, 1))))
    f = next(iter_frames(p))
    np.testing.assert_allclose(f.positions(), [[1.0, 1.0, 0.0], [3.0, 0.2, -0.8]])
    np.testing.assert_allclose(f.unwrapped(), [[9.0, -1.0, 0.0], [3.0, 0.2, 1.2]])
    np.testing.assert_allclose(f.wrapped(), f.positions())
    # only unwrapped coordinates: wrapped ones are derived on periodic axes
    p2 = write(tmp_path, frame(3, [(1, 1, 9.0, -1.0, 0.5, 0, 0, 0, 0, 0, 0)],
                               cols="id type xu yu zu vx vy vz fx fy fz", box="pp pp ff",
                               bounds=((0, 4), (0, 2), (-1, 1))), "u.dump")
    np.testing.assert_allclose(next(iter_frames(p2)).wrapped(), [[1.0, 1.0, 0.5]])
    post(p2, "res", tmp_path / "r")
    row = (tmp_path / "r_restart.res").read_text().splitlines()[2].split()
    assert row[:7] == ["1", "1", "1", "0.5", "9", "-1", "0.5"]


def test_triclinic_box(tmp_path):
    # bounding box of a box with lo (0,0,0), lengths (4,2,3), tilts xy=1 xz=-0.5 yz=0.25
    p = write(tmp_path, frame(0, [(1, 1, 0.5, 0.5, 0.5)], cols="id type xs ys zs", box="xy xz yz pp pp pp",
                              bounds=((-0.5, 5.0, 1.0), (0.0, 2.25, -0.5), (0.0, 3.0, 0.25))))
    f = next(iter_frames(p))
    assert f.triclinic
    np.testing.assert_allclose(f.lo, [0, 0, 0])
    np.testing.assert_allclose(f.hi, [4, 2, 3])
    np.testing.assert_allclose(f.positions(), [[2.0 + 0.5 - 0.25, 1.0 + 0.125, 1.5]])


def test_gz_dump_and_time_item(tmp_path):
    p = tmp_path / "d.dump.gz"
    with gzip.open(p, "wt") as fh:
        fh.write(frame(0, ROWS, time=0.0) + frame(100, ROWS, time=0.25))
    frames = list(iter_frames(p))
    assert [f.time for f in frames] == [0.0, 0.25]
    post(p, "xyz", tmp_path / "o")
    assert read_xyz(tmp_path / "o_coord.xyz")[1].dt == 0.0025


def test_dump_local_entries(tmp_path):
    text = ("ITEM: TIMESTEP\n4\nITEM: NUMBER OF ENTRIES\n2\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n"
            "ITEM: ENTRIES id1 id2 fx\n1 2 0.5\n2 3 -1e-3\n")
    f = next(iter_frames(write(tmp_path, text)))
    assert f.count == 2 and list(f.column("fx")) == [0.5, -1e-3]


@pytest.mark.parametrize("text,line,message", [
    ("", None, "empty dump file"),
    ("\n\n  \n", None, "empty dump file"),
    ("hello world\n", 1, "not a LAMMPS text dump"),
    (frame(0, ROWS).replace("1 2 0.25", "1 2 zz"), 11, "column 'x': expected a number, got 'zz'"),
    (frame(0, ROWS).replace("3 1 4.0 4.0 4.0", "3 1 4.0 4.0"), 12, "atom line has 4 values"),
    (frame(0, ROWS).replace("ITEM: NUMBER OF ATOMS\n3", "ITEM: NUMBER OF ATOMS\nthree"), 4, "malformed value"),
    (frame(0, ROWS).replace("0 10\n0 10\n0 10", "0 10\n0 x\n0 10"), 6, "BOX BOUNDS"),
    (frame(0, ROWS).replace("ITEM: TIMESTEP\n0\n", ""), 7, "no ITEM: TIMESTEP"),
    (frame(0, ROWS).replace("NUMBER OF ATOMS\n3", "NUMBER OF ATOMS\n2"), 12, "more atom lines"),
    (frame(0, ROWS).replace("NUMBER OF ATOMS\n3", "NUMBER OF ATOMS\n4") + frame(1, ROWS), 13,
     "frame has 3 atom lines but NUMBER OF ATOMS says 4"),
    (frame(0, ROWS).replace("ITEM: BOX BOUNDS", "ITEM: WHATEVER"), 5, "unknown dump item"),
    # an empty item (hypothesis found it raising IndexError once)
    ("ITEM:\r\n TIMESTEP\n0\n" + frame(0, ROWS), 1, "unknown dump item"),
    # a frame cut after its header's NUMBER OF ATOMS, another frame after it: not merged
    ("ITEM: TIMESTEP\n7\nITEM: NUMBER OF ATOMS\n0\n" + frame(0, ROWS), 5,
     "ITEM: TIMESTEP again before an ITEM: ATOMS (or ENTRIES) block: the frame starting at line 1"),
])
def test_broken_dumps_raise_input_error(tmp_path, text, line, message):
    p = write(tmp_path, text)
    with pytest.raises(InputError) as err:
        list(iter_frames(p, []))
    assert err.value.path == str(p) and err.value.line == line
    assert message in str(err.value)
    with pytest.raises(InputError):
        post(p, "xyz", tmp_path / "o")


def test_binary_garbage(tmp_path):
    rng = np.random.default_rng(5)
    for k, blob in enumerate([rng.integers(0, 256, 5000, dtype=np.uint8).tobytes(),
                              b"\x00" * 100 + b"\n" + b"\x01" * 10,
                              bytes(range(1, 256)) * 10000]):            # no newline, 2.5 MB
        p = write(tmp_path, blob, f"g{k}.bin")
        with pytest.raises(InputError) as err:
            list(iter_frames(p))
        assert str(err.value).startswith(f"{p}:")
        with pytest.raises(InputError):
            post(p, "vtk", tmp_path / f"v{k}")
    # a gzip header with a corrupt stream
    p = write(tmp_path, b"\x1f\x8b\x08\x00" + b"garbage" * 50, "bad.gz")
    with pytest.raises(InputError, match="cannot read the dump"):
        list(iter_frames(p))


def test_missing_columns_are_named(tmp_path):
    p = write(tmp_path, frame(0, [(1, 1)], cols="id type"))
    with pytest.raises(InputError, match="no positions"):
        post(p, "xyz", tmp_path / "o")
    p = write(tmp_path, frame(0, ROWS), "b.dump")
    with pytest.raises(InputError, match="restart needs velocity: the dump has no vx vy vz"):
        post(p, "res", tmp_path / "o")
    with pytest.raises(InputError, match="per-atom masses"):
        post(p, "mercury", tmp_path / "m")
    assert not (tmp_path / "m.data").exists() and not list(tmp_path.glob(".m.*"))   # no half outputs
    local = write(tmp_path, "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ENTRIES\n1\nITEM: BOX BOUNDS pp pp pp\n0 1\n"
                  "0 1\n0 1\nITEM: ENTRIES c_1[1] c_1[2]\n1 2\n", "l.dump")
    p = write(tmp_path, frame(0, [(1, 1, 1, 1, 1, 1.0, 0.1), (2, 1, 1.1, 1, 1, 1.0, 0.1)],
                              cols="id type x y z mass radius"), "c.dump")
    with pytest.raises(InputError, match="local dump has no column 'id1'"):
        post(p, "mercury", tmp_path / "m", local=local)
    # xyz without velocities/forces: only the coordinate file, with a warning
    said = []
    written = post(write(tmp_path, frame(0, ROWS), "e.dump"), "xyz", tmp_path / "x", say=said.append)
    assert [w.name for w in written] == ["x_coord.xyz"] and any("missing fields" in s for s in said)


def test_missing_files_and_bad_options(tmp_path):
    with pytest.raises(InputError, match="not found"):
        post(tmp_path / "nope.dump", "xyz", tmp_path / "o")
    p = write(tmp_path, frame(0, ROWS))
    with pytest.raises(InputError, match="--to"):
        post(p, None, tmp_path / "o")
    with pytest.raises(InputError, match="-o"):
        post(p, "xyz", None)
    with pytest.raises(InputError, match="unknown type 'Z'"):
        post(p, "xyz", tmp_path / "o", types=["Z"])
    with pytest.raises(InputError, match="data file not found"):
        post(p, "xyz", tmp_path / "o", data=tmp_path / "none.data")


def test_info_lines(tmp_path):
    p = write(tmp_path, frame(0, ROWS, time=0.0) + frame(10, ROWS[:2], time=0.5) + "ITEM: TIMESTEP\n20\n")
    said = []
    assert post(p, info=True, say=said.append) == []
    text = "\n".join(said)
    assert "frames     2 (steps 0 .. 10, every 10)" in text
    assert "atoms      2 .. 3 (changes between frames)" in text
    assert "columns    id type x y z" in text and "time       0 .. 0.5" in text
    assert "truncated dump" in text


@pytest.mark.filterwarnings("ignore")
def test_mdanalysis_bridge(tmp_path):
    """--topology + a DCD written by MDAnalysis converts like a dump."""
    mda = pytest.importorskip("MDAnalysis")
    n = 5
    u = mda.Universe.empty(n, trajectory=True, atom_resindex=np.zeros(n, int))
    u.add_TopologyAttr("types", ["A", "B", "A", "B", "B"])
    u.add_TopologyAttr("names", ["X"] * n)
    u.add_TopologyAttr("resnames", ["R"])
    u.dimensions = [10, 10, 10, 90, 90, 90]
    pos = np.arange(3 * n, dtype=np.float32).reshape(n, 3) / 2
    u.atoms.positions = pos
    u.atoms.write(tmp_path / "top.pdb")
    with mda.Writer(str(tmp_path / "traj.dcd"), n) as w:
        for k in range(3):
            u.atoms.positions = pos + k
            w.write(u.atoms)
    said = []
    post(tmp_path / "traj.dcd", info=True, topology=tmp_path / "top.pdb", say=said.append)
    assert any(s.startswith("frames     3") for s in said)
    post(tmp_path / "traj.dcd", "xyz", tmp_path / "o", topology=tmp_path / "top.pdb")
    frames = read_xyz(tmp_path / "o_coord.xyz")
    assert len(frames) == 3
    np.testing.assert_allclose(frames[2].values, pos + 2, atol=5e-6)
    assert frames[0].names == list(mda.Universe(str(tmp_path / "top.pdb")).atoms.types)
    u.atoms[:3].write(tmp_path / "three.pdb")                  # atom counts do not match
    with pytest.raises(InputError, match="MDAnalysis cannot read"):
        post(tmp_path / "traj.dcd", "xyz", tmp_path / "q", topology=tmp_path / "three.pdb")


def test_type_labels_in_the_dump(tmp_path):
    rows = [(1, "Cx", 1.0, 1.0, 1.0), (2, "O", 2.0, 2.0, 2.0), (3, "Cx", 3.0, 3.0, 3.0)]
    p = write(tmp_path, frame(0, rows) + frame(1, rows[::-1]))
    post(p, "xyz", tmp_path / "o", types=None)
    frames = read_xyz(tmp_path / "o_coord.xyz")
    assert frames[0].names == frames[1].names == ["Cx", "O", "Cx"]
    with pytest.raises(InputError, match=r"column 'x': expected a number"):
        list(iter_frames(write(tmp_path, frame(0, [(1, 1, "x1", 1, 1)]), "bad.dump")))


@pytest.mark.parametrize("chunk", [7, 64, 1000])
def test_small_read_chunks_give_the_same_frames(tmp_path, monkeypatch, chunk):
    """Frames spanning many read chunks (and buffer compaction) parse as with one read."""
    from fibrelmp.post.lammps_dump import reader as lammps_dump

    rng = np.random.default_rng(chunk)
    text = "".join(frame(s, [(k + 1, 1 + k % 2, *rng.random(3).round(6)) for k in range(n)], time=s / 10)
                   for s, n in ((0, 40), (5, 3), (9, 0), (12, 25)))
    p = write(tmp_path, text)
    want = list(iter_frames(p))
    monkeypatch.setattr(lammps_dump, "CHUNK", chunk)
    got = list(iter_frames(p))
    assert [f.step for f in got] == [0, 5, 9, 12] and [f.count for f in got] == [40, 3, 0, 25]
    for a, b in zip(got, want):
        for name in a.columns:
            np.testing.assert_array_equal(a.columns[name], b.columns[name])
