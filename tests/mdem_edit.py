"""Test helper: a ``.mdem`` written again with its scene message edited and its time-point
blocks kept byte for byte (as stored, compressed or not)."""

from __future__ import annotations

import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from fibrelmp.translate.musen.mdem.container import ContainerWriter
from fibrelmp.translate.musen.mdem.document import MdemFile


def with_edited_scene(source: Path, target: Path, edit: Callable[[Any], None]) -> Path:
    """``source`` written to ``target`` (may be the same file) after ``edit(storage)``."""
    with MdemFile(source) as mdem:
        storage = mdem.storage
        blocks = [mdem.block_raw(i) for i in range(len(mdem.blocks))]
    edit(storage)
    with open(target, "w+b") as fh:
        w = ContainerWriter(fh)
        w._block(0, 0)
        for d, raw in zip(storage.data_blocks, blocks):
            w.write(1, d.offset_in_file, raw)
        w.write(0, 0, zlib.compress(storage.SerializeToString(), 1))
        w.finish()
    return target
