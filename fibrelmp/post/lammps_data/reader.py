"""The per-atom facts a dump may lack, read from a LAMMPS data file (``--data``).

Gives, by atom id: type, radius, mass and molecule; per type: name and mass; the bond
list.  Type names come from an ``Atom Type Labels`` section, else from the first word of
the comment on each ``Masses`` line (fibrelmp writes ``1 1.0  # F1 m=1 R=0.42``; VMD and
moltemplate write similar comments), else the type number.  A data file fibrelmp wrote for a
job has its ``data.fibrelmp.json`` beside it (``translate.work_facts``): the source's exact
names, MUSEN object ids and initial orientations, the run's exact times; ``facts`` holds them,
and its names win.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.textio import integer_column, parse_table, read_text
from fibrelmp.translate.work_facts import WorkFacts, read_facts

SECTIONS = {
    "Atoms", "Velocities", "Masses", "Ellipsoids", "Lines", "Triangles", "Bodies", "Bonds",
    "Angles", "Dihedrals", "Impropers", "Pair Coeffs", "PairIJ Coeffs", "Bond Coeffs",
    "Angle Coeffs", "Dihedral Coeffs", "Improper Coeffs", "BondBond Coeffs", "BondAngle Coeffs",
    "MiddleBondTorsion Coeffs", "EndBondTorsion Coeffs", "AngleTorsion Coeffs",
    "AngleAngleTorsion Coeffs", "BondBond13 Coeffs", "AngleAngle Coeffs", "Atom Type Labels",
    "Bond Type Labels", "Angle Type Labels", "Dihedral Type Labels", "Improper Type Labels",
}

# per-atom columns before the image flags, by atom style ("x" marks x y z)
STYLE_COLUMNS = {
    "atomic": ["id", "type", "x"],
    "charge": ["id", "type", "q", "x"],
    "bond": ["id", "mol", "type", "x"],
    "angle": ["id", "mol", "type", "x"],
    "molecular": ["id", "mol", "type", "x"],
    "full": ["id", "mol", "type", "q", "x"],
    "sphere": ["id", "type", "diameter", "density", "x"],
    "bpm/sphere": ["id", "mol", "type", "diameter", "density", "x"],
    "ellipsoid": ["id", "type", "ellipsoidflag", "density", "x"],
    "sph": ["id", "type", "rho", "esph", "cv", "x"],
}
# extra per-atom fields each sub-style adds after "id type x y z" in atom_style hybrid
HYBRID_FIELDS = {
    "atomic": [], "charge": ["q"], "bond": ["mol"], "angle": ["mol"], "molecular": ["mol"],
    "full": ["mol", "q"], "sphere": ["diameter", "density"], "bpm/sphere": ["mol", "diameter", "density"],
    "ellipsoid": ["ellipsoidflag", "density"], "mdpd": ["rho"], "sph": ["rho", "esph", "cv"],
}


@dataclass
class DataFile:
    path: Path
    ids: np.ndarray                       # (n,) sorted atom ids
    types: np.ndarray                     # (n,) int
    mol: np.ndarray | None
    radius: np.ndarray | None             # (n,) from sphere styles
    mass: np.ndarray | None               # (n,) per atom (sphere density or Masses)
    type_names: dict[int, str]
    type_masses: dict[int, float]
    bonds: np.ndarray                     # (m, 2) atom ids
    lo: np.ndarray
    hi: np.ndarray
    tilt: np.ndarray | None = None
    atom_style: str = ""
    notes: list[str] = field(default_factory=list)
    facts: WorkFacts | None = None        # fibrelmp's job facts (data.fibrelmp.json), if any

    def rows(self, ids: np.ndarray, what: str) -> np.ndarray:
        """Row of each id in this file's arrays; an InputError names an id it lacks."""
        ids = np.asarray(ids).astype(np.int64)
        k = np.searchsorted(self.ids, ids)
        k = np.minimum(k, len(self.ids) - 1) if len(self.ids) else k
        bad = (len(self.ids) == 0) | (self.ids[k] != ids) if len(self.ids) else np.ones(len(ids), bool)
        if np.any(bad):
            raise InputError(self.path, None, f"atom id {int(ids[np.flatnonzero(bad)[0]])} of the "
                             f"dump is not in the data file (needed for {what})")
        return k

    def name(self, t: int) -> str:
        return self.type_names.get(int(t), str(int(t)))


def _strip(line: str) -> tuple[str, str]:
    body, _, comment = line.partition("#")
    return body.strip(), comment.strip()


