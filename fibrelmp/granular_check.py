"""What ``fibrelmp check`` prints for a granular (MUSEN / DEMDF) model."""

from __future__ import annotations

import math

import numpy as np

from .granmodel import GranularModel


def hertz_contact_time(model: GranularModel) -> tuple[float, str] | None:
    """Shortest Hertz contact duration over the material pairs present, at the fastest
    sphere speed in the input (at least 0.1 m/s... of the input's units): t_c = 2.87
    (m*^2 / (R* E*^2 v))^(1/5) (Johnson 1985).  None when there are no spheres."""
    s = model.spheres
    if s.count == 0:
        return None
    speed = float(np.max(np.linalg.norm(s.velocity, axis=1))) if s.count else 0.0
    g = float(np.linalg.norm(model.plan.gravity))
    if model.plan.domain is not None and g > 0:
        height = float(np.max(model.plan.domain[1] - model.plan.domain[0]))
        speed = math.sqrt(speed ** 2 + 2 * g * height)
    speed = max(speed, 1e-12)
    best = None
    for mat in np.unique(s.material):
        rows = s.material == mat
        r = float(s.contact_radius[rows].min())
        m = float(s.mass[rows].min())
        for (a, b), law in model.contacts.items():
            if int(mat) not in (a, b) or not law.youngs_eff > 0:
                continue
            # sphere-sphere of the smallest sphere of this material (R* = r/2, m* = m/2)
            tc = 2.87 * ((m / 2) ** 2 / ((r / 2) * law.youngs_eff ** 2 * speed)) ** 0.2
            name = f"{model.materials[a].name}-{model.materials[b].name}"
            if best is None or tc < best[0]:
                best = (tc, name)
    return best


def summary(model: GranularModel) -> list[str]:
    s, plan = model.spheres, model.plan
    lines = [f"input        {model.source} ({model.kind})",
             f"units        {model.units}",
             f"spheres      {s.count}"]
    if model.bonds is not None:
        lines.append(f"solid bonds  {model.bonds.count}")
    if model.triangles is not None:
        lines.append(f"wall triangles {model.triangles.count} in {len(model.geometries)} geometries")
    if model.planes:
        lines.append(f"wall planes  {len(model.planes)}")
    try:
        from .translate.granular_job import describe_walls

        for text in describe_walls(model):
            lines.append(f"wall         {text}")
    except ImportError:
        pass
    lines.append("materials    " + ", ".join(f"{m.key} ({m.name})" for m in model.materials))
    for (a, b), law in sorted(model.contacts.items()):
        lines.append(f"contact      {model.materials[a].name}-{model.materials[b].name}: "
                     f"E* {law.youngs_eff:.4g}  G* {law.shear_eff:.4g}  e {law.restitution:g}  "
                     f"mu {law.friction:g}  mu_roll {law.rolling_friction:g}")
    if plan.domain is not None:
        lo, hi = plan.domain
        lines.append(f"domain       {' '.join(f'{v:g}' for v in lo)} .. {' '.join(f'{v:g}' for v in hi)}")
    lines.append(f"gravity      {' '.join(f'{v:g}' for v in plan.gravity)}")
    lines.append(f"time         {plan.t_start:g} .. {plan.t_end:g}  step {plan.dt:g}")
    if plan.save_every_time is not None:
        lines.append(f"saves        every {plan.save_every_time:g} time units")
    elif plan.save_every_steps is not None:
        lines.append(f"saves        every {plan.save_every_steps} steps")
    tc = hertz_contact_time(model)
    if tc is not None and math.isfinite(plan.dt) and plan.dt > 0:
        ratio = tc[0] / plan.dt
        lines.append(f"contact time {tc[0]:.3g} (Hertz, {tc[1]}, fastest approach in the input) = "
                     f"{ratio:.1f} time steps")
        if ratio < 10:
            model.warn("time step", f"the time step {plan.dt:g} exceeds 1/10 of the Hertz contact "
                       f"time {tc[0]:.3g}: contacts will be poorly resolved")
    return lines
