/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenField: see fix_musen_field.h.
------------------------------------------------------------------------- */

#include "fix_musen_field.h"
#include "style_registry.h"

#include "atom.h"
#include "error.h"
#include "memory.h"
#include "musen_startup.h"
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
    heat_scale(0), heat_capacity(nullptr), flux(nullptr), startup_setups(0)
{
  const int ntypes = atom->ntypes;
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
  } else if (narg == 11 + ntypes && strcmp(arg[3], "heat") == 0 && strcmp(arg[10], "cp") == 0) {
    law = HEAT;
    air_t0 = non_negative(arg[4], "heat T0 (initial air temperature)", lmp);
    air_t1 = non_negative(arg[5], "heat T1 (final air temperature)", lmp);
    heating_time = positive(arg[6], "heat TIME (heating time)", lmp);
    heat_alpha = non_negative(arg[7], "heat ALPHA (heat transfer coefficient)", lmp);
    emissivity = non_negative(arg[8], "heat EPS (surface emissivity)", lmp);
    heat_scale = non_negative(arg[9], "heat SCALE (scaling factor)", lmp);
    memory->create(heat_capacity, ntypes + 1, "musen/field:heat_capacity");
    heat_capacity[0] = 0.0;
    for (int k = 1; k <= ntypes; k++)
      heat_capacity[k] = non_negative(arg[10 + k], "heat cp (heat capacity)", lmp);
    FixMusenField::grow_arrays(atom->nmax);
    atom->add_callback(Atom::GROW);
    for (int i = 0; i < atom->nlocal; i++) flux[i] = 0.0;
  } else {
    error->all(FLERR, "Illegal fix musen/field command: fix ID group musen/field viscous NU RHO | "
               "centrifugal OMEGA RHO MU | heat T0 T1 TIME ALPHA EPS SCALE cp C_1 ... C_ntypes");
  }
}

FixMusenField::~FixMusenField()
{
  if (copymode) return;
  if (law == HEAT) atom->delete_callback(id, Atom::GROW);
  memory->destroy(heat_capacity);
  memory->destroy(flux);
}

void FixMusenField::grow_arrays(int nmax)
{
  memory->grow(flux, nmax, "musen/field:flux");
}

void FixMusenField::set_arrays(int i)
{
  flux[i] = 0.0;
}

void FixMusenField::copy_arrays(int i, int j, int /*delflag*/)
{
  flux[j] = flux[i];
}

int FixMusenField::pack_exchange(int i, double *buf)
{
  buf[0] = flux[i];
  return 1;
}

int FixMusenField::unpack_exchange(int nlocal, double *buf)
{
  flux[nlocal] = buf[0];
  return 1;
}

double FixMusenField::memory_usage()
{
  return law == HEAT ? atom->nmax * sizeof(double) : 0.0;
}

double *FixMusenField::temperature()
{
  int flag, cols;
  const int index = atom->find_custom("musen_temperature", flag, cols);
  if (index < 0 || flag != 1 || cols != 0)
    error->all(FLERR, "Fix musen/field heat needs the per-atom property d_musen_temperature "
               "(fix ID all property/atom d_musen_temperature)");
  return atom->dvector[index];
}

/* CCPUSimulator::UpdateTemperatures with the last evaluation's flux */
void FixMusenField::update_temperature(double dt)
{
  double *t = temperature();
  const double *rmass = atom->rmass;
  const int *mask = atom->mask, *type = atom->type;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    t[i] += flux[i] / (heat_capacity[type[i]] * rmass[i]) * dt;
    t[i] = t[i] < 0.0 ? 0.0 : t[i];
  }
}

void FixMusenField::initial_integrate(int /*vflag*/)
{
  if (law == HEAT) update_temperature(update->dt);
}

int FixMusenField::setmask()
{
  int mask = PRE_FORCE;
  if (law == HEAT) mask |= INITIAL_INTEGRATE;
  return mask;
}

void FixMusenField::init()
{
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "Fix musen/field needs atom style sphere (radius, rmass)");
}

// the set-up evaluations (MUSEN's two at t = 0, musen_startup.h) carry the field as well
void FixMusenField::setup_pre_force(int vflag)
{
  // heat: the second set-up at t = 0 follows MUSEN's prediction iteration, whose temperature
  // update is half a step (its velocities' half kick is musen/predict's)
  if (law == HEAT && musen_startup::advances(update) && update->setupflag) {
    if (++startup_setups == 2) update_temperature(0.5 * update->dt);
  }
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

/* CModelEFHeatTransfer::CalculateEF at the evaluation's time */
void FixMusenField::heat()
{
  const double *t = temperature();
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  const double time = update->atime + static_cast<double>(update->ntimestep - update->atimestep) * update->dt;
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
    flux[i] = heat_scale * (convection + radiation);    // MUSEN clears HeatFlux each step
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
