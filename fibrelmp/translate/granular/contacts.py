"""Contact laws in LAMMPS terms: the pair_coeff lines of every pair of LAMMPS types (spheres
and wall particles), either for fibrelmp's ``pair_style musen/hm`` (MUSEN's law exactly:
E*, G*, e, mu, mu_r as the model holds them) or for stock ``pair_style granular``
(``law_args``: hertz/material + mindlin + rolling sds approximating it, also used by the
``fix wall/gran`` walls), and the rolling-resistance spring of the stock form."""

from __future__ import annotations

import math

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ContactLaw, GranularModel
from fibrelmp.translate.lammps_format import float_text

ROLL_OMEGA_DT = 0.1         # rolling spring: angular frequency * dt of the stiffest case


def law_args(law: ContactLaw, mu_roll: float, roll_k: float, roll_g: float,
             scale: float = 1.0) -> str:
    """pair_coeff / wall/gran arguments reproducing ``law`` (E*, G* optionally scaled).

    LAMMPS (explicit pair_coeff i j, and every fix wall/gran) uses E_eff = E/(2(1-nu^2)) and
    G_eff = E/(4(2-nu)(1+nu)); with r = G*/E*, nu = (4r-1)/(2r-1), E = 2(1-nu^2) E* both equal
    the model's values.  Outside 0 < r < 1/3 no |nu| < 1 exists: then k_t = 8 G* is given
    explicitly (identical force; see docs/granular.md).
    """
    e_star, g_star = law.youngs_eff * scale, law.shear_eff * scale
    r = g_star / e_star
    if 0 < r < 1.0 / 3.0:
        nu = (4 * r - 1) / (2 * r - 1)
        kt = "NULL"
    else:
        nu = 0.0
        kt = float_text(8.0 * g_star)
    e_in = 2.0 * (1.0 - nu * nu) * e_star
    parts = [f"hertz/material {float_text(e_in)} {float_text(law.restitution)} {float_text(nu)}"]
    if g_star > 0 and law.friction > 0:
        xt = 2.0 * math.sqrt(g_star / e_star)
        parts.append(f"tangential mindlin {kt} {float_text(xt)} {float_text(law.friction)}")
    else:
        parts.append("tangential linear_nohistory 0.0 0.0")
    if law.rolling_friction > 0:
        parts.append(f"rolling sds {float_text(roll_k)} {float_text(roll_g)} {float_text(mu_roll)}")
    parts.append("damping coeff_restitution")
    return " ".join(parts)


def check_law(model: GranularModel, a: int, b: int) -> ContactLaw:
    key = (min(a, b), max(a, b))
    if key not in model.contacts:
        na, nb = model.materials[a].name, model.materials[b].name
        raise InputError(model.source, None, f"no contact parameters for materials '{na}' and '{nb}'")
    law = model.contacts[key]
    na, nb = model.materials[key[0]].name, model.materials[key[1]].name
    if not (law.youngs_eff > 0 and math.isfinite(law.youngs_eff)):
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': effective Young's modulus "
                         f"must be > 0, got {law.youngs_eff!r}")
    if not (law.shear_eff >= 0 and math.isfinite(law.shear_eff)):
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': effective shear modulus "
                         f"must be >= 0, got {law.shear_eff!r}")
    if not (0 < law.restitution <= 1):
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': restitution coefficient must "
                         f"be in (0, 1], got {law.restitution!r}")
    if law.friction < 0 or law.rolling_friction < 0:
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': friction coefficients must "
                         "be >= 0")
    return law


def rolling_spring(m_min: float, dt: float, source=None) -> tuple[float, float]:
    """k and gamma of ``rolling sds``: the rolling spring's angular frequency is at most
    ROLL_OMEGA_DT/dt for the lightest sphere involved (I = 2/5 m R^2, R_eff <= R), critically
    damped; MUSEN's rolling torque is a constant plateau, reached after mu F/k of rolling.

    k grows as 1/dt^2: a step so small that k or gamma leaves the double range is an
    InputError (``source``: the input path for the message), never an OverflowError."""
    try:
        k = 0.4 * m_min * (ROLL_OMEGA_DT / dt) ** 2
        g = 2.0 * math.sqrt(0.4 * k * m_min)
    except (OverflowError, ZeroDivisionError, ValueError):
        k = g = math.nan
    if not (math.isfinite(k) and math.isfinite(g)):
        raise InputError(source, None, f"time step {dt:g} is too small for spheres of mass "
                         f"{m_min:g}: the rolling-resistance spring (stiffness ~ m/dt^2) "
                         "overflows; use a larger time step")
    return k, g



