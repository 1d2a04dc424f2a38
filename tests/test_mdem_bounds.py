"""Hostile .mdem files (issue 24): zlib bombs in a time-point block and in the scene are refused
by the CLI within seconds and under a memory limit, naming the file, writing nothing."""

from __future__ import annotations

import resource
import struct
import subprocess
import sys
import time
import zlib
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.translate.musen.mdem import bounds
from fibrelmp.translate.musen.mdem import timepoints as tp
from fibrelmp.translate.musen.mdem.container import ContainerWriter
from fibrelmp.translate.musen.mdem.messages import new

LIMIT_AS = 1536 << 20            # the subprocess's address space (1.5 GiB)
TIMEOUT = 60


def _stream(head: bytes, chunk: bytes, copies: int, tail: bytes, level: int = 9) -> bytes:
    """A zlib stream of ``head + chunk * copies + tail``, built in milliseconds: after a full
    flush (which resets the dictionary) every chunk compresses to the same bytes, so one
    compressed chunk is repeated; the trailer's Adler-32 is computed."""
    c = zlib.compressobj(level)
    first = c.compress(head + chunk) + c.flush(zlib.Z_FULL_FLUSH)
    unit = c.compress(chunk) + c.flush(zlib.Z_FULL_FLUSH)
    assert unit == c.compress(chunk) + c.flush(zlib.Z_FULL_FLUSH)
    raw = zlib.compressobj(9, zlib.DEFLATED, -15)          # the last, final block
    end = raw.compress(tail) + raw.flush()
    adler = zlib.adler32(head)
    for _ in range(copies):
        adler = zlib.adler32(chunk, adler)
    adler = zlib.adler32(tail, adler)
    return first + unit * (copies - 1) + end + struct.pack(">I", adler)


def _field(number: int, payload: bytes) -> bytes:
    head, n = bytearray([number << 3 | 2]), len(payload)
    while n >= 0x80:
        head.append(n & 0x7F | 0x80)
        n >>= 7
    head.append(n)
    return bytes(head) + payload


def _write(path: Path, scene_stream: bytes, block: bytes) -> Path:
    with open(path, "w+b") as fh:
        w = ContainerWriter(fh)
        w._block(0, 0)
        w.write(1, 0, block)
        w.write(0, 0, scene_stream)
        w.finish()
    return path


def _one_sphere_scene(block_size: int, uncompressed: int, saved: int = 1) -> bytes:
    storage = new("ProtoSimulationStorage")
    storage.info.particles.add(id=0, type=1, encoded_properties=struct.pack("<dd", 1e-3, 1e-3))
    storage.info.savedTimePoints.extend(np.arange(saved) * 1e-3)
    storage.data_blocks.add(start_time=0.0, offset_in_file=0, size=block_size,
                            uncompressed_size=uncompressed, format=2)
    return zlib.compress(storage.SerializeToString(), 1)


@pytest.fixture(scope="module")
def block_bomb(tmp_path_factory) -> Path:
    """Issue 24: a 1.4 MB .mdem whose first time-point block is a zlib stream of 1.5e9 zero
    bytes, declaring them."""
    copies = 357                                          # x 4 MiB = 1.497e9 bytes
    block = _stream(b"", bytes(1 << 22), copies, b"")
    path = tmp_path_factory.mktemp("bomb") / "block_bomb.mdem"
    _write(path, _one_sphere_scene(len(block), copies << 22), block)
    assert 1.3e6 < path.stat().st_size < 1.6e6
    return path


@pytest.fixture(scope="module")
def saved_times_bomb(tmp_path_factory) -> Path:
    """The block bomb, with 5000 saved times listed in the scene: the declared 1.5e9 bytes
    then fit 5000 time points of one sphere, so the block is read, one time point at a time."""
    copies = 357
    block = _stream(b"", bytes(1 << 22), copies, b"")
    path = tmp_path_factory.mktemp("bomb") / "saved_times_bomb.mdem"
    _write(path, _one_sphere_scene(len(block), copies << 22, saved=5000), block)
    return path


