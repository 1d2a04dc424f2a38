"""The frames of a FibreNet job as the run reads them (``pipeline.run``'s frame source:
``is_frame``, ``read``, ``close``), and how the files LAMMPS wrote itself move into place."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Iterator

from fibrelmp.errors import wrong_frame
from fibrelmp.runplan import FRAME_COMMANDS

if TYPE_CHECKING:
    from fibrelmp.post.lammps_dump.reader import Frame


class DumpFrames:
    """The frames of the job's dump (``write_dump``, or ``fibrenet/frame`` when fix
    fibrenet/output writes the dump), read as LAMMPS writes them."""

    def __init__(self, path: Path):
        self.path = path
        self.frames: Iterator["Frame"] | None = None

    def is_frame(self, words: list[str]) -> bool:
        return words[0] in FRAME_COMMANDS

    def read(self, step: int) -> "Frame":
        from fibrelmp.post.lammps_dump.reader import iter_frames

        if self.frames is None:
            self.frames = iter_frames(self.path)
        frame = next(self.frames, None)
        if frame is None or frame.step != step:
            raise wrong_frame(self.path, step, None if frame is None else frame.step)
        return frame

    def close(self) -> None:
        if self.frames is not None:
            self.frames.close()


class WrittenFrames:
    """The frames of a job that writes FibreNet's files (and its work dump) itself with
    ``fibrenet/frame``: nothing is read back (the schedule is still checked)."""

    def is_frame(self, words: list[str]) -> bool:
        return words[0] == "fibrenet/frame"

    def read(self, step: int) -> int:
        return step

    def close(self) -> None:
        pass


def move_file(src: Path, dst: Path) -> None:
    """Rename ``src`` to ``dst`` (replacing it); across file systems through a temp file
    beside ``dst``, so ``dst`` is never half written."""
    import errno
    import shutil

    from fibrelmp.formatbase import place
    from fibrelmp.textio import discard, temp_name, write_failure

    try:
        place(src, dst)          # undone with the run's other results if the run fails
        return
    except OSError as exc:
        if exc.errno != errno.EXDEV:
            raise write_failure(dst, exc) from None
    tmp = temp_name(dst)
    try:
        shutil.copyfile(src, tmp)
        place(tmp, dst)
    except OSError as exc:
        discard(tmp)
        raise write_failure(dst, exc) from None
    src.unlink(missing_ok=True)