def read_data(path: str | Path) -> DataFile:
    """The data file at ``path``: header, sections, type names and masses, atoms, bonds."""
    path = Path(path)
    lines = read_text(path, "LAMMPS data file").splitlines()
    k, lo, hi, tilt = _read_header(path, lines)
    sections = _read_sections(path, lines, k)
    type_masses, type_names = _type_masses_and_names(path, sections)
    atoms = _read_atoms(path, sections, type_names, type_masses)
    bonds = _read_bonds(path, sections)
    facts = read_facts(path)
    if facts is not None:
        type_names.update(facts.type_names)
    return DataFile(path, atoms.ids, atoms.types, atoms.mol, atoms.radius, atoms.mass, type_names,
                    type_masses, bonds, lo, hi, tilt, atoms.style, facts=facts)


def _read_header(path: Path, lines: list[str]) -> tuple[int, np.ndarray, np.ndarray, np.ndarray | None]:
    """Box and tilt from the header (up to the first section keyword) and the index of that line."""
    counts: dict[str, int] = {}
    lo, hi, tilt = np.zeros(3), np.ones(3), None
    k = 1
    while k < len(lines):
        body, _ = _strip(lines[k])
        if body in SECTIONS:
            break
        words = body.split()
        try:
            if len(words) == 4 and words[2:] in (["xlo", "xhi"], ["ylo", "yhi"], ["zlo", "zhi"]):
                axis = "xyz".index(words[2][0])
                lo[axis], hi[axis] = float(words[0]), float(words[1])
            elif len(words) == 6 and words[3:] == ["xy", "xz", "yz"]:
                tilt = np.array(words[:3], dtype=float)
            elif len(words) >= 2 and words[0].lstrip("-").isdigit():
                counts[" ".join(words[1:])] = int(words[0])
        except ValueError:
            raise InputError(path, k + 1, f"malformed header line {lines[k].strip()!r}") from None
        k += 1
    return k, lo, hi, tilt


# section name -> (line number of its keyword, keyword comment, data rows, their line numbers)
Sections = dict[str, tuple[int, str, list[str], list[int]]]


def _read_sections(path: Path, lines: list[str], k: int) -> Sections:
    """Every section from line index ``k`` on, by name."""
    def is_section(j: int) -> bool:
        b = _strip(lines[j])[0]
        # known keywords, and sections of fixes (read_data ... fix ID NULL Name): a word
        # line followed by a blank line (data rows start with numbers)
        return b in SECTIONS or (bool(b) and b[0].isalpha() and (j + 1 >= len(lines) or not lines[j + 1].strip()))

    sections: Sections = {}
    while k < len(lines):
        body, comment = _strip(lines[k])
        if not is_section(k):
            if body:
                raise InputError(path, k + 1, f"expected a section keyword, got {body[:40]!r}")
            k += 1
            continue
        start, k = k, k + 1
        rows, numbers = [], []
        while k < len(lines):
            b, _ = _strip(lines[k])
            if is_section(k):
                break
            if b:
                rows.append(lines[k])
                numbers.append(k + 1)
            k += 1
        sections[body] = (start + 1, comment, rows, numbers)
    return sections


def _type_masses_and_names(path: Path, sections: Sections) -> tuple[dict[int, float], dict[int, str]]:
    """Masses by type, and names from the Masses comments, overridden by Atom Type Labels."""
    type_masses: dict[int, float] = {}
    type_names: dict[int, str] = {}
    if "Masses" in sections:
        _, _, rows, numbers = sections["Masses"]
        for row, ln in zip(rows, numbers):
            body, comment = _strip(row)
            w = body.split()
            try:
                type_masses[int(w[0])] = float(w[1])
            except (ValueError, IndexError):
                raise InputError(path, ln, f"Masses line needs 'type mass', got {body!r}") from None
            if comment:
                type_names[int(w[0])] = comment.split()[0]
    if "Atom Type Labels" in sections:
        _, _, rows, numbers = sections["Atom Type Labels"]
        for row, ln in zip(rows, numbers):
            w = _strip(row)[0].split()
            if len(w) != 2 or not w[0].isdigit():
                raise InputError(path, ln, "Atom Type Labels line needs 'type label'")
            type_names[int(w[0])] = w[1]
    return type_masses, type_names


@dataclass
class _Atoms:
    """The Atoms section's columns, sorted by id."""

    style: str
    ids: np.ndarray
    types: np.ndarray
    mol: np.ndarray | None
    radius: np.ndarray | None
    mass: np.ndarray | None


