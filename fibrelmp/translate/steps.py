"""Frame schedules without listing every step (memory O(1) in the number of frames)."""

from __future__ import annotations

import math

PROGRESS_PIECES = 50        # a run is cut into up to this many 'run N' commands (progress)
MIN_PIECE_STEPS = 200       # bead-spring jobs: pieces of at least this many steps (see run_piece)
MAX_RUN = 2 ** 31 - 1       # LAMMPS: run N <= 2^31-1


def run_piece(total: int, min_steps: int = 1) -> int:
    """The steps of one ``run N`` command of a job of ``total`` steps: 1/50 of the run, so the
    runner can show progress and take checkpoints, and at least ``min_steps``.

    Every ``run`` prints two thermo rows (its first and last step).  In a bead-spring job a
    row costs about a force evaluation (energies from the styles' ``single()``,
    docs/record.md), so its pieces are at least ``MIN_PIECE_STEPS`` long (1 % instead of the
    17 % that the 12-step pieces of a 600-step run cost); the pieces do not change its
    trajectory ("pre no").  Granular jobs keep 1/50: their rows are cheap, and LAMMPS's
    ``time``, which moves their walls, is summed once per ``run``."""
    return max(1, min(max(math.ceil(total / PROGRESS_PIECES), min_steps), MAX_RUN))


class SaveSteps:
    """The steps at which frames are saved, in order, without listing them: every ``period``
    steps up to ``total`` (and ``total``), or a short explicit list."""

    def __init__(self, total: int, period: int | None = None, explicit: list[int] | None = None):
        self.total, self.period = total, period
        self.explicit = sorted(set(explicit)) if explicit is not None else None

    def __iter__(self):
        if self.explicit is not None:
            yield from self.explicit
            return
        yield from range(0, self.total + 1, self.period)
        if self.total % self.period:
            yield self.total

    def __len__(self) -> int:
        if self.explicit is not None:
            return len(self.explicit)
        return self.total // self.period + 1 + (1 if self.total % self.period else 0)

    def __contains__(self, step: int) -> bool:
        if self.explicit is not None:
            return step in self.explicit
        return 0 <= step <= self.total and (step % self.period == 0 or step == self.total)

    def __eq__(self, other) -> bool:
        return list(self) == list(other)