def _removed_objects_scene(path: Path, copies: int, padding: int) -> Path:
    """A scene of ``copies`` x 2^21 removed objects (MUSEN's empty entries, "32 00"), and
    ``padding`` random bytes in an unknown field 15 of the storage message (they raise the
    stored size, so the entries decompress within the scene's size bound)."""
    point = _field(2, tp.encode(0.0, np.zeros((0, tp.NCOLS)), np.zeros(0, np.uint32)))
    block = zlib.compress(point, 1)
    removed = copies << 21
    descriptor = new("ProtoBlockDescriptor")
    descriptor.start_time, descriptor.size, descriptor.format = 0.0, len(block), 2
    descriptor.uncompressed_size = len(point)
    # ProtoSimulationStorage: field 1 (info: the entries), field 3 (the block's descriptor)
    head = _field(1, bytes(2 * removed))[:-2 * removed]
    tail = _field(3, descriptor.SerializeToString())
    if padding:
        tail += _field(15, np.random.default_rng(24).bytes(padding))
    stream = _stream(head, b"\x32\x00" * (1 << 21), copies, tail, level=1)
    return _write(path, stream, block)


@pytest.fixture(scope="module")
def scene_bomb(tmp_path_factory) -> Path:
    """Issue 24: a 1.3 MB scene listing 90 million removed objects (180 MB decompressed)."""
    path = _removed_objects_scene(tmp_path_factory.mktemp("bomb") / "scene_bomb.mdem", 43, 600_000)
    assert 1.2e6 < path.stat().st_size < 1.6e6
    return path


@pytest.fixture(scope="module")
def scene_entries_bomb(tmp_path_factory) -> Path:
    """40 million removed objects (80 MB decompressed) in a 1.35 MB scene: within the scene's
    decompression bound, so the entries reach the count before protobuf."""
    path = _removed_objects_scene(tmp_path_factory.mktemp("bomb") / "entries_bomb.mdem", 19,
                                  1_000_000)
    stored = path.stat().st_size
    assert 80e6 < bounds.scene_limit(stored) and bounds.message_budget(stored) < 40e6
    return path


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT_AS, LIMIT_AS))


def _cli(*args: str, cwd: Path) -> tuple[subprocess.CompletedProcess, float]:
    start = time.monotonic()
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=TIMEOUT, preexec_fn=_limited)
    return proc, time.monotonic() - start


