/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenLeapfrog, MusenPredict: see fix_musen_leapfrog.h.
------------------------------------------------------------------------- */

#include "fix_musen_leapfrog.h"
#include "style_registry.h"
#include "musen_startup.h"

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "update.h"
#include "utils.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixMusenLeapfrog::FixMusenLeapfrog(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), vmax(0.0)
{
  if (narg != 3 && !(narg == 5 && strcmp(arg[3], "vlimit") == 0))
    error->all(FLERR, "Illegal fix musen/leapfrog command: fix ID group musen/leapfrog [vlimit VMAX]");
  if (narg == 5) {
    vmax = utils::numeric(FLERR, arg[4], false, lmp);
    if (!(vmax > 0) || !std::isfinite(vmax))
      error->all(FLERR, "Fix musen/leapfrog: vlimit must be a positive finite speed");
  }
  time_integrate = 1;
  peratom_flag = 1;
  size_peratom_cols = 3;
  peratom_freq = 1;
  restart_peratom = 1;
  create_attribute = 1;      // spheres an inlet makes mid-run: MUSEN saves them with zero force
  saved_force = nullptr;
  FixMusenLeapfrog::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) saved_force[i][0] = saved_force[i][1] = saved_force[i][2] = 0.0;
}

FixMusenLeapfrog::~FixMusenLeapfrog()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(saved_force);
}

void FixMusenLeapfrog::grow_arrays(int nmax)
{
  memory->grow(saved_force, nmax, 3, "musen/leapfrog:saved_force");
  array_atom = saved_force;
}

void FixMusenLeapfrog::set_arrays(int i)
{
  saved_force[i][0] = saved_force[i][1] = saved_force[i][2] = 0.0;
}

void FixMusenLeapfrog::copy_arrays(int i, int j, int /*delflag*/)
{
  for (int k = 0; k < 3; k++) saved_force[j][k] = saved_force[i][k];
}

int FixMusenLeapfrog::pack_exchange(int i, double *buf)
{
  for (int k = 0; k < 3; k++) buf[k] = saved_force[i][k];
  return 3;
}

int FixMusenLeapfrog::unpack_exchange(int nlocal, double *buf)
{
  for (int k = 0; k < 3; k++) saved_force[nlocal][k] = buf[k];
  return 3;
}

int FixMusenLeapfrog::pack_restart(int i, double *buf)
{
  buf[0] = 4;    // this fix's values and their count (LAMMPS's per-atom restart layout)
  for (int k = 0; k < 3; k++) buf[k + 1] = saved_force[i][k];
  return 4;
}

void FixMusenLeapfrog::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; i++) m += static_cast<int>(extra[nlocal][m]);
  m++;
  for (int k = 0; k < 3; k++) saved_force[nlocal][k] = extra[nlocal][m++];
}

int FixMusenLeapfrog::size_restart(int /*nlocal*/)
{
  return 4;
}

int FixMusenLeapfrog::maxsize_restart()
{
  return 4;
}

double FixMusenLeapfrog::memory_usage()
{
  return 3.0 * atom->nmax * sizeof(double);
}

int FixMusenLeapfrog::setmask()
{
  return INITIAL_INTEGRATE;
}

void FixMusenLeapfrog::init()
{
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "Fix musen/leapfrog needs atom style sphere (radius, rmass, omega, torque)");
  for (const auto &fix : modify->get_fix_list())
    if (fix != this && fix->time_integrate && (fix->groupbit & groupbit))
      error->all(FLERR, "Fix musen/leapfrog: fix {} integrates the same atoms", fix->id);
}

void FixMusenLeapfrog::kick(double fraction)
{
  double **v = atom->v, **f = atom->f, **omega = atom->omega, **torque = atom->torque;
  const double *rmass = atom->rmass, *radius = atom->radius;
  const int *mask = atom->mask;
  const double dt = fraction * update->dt;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    // MUSEN: Vel += Force / Mass * dt; AnglVel += Moment / InertiaMoment * dt (I = 2/5 m r^2)
    for (int k = 0; k < 3; k++) v[i][k] += f[i][k] / rmass[i] * dt;
    const double inertia = 2.0 / 5.0 * rmass[i] * radius[i] * radius[i];
    for (int k = 0; k < 3; k++) omega[i][k] += torque[i][k] / inertia * dt;
    if (vmax > 0) {
      const double speed = std::sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
      if (speed > vmax)
        for (int k = 0; k < 3; k++) v[i][k] *= vmax / speed;    // Vel *= limit / |Vel|
    }
  }
}

void FixMusenLeapfrog::initial_integrate(int /*vflag*/)
{
  // time steps have begun: later set-ups (checkpoints, deletions) do not advance states
  musen_startup::advancing_setups() = 0;
  // cmusen saves before its force evaluation: the force of the previous one, still in f
  const double *const *f = atom->f;
  for (int i = 0; i < atom->nlocal; i++)
    if (atom->mask[i] & groupbit)
      for (int k = 0; k < 3; k++) saved_force[i][k] = f[i][k];
  kick(1.0);
  double **x = atom->x, **v = atom->v;
  const int *mask = atom->mask;
  const double dt = update->dt;
  for (int i = 0; i < atom->nlocal; i++)
    if (mask[i] & groupbit)
      for (int k = 0; k < 3; k++) x[i][k] += v[i][k] * dt;    // Coord += Vel * dt
}

void MusenPredict::command(int narg, char **arg)
{
  const bool start = narg == 2 && strcmp(arg[1], "start") == 0;
  if (narg != 1 && !start) error->all(FLERR, "Illegal musen/predict command: musen/predict <fix ID> [start]");
  auto *fix = dynamic_cast<FixMusenLeapfrog *>(modify->get_fix_by_id(arg[0]));
  if (!fix) error->all(FLERR, "musen/predict: {} is not the ID of a fix musen/leapfrog", arg[0]);
  if (!domain->box_exist) error->all(FLERR, "musen/predict before the simulation box exists");
  // start: the next set-up (run 0) is the evaluation of MUSEN's prediction iteration;
  // else f and torque hold its forces: the half kick, and the next set-up is MUSEN's
  // evaluation of its first step, at x(0) with the predicted velocities
  if (!start) fix->kick(0.5);
  musen_startup::advancing_setups() = 1;
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create_fix(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenLeapfrog(lmp, narg, arg);
}
Command *create_predict(LAMMPS *lmp) { return new MusenPredict(lmp); }
const style_registry::Registration registered_fix(
    110, "musen/leapfrog", "MUSEN leapfrog integrator for spheres", &create_fix);
const style_registry::Registration registered_predict(
    111, "musen/predict", "MUSEN half-step prediction kick", &create_predict);
}    // namespace
