"""Strict JSON loading and typed access with JSON-location error messages (DEMDF documents,
CardioProof cases).

Every problem becomes ``InputError(path, line, "location: message")`` where ``location`` is
the JSON path (``objects.particles[3][6]``); syntax errors carry the line and column.
"""

from __future__ import annotations

import difflib
import json
import math
from json.decoder import scanstring
from pathlib import Path
from typing import Any, Iterable, NoReturn

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.textio import read_text


class _JsonValueError(ValueError):
    pass


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise _JsonValueError(f"the number {text} is too large for a double")
    return value


def _constant(name: str) -> float:
    raise _JsonValueError(f"{name} is not valid JSON (numbers must be finite)")


def load_json(path: Path, what: str) -> Any:
    """Parse a JSON file; syntax errors report ``path:line: ... (line l, column c)``.

    A key repeated in one object is an error (JSON readers disagree on which copy counts;
    BOS's rapidjson takes the first), except in a JSON Schema (``$schema``), which the caller
    recognises and refuses by itself."""
    text = read_text(path, what)
    repeated: list[str] = []

    def first_wins(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        obj: dict[str, Any] = {}
        for key, value in pairs:
            if key in obj:
                repeated.append(key)
            else:
                obj[key] = value
        return obj

    try:
        doc = json.loads(text, object_pairs_hook=first_wins, parse_float=_finite_float,
                         parse_constant=_constant)
    except json.JSONDecodeError as exc:
        raise InputError(path, exc.lineno, f"{what} is not valid JSON: {exc.msg} "
                         f"(line {exc.lineno}, column {exc.colno})") from None
    except _JsonValueError as exc:
        raise InputError(path, None, f"{what} is not valid JSON: {exc}") from None
    except RecursionError:
        raise InputError(path, None, f"{what} is not valid JSON: nested too deeply") from None
    if repeated and not (isinstance(doc, dict) and "$schema" in doc):
        raise InputError(path, None, f"the key {repeated[0]!r} appears twice in one JSON object; "
                         "readers disagree on which copy counts, so remove one")
    return doc


def describe(value: Any) -> str:
    """How a JSON value reads in an error message."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f"the string {value[:40]!r}"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, list):
        return f"an array of {len(value)}"
    if isinstance(value, dict):
        return "an object"
    return type(value).__name__


def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def key_line(text: str, location: tuple) -> int | None:
    """The line of the key at ``location`` (object keys and array indices from the top, the
    key last, e.g. ``("objectTypes", 0, "raduis")``) in the JSON ``text`` (None: not found).
    A scan of the valid document's tokens: only run to report an error."""
    stack: list[list] = []             # per open container: [kind, key or index, expecting key]
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "{":
            stack.append(["o", None, True])
        elif c == "[":
            stack.append(["a", 0, False])
        elif c in "]}":
            stack.pop()
        elif c == "," and stack:
            if stack[-1][0] == "a":
                stack[-1][1] += 1
            else:
                stack[-1][2] = True
        elif c == ":" and stack:
            stack[-1][2] = False
        elif c == '"':
            value, end = scanstring(text, i + 1)
            if stack and stack[-1][0] == "o" and stack[-1][2]:
                stack[-1][1] = value
                if tuple(entry[1] for entry in stack) == location:
                    return text.count("\n", 0, i) + 1
            i = end
            continue
        i += 1
    return None


class JsonDoc:
    """Typed getters that name the JSON location on failure."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, where: str, message: str, line: int | None = None) -> NoReturn:
        raise InputError(self.path, line, f"{where}: {message}" if where else message)

    def check_keys(self, obj: dict, where: str, location: tuple, known: Iterable[str],
                   lenient: bool = False) -> list[str]:
        """Every key of ``obj`` (at JSON path ``where``, ``location`` as for ``key_line``) must
        be one of ``known``: an unknown one is an error at its line, with the known key it
        most resembles (a misspelt key would otherwise leave its default in force silently).
        ``lenient``: where the format allows other entries (other output routines), only a
        key that resembles a known one is an error; the others are returned."""
        known = list(known)
        others = []
        for key in obj:
            if key in known:
                continue
            close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
            if lenient and not close:
                others.append(key)
                continue
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            line = key_line(read_text(self.path, "JSON file"), location + (key,))
            self.fail(f"{where}" if where else "", f"unknown key {key!r}{hint}; the keys read "
                      f"here are {', '.join(known)}", line)
        return others

    def number(self, value: Any, where: str, *, minimum: float | None = None,
               positive: bool = False) -> float:
        if not is_number(value):
            self.fail(where, f"expected a number, got {describe(value)}")
        try:
            result = float(value)
        except OverflowError:
            self.fail(where, "the number is too large for a double")
        if positive and not result > 0:
            self.fail(where, f"must be positive, got {value!r}")
        if minimum is not None and result < minimum:
            self.fail(where, f"must be at least {minimum:g}, got {value!r}")
        return result

    def integer(self, value: Any, where: str, *, minimum: int | None = None) -> int:
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if not isinstance(value, int) or isinstance(value, bool):
            self.fail(where, f"expected an integer, got {describe(value)}")
        if minimum is not None and value < minimum:
            self.fail(where, f"must be at least {minimum}, got {value}")
        if abs(value) > 2 ** 53:
            self.fail(where, f"{value} is too large")
        return value

    def string(self, value: Any, where: str) -> str:
        if not isinstance(value, str):
            self.fail(where, f"expected a string, got {describe(value)}")
        return value

    def obj(self, value: Any, where: str) -> dict:
        if not isinstance(value, dict):
            self.fail(where, f"expected an object {{...}}, got {describe(value)}")
        return value

    def array(self, value: Any, where: str) -> list:
        if not isinstance(value, list):
            self.fail(where, f"expected an array [...], got {describe(value)}")
        return value

    def vector(self, value: Any, n: int, where: str, layout: str) -> np.ndarray:
        items = self.array(value, where)
        if len(items) != n:
            self.fail(where, f"expected {n} numbers {layout}, got {describe(items)}")
        return np.array([self.number(x, f"{where}[{i}]") for i, x in enumerate(items)])

    def table(self, rows: Any, where: str, ncols: int, layout: str, hint: str = "") -> np.ndarray:
        """An array of equal-length number arrays, as an (n, ncols) float array."""
        rows = self.array(rows, where)
        for i, row in enumerate(rows):
            if not isinstance(row, list):
                self.fail(f"{where}[{i}]", f"a row is an array {layout}, got {describe(row)}")
            if len(row) != ncols:
                self.fail(f"{where}[{i}]", f"expected {ncols} entries {layout}, got {len(row)}{hint}")
        kinds = {type(x) for row in rows for x in row}
        if kinds <= {int, float}:
            try:
                return np.array(rows, dtype=float).reshape(len(rows), ncols)
            except (OverflowError, ValueError, TypeError):
                pass
        for i, row in enumerate(rows):          # slow path: find the first offender
            for j, x in enumerate(row):
                self.number(x, f"{where}[{i}][{j}]")
        raise AssertionError("unreachable")     # pragma: no cover
