"""A LAMMPS text dump with ``ITEM: TIME`` (fibrelmp's work dumps) as an MDAnalysis ``Universe``.

MDAnalysis 2.x's ``LAMMPSDUMP`` reader expects every frame to start with ``ITEM: TIMESTEP``
and counts a fixed number of lines per frame, so the ``ITEM: TIME`` (and ``ITEM: UNITS``) lines
``dump_modify time yes`` adds break it ("No id column found").  ``TimedDumpReader`` is that
reader with the frames found by their ``ITEM: TIMESTEP`` lines and the time taken from
``ITEM: TIME``; everything else (columns, velocities, forces, sorting by id) is MDAnalysis's.
The topology (ids, types) comes from the first frame, as MDAnalysis's dump parser gives it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from MDAnalysis.coordinates.LAMMPS import DumpReader
from MDAnalysis.lib import util


class TimedDumpReader(DumpReader):
    """MDAnalysis's dump reader for dumps whose frames may begin with ITEM: UNITS / ITEM: TIME."""

    format = "FIBRELMP_LAMMPSDUMP"          # its own name: MDAnalysis's LAMMPSDUMP stays as it is

    def _index(self) -> None:
        """Byte offset of every frame's ITEM: TIMESTEP line, its time, and the atom count."""
        offsets, times, count = [], [], None
        time = None
        with util.anyopen(self.filename, "rb") as raw:
            fh = _BoundedLines(raw, self.filename)
            pos = fh.tell()
            line = fh.readline()
            while line:
                if line.startswith(b"ITEM: TIME") and not line.startswith(b"ITEM: TIMESTEP"):
                    time = float(fh.readline())
                elif line.startswith(b"ITEM: TIMESTEP"):
                    offsets.append(pos)
                    times.append(time)
                    time = None
                    fh.readline()                               # the step
                    fh.readline()                               # ITEM: NUMBER OF ATOMS
                    n = int(fh.readline())
                    count = n if count is None else count
                    for _ in range(5 + n):                      # box (4 lines), ITEM: ATOMS, atoms
                        fh.readline()
                pos = fh.tell()
                line = fh.readline()
        self._offsets, self._times, self._count = offsets, times, count or 0

    @property
    def n_atoms(self) -> int:
        if not hasattr(self, "_count"):
            self._index()
        return self._count

    @property
    def n_frames(self) -> int:
        if not hasattr(self, "_offsets"):
            self._index()
        return len(self._offsets)

    def _reopen(self) -> None:
        self.close()
        self._file = util.anyopen(self.filename)
        self.ts = self._Timestep(self.n_atoms, **self._ts_kwargs)
        self.ts.frame = -1

    def _read_next_timestep(self):
        k = self.ts.frame + 1
        if k < self.n_frames:
            self._file.seek(self._offsets[k])
        ts = super()._read_next_timestep()
        if self._times[ts.frame] is not None:
            ts.data["time"] = self._times[ts.frame]
        return ts


class _BoundedLines:
    """``readline`` of at most ``MAX_LINE`` bytes (the dump reader's bound): a line without
    its end within that is an InputError, not a read of the whole rest of the file."""

    def __init__(self, fh, path):
        self.fh, self.path, self.lines = fh, path, 0

    def tell(self) -> int:
        return self.fh.tell()

    def readline(self) -> bytes:
        from fibrelmp.errors import InputError
        from fibrelmp.post.lammps_dump.reader import MAX_LINE

        line = self.fh.readline(MAX_LINE + 1)
        self.lines += 1
        if len(line) > MAX_LINE:
            raise InputError(self.path, self.lines, f"line longer than {MAX_LINE >> 20} MiB, the "
                             "longest a dump line may be")
        return line


def dump_universe(path: str | Path):
    """The frames of a LAMMPS text dump (with or without ITEM: TIME) as an MDAnalysis Universe."""
    import MDAnalysis

    from fibrelmp.post.lammps_dump.reader import iter_frames

    frames = iter_frames(path)
    first = next(frames)
    frames.close()
    order = np.argsort(first.column("id"), kind="stable")
    universe = MDAnalysis.Universe.empty(first.count, trajectory=False)
    universe.add_TopologyAttr("ids", first.column("id")[order].astype(np.int64))
    types = first.columns.get("type")
    if types is not None:
        text = types[order] if types.dtype.kind not in "fiu" else types[order].astype(np.int64)
        universe.add_TopologyAttr("types", text.astype(str))
    universe.load_new(str(path), format=TimedDumpReader, dt=_time_step(path))
    return universe


def _time_step(path: str | Path) -> float:
    """Time per step from the first two frames' ITEM: TIME (1.0 without them)."""
    from fibrelmp.post.lammps_dump.reader import iter_headers

    heads = []
    for head, _ in iter_headers(path, want=lambda index, header: False):
        heads.append(head)
        if len(heads) == 2:
            break
    if len(heads) == 2 and None not in (heads[0].time, heads[1].time) and heads[1].step != heads[0].step:
        return (heads[1].time - heads[0].time) / (heads[1].step - heads[0].step)
    if heads and heads[0].time is not None and heads[0].step:
        return heads[0].time / heads[0].step
    return 1.0
