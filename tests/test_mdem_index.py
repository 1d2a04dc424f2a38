"""Issue 28: a .mdem's time points found without decoding the others.  The block descriptors
are read into arrays (``BlockIndex``; a C scan of the scene message, or protobuf), time point
i is located from the saved times and only its block is decoded (``MdemFile.time_point``).
Checked: the C scan reads the descriptors as protobuf does; every time point of every .mdem in
tests/data (real cmusen files) read lazily equals the full decode; a file of a million time
points (its bytes built here) gives sampled frames equal to what was written, without parsing
its descriptors as messages; a file whose saved times disagree with its blocks is refused."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.numtext import fast
from fibrelmp.translate.musen.mdem import blockindex, document
from fibrelmp.translate.musen.mdem import timepoints as tp
from fibrelmp.translate.musen.mdem.container import ContainerWriter
from fibrelmp.translate.musen.mdem.document import BlockIndex, MdemFile, MdemWriter
from fibrelmp.translate.musen.mdem.messages import new

from .conftest import REPO
from .mdem_edit import with_edited_scene

MDEM_FILES = sorted((REPO / "tests" / "data").rglob("*.mdem"))
BOUNCE = REPO / "tests" / "data" / "real-outputs" / "musen" / "bounce" / "bounce_result.mdem"
# cmusen's scene of two glass spheres (the first is kept)
ONE_GLASS_SPHERE = REPO / "tests" / "data" / "real-outputs" / "musen" / "moving_pbc" / "pbc_init.mdem"
needs_c = pytest.mark.skipif(fast.library() is None, reason="the C helpers are not available")


def _same_point(a, b) -> None:
    assert a[0] == b[0]
    assert a[1].tobytes() == b[1].tobytes() and np.array_equal(a[2], b[2])


def _as_protobuf_reads(monkeypatch) -> None:
    """MdemFile without the C scan: the scene message parsed whole by protobuf."""
    monkeypatch.setattr(document.fast, "mdem_blocks", lambda raw, most: None)


@pytest.mark.parametrize("path", MDEM_FILES, ids=lambda p: p.name)
def test_every_time_point_read_lazily_equals_the_full_decode(path):
    with MdemFile(path) as mdem:
        full = list(mdem.time_points())
        assert mdem.count() == len(full)
        for i in range(len(full)):
            _same_point(mdem.time_point(i), full[i])
        with pytest.raises(IndexError):
            mdem.time_point(len(full))
        # MUSEN's files are indexed from their saved times, no block read to count them
        assert mdem._point_index().counted == (len(mdem.info.savedTimePoints) == 0)


@needs_c
@pytest.mark.parametrize("path", MDEM_FILES, ids=lambda p: p.name)
def test_descriptor_scan_reads_what_protobuf_reads(path, monkeypatch):
    with MdemFile(path) as scanned:
        c = scanned.blocks
        assert scanned._storage is None             # the whole message was not parsed
        scene = scanned.scene.SerializeToString()
        whole = scanned.storage                     # parsed now, from the file
        assert len(whole.data_blocks) == len(c)
        assert not scanned.scene.data_blocks
    _as_protobuf_reads(monkeypatch)
    with MdemFile(path) as parsed:
        p = parsed.blocks
        stripped = new("ProtoSimulationStorage")
        stripped.CopyFrom(parsed.storage)
        stripped.ClearField("data_blocks")
        assert stripped.SerializeToString() == scene
    for name in ("start_time", "offset", "size", "uncompressed_size", "format"):
        assert getattr(c, name).tobytes() == getattr(p, name).tobytes(), name


def _descriptor(**fields) -> bytes:
    d = new("ProtoBlockDescriptor")
    for k, v in fields.items():
        setattr(d, k, v)
    return d.SerializeToString()


def _varint(n: int) -> bytes:
    out = bytearray()
    while n >= 0x80:
        out.append(n & 0x7F | 0x80)
        n >>= 7
    out.append(n)
    return bytes(out)


def _field(number: int, payload: bytes) -> bytes:
    head, n = bytearray([number << 3 | 2]), len(payload)
    while n >= 0x80:
        head.append(n & 0x7F | 0x80)
        n >>= 7
    head.append(n)
    return bytes(head) + payload


@needs_c
def test_descriptor_scan_edge_cases_match_protobuf():
    """Negative and 64-bit values, repeated fields (the last wins), descriptors apart from
    one another (two spans): the scan equals protobuf's parse; anything protobuf might read
    otherwise (an unknown descriptor field, wrong wire type, a cut record) is declined."""
    info = new("ProtoSimulationStorage")
    info.info.savedTimePoints.extend([0.0, 1.5])
    info.info.particles.add(type=1)
    head = info.SerializeToString()
    d1 = _descriptor(start_time=-0.0, offset_in_file=(1 << 40) + 3, size=-5, uncompressed_size=2**31 - 1,
                     format=2)
    d2 = _descriptor(start_time=1.5, offset_in_file=-7, size=9) + _descriptor(size=11, format=7)
    raw = _field(3, d1) + head + _field(3, d2) + _field(3, b"")
    storage = new("ProtoSimulationStorage", raw)
    start, ints, spans = fast.mdem_blocks(raw, 3)
    with pytest.raises(OverflowError):
        fast.mdem_blocks(raw, 2)
    want = BlockIndex.of_messages(storage.data_blocks)
    assert start.tobytes() == want.start_time.tobytes()
    assert [list(r) for r in ints] == [list(getattr(want, n)) for n in
                                       ("offset", "size", "uncompressed_size", "format")]
    assert list(ints[1]) == [-5, 11, 0] and ints[0][1] == -7
    assert spans.tolist() == [[0, 2 + len(d1)], [2 + len(d1) + len(head), len(raw)]]
    rest = blockindex.cut(raw, spans)
    assert rest == head
    for odd in (_field(3, d1 + b"\x30\x01"),                 # field 6 in a descriptor
                _field(3, b"\x09\x01"),                      # start_time cut short
                b"\x19" + bytes(8),                          # field 3 as a double
                head[:-1],                                   # the message cut short
                _varint(((1 << 32) + 3) << 3 | 2) + _field(3, d1)[1:]):   # field 2^32+3: no protobuf field
        assert fast.mdem_blocks(odd, 10) is None


# -- a million time points ------------------------------------------------------------------
POINTS = 1_000_000
T0, DT = 1e-3, 1e-5                 # no time point at 0: proto3 would leave its time out


def _stored_zlib(rows: np.ndarray) -> np.ndarray:
    """Each row as a zlib stream of one stored (uncompressed) deflate block: what zlib
    reads, built for a million rows at once (Adler-32 computed with numpy)."""
    n, length = rows.shape
    a = (1 + rows.sum(axis=1, dtype=np.int64)) % 65521
    b = np.empty(n, np.int64)
    weights = length - np.arange(length, dtype=np.int64)
    for lo in range(0, n, 100_000):
        b[lo:lo + 100_000] = (length + rows[lo:lo + 100_000].astype(np.int64) @ weights) % 65521
    head = np.frombuffer(b"\x78\x01\x01" + struct.pack("<HH", length, length ^ 0xFFFF), np.uint8)
    adler = ((b << 16) | a).astype(">u4").view(np.uint8).reshape(n, 4)
    return np.hstack([np.tile(head, (n, 1)), rows, adler])


def _one_sphere_point(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Values written at point k: a sphere at (k, 2k, -1) mm (coord only)."""
    return np.stack([k * 1e-3, 2 * k * 1e-3, np.full(len(k), -1e-3)], axis=1), np.full(len(k), tp.bit("coord"))


