"""openCARP's reference samples for the conformance tests (tests/conformance/test_opencarp.py,
test_dynpt.py): a mesh the reader must refuse, and ``.dynpt`` files built byte by byte as
meshalyzer writes them (not by fibrelmp's writer; docs/architecture.md, "Conformance tests")."""

from __future__ import annotations

from pathlib import Path

import numpy as np

IGB_HEADER = 1024          # the IGB header's size (openCARP)


def bad_mesh(folder: Path) -> Path:
    """``bad.pts`` (says 3 points, has 2) and ``bad.elem``; the ``.pts`` path."""
    (folder / "bad.pts").write_text("3\n0 0 0\n1 1 1\n")
    (folder / "bad.elem").write_text("0\n")
    return folder / "bad.pts"


def igb(items: bytes, values: np.ndarray) -> bytes:
    """A header as meshalyzer writes it (items, CR LF, space padding, form feed), then data."""
    head = items + b" \r\n"
    return head + b" " * (IGB_HEADER - len(head) - 1) + b"\f" + values.astype("<f4").tobytes()


def motion(folder: Path) -> tuple[Path, list[tuple[float, np.ndarray]]]:
    """``move.dynpt``: 3 frames of 2 nodes (µm), 2.5 ms apart from 1 ms; (path, its frames)."""
    values = np.arange(3 * 2 * 3, dtype=np.float64) * 1.5 - 4.0
    path = folder / "move.dynpt"
    path.write_bytes(igb(b"x:2 y:1 z:1 t:3 type:vec3f systeme:little_endian org_t:1 inc_t:2.5 "
                         b"unites_t:ms", values))
    return path, [(1.0 + 2.5 * k, values[6 * k:6 * k + 6].reshape(2, 3)) for k in range(3)]


def bad_motions(folder: Path) -> list[Path]:
    """``motion``'s file spoilt four ways the reader must refuse."""
    good, _ = motion(folder)
    data = good.read_bytes()
    edits = {"short.dynpt": data[:IGB_HEADER + 10],                          # truncated frames
             "float.dynpt": data.replace(b"vec3f", b"float"),               # not positions
             "huge.dynpt": data.replace(b"t:3 ", b"t:" + b"9" * 20 + b" "),  # hostile count
             "nan.dynpt": data[:IGB_HEADER] + np.full(18, np.nan, "<f4").tobytes()}
    for name, content in edits.items():
        (folder / name).write_bytes(content)
    return [folder / name for name in edits]
