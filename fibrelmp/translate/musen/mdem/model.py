"""``.mdem`` scenes as the neutral GranularModel (run inputs)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel


def read_scene(path: str | os.PathLike) -> GranularModel:
    """The scene of a ``.mdem`` file at its first saved time point, where MUSEN's simulator
    starts (it clears every later time point before simulating).  The scene is written as
    MUSEN's text export (17 digits: every double exactly) and read by the text scene reader,
    so both forms of a scene give the same model."""
    from fibrelmp.translate.musen import scene
    from fibrelmp.translate.musen.mdem.document import MdemFile
    from fibrelmp.translate.musen.mdem.text_export import export

    path = Path(path)
    with MdemFile(path) as mdem, tempfile.TemporaryDirectory(prefix="fibrelmp-mdem-") as tmp:
        text = Path(tmp) / f"{path.stem}.txt"
        with open(text, "w", newline="\n") as out:
            export(mdem, out, precision=17, spool_dir=Path(tmp), times_limit=1)
        try:
            model = scene.read(text)
        except InputError as exc:
            where = f" (its text form, line {exc.line})" if exc.line else ""
            raise InputError(path, None, f"{exc.message}{where}") from None
        mdem_version = mdem.version
    model.source = path
    model.passthrough["mdem_source"] = path
    model.passthrough["mdem_version"] = mdem_version
    return model