@pytest.fixture(scope="module")
def million(tmp_path_factory) -> Path:
    """A MUSEN-layout .mdem of one glass sphere and a million time points, one block each (as
    MUSEN saves), ~60 MB: blocks are zlib streams of ProtoBlockOfTimePoints whose bytes are
    those of fibrelmp's encoder with the time and coordinates set in place."""
    times = T0 + DT * np.arange(POINTS)
    coord, masks = _one_sphere_point(np.arange(POINTS, dtype=float))
    values = np.zeros((1, tp.NCOLS))
    values[0, :3] = (1.0, 1.0, 1.0)                     # every double present: fixed length
    block = document._field2(tp.encode(1.0, values, masks[:1]))
    rows = np.tile(np.frombuffer(block, np.uint8), (POINTS, 1))
    one, at = struct.pack("<d", 1.0), -1
    for column in [times, *coord.T]:                # the time, then x, y, z, in wire order
        at = block.index(one, at + 1)
        rows[:, at:at + 8] = column.astype("<f8").view(np.uint8).reshape(-1, 8)
    streams = _stored_zlib(rows)
    assert zlib.decompress(streams[7].tobytes()) == rows[7].tobytes()
    storage = new("ProtoSimulationStorage")
    with MdemFile(ONE_GLASS_SPHERE) as scene:                  # a cmusen scene: materials etc.
        storage.CopyFrom(scene.scene)
    del storage.info.particles[1:], storage.info.savedTimePoints[:]
    storage.info.savedTimePoints.extend(times)
    size = streams.shape[1]
    for k in range(POINTS):
        storage.data_blocks.add(start_time=times[k], offset_in_file=k * size, size=size,
                                uncompressed_size=len(block), format=2)
    path = tmp_path_factory.mktemp("million") / "million.mdem"
    with open(path, "w+b") as fh:
        w = ContainerWriter(fh)
        w._block(0, 0)
        w.write(1, 0, streams.tobytes())
        w.write(0, 0, zlib.compress(storage.SerializeToString(), 1))
        w.finish()
    return path


