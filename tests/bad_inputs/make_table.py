"""Regenerate the corpus table in docs/errors.md from the messages fibrelmp prints now.

    python tests/bad_inputs/make_table.py

Run it after changing a message or adding a case; ``tests/test_bad_inputs_corpus.py`` fails
while the table and the real messages differ.  As root, the unreadable-file case cannot be
made (root reads any file): its existing row is kept.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from tests.bad_inputs.corpus import (CASES, DOC, END, HEADER, START, doc_rows, row,  # noqa: E402
                                     run_case, unreadable_possible)


def table() -> str:
    old = doc_rows() if DOC.exists() else {}
    rows = []
    for case in CASES:
        with tempfile.TemporaryDirectory() as tmp:
            if case.needs_unreadable and not unreadable_possible(Path(tmp)):
                rows.append(old.get(case.name, f"| {case.name} | {case.fmt} | {case.what} | "
                                   "exit 2 | (not generated: run make_table.py as a normal user) |"))
                continue
            outcome = run_case(case, Path(tmp))
            if outcome.exception is not None:
                raise SystemExit(f"{case.name}: {type(outcome.exception).__name__} escaped: "
                                 f"{outcome.exception}")
            rows.append(row(case, outcome))
    return "\n".join([START, HEADER, *rows, END])


def one_row(name: str) -> str:
    """The table row of one case (e.g. the unreadable-file case, run as a normal user:
    ``setpriv --reuid=nobody --regid=nogroup --clear-groups python make_table.py --row
    generated/unreadable``, then paste the row into docs/errors.md)."""
    (case,) = [c for c in CASES if c.name == name]
    with tempfile.TemporaryDirectory() as tmp:
        return row(case, run_case(case, Path(tmp)))


def main() -> None:
    if sys.argv[1:2] == ["--row"]:
        print(one_row(sys.argv[2]))
        return
    text = DOC.read_text()
    if START not in text or END not in text:
        raise SystemExit(f"{DOC}: the markers {START!r} and {END!r} are missing")
    new = text[:text.index(START)] + table() + text[text.index(END) + len(END):]
    DOC.write_text(new)
    print(f"wrote {DOC} ({len(CASES)} cases)")


if __name__ == "__main__":
    main()
