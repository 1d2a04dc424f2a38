"""The LAMMPS box of a granular job: periodic axes, domain faces (leaving the domain removes a
sphere) or shrink-wrapped axes; oversized domains and sparse scenes (coarse or no neighbour
bins); the commands that remove spheres beyond an oversized domain and stop a run whose
spheres get beyond the wall particles placed within their reach."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel, GranularPlan
from fibrelmp.lammps_text import LammpsText, comment_text
from fibrelmp.translate.lammps_format import float_text

OVERSIZED_BINS = 1_000_000  # a domain box with more neighbour bins than this ...
OVERSIZED_RATIO = 64        # ... and this many times those of the spheres' box is oversized
BIN_CAP = 10_000_000        # above this many default-size bins (and BINS_PER_ATOM x the
BINS_PER_ATOM = 8           # atoms), bins are coarsened
CHECK_EVERY_MAX = 100       # domain removal / reach check at least every this many steps
NSQ_RATIO = 50.0            # coarse bins > this x the thinnest box extent: neighbor nsq instead


@dataclass
class BoxAxes:
    """Per axis: the LAMMPS boundary ('p' periodic, 'f' domain face, 'm' shrink-wrapped) and
    box bounds (filled for 'p' and 'f' axes; ``fit_box`` completes them)."""

    lo: np.ndarray
    hi: np.ndarray
    bnd: list[str]
    removal_axes: np.ndarray         # (3,) bool: axes where leaving the box removes a sphere
    face_hi: np.ndarray              # upper domain faces, a hair above the domain
    dom_lo: np.ndarray | None        # the domain (None: no domain)
    dom_hi: np.ndarray | None


def periodic_axes(plan: GranularPlan, dim: int) -> np.ndarray:
    """(3,) bool; z of a 2D model counts as periodic."""
    return np.array(plan.periodic, bool) if dim == 3 else np.array([plan.periodic[0], plan.periodic[1], True])


def domain_bounds(plan: GranularPlan) -> tuple[np.ndarray | None, np.ndarray | None]:
    if plan.domain is None:
        return None, None
    return np.asarray(plan.domain[0], float), np.asarray(plan.domain[1], float)


def box_axes(model: GranularModel, dim: int, periodic: np.ndarray, dom_lo, dom_hi, spheres) -> BoxAxes:
    """Periodic axes = periodic box; non-periodic axes with a domain = 'f' faces at the domain
    (leaving it removes a sphere), unless the domain is oversized (see ``fit_box``); otherwise
    shrink-wrapped ('m') around spheres and wall particles."""
    plan = model.plan
    rows, x, r_max = spheres.rows, spheres.x, spheres.r_max
    box_lo, box_hi = np.zeros(3), np.zeros(3)
    bnd = [""] * 3
    removal_axes = np.zeros(3, bool)
    face_hi = np.zeros(3)
    for a in range(3):
        if dim == 2 and a == 2:
            h = max(2.0 * r_max, 1e-9)
            box_lo[a], box_hi[a] = -h, h
            bnd[a] = "p"
        elif periodic[a]:
            pb = plan.periodic_box if plan.periodic_box is not None else plan.domain
            if pb is None:
                raise InputError(model.source, None, f"periodic {'xyz'[a]} axis needs a periodic box")
            box_lo[a], box_hi[a] = float(pb[0][a]), float(pb[1][a])
            bnd[a] = "p"
        elif dom_lo is not None:
            face_hi[a] = dom_hi[a] + 1e-12 * max(dom_hi[a] - dom_lo[a], abs(dom_hi[a]), 1e-300)
            bnd[a] = "f"
            removal_axes[a] = True
        else:
            bnd[a] = "m"
    if dim == 2 and len(rows) and np.abs(x[rows, 2]).max() > 0:
        raise InputError(model.source, None, "2D model with non-zero z coordinates")
    return BoxAxes(box_lo, box_hi, bnd, removal_axes, face_hi, dom_lo, dom_hi)


@dataclass
class BoxFit:
    oversized: bool              # removal axes shrink-wrapped, fix evaporate at the domain faces
    domain_bins: float           # default-size neighbour bins of the box with 'f' domain faces
    bins: float                  # default-size neighbour bins of the box used
    binsize: float | None        # coarser neighbour / sort bin size, None: LAMMPS' default
    nsq: bool = False            # no bins at all: neighbor nsq, no atom sorting


def _bin_count(lo: np.ndarray, hi: np.ndarray, binsize: float, dim: int) -> float:
    """Approximate number of LAMMPS bins of size ``binsize`` over a box (float: never
    overflows; z is not binned in 2D)."""
    ext = np.maximum(np.asarray(hi, float) - np.asarray(lo, float), 0.0)[:dim]
    with np.errstate(over="ignore", invalid="ignore"):
        n = float(np.prod(ext / binsize + 1.0))
    return n if n == n else math.inf



def fit_box(model: GranularModel, axes: BoxAxes, spheres, tiles, dim: int) -> BoxFit:
    """Complete the box around spheres and wall particles (``_fit_box``); an empty extent is an
    error."""
    rows, r_max = spheres.rows, spheres.r_max
    pts = np.vstack([spheres.x[rows], tiles.x])
    if not len(pts):
        pts = np.zeros((1, 3))
    fit = _fit_box(pts, axes.lo, axes.hi, axes.bnd, axes.removal_axes, axes.dom_lo, axes.face_hi, r_max,
                   tiles.largest_radius(r_max), dim, len(rows) + tiles.total)
    for a in range(3):
        if not axes.hi[a] > axes.lo[a]:
            raise InputError(model.source, None, f"empty simulation box along {'xyz'[a]}")
    return fit


def _fit_box(pts, box_lo, box_hi, bnd, removal_axes, dom_lo, face_hi, r_max: float,
             r_bin: float, dim: int, atoms: int) -> BoxFit:
    """Fill box_lo/box_hi (and 'm' into ``bnd`` when the domain is oversized) in place.

    LAMMPS allocates neighbour bins (and atom-sort bins) of half the neighbour cutoff over the
    whole box, 1.25 x the largest radius here (cutoff 2 r + skin r/2).  A MUSEN domain of 2 m
    around 1 mm spheres is ~4e9 bins: "Too many atom sorting bins" after minutes and GBs.
    So a domain whose box has > OVERSIZED_BINS bins and > OVERSIZED_RATIO x the bins of the
    box around spheres and wall particles is not used as the box: its axes are shrink-wrapped
    like axes without a domain, and the caller deletes spheres beyond the domain faces.

    If the box used still has more than max(BIN_CAP, BINS_PER_ATOM x atoms) bins (sparse
    spheres, a huge periodic box), the bins are made just large enough to stay below that.
    LAMMPS refuses bins > 100 x the box's thinnest extent, so a box that needs more (one sphere
    1e6 radii away from the others along one axis) gets no bins at all: ``neighbor nsq``,
    O(N^2) but only ever for such sparse scenes."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = np.maximum(np.maximum(r_max, 1e-6 * (hi - lo)), 1e-12)
    c_lo, c_hi = lo - pad, hi + pad
    for a in range(3):
        if bnd[a] == "m":
            box_lo[a], box_hi[a] = c_lo[a], c_hi[a]
    binsize = 1.25 * r_bin
    oversized = False
    domain_bins = 0.0
    if removal_axes.any():
        f_lo, f_hi = box_lo.copy(), box_hi.copy()
        m_lo, m_hi = box_lo.copy(), box_hi.copy()
        f_lo[removal_axes], f_hi[removal_axes] = dom_lo[removal_axes], face_hi[removal_axes]
        m_lo[removal_axes], m_hi[removal_axes] = c_lo[removal_axes], c_hi[removal_axes]
        domain_bins = _bin_count(f_lo, f_hi, binsize, dim)
        oversized = (domain_bins > OVERSIZED_BINS
                     and domain_bins > OVERSIZED_RATIO * _bin_count(m_lo, m_hi, binsize, dim))
        src_lo, src_hi = (m_lo, m_hi) if oversized else (f_lo, f_hi)
        box_lo[removal_axes], box_hi[removal_axes] = src_lo[removal_axes], src_hi[removal_axes]
        if oversized:
            for a in np.flatnonzero(removal_axes):
                bnd[a] = "m"
    bins = _bin_count(box_lo, box_hi, binsize, dim)
    coarse = None
    cap = max(BIN_CAP, BINS_PER_ATOM * atoms)
    if bins > cap:
        # smallest bin size with <= cap bins (bisection on log(size); monotone)
        lo_b, hi_b = math.log(binsize), math.log(max(float(np.max((box_hi - box_lo)[:dim])), binsize)) + 1.0
        for _ in range(100):
            mid = 0.5 * (lo_b + hi_b)
            if _bin_count(box_lo, box_hi, math.exp(mid), dim) > cap:
                lo_b = mid
            else:
                hi_b = mid
        coarse = math.exp(hi_b)
        if coarse > NSQ_RATIO * float(np.min(box_hi - box_lo)):
            return BoxFit(oversized, domain_bins, bins, None, True)
    return BoxFit(oversized, domain_bins, bins, coarse)