@pytest.mark.parametrize("bomb, message", [
    ("block_bomb", "time-point block 0 declares 1497366528 bytes, more than 1 time point(s) of "
                   "a scene of 1 objects can take"),
    ("saved_times_bomb", "corrupt .mdem file: time-point block 0: field number 0 (not a protobuf"),
    ("scene_bomb", "the scene (file thread 0) is larger than a MUSEN scene of"),
    ("scene_entries_bomb", "objects and other entries, more than a MUSEN file of its size holds"),
])
@pytest.mark.parametrize("command", ["convert", "check", "copy"])
def test_mdem_bombs_are_refused_at_once(request, tmp_path, bomb, message, command):
    """``convert`` to text, ``check``, and ``convert`` to .mdem (the byte-identical copy)."""
    path = request.getfixturevalue(bomb)
    out = {"convert": ["-o", str(tmp_path / "out.txt")], "copy": ["-o", str(tmp_path / "out.mdem")]}
    args = ["convert" if command == "copy" else command, str(path)] + out.get(command, [])
    proc, seconds = _cli(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr[-2000:]
    error = [line for line in proc.stderr.splitlines() if line.startswith("error:")]
    assert error and str(path) in error[0] and message in error[0], proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    assert seconds < 20, seconds


def test_block_bound_is_the_largest_entry_protobuf_writes():
    """MAX_ENTRY (331 bytes) is the size protobuf gives an object entry with every field set,
    and a time point of the scene's objects fits block_bound."""
    props = new("ProtoTimeDependentProperties")
    for name in ("coord", "angles", "vel", "angle_vel", "angle_accl", "force"):
        v = getattr(props, name)
        v.x, v.y, v.z = 1.5, -2.5, 3.5
    props.total_torque = props.temperature = props.liquid_film_mass = 1.25
    props.quaternion.q0 = props.quaternion.q1 = props.quaternion.q2 = props.quaternion.q3 = 0.5
    for v in (props.stress_tensor.v1, props.stress_tensor.v2, props.stress_tensor.v3):
        v.x, v.y, v.z = 1.5, 2.5, 3.5
    entry = props.SerializeToString()
    assert bounds.MAX_ENTRY == 1 + 2 + len(entry) == 331
    point = new("ProtoTimePoint")
    point.time = 0.5
    for _ in range(bounds.objects_per_point(3)):
        point.particles.add().CopyFrom(props)
    assert len(_field(2, point.SerializeToString())) <= bounds.block_bound(3, 1)


def test_scene_messages_are_counted_as_protobuf_parses_them():
    """count_messages counts what protobuf allocates (itself and every nested message),
    runs of identical entries and scattered ones alike, and stops at its budget."""
    storage = new("ProtoSimulationStorage")
    for i in range(50):
        storage.info.particles.add(id=i, type=1 if i % 3 else 0)
    storage.info.particles.add()
    storage.info.particles.add()
    for _ in range(7):
        storage.info.particles.add()
    storage.info.real_geometry.add().base_geometry.motion.intervals.add()
    storage.modules_data.materials_database.compound.add().constProperty.add(value=2.0)
    storage.data_blocks.add(size=4)
    raw = storage.SerializeToString()
    parsed = new("ProtoSimulationStorage", raw)
    expected = 1 + 1 + len(parsed.info.particles) + 4 + 4 + 1
    assert bounds.count_messages(raw, "ProtoSimulationStorage", 10 ** 6) == expected
    with pytest.raises(bounds.TooMany):
        bounds.count_messages(raw, "ProtoSimulationStorage", expected - 1)
    with pytest.raises(ValueError):
        bounds.count_messages(b"\0\0\0\0", "ProtoSimulationStorage", 10)


def test_a_block_of_several_time_points_is_read_one_at_a_time(tmp_path):
    """A block holding two time points of 5000 spheres (0.8 MB each, so they cross the 1 MiB
    pieces the block is decompressed in) reads back exactly; listing only one saved time
    for it makes the second a corrupt-file error."""
    from fibrelmp.errors import InputError
    from fibrelmp.translate.musen.mdem.document import MdemFile

    rng = np.random.default_rng(7)
    n = 5000
    masks = np.full(n, tp.bit("coord", "vel", "angle_vel", "force", "quaternion"), np.uint32)
    points = [(t, rng.standard_normal((n, tp.NCOLS))) for t in (0.0, 1e-3)]
    block = b"".join(_field(2, tp.encode(t, v, masks)) for t, v in points)
    packed = zlib.compress(block, 1)
    for saved, ok in ((2, True), (1, False)):
        storage = new("ProtoSimulationStorage")
        for i in range(n):
            storage.info.particles.add(id=i, type=1, encoded_properties=struct.pack("<dd", 1e-3, 1e-3))
        storage.info.savedTimePoints.extend([0.0, 1e-3][:saved])
        storage.data_blocks.add(start_time=0.0, offset_in_file=0, size=len(packed),
                                uncompressed_size=len(block), format=2)
        path = _write(tmp_path / f"two_{saved}.mdem", zlib.compress(storage.SerializeToString(), 1), packed)
        with MdemFile(path) as mdem:
            if ok:
                got = list(mdem.time_points())
                assert [g[0] for g in got] == [t for t, _ in points]
                for (_, values, m), (_, want) in zip(got, points):
                    cols = np.concatenate([np.r_[tp.columns(f)] for f in
                                           ("coord", "vel", "angle_vel", "force", "quaternion")])
                    assert np.array_equal(values[:, cols], want[:, cols]) and np.array_equal(m, masks)
            else:
                with pytest.raises(InputError, match="more than the 1 time point"):
                    list(mdem.time_points())
