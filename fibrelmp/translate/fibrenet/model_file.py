"""FibreNet's model file: BEAD, SPRING and ANGLE lines into particles, springs and angles.

Read as FibreNet's SimulationManager.cpp reads it (commit fe11bbcc); the input file's
keywords (and the order FibreNet applies them in) are ``reader.py``'s.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.model import Angles, Bonds, Particles
from fibrelmp.textio import integer_column, parse_table, read_checked_bytes, read_text, to_float, to_int

_STOI = re.compile(r"^\s*[+-]?\d+")


def model_sections(path: Path) -> dict[str, tuple[list[str], list[int]]]:
    """Lines of the model file grouped by their first token (BEAD, SPRING, ANGLE)."""
    text = read_text(path, "FibreNet model file")
    sections: dict[str, tuple[list[str], list[int]]] = {k: ([], []) for k in ("BEAD", "SPRING", "ANGLE")}
    for number, raw in enumerate(text.splitlines(), 1):
        head = raw.lstrip()[:6]
        for key in sections:
            if head.startswith(key) and (len(raw.split(None, 1)[0]) == len(key)):
                sections[key][0].append(raw)
                sections[key][1].append(number)
                break
    return sections


def _stoi(token: str) -> int | None:
    m = _STOI.match(token)
    return int(m.group()) if m else None


def read_model(path: Path, type_index: dict[str, int], type_names: list[str], size: np.ndarray,
                notes: list) -> tuple[Particles, "Springs", Angles]:
    from fibrelmp.translate.fibrenet.fast_reader import fast_read_model

    raw = read_checked_bytes(path, "FibreNet model file")    # encoding / binary checks
    fast = fast_read_model(raw, type_index, type_names, size, Springs)
    del raw
    if fast is not None:
        return fast
    sections = model_sections(path)
    lines, numbers = sections["BEAD"]
    if not lines:
        raise InputError(path, None, "no BEAD lines in the model file")
    table, val = parse_table(lines, numbers, 18, path, "BEAD", text_cols=(0, 1))
    names = table[:, 1]
    unknown = [k for k, name in enumerate(names) if name not in type_index]
    if unknown:
        raise InputError(path, numbers[unknown[0]], f"bead type '{names[unknown[0]]}' is not "
                         f"defined by a 'type' line (defined: {', '.join(type_names)})")
    types = np.array([type_index[name] for name in names], dtype=np.int64)
    tags = integer_column(val, table, 2, path, numbers, "BEAD")
    loc = integer_column(val, table, 3, path, numbers, "BEAD")
    radius, mass = val[:, 4], val[:, 5]
    for col, arr, what in ((5, radius, "radius"), (6, mass, "mass")):
        if (arr < 0).any():
            row = int(np.flatnonzero(arr < 0)[0])
            raise InputError(path, numbers[row], f"BEAD {what} must be >= 0, got {table[row, col - 1]}")
    pos, vel, force, image = val[:, 6:9], val[:, 9:12], val[:, 12:15], val[:, 15:18]
    outside = ((pos < 0) | (pos > size)).any(axis=1)
    if outside.any():
        row = int(np.flatnonzero(outside)[0])
        raise InputError(path, numbers[row], f"bead {row} at ({pos[row, 0]:g}, {pos[row, 1]:g}, "
                         f"{pos[row, 2]:g}) lies outside the box [0, L] (box_size "
                         f"{size[0]:g} {size[1]:g} {size[2]:g})")
    # FibreNet bug (S:1404): the integrator starts from v_old = (vx, vx, vx)
    v_old = np.repeat(vel[:, :1], 3, axis=1)
    particles = Particles(list(type_names), types, pos.copy(), image.copy(), v_old, mass.copy(),
                          radius.copy(), tags, loc, force.copy(), vel.copy())
    springs = _read_springs(path, sections["SPRING"], len(types), notes)
    angles = _read_angles(path, sections["ANGLE"], len(types))
    return particles, springs, angles


def _check_index(idx: np.ndarray, n: int, path: Path, numbers: list[int], what: str) -> None:
    bad = (idx < 0) | (idx >= n)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise InputError(path, numbers[row], f"{what} refers to bead {idx[row, col]}, but the "
                         f"model has beads 0..{n - 1}")


class Springs:
    """Spring data as read, before HR_FL parameters become break lengths."""

    def __init__(self, m: int):
        self.atoms = np.zeros((m, 2), np.int64)
        self.r0, self.k = np.zeros(m), np.zeros(m)
        self.tags = np.zeros(m, np.int64)
        self.fl = np.zeros(m, bool)
        self.c1, self.c2 = np.zeros(m), np.zeros(m)

    def to_bonds(self) -> Bonds:
        brk = np.full(len(self.r0), np.nan)
        for r in np.flatnonzero(self.fl):
            brk[r] = _break_length(self.r0[r], self.c1[r], self.c2[r])
        return Bonds(self.atoms, self.k, self.r0, brk)


def _read_springs(path: Path, section: tuple[list[str], list[int]], n: int, notes: list) -> Springs:
    lines, numbers = section
    s = Springs(len(lines))
    if not lines:
        return s
    rows: list[list[str]] = [ln.split() for ln in lines]
    if all(len(r) == 7 and r[1] == "HR" for r in rows):      # fast path: all plain HR
        table, val = parse_table(lines, numbers, 7, path, "SPRING", text_cols=(0, 1))
        s.tags = integer_column(val, table, 2, path, numbers, "SPRING")
        s.atoms[:] = np.stack([integer_column(val, table, c, path, numbers, "SPRING") for c in (3, 4)], 1)
        s.r0[:], s.k[:] = val[:, 5], val[:, 6]
    else:
        truncated = []
        for r, tok in enumerate(rows):
            ln = numbers[r]
            kind = tok[1] if len(tok) > 1 else ""
            if kind not in ("HR", "HR_FL"):
                raise InputError(path, ln, f"unknown spring kind '{kind}' (HR or HR_FL)")
            if kind == "HR" and len(tok) < 7:
                raise InputError(path, ln, f"SPRING HR needs at least 7 tokens, found {len(tok)}")
            if kind == "HR_FL" and len(tok) != 9:
                raise InputError(path, ln, f"SPRING HR_FL needs 9 tokens, found {len(tok)}")
            s.tags[r] = to_int(tok[2], path, ln, "SPRING tag")
            s.atoms[r] = (to_int(tok[3], path, ln, "SPRING bead"), to_int(tok[4], path, ln, "SPRING bead"))
            s.r0[r] = to_float(tok[5], path, ln, "SPRING rest length")
            s.k[r] = to_float(tok[6], path, ln, "SPRING stiffness")
            if kind == "HR_FL":
                c1, c2 = _stoi(tok[7]), _stoi(tok[8])
                if c1 is None or c2 is None:
                    raise InputError(path, ln, "SPRING HR_FL c1/c2 must start with an integer "
                                     "(FibreNet reads them with std::stoi)")
                if str(c1) != tok[7].strip() or str(c2) != tok[8].strip():
                    truncated.append(ln)
                s.fl[r], s.c1[r], s.c2[r] = True, c1, c2
        if truncated:
            notes.append(("HR_FL integer truncation", f"{path}:{truncated[0]}: FibreNet reads "
                          f"HR_FL c1 and c2 with std::stoi, truncating them to integers "
                          f"({len(truncated)} spring(s)); fibrelmp reproduces this"))
    _check_index(s.atoms, n, path, numbers, "SPRING")
    for arr, what in ((s.r0, "rest length"), (s.k, "stiffness")):
        if (arr < 0).any():
            row = int(np.flatnonzero(arr < 0)[0])
            raise InputError(path, numbers[row], f"SPRING {what} must be >= 0")
    same = s.atoms[:, 0] == s.atoms[:, 1]
    if same.any():
        raise InputError(path, numbers[int(np.flatnonzero(same)[0])], "SPRING connects a bead to itself")
    return s


def _break_length(r0: float, c1: float, c2: float) -> float:
    """Tension break length of HR_FL: |c1 (r - r0) / r| > c2  <=>  r > r0 c1 / (c1 - c2)."""
    if c1 > c2:
        return r0 * c1 / (c1 - c2)
    return np.inf


def _read_angles(path: Path, section: tuple[list[str], list[int]], n: int) -> Angles:
    lines, numbers = section
    if not lines:
        return Angles.empty()
    table, val = parse_table(lines, numbers, 10, path, "ANGLE", text_cols=(0, 1))
    bad = [r for r in range(len(lines)) if table[r, 1] not in ("HR", "HR_FL")]
    if bad:
        raise InputError(path, numbers[bad[0]], f"unknown angle kind '{table[bad[0], 1]}' (HR or HR_FL)")
    atoms = np.stack([integer_column(val, table, c, path, numbers, "ANGLE") for c in (3, 4, 5)], 1)
    _check_index(atoms, n, path, numbers, "ANGLE")
    twice = (atoms[:, 0] == atoms[:, 1]) | (atoms[:, 1] == atoms[:, 2]) | (atoms[:, 0] == atoms[:, 2])
    if twice.any():
        row = int(np.flatnonzero(twice)[0])
        raise InputError(path, numbers[row], f"ANGLE uses one bead twice "
                         f"({' '.join(map(str, atoms[row]))}): an angle needs three different beads")
    # FibreNet reads theta0 with std::stof: float precision
    theta0 = val[:, 8].astype(np.float32).astype(np.float64)
    return Angles(atoms, val[:, 9].copy(), theta0)
