/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenVelocityLimit: see fix_musen_velocity_limit.h.
------------------------------------------------------------------------- */

#include "fix_musen_velocity_limit.h"
#include "style_registry.h"

#include "atom.h"
#include "error.h"
#include "force.h"
#include "modify.h"
#include "update.h"
#include "utils.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixMusenVelocityLimit::FixMusenVelocityLimit(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), vmax(0.0)
{
  if (narg != 4) error->all(FLERR, "Illegal fix musen/velocity/limit command: fix ID group musen/velocity/limit VMAX");
  vmax = utils::numeric(FLERR, arg[3], false, lmp);
  if (!(vmax > 0) || !std::isfinite(vmax))
    error->all(FLERR, "Fix musen/velocity/limit: VMAX must be a positive finite speed");
}

int FixMusenVelocityLimit::setmask()
{
  return INITIAL_INTEGRATE;
}

void FixMusenVelocityLimit::init()
{
  if (!atom->rmass_flag) error->all(FLERR, "Fix musen/velocity/limit needs per-atom masses (rmass)");
  // the integrator must come after this fix: its kick then gives the clamped velocity
  bool after = false;
  for (const auto &fix : modify->get_fix_list()) {
    if (fix == this) after = true;
    else if (!after && fix->time_integrate)
      error->all(FLERR, "Fix musen/velocity/limit must be defined before the integrator fix {}", fix->id);
  }
}

void FixMusenVelocityLimit::initial_integrate(int /*vflag*/)
{
  double **v = atom->v, **f = atom->f;
  const double *rmass = atom->rmass;
  const int *mask = atom->mask;
  const double dtf = 0.5 * update->dt * force->ftm2v;    // as fix nve/bpm/sphere
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double dtfm = dtf / rmass[i];
    double u[3];
    for (int k = 0; k < 3; k++) u[k] = v[i][k] + dtfm * f[i][k];
    const double speed = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);    // CVector3::Length
    if (!(speed > vmax)) continue;
    const double scale = vmax / speed;                    // Vel *= limit / |Vel|
    for (int k = 0; k < 3; k++) v[i][k] = u[k] * scale - dtfm * f[i][k];
  }
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenVelocityLimit(lmp, narg, arg);
}
const style_registry::Registration registered(
    90, "musen/velocity/limit", "MUSEN particle velocity limit", &create);
}    // namespace
