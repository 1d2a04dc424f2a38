"""Soft-sphere contact parameters for DEMDF's hard-sphere (BOS) descriptions.

BOS treats collisions as instantaneous.  fibrelmp replaces them with frictionless Hertz
contacts (``pair_style granular hertz/material ... damping coeff_restitution``) stiff enough
that the peak overlap stays below a small fraction of the radius:

* peak overlap of a Hertz contact hit at normal speed v:
  ``delta = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5)``  (Johnson 1985)
* so the smallest modulus keeping ``delta <= f * R_min`` is
  ``E* = 15 m* v^2 / (16 sqrt(R*) (f R_min)^(5/2))``
* elastic contact duration ``t_c = 2.9432 delta / v`` (slower impacts last longer, so the
  fastest one sets the time step).

The approach speed bound of a particle is ``sqrt(|v|^2 + 2 |g| L)``: its own speed plus what
the body force can add over the domain's extent ``L`` along it.  A particle pair's bound is
the sum of the two fastest bounds of the two types; a particle-wall bound is the particle's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# the Hertz impact formulas and speed bounds live in fibrelmp.sanity (``fibrelmp check``
# prints the same contact time)
from fibrelmp.sanity import hertz_contact_time as contact_time  # noqa: F401
from fibrelmp.sanity import hertz_peak_overlap as peak_overlap  # noqa: F401
from fibrelmp.sanity import pair_speed, speed_bounds  # noqa: F401


def modulus_for_overlap(m_eff: float, r_eff: float, speed: float, overlap: float) -> float:
    return 15.0 * m_eff * speed ** 2 / (16.0 * math.sqrt(r_eff) * overlap ** 2.5)


@dataclass
class Partner:
    """One contact kind: a particle type against a particle type or a wall material."""

    key: tuple[int, int]          # material indices (a <= b)
    m_eff: float
    r_eff: float
    r_min: float                  # the overlap limit is a fraction of this radius
    speed: float                  # approach speed bound (> 0)
    restitution: float
    label: str