def test_a_million_time_points_open_any_frame_from_its_block(million):
    with MdemFile(million) as mdem:
        assert mdem.count() == POINTS
        assert mdem._storage is None                # descriptors never became messages
        sample = [0, 1, 2, 499_999, 500_000, 777_777, POINTS - 2, POINTS - 1]
        for k in sample:
            time, values, masks = mdem.time_point(k)
            coord, mask = _one_sphere_point(np.array([float(k)]))
            assert time == T0 + DT * k
            assert values.shape == (1, tp.NCOLS) and np.array_equal(masks, mask)
            assert values[0, :3].tobytes() == coord[0].tobytes() and not values[0, 3:].any()
        # the first points of the full decode agree too (all of it: the slow path's ~30 s)
        for k, point in zip(range(3), mdem.time_points()):
            _same_point(mdem.time_point(k), point)


def test_a_million_time_points_in_a_snapshot_source(million):
    """``snapshot``'s source: the scene and any frame, from the descriptors' index."""
    from fibrelmp.translate.musen.mdem.pictures import MdemSource

    source = MdemSource(million)
    assert source.count() == POINTS
    last = source.frame(None)
    assert last.index == POINTS - 1 and last.time == T0 + DT * (POINTS - 1)
    assert np.array_equal(last.position, _one_sphere_point(np.array([POINTS - 1.0]))[0])
    assert source.frame(-POINTS).time == T0 and source.frame(12345).index == 12345
    with pytest.raises(InputError, match="has 1000000 frame"):
        source.frame(POINTS)


# -- files whose saved times do not index their blocks ----------------------------------------
def _small(path: Path, saved: list[float] | None) -> Path:
    """Three time points (one block each) at 1, 2, 3 ms; ``saved`` replaces the saved times."""
    with open(path, "w+b") as fh:
        out = MdemWriter(fh)
        for k in range(3):
            out.add((k + 1) * 1e-3, np.full((2, tp.NCOLS), k + 0.5), np.full(2, tp.bit("coord", "vel"), np.uint32))
        storage = new("ProtoSimulationStorage")
        for _ in range(2):
            storage.info.particles.add(type=1, encoded_properties=b"\0" * 16)
        out.finish(storage)
    if saved is not None:                           # written again with other saved times
        def resave(storage) -> None:
            del storage.info.savedTimePoints[:]
            storage.info.savedTimePoints.extend(saved)
        with_edited_scene(path, path, resave)
    return path