def musen_args(law: ContactLaw, scale: float = 1.0) -> str:
    """``pair_coeff`` arguments of ``pair_style musen/hm``: E* G* e mu mu_r (moduli optionally
    scaled, for wall particles)."""
    return " ".join(float_text(v) for v in (law.youngs_eff * scale, law.shear_eff * scale,
                                            law.restitution, law.friction, law.rolling_friction))


# fallback of type pairs without a law (wall particle - wall particle: never in contact)
NO_CONTACT = "hertz/material 1.0 1.0 0.0 tangential linear_nohistory 0.0 0.0 damping coeff_restitution"
NO_CONTACT_MUSEN = "1.0 0.0 1.0 0.0 0.0"

# the stock form's deviations from MUSEN's particle-particle law (docs/granular.md)
STOCK_PAIR_WARNING = ("particle-particle contacts use stock `pair_style granular`: rolling friction "
                      "acts on the relative rolling (LAMMPS rolling sds) instead of each sphere's "
                      "own spin, spin about the contact normal is not braked, and the tangential "
                      "damping is inside the Coulomb test (MUSEN tests the spring force alone)")


def stock_pair_deviates(model: GranularModel, sphere_mats) -> bool:
    """Whether stock ``pair_style granular`` deviates from MUSEN's law for some pair of these
    sphere materials: only through friction (tangential or rolling); the normal law is exact."""
    for a in sphere_mats:
        for b in sphere_mats:
            law = model.contacts.get((min(a, b), max(a, b)))
            if law is not None and ((law.shear_eff > 0 and law.friction > 0) or law.rolling_friction > 0):
                return True
    return False


def pair_coeff_lines(model: GranularModel, spheres, tile_materials: list[int], tile_radius: float,
                     dt: float, musen_hm: bool = False) -> list[str]:
    """``pair_coeff i j ...`` of every pair of LAMMPS types: sphere types (one per sphere
    material of ``spheres``, a ``SimulatedSpheres``), then wall-particle types (one per
    ``tile_materials``).  ``musen_hm``: for ``pair_style musen/hm``, else ``granular``.

    A sphere meets a wall particle of ``tile_radius`` with E* and G* scaled by
    sqrt((R_p + r_w)/r_w) (R_p: the material's mean contact radius), so that the Hertz force
    and both stiffnesses are those of the flat wall (R* = R_p).  The stock rolling spring's
    cap, mu_roll |F_n| R*, is scaled to mu_r |F_n| R_p too; musen/hm's rolling torque already
    uses the sphere's own radius, so mu_r stays."""
    pair_lines = []
    types_mat = [("s", m) for m in spheres.mats] + [("t", m) for m in tile_materials]
    if not types_mat:
        types_mat = [("none", 0)]
    any_law = None
    for i, (ki, mi) in enumerate(types_mat):
        for j in range(i, len(types_mat)):
            kj, mj = types_mat[j]
            if ki == "s" and kj == "s":
                law = check_law(model, mi, mj)
                if musen_hm:
                    args = musen_args(law)
                else:
                    k, g = rolling_spring(min(spheres.m_min[mi], spheres.m_min[mj]), dt)
                    args = law_args(law, 2.0 * law.rolling_friction, k, g)
            elif ki == "s" and kj == "t":
                law = check_law(model, mi, mj)
                rp = spheres.r_mean[mi]
                scale = math.sqrt((rp + tile_radius) / tile_radius)
                if musen_hm:
                    args = musen_args(law, scale)
                else:
                    k, g = rolling_spring(spheres.m_min[mi], dt)
                    args = law_args(law, law.rolling_friction * (rp + tile_radius) / tile_radius, k, g,
                                    scale)
            else:
                args = None
            if args is not None and any_law is None:
                any_law = args
            pair_lines.append([i + 1, j + 1, args])
    fallback = any_law or (NO_CONTACT_MUSEN if musen_hm else NO_CONTACT)
    return [f"pair_coeff      {i} {j} {a if a is not None else fallback}" for i, j, a in pair_lines]