def _read_atoms(path: Path, sections: Sections, type_names: dict[int, str],
                type_masses: dict[int, float]) -> _Atoms:
    """Ids, types (numbers or labels), molecules, radii and masses of the Atoms section."""
    if "Atoms" not in sections:
        raise InputError(path, None, "data file has no Atoms section")
    line0, style_comment, rows, numbers = sections["Atoms"]
    style, columns = _style_columns(path, line0, style_comment, rows)
    ncol = len(rows[0].partition("#")[0].split()) if rows else len(columns)
    bodies = [r.partition("#")[0] for r in rows]
    if rows and ncol not in (len(columns) - 3, len(columns)):
        raise InputError(path, numbers[0], f"Atoms # {style}: expected {len(columns) - 3} columns "
                         f"({' '.join(columns[:-3])}) plus optional image flags, found {ncol}")
    table, val = parse_table(bodies, numbers, ncol, path, "Atoms")
    col = {name: c for c, name in enumerate(columns) if c < ncol}
    ids = integer_column(val, table, col["id"], path, numbers, "Atoms")
    types_raw = table[:, col["type"]]
    if np.isnan(val[:, col["type"]]).any():        # type labels in the Atoms section
        inverse = {v: t for t, v in type_names.items()}
        try:
            types = np.array([inverse[t] for t in types_raw], np.int64)
        except KeyError as exc:
            raise InputError(path, None, f"Atoms: unknown type label {exc.args[0]!r}") from None
    else:
        types = integer_column(val, table, col["type"], path, numbers, "Atoms")
    order = np.argsort(ids, kind="stable")
    ids, types = ids[order], types[order]
    if np.any(ids[1:] == ids[:-1]):
        raise InputError(path, line0, f"Atoms: atom id {int(ids[np.flatnonzero(ids[1:] == ids[:-1])[0]])} repeated")
    mol = val[order, col["mol"]].astype(np.int64) if "mol" in col else None
    radius = mass = None
    if "diameter" in col:
        d = val[order, col["diameter"]]
        rho = val[order, col["density"]]
        radius = d / 2
        # LAMMPS: a point particle (diameter 0) stores its mass in the density field
        mass = np.where(d > 0, rho * (4.0 / 3.0) * math.pi * radius ** 3, rho)
    elif type_masses:
        lut = np.full(int(types.max(initial=0)) + 1, np.nan)
        for t, m in type_masses.items():
            if t < len(lut):
                lut[t] = m
        mass = lut[types]
    return _Atoms(style, ids, types, mol, radius, mass)


def _read_bonds(path: Path, sections: Sections) -> np.ndarray:
    """(m, 2) atom ids of the Bonds section (none without one)."""
    if "Bonds" not in sections:
        return np.zeros((0, 2), np.int64)
    _, _, brows, bnum = sections["Bonds"]
    btab, bval = parse_table([r.partition("#")[0] for r in brows], bnum, 4, path, "Bonds")
    return np.column_stack([integer_column(bval, btab, 2, path, bnum, "Bonds"),
                            integer_column(bval, btab, 3, path, bnum, "Bonds")])


def _style_columns(path: Path, line: int, comment: str, rows: list[str]) -> tuple[str, list[str]]:
    words = comment.split()
    ncol = len(rows[0].partition("#")[0].split()) if rows else 0
    if words and words[0] == "hybrid":
        if len(words) == 1:
            raise InputError(path, line, "Atoms # hybrid: name the sub-styles in the comment "
                             "(e.g. 'Atoms # hybrid sphere bond') so the columns are known")
        cols = ["id", "type", "x"]
        for sub in words[1:]:
            if sub not in HYBRID_FIELDS:
                raise InputError(path, line, f"Atoms: unsupported hybrid sub-style {sub!r}")
            cols += [c for c in HYBRID_FIELDS[sub] if c not in cols]
        return "hybrid", _expand(cols)
    if words:
        if words[0] not in STYLE_COLUMNS:
            raise InputError(path, line, f"Atoms: unsupported atom style {words[0]!r} "
                             f"(supported: {', '.join(STYLE_COLUMNS)}, hybrid)")
        return words[0], _expand(STYLE_COLUMNS[words[0]])
    # no style comment: only the column count can tell; accept the unambiguous cases
    by_count = {5: "atomic", 7: "sphere"}
    guess = by_count.get(ncol) or by_count.get(ncol - 3)
    if guess is None:
        raise InputError(path, line, f"Atoms section has {ncol} columns and no '# style' comment; "
                         "add the atom style after the keyword, e.g. 'Atoms # full'")
    return guess, _expand(STYLE_COLUMNS[guess])


def _expand(cols: list[str]) -> list[str]:
    out = []
    for c in cols:
        out += ["x", "y", "z"] if c == "x" else [c]
    return out + ["ix", "iy", "iz"]          # image flags, when present (parse_table fixes the count)