@pytest.mark.parametrize("saved", [[], [3e-3, 2e-3, 1e-3, 2e-3], [1e-3, 2e-3, 3e-3, np.nan]],
                         ids=["none", "unsorted", "nan"])
def test_files_without_usable_saved_times_are_indexed_by_counting(tmp_path, saved):
    path = _small(tmp_path / "s.mdem", saved)
    with MdemFile(path) as mdem:
        full = list(mdem.time_points())
        assert mdem.count() == len(full) == 3
        for i in range(3):
            _same_point(mdem.time_point(i), full[i])
        assert mdem._point_index().counted == (not saved or np.isnan(saved).any())


def test_saved_times_that_misplace_a_time_point_are_refused(tmp_path):
    """Saved times 1, 1.5, 2, 3 ms place two time points in the first block, which holds one:
    time point 1 is not where they say, and reading it is refused (never another one)."""
    path = _small(tmp_path / "s.mdem", [1e-3, 1.5e-3, 2e-3, 3e-3])
    with MdemFile(path) as mdem:
        assert mdem.count() == 4
        _same_point(mdem.time_point(3), list(mdem.time_points())[2])   # saved time 3 ms
        with pytest.raises(InputError, match=r"block 0 holds 1 time point\(s\), where the file's "
                                             r"saved times \(savedTimePoints\) place 2"):
            mdem.time_point(1)


# -- text of results with many saves: object lines written in pieces -------------------------
def test_text_export_in_pieces_is_cmusens_export(tmp_path, monkeypatch):
    """With lines written a few saves at a time (what a result of many saves gets, so that
    memory holds a piece, not a line), fibrelmp's text of cmusen's .mdem is still cmusen's own
    17-digit export, byte for byte."""
    from fibrelmp import python_api
    from fibrelmp.translate.musen.mdem import text_export

    monkeypatch.setattr(text_export, "_CHUNK_VALUES", 70)          # 2 saves per piece
    out = tmp_path / "bounce.txt"
    python_api.convert_file(BOUNCE, out, precision=17)
    assert out.read_bytes() == (BOUNCE.parent / "bounce_result_prec17.txt").read_bytes()


def test_result_writer_in_pieces_writes_the_same_text(tmp_path, monkeypatch):
    """The text result writer (``run``, ``post --to musen``): the same file whole or in pieces
    (cmusen's bounce: a sphere and 12 wall triangles, 102 saves)."""
    from fibrelmp.translate.musen import writer
    from fibrelmp.translate.musen.mdem.model import MdemReader

    def write(path: Path) -> bytes:
        reader = MdemReader(BOUNCE)
        w = writer.MusenResultWriter(reader.read(), path, precision=17)
        for frame in reader:
            w.add(frame)
        w.close()
        return path.read_bytes()

    whole = write(tmp_path / "whole.txt")
    monkeypatch.setattr(writer, "_VALUES_PER_CHUNK", 50)           # 2 saves per piece
    assert writer.long_lines(102, 19, 50) == 2
    assert write(tmp_path / "pieces.txt") == whole


# -- writing: the descriptors of many time points as arrays ----------------------------------
@needs_c
@pytest.mark.parametrize("unknown", [False, True], ids=["scene", "scene-with-unknown-field"])
def test_writer_descriptors_are_what_protobuf_writes(tmp_path, monkeypatch, unknown):
    """MdemWriter keeps each block's descriptor in arrays and serializes them with the C
    helper: the file is byte for byte the one protobuf's own serialization gives (times with
    -0.0 and 0, offsets past 2**32; a scene with an unknown top-level field keeps protobuf's
    order through protobuf)."""
    def write(path: Path) -> bytes:
        with open(path, "w+b") as fh:
            out = MdemWriter(fh)
            for k, t in enumerate([-0.0, 0.0, 1e-3, 2.5e-3]):
                out.add(t, np.full((2, tp.NCOLS), k - 1.5), np.full(2, tp.bit("coord", "force"), np.uint32))
            out.offsets[-1] += 1 << 33               # a descriptor protobuf writes in 5+ bytes
            with MdemFile(ONE_GLASS_SPHERE) as scene:
                storage = new("ProtoSimulationStorage")
                storage.CopyFrom(scene.scene)
            if unknown:
                storage.MergeFromString(b"\xa0\x06\x07")         # field 100, varint 7
            out.finish(storage)
        return path.read_bytes()

    used = []
    real = fast.mdem_put_blocks
    monkeypatch.setattr(document.fast, "mdem_put_blocks", lambda *a: used.append(1) or real(*a))
    fast_bytes = write(tmp_path / "c.mdem")
    assert used == ([] if unknown else [1])
    monkeypatch.setattr(document.fast, "mdem_put_blocks", lambda *a: None)
    assert write(tmp_path / "protobuf.mdem") == fast_bytes
    with MdemFile(ONE_GLASS_SPHERE) as scene:
        assert document._top_fields(scene.scene.SerializeToString()) == {1, 2}


