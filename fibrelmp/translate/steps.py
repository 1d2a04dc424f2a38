"""Frame schedules without listing every step (memory O(1) in the number of frames)."""

from __future__ import annotations


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
