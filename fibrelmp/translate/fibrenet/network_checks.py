"""Checks of a read FibreNet network: positions in the box, spring and angle legs against
half the box (periodic images), the exclusion rule and the quirks worth a note.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.model import Angles, Bonds, Box, Dynamics, PairLaw, Particles
from fibrelmp.translate.fibrenet.model_file import model_sections


def bond_legs(p: Particles, bonds: Bonds, angles: Angles) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(kind, index pairs (i, j), x_j - x_i on the unwrapped positions) of every spring and
    both legs of every angle (the second angle leg is bead 2 -> bead 3), computed once for
    the checks below."""
    x = p.unwrapped
    out = []
    for kind, pairs in (("SPRING", bonds.atoms), ("ANGLE", angles.atoms[:, :2]),
                        ("ANGLE", angles.atoms[:, 1:])):
        with np.errstate(all="ignore"):
            out.append((kind, pairs, x[pairs[:, 1]] - x[pairs[:, 0]]))
    return out


def check_lengths(p: Particles, legs: list, path: Path) -> None:
    """Springs and angle legs of zero length have no direction: FibreNet's forces divide by
    the length (NaN), LAMMPS's bond style silently gives no force."""
    x = p.unwrapped
    for kind, pairs, d in legs:
        if not len(pairs):
            continue
        same = (d == 0).all(axis=1)              # finite positions: x_j - x_i == 0 iff equal
        if same.any():
            row = int(np.flatnonzero(same)[0])
            i, j = (int(v) for v in pairs[row])
            line = model_sections(path)[kind][1][row]     # only on error: no cost otherwise
            what = "the spring has zero length" if kind == "SPRING" else "the angle is undefined"
            raise InputError(path, line, f"{kind} joins beads {i} and {j}, which are at the same "
                             f"position ({', '.join(f'{v:g}' for v in x[i])}): {what}")


def check_periodic_extent(p: Particles, legs: list, box: Box, path: Path) -> None:
    """Springs and angle legs must span less than half the box along every periodic axis.

    FibreNet computes springs and angles on the unwrapped positions (ix iy iz) with no minimum
    image (kernel.cl ResolveSprings/ResolveAngles), so a spring longer than half the box acts
    along its own, long, vector.  LAMMPS takes every bond and angle partner as the periodic
    image nearest to the atom that owns it, i.e. the minimum image: such a spring would act on
    a different, shorter vector (a spring at rest in FibreNet pulls hard in LAMMPS).  Nothing
    in LAMMPS can reproduce that, so it is an error rather than a silently different run."""
    per = np.asarray(box.periodic, bool)
    if not per.any():
        return
    half = 0.5 * box.lengths
    for kind, pairs, d in legs:
        if not len(pairs):
            continue
        with np.errstate(all="ignore"):
            bad = (~(np.abs(d[:, per]) < half[per])).any(axis=1)
        if not bad.any():
            continue
        row = int(np.flatnonzero(bad)[0])
        i, j = (int(v) for v in pairs[row])
        with np.errstate(all="ignore"):
            dv = d[row]
            image = dv.copy()
            image[per] -= box.lengths[per] * np.round(dv[per] / box.lengths[per])
            r, r_img = float(np.linalg.norm(dv)), float(np.linalg.norm(image))
        axes = "".join("xyz"[a] for a in range(3) if per[a] and not abs(dv[a]) < half[a])
        line = model_sections(path)[kind][1][row]     # only on error: no cost otherwise
        what = "spring" if kind == "SPRING" else "angle leg"
        raise InputError(path, line, f"{kind}: the {what} between beads {i} and {j} spans "
                         f"{', '.join(f'{dv[a]:g}' for a in range(3))} (length {r:g}), at least half "
                         f"the periodic box ({', '.join(f'{v:g}' for v in box.lengths)}) along "
                         f"{axes} ({int(bad.sum())} {what}(s) do): FibreNet uses this unwrapped "
                         f"vector, LAMMPS the nearest periodic image (length {r_img:g}), so the "
                         "forces would differ; enlarge box_size or split the "
                         f"{'spring' if kind == 'SPRING' else 'fibre'} into shorter segments")


def check_positions(p: Particles, box: Box, periodic: bool, path: Path, notes: list) -> None:
    diff = p.unwrapped - p.positions
    if periodic:
        shift = diff / box.lengths
        off = np.abs(shift - np.round(shift)) * box.lengths > 1e-6 * box.lengths.max()
        if off.any():
            row = int(np.flatnonzero(off.any(axis=1))[0])
            notes.append(("wrapped/unwrapped mismatch", f"{path}: bead {row}: unwrapped position "
                          "is not the wrapped one plus whole box lengths; fibrelmp uses the "
                          "unwrapped position (bonds follow it) and wraps it"))
    elif (np.abs(diff) > 0).any():
        row = int(np.flatnonzero((np.abs(diff) > 0).any(axis=1))[0])
        notes.append(("wrapped/unwrapped mismatch", f"{path}: bead {row}: in a finite box the "
                      "unwrapped (ix iy iz) and wrapped positions differ; fibrelmp uses px py pz "
                      "for everything (FibreNet uses ix for springs/angles)"))
        p.unwrapped = p.positions.copy()


def exclusion_rule(p: Particles, bonds: Bonds, path: Path) -> str:
    """FibreNet skips non-bonded pairs with the same tag and |loc_id_i - loc_id_j| <= 1."""
    order = np.lexsort((p.loc_ids, p.molecules))
    tag, loc = p.molecules[order], p.loc_ids[order]
    starts = np.r_[0, np.flatnonzero(np.diff(tag)) + 1]
    span = np.maximum.reduceat(loc, starts) - np.minimum.reduceat(loc, starts)
    if (span <= 1).all():
        return "molecule"       # every pair inside a tag is excluded
    raise InputError(path, None, "beads of one tag have loc_id values more than 1 apart: "
                     "FibreNet's partial exclusion (|loc_id_i - loc_id_j| <= 1) has no exact "
                     "LAMMPS equivalent; give every bead of a fibre the same loc_id")


def note_quirks(p: Particles, bonds: Bonds, angles: Angles, legs: list, pairs: list[PairLaw],
                 dyn: Dynamics, notes: list, path: Path) -> None:
    for law in pairs:
        if law.kind == "st" and law.params["B"] * (law.params["rstar"] - law.params["cutoff"]) != 0:
            jump = law.params["B"] * (law.params["rstar"] - law.params["cutoff"])
            notes.append(("st force jump", f"pair st {p.type_names[law.type_i]} "
                          f"{p.type_names[law.type_j]}: as FibreNet runs it the force is one linear "
                          f"spring B={law.params['B']:g}, r*={law.params['rstar']:.6g}, cut at "
                          f"{law.params['cutoff']:g} where it jumps by {jump:.6g}; reproduced"))
    if (~np.isnan(bonds.break_length)).any():
        notes.append(("HR_FL breaking", f"{path}: HR_FL springs break only in tension here "
                      "(fix bond/break); FibreNet also breaks them in compression and keeps HR "
                      "angles that contain them"))
    if angles.count:
        u, v = -legs[1][2], legs[2][2]            # bead 1 - bead 2, bead 3 - bead 2
        with np.errstate(all="ignore"):         # huge coordinates overflow: not straight
            cos = (u * v).sum(1) / np.sqrt((u * u).sum(1) * (v * v).sum(1))
        if (cos <= -1.0 + 1e-14).any():
            notes.append(("straight triple", f"{path}: some angle triples are exactly straight; "
                          "FibreNet clamps cos to -0.999999 there and applies a spurious force, "
                          "fibrelmp does not"))
