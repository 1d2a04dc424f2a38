/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenLeapfrog, MusenPredict: see fix_musen_leapfrog.h.
------------------------------------------------------------------------- */

#include "fix_musen_leapfrog.h"
#include "lammps_time.h"
#include "style_registry.h"
#include "musen_startup.h"

#include "atom.h"
#include "comm.h"
#include "pair.h"
#include "timer.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixMusenLeapfrog::FixMusenLeapfrog(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), vmax(0.0), variable(false), move_limit(0.0), step_factor(0.0),
    step_max(0.0), saving_step(0.0), end_time(0.0), t_now(0.0), t_last(0.0), t_before(0.0),
    dt_before(0.0), stopped_for(0)
{
  const char *usage = "Illegal fix musen/leapfrog command: fix ID group musen/leapfrog "
                      "[vlimit VMAX] [variable MOVE FACTOR STEP SAVING END]";
  int iarg = 3;
  while (iarg < narg) {
    if (strcmp(arg[iarg], "vlimit") == 0 && iarg + 2 <= narg) {
      vmax = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(vmax > 0) || !std::isfinite(vmax))
        error->all(FLERR, "Fix musen/leapfrog: vlimit must be a positive finite speed");
      iarg += 2;
    } else if (strcmp(arg[iarg], "variable") == 0 && iarg + 6 <= narg) {
      variable = true;
      move_limit = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      step_factor = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      step_max = utils::numeric(FLERR, arg[iarg + 3], false, lmp);
      saving_step = utils::numeric(FLERR, arg[iarg + 4], false, lmp);
      end_time = utils::numeric(FLERR, arg[iarg + 5], false, lmp);
      if (!(move_limit > 0) || !(step_factor > 0) || !(step_max > 0) || !(saving_step > 0))
        error->all(FLERR, "Fix musen/leapfrog: variable MOVE FACTOR STEP SAVING must be > 0");
      iarg += 6;
    } else {
      error->all(FLERR, usage);
    }
  }
  if (variable) {
    // MUSEN's clock starts at the time of this step; the restart file may replace it
    t_now = t_last = t_before = simulation_time(update);
    dt_before = update->dt;
    vector_flag = 1;
    size_vector = 4;
    global_freq = 1;
    extvector = 0;
    restart_global = 1;
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
  return variable ? INITIAL_INTEGRATE | END_OF_STEP : INITIAL_INTEGRATE;
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
  if (variable) {
    t_before = t_now;
    dt_before = update->dt;
    vary_step();
    t_now = t_before + update->dt;    // CBaseSimulator::StartSimulation: m_currentTime += dt
    update->atime = t_now;
    update->atimestep = update->ntimestep;
  }
  kick(1.0);
  double **x = atom->x, **v = atom->v;
  const int *mask = atom->mask;
  const double dt = update->dt;
  for (int i = 0; i < atom->nlocal; i++)
    if (mask[i] & groupbit)
      for (int k = 0; k < 3; k++) x[i][k] += v[i][k] * dt;    // Coord += Vel * dt
}

void FixMusenLeapfrog::vary_step()
{
  // CCPUSimulator::MoveParticles: maxStep over the particles whose force is not zero
  const double *const *f = atom->f;
  const double *rmass = atom->rmass;
  const int *mask = atom->mask;
  double ratio = std::numeric_limits<double>::max();
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    if (f[i][0] == 0.0 && f[i][1] == 0.0 && f[i][2] == 0.0) continue;
    const double squared = f[i][0] * f[i][0] + f[i][1] * f[i][1] + f[i][2] * f[i][2];
    ratio = std::min(ratio, std::pow(rmass[i], 2.) / squared);
  }
  double ratio_all;
  MPI_Allreduce(&ratio, &ratio_all, 1, MPI_DOUBLE, MPI_MIN, world);
  const double max_step = std::sqrt(std::sqrt(ratio_all) * move_limit);
  double dt = update->dt;
  if (dt > max_step)
    dt = max_step;
  else if (dt < step_max)
    dt = std::min(dt * step_factor, step_max);
  if (dt == update->dt) return;
  // as fix dt/reset: the styles that keep dt-dependent values recompute them
  update->dt = dt;
  update->dt_default = 0;
  if (force->pair) force->pair->reset_dt();
  for (auto &ifix : modify->get_fix_list()) ifix->reset_dt();
}

void FixMusenLeapfrog::end_of_step()
{
  // CBaseSimulator::StartSimulation ends at t >= END; PreCalculationStep saves when
  // |t - t_last| + 0.1 dt > SAVING (dt: the step that reached t): stop the run for the frame
  if (t_now >= end_time)
    stopped_for = 2;
  else if (std::fabs(t_now - t_last) + 0.1 * update->dt > saving_step)
    stopped_for = 1;
  else
    return;
  timer->force_timeout();
}

void FixMusenLeapfrog::post_run()
{
  if (!variable) return;
  timer->reset_timeout();    // later runs go on (fix halt's "continue")
  // a run of steps always ends where MUSEN saves or ends; else its N steps ran out first
  // (a run of one step is the stop criterion's last step: MUSEN saves after it regardless)
  if (update->nsteps > 1 && stopped_for == 0)
    error->all(FLERR, "Fix musen/leapfrog: the run's {} steps ended before MUSEN's next save "
               "(time {:.17g}): its frame would be at a time MUSEN does not save", update->nsteps, t_now);
}

double FixMusenLeapfrog::compute_vector(int n)
{
  switch (n) {
    case 0: return t_now;
    case 1: return t_now >= end_time ? 1.0 : 0.0;
    case 2: return update->dt;
    default: return dt_before;
  }
}

int FixMusenLeapfrog::modify_param(int narg, char **arg)
{
  if (strcmp(arg[0], "write") != 0) return 0;
  if (!variable) error->all(FLERR, "fix_modify {} write: only with a variable time step", id);
  if (narg != 2 && !(narg == 4 && strcmp(arg[2], "append") == 0))
    error->all(FLERR, "Illegal fix_modify {} write FILE [append yes|no]", id);
  const bool append = narg == 4 && utils::logical(FLERR, arg[3], false, lmp);
  if (comm->me == 0) {
    FILE *fp = fopen(arg[1], append ? "a" : "w");
    if (!fp) error->one(FLERR, "fix_modify {} write: cannot open {}", id, arg[1]);
    fmt::print(fp, "{} {:.17g} {:.17g}\n", update->ntimestep, t_now, update->dt);
    fclose(fp);
  }
  t_last = t_now;    // SaveData: m_lastSavingTime = m_currentTime
  stopped_for = 0;
  return narg;
}

void FixMusenLeapfrog::write_restart(FILE *fp)
{
  if (!variable) return;
  double list[6] = {t_now, t_last, t_before, dt_before, update->dt, (double) stopped_for};
  if (comm->me == 0) {
    int size = sizeof(list);
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(list, sizeof(double), 6, fp);
  }
}

void FixMusenLeapfrog::restart(char *buf)
{
  if (!variable) return;
  const auto *list = reinterpret_cast<const double *>(buf);
  t_now = list[0];
  t_last = list[1];
  t_before = list[2];
  dt_before = list[3];
  update->dt = list[4];    // the script's timestep command set the initial one
  update->dt_default = 0;
  stopped_for = static_cast<int>(list[5]);
  update->atime = t_now;
  update->atimestep = update->ntimestep;
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
  if (!start) {
    if (fix->variable_step()) fix->vary_step();    // MoveParticles applies the rule here too
    fix->kick(0.5);
  }
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