@pytest.mark.parametrize("scan", [True, False], ids=["c-scan", "protobuf"])
def test_a_scene_of_millions_of_empty_descriptors_is_refused_before_allocating(tmp_path, monkeypatch,
                                                                               scan):
    """10 MB of empty block descriptors zip to 10 kB: the scan counts them against the scene's
    message budget before it allocates arrays for them (5 million x 40 bytes), as
    ``count_messages`` does before protobuf parses them."""
    if scan and fast.library() is None:
        pytest.skip("the C helpers are not available")
    if not scan:
        _as_protobuf_reads(monkeypatch)
    path = _small(tmp_path / "s.mdem", None)
    with MdemFile(path) as mdem:
        storage = mdem.storage
        blocks = [mdem.block_raw(i) for i in range(len(mdem.blocks))]
    scene = storage.SerializeToString() + b"\x1a\x00" * 5_000_000
    with open(path, "w+b") as fh:
        w = ContainerWriter(fh)
        w._block(0, 0)
        for d, raw in zip(storage.data_blocks, blocks):
            w.write(1, d.offset_in_file, raw)
        w.write(0, 0, zlib.compress(scene, 9))
        w.finish()
    assert path.stat().st_size < 100_000
    with pytest.raises(InputError, match="lists more than 10.* objects and other entries"):
        MdemFile(path)


def test_blocks_compressed_beside_the_caller_give_the_same_file(tmp_path, monkeypatch):
    """MdemWriter compresses a large time point on the helper thread while the next one is
    prepared: the file is byte-identical to compressing each in turn, and reads back."""
    from concurrent.futures import ThreadPoolExecutor

    from fibrelmp.numtext import fast

    rng = np.random.default_rng(2)
    points = [rng.standard_normal((40000, tp.NCOLS)) for _ in range(3)]   # ~10 MB each: split size

    def write(path: Path) -> bytes:
        with open(path, "w+b") as fh:
            out = MdemWriter(fh)
            for k, values in enumerate(points):
                out.add((k + 1) * 1e-3, values, np.full(len(values), tp.bit("coord", "vel"), np.uint32))
            storage = new("ProtoSimulationStorage")
            for _ in range(len(points[0])):
                storage.info.particles.add(type=1, encoded_properties=b"\0" * 16)
            out.finish(storage)
        return path.read_bytes()
    monkeypatch.setattr(fast, "helper_pool", lambda: None)
    alone = write(tmp_path / "alone.mdem")
    submitted = []

    class Pool(ThreadPoolExecutor):
        def submit(self, *args, **kwargs):
            submitted.append(args[0])
            return super().submit(*args, **kwargs)
    with Pool(1) as pool:
        monkeypatch.setattr(fast, "helper_pool", lambda: pool)
        beside = write(tmp_path / "beside.mdem")
    assert beside == alone and len(submitted) == 3
    with MdemFile(tmp_path / "beside.mdem") as mdem:
        assert mdem.count() == 3
        t, values, _ = mdem.time_point(2)
        assert t == 3e-3 and np.array_equal(values[:, :3], points[2][:, :3])
