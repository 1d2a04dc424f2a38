/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenField: see fix_musen_field.h.
------------------------------------------------------------------------- */

#include "fix_musen_field.h"
#include "lammps_time.h"
#include "style_registry.h"

#include "atom.h"
#include "error.h"
#include "modify.h"
#include "update.h"
#include "utils.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {
constexpr double MUSEN_PI = 3.14159265358979323846;    // MUSENDefinitions.h PI

double positive(const char *value, const char *what, LAMMPS *lmp)
{
  const double x = utils::numeric(FLERR, value, false, lmp);
  if (!(x > 0) || !std::isfinite(x))
    lmp->error->all(FLERR, "Fix musen/field: {} must be positive and finite (got {})", what, value);
  return x;
}

double non_negative(const char *value, const char *what, LAMMPS *lmp)
{
  const double x = utils::numeric(FLERR, value, false, lmp);
  if (!(x >= 0) || !std::isfinite(x))
    lmp->error->all(FLERR, "Fix musen/field: {} must be >= 0 and finite (got {})", what, value);
  return x;
}
}    // namespace

FixMusenField::FixMusenField(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), law(VISCOUS), nu(0), medium_density(0), omega(0), liquid_density(0),
    liquid_viscosity(0), air_t0(0), air_t1(0), heating_time(0), heat_alpha(0), emissivity(0),
    heat_scale(0), heat_fix(nullptr)
{
  if (narg == 6 && strcmp(arg[3], "viscous") == 0) {
    law = VISCOUS;
    nu = positive(arg[4], "viscous NU (kinematic viscosity)", lmp);
    medium_density = non_negative(arg[5], "viscous RHO (medium density)", lmp);
  } else if (narg == 7 && strcmp(arg[3], "centrifugal") == 0) {
    law = CENTRIFUGAL;
    omega = utils::numeric(FLERR, arg[4], false, lmp);
    if (!std::isfinite(omega)) error->all(FLERR, "Fix musen/field: centrifugal OMEGA must be finite");
    liquid_density = non_negative(arg[5], "centrifugal RHO (liquid density)", lmp);
    liquid_viscosity = non_negative(arg[6], "centrifugal MU (liquid viscosity)", lmp);
  } else if (narg == 10 && strcmp(arg[3], "heat") == 0) {
    law = HEAT;
    air_t0 = non_negative(arg[4], "heat T0 (initial air temperature)", lmp);
    air_t1 = non_negative(arg[5], "heat T1 (final air temperature)", lmp);
    heating_time = positive(arg[6], "heat TIME (heating time)", lmp);
    heat_alpha = non_negative(arg[7], "heat ALPHA (heat transfer coefficient)", lmp);
    emissivity = non_negative(arg[8], "heat EPS (surface emissivity)", lmp);
    heat_scale = non_negative(arg[9], "heat SCALE (scaling factor)", lmp);
  } else {
    error->all(FLERR, "Illegal fix musen/field command: fix ID group musen/field viscous NU RHO | "
               "centrifugal OMEGA RHO MU | heat T0 T1 TIME ALPHA EPS SCALE");
  }
}

FixMusenField::~FixMusenField() = default;

int FixMusenField::setmask()
{
  return PRE_FORCE;
}

void FixMusenField::init()
{
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "Fix musen/field needs atom style sphere (radius, rmass)");
  if (law != HEAT) return;
  // the heat flux and the temperature update are fix musen/heat's; it must clear the flux
  // (its pre_force) before this fix adds to it (MUSEN: the EF models first)
  const auto &fixes = modify->get_fix_list();
  const auto heats = modify->get_fix_by_style("^musen/heat$");
  if (heats.size() != 1)
    error->all(FLERR, "Fix musen/field heat needs one fix musen/heat (found {})", heats.size());
  heat_fix = heats[0];
  for (const Fix *f : fixes) {
    if (f == this)
      error->all(FLERR, "Fix musen/field heat must be defined after fix musen/heat {}", heat_fix->id);
    if (f == heat_fix) break;
  }
  int flag, cols;
  const int index = atom->find_custom("musen_temperature", flag, cols);
  if (index < 0 || flag != 1 || cols != 0)
    error->all(FLERR, "Fix musen/field heat needs the per-atom property d_musen_temperature "
               "(fix ID all property/atom d_musen_temperature)");
}

// the set-up evaluations (MUSEN's two at t = 0, musen_startup.h) carry the field as well
void FixMusenField::setup_pre_force(int vflag)
{
  pre_force(vflag);
}

void FixMusenField::pre_force(int /*vflag*/)
{
  if (law == VISCOUS)
    viscous();
  else if (law == CENTRIFUGAL)
    centrifugal();
  else
    heat();
}

/* CModelEFViscousField::CalculateEF */
void FixMusenField::viscous()
{
  double **v = atom->v, **f = atom->f;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double speed = std::sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
    const double reynolds = radius[i] * 2 * speed / nu;
    if (reynolds == 0) continue;    // no drag
    double cd;
    if (reynolds < 0.5)
      cd = 24.0 / reynolds;
    else if (reynolds < 10.1)
      cd = 27.0 / std::pow(reynolds, 0.8);
    else
      cd = 17.0 / std::pow(reynolds, 0.6);
    // vRelVel.Normalized() * dCd * PI * pow(r, 2) * rho / 2 * pow(|v|, 2), left to right
    const double len = std::sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
    for (int k = 0; k < 3; k++) {
      const double unit = len != 0 ? v[i][k] / len : 0.0;
      f[i][k] -= unit * cd * MUSEN_PI * std::pow(radius[i], 2) * medium_density / 2 * std::pow(speed, 2);
    }
  }
}

/* CModelEFCentrifugalCasting::CalculateEF */
void FixMusenField::centrifugal()
{
  double **x = atom->x, **v = atom->v, **f = atom->f;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double volume = MUSEN_PI * 4.0 / 3 * std::pow(radius[i], 3);
    const double buoyant = (rmass[i] - volume * liquid_density) * omega * omega;
    const double centrifugal[3] = {x[i][0] * buoyant, 0, x[i][2] * buoyant};
    const double fluid[3] = {x[i][2] * omega, 0, -x[i][0] * omega};
    const double stokes = 6 * MUSEN_PI * liquid_viscosity * radius[i];
    for (int k = 0; k < 3; k++) {
      const double friction = (fluid[k] - v[i][k]) * stokes;
      f[i][k] += friction + centrifugal[k];
    }
  }
}

/* CModelEFHeatTransfer::CalculateEF at the evaluation's time: adds to fix musen/heat's flux */
void FixMusenField::heat()
{
  int flag, cols, dim;
  const double *t = atom->dvector[atom->find_custom("musen_temperature", flag, cols)];
  double *flux = static_cast<double *>(heat_fix->extract("flux", dim));
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  const double time = simulation_time(update);
  double environment;
  if (time > heating_time)
    environment = air_t1;
  else
    environment = air_t0 + time * (air_t1 - air_t0) / heating_time;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double surface = MUSEN_PI * std::pow(radius[i], 2);
    const double convection = heat_alpha * surface * (environment - t[i]);
    const double radiation = emissivity * surface * (std::pow(environment, 4) - std::pow(t[i], 4));
    flux[i] += heat_scale * (convection + radiation);
  }
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create_fix(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenField(lmp, narg, arg);
}
const style_registry::Registration registered(
    115, "musen/field", "MUSEN external-force field (viscous drag, centrifugal casting, heat transfer)", &create_fix);
}    // namespace
