"""``--frames``: which frames of a trajectory ``fibrelmp post`` converts."""

from __future__ import annotations

from typing import Callable

from fibrelmp.errors import InputError


class Selection:
    """``--frames``: ``i``, ``start:stop:step`` (Python slice over frame indices) or a comma
    list of those.  Negative indices count from the end (they need the frame count)."""

    def __init__(self, spec: str | None, default_last: bool = False):
        self.spec = spec
        self.parts: list[tuple[int | None, int | None, int | None] | int] = []
        if spec is None:
            self.parts = [-1] if default_last else [(None, None, None)]
            return
        for part in spec.split(","):
            part = part.strip()
            try:
                if ":" in part:
                    bits = part.split(":")
                    if len(bits) > 3:
                        raise ValueError
                    a, b, c = (bits + [""] * 3)[:3]
                    sl = tuple(int(v) if v.strip() else None for v in (a, b, c))
                    if sl[2] is not None and sl[2] <= 0:
                        raise ValueError
                    self.parts.append(sl)
                else:
                    self.parts.append(int(part))
            except ValueError:
                raise InputError(None, None, f"--frames {spec!r}: expected an index, start:stop:step "
                                 "(positive step) or a comma list of those") from None

    @property
    def needs_count(self) -> bool:
        return any((p < 0) if isinstance(p, int) else any(v is not None and v < 0 for v in p[:2])
                   for p in self.parts)

    def check(self, total: int, what: str, path=None) -> None:
        """An InputError saying how many frames there are, if an index given is not one of
        the ``total`` frames or the selection selects none."""
        singles = [p for p in self.parts if isinstance(p, int)]
        bad = [p for p in singles if not -total <= p < total]
        picked = (any(-total <= p < total for p in singles)
                  or any(len(range(*slice(*p).indices(total))) for p in self.parts if not isinstance(p, int)))
        if bad or not picked:
            which = f"frame {bad[0]} does not exist" if bad else "selects no frame"
            have = (f"{total} frame{'s' if total != 1 else ''} (indices 0..{total - 1}, or "
                    f"-{total}..-1 from the end)") if total else "no frames"
            raise InputError(path, None, f"--frames {self.spec!r}: {which}: the {what} has {have}")

    def resolve(self, total: int | None) -> Callable[[int], bool]:
        singles, slices = set(), []
        for p in self.parts:
            if isinstance(p, int):
                singles.add(p + total if p < 0 and total is not None else p)
            else:
                a, b, c = p
                if total is not None:
                    a, b, c = slice(a, b, c).indices(total)
                slices.append((a or 0, b, c or 1))
        self.stop = None if any(b is None for _, b, _ in slices) else \
            max([b for _, b, _ in slices] + [s + 1 for s in singles] + [0])

        def want(i: int) -> bool:
            return i in singles or any(i >= a and (b is None or i < b) and (i - a) % c == 0
                                       for a, b, c in slices)
        return want