def _note(text: str) -> LammpsText:
    """A comment line of fibrelmp's own in the script (escaped like user text all the same)."""
    return LammpsText("# " + comment_text(text))


def box_commands(fit: BoxFit, axes: BoxAxes, spheres, tiles, travel, dt: float,
                 warnings: list[tuple[str, str]]) -> list[str]:
    """Commands after the box is created: fix evaporate beyond an oversized domain, coarse or no
    neighbour bins, and the halt of a run whose spheres leave the wall particles' reach."""
    rows, r_max = spheres.rows, spheres.r_max
    tile_radius, clipped, reach = tiles.radius, tiles.clipped, tiles.reach
    keep_lo, keep_hi = tiles.keep_lo, tiles.keep_hi
    dom_lo, dom_hi, removal_axes = axes.dom_lo, axes.dom_hi, axes.removal_axes
    # LAMMPS re-neighbours when a sphere has moved half the skin: the same interval (at the
    # fastest speed the run can reach) paces the domain removal and the reach check below
    skin_est = 0.5 * tiles.largest_radius(r_max)
    every = CHECK_EVERY_MAX
    if fit.oversized or clipped:
        v_end = travel.end_speed()
        if v_end > 0:
            every = int(min(CHECK_EVERY_MAX, max(1, math.floor(0.5 * skin_est / (v_end * dt)))))
    box_cmds: list[str] = []
    if fit.oversized:
        warnings.append(("oversized domain", f"the simulation domain spans {fit.domain_bins:.3g} "
                         "neighbour bins, far more than the spheres and walls need: the LAMMPS box "
                         "is shrink-wrapped around them and spheres beyond the domain faces are "
                         f"deleted every {every} step(s) (fix evaporate)"))
        lim = " ".join(f"{float_text(dom_lo[a])} {float_text(dom_hi[a])}" if removal_axes[a] else "INF INF"
                       for a in range(3))
        box_cmds += [_note("the domain is far larger than the spheres need: shrink-wrapped box, spheres "
                           "beyond the domain faces are deleted"),
                     f"region          fl_domain block {lim} side out units box",
                     f"fix             fl_domain spheres evaporate {every} {max(1, len(rows))} "
                     "fl_domain 4711"]
    if fit.binsize is not None:
        box_cmds += [_note(f"coarse bins: the box spans {fit.bins:.3g} bins of the default size"),
                     f"neigh_modify    binsize {float_text(fit.binsize)}",
                     f"atom_modify     sort 1000 {float_text(fit.binsize)}"]
    elif fit.nsq:
        box_cmds += [_note(f"no bins: the box spans {fit.bins:.3g} bins of the default size and is too "
                           "thin for coarse ones"),
                     f"neighbor        {float_text(skin_est)} nsq",
                     "atom_modify     sort 0 0.0"]
    if fit.binsize is not None or fit.nsq:
        warnings.append(("sparse spheres", f"the LAMMPS box spans {fit.bins:.3g} neighbour bins of "
                         "the default size (spheres far apart): "
                         + (f"bins of {fit.binsize:.3g} are used" if fit.binsize is not None else
                            "neighbour lists are built without bins (O(N^2))")))
    if clipped and len(rows):
        lim = " ".join(f"{float_text(keep_lo[a] + 2.0 * (r_max + tile_radius))} "
                       f"{float_text(keep_hi[a] - 2.0 * (r_max + tile_radius))}" if math.isfinite(keep_lo[a])
                       else "INF INF" for a in range(3))
        warnings.append(("wall particles within reach", f"{', '.join(clipped)}: wall particles are "
                         f"placed only within {reach:.3g} of the spheres (twice the distance they can "
                         "travel in the run from their speeds, initial overlaps and gravity); the run "
                         "stops with an error if a sphere gets farther"))
        box_cmds += [_note("wall particles exist only within reach of the spheres: stop if one gets farther"),
                     f"region          fl_reach block {lim} side out units box",
                     "variable        fl_reach_out equal count(spheres,fl_reach)",
                     f"fix             fl_sphere_beyond_wall_particles spheres halt {every} "
                     "v_fl_reach_out > 0 error hard message yes"]
    return box_cmds
