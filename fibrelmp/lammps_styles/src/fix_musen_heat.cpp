/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenHeat: see fix_musen_heat.h.
------------------------------------------------------------------------- */

#include "fix_musen_heat.h"
#include "style_registry.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "memory.h"
#include "musen_startup.h"
#include "update.h"
#include "utils.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixMusenHeat::FixMusenHeat(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), heat_capacity(nullptr), conductivity(nullptr), flux(nullptr),
    startup_setups(0)
{
  const int ntypes = atom->ntypes;
  // the conductivities are for the contact laws (pair musen/hm's heat/conduction); an
  // external heat field alone (fix musen/field heat) needs only the heat capacities
  const bool with_k = narg == 5 + 2 * ntypes;
  if ((narg != 4 + ntypes && !with_k) || strcmp(arg[3], "cp") != 0 ||
      (with_k && strcmp(arg[4 + ntypes], "k") != 0))
    error->all(FLERR, "Illegal fix musen/heat command: fix ID group musen/heat cp C_1 ... "
               "C_ntypes [k K_1 ... K_ntypes]");
  memory->create(heat_capacity, ntypes + 1, "musen/heat:heat_capacity");
  if (with_k) memory->create(conductivity, ntypes + 1, "musen/heat:conductivity");
  heat_capacity[0] = 0.0;
  if (with_k) conductivity[0] = 0.0;
  for (int k = 1; k <= ntypes; k++) {
    heat_capacity[k] = utils::numeric(FLERR, arg[3 + k], false, lmp);
    if (!(heat_capacity[k] >= 0) || !std::isfinite(heat_capacity[k]))
      error->all(FLERR, "Fix musen/heat: heat capacities must be >= 0 and finite");
    if (!with_k) continue;
    conductivity[k] = utils::numeric(FLERR, arg[4 + ntypes + k], false, lmp);
    if (!(conductivity[k] >= 0) || !std::isfinite(conductivity[k]))
      error->all(FLERR, "Fix musen/heat: conductivities must be >= 0 and finite");
  }
  comm_forward = 1;
  comm_reverse = 1;
  FixMusenHeat::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  for (int i = 0; i < atom->nlocal; i++) flux[i] = 0.0;
}

FixMusenHeat::~FixMusenHeat()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  memory->destroy(heat_capacity);
  memory->destroy(conductivity);
  memory->destroy(flux);
}

int FixMusenHeat::setmask()
{
  return PRE_FORCE | INITIAL_INTEGRATE | POST_FORCE;
}

void FixMusenHeat::init()
{
  if (!atom->rmass_flag) error->all(FLERR, "Fix musen/heat needs per-atom masses (atom style sphere)");
  temperature();
}

double *FixMusenHeat::temperature()
{
  int flag, cols;
  const int index = atom->find_custom("musen_temperature", flag, cols);
  if (index < 0 || flag != 1 || cols != 0)
    error->all(FLERR, "Fix musen/heat needs the per-atom property d_musen_temperature "
               "(fix ID all property/atom d_musen_temperature ghost yes)");
  return atom->dvector[index];
}

/* CCPUSimulator::UpdateTemperatures with the last evaluation's flux */
void FixMusenHeat::update_temperature(double dt)
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

void FixMusenHeat::initial_integrate(int /*vflag*/)
{
  update_temperature(update->dt);
}

// ghosts get this evaluation's temperatures; HeatFlux = 0 (ClearState)
void FixMusenHeat::start_evaluation()
{
  comm->forward_comm(this);
  const int nall = atom->nlocal + atom->nghost;
  for (int i = 0; i < nall; i++) flux[i] = 0.0;
}

void FixMusenHeat::setup_pre_force(int /*vflag*/)
{
  // the second set-up at t = 0 follows MUSEN's prediction iteration, whose temperature
  // update is half a step (its velocities' half kick is musen/predict's)
  if (musen_startup::advances(update) && update->setupflag && ++startup_setups == 2)
    update_temperature(0.5 * update->dt);
  start_evaluation();
}

void FixMusenHeat::pre_force(int /*vflag*/)
{
  start_evaluation();
}

// bond_style musen/elastic's heat law adds to its ghost partner (newton_bond): to the owner
void FixMusenHeat::setup(int /*vflag*/)
{
  comm->reverse_comm(this);
}

void FixMusenHeat::post_force(int /*vflag*/)
{
  comm->reverse_comm(this);
}

int FixMusenHeat::pack_reverse_comm(int n, int first, double *buf)
{
  for (int k = 0; k < n; k++) buf[k] = flux[first + k];
  return n;
}

void FixMusenHeat::unpack_reverse_comm(int n, int *list, double *buf)
{
  for (int k = 0; k < n; k++) flux[list[k]] += buf[k];
}

void *FixMusenHeat::extract(const char *name, int &dim)
{
  if (strcmp(name, "flux") == 0) {
    dim = 1;
    return flux;
  }
  if (strcmp(name, "conductivity") == 0) {    // nullptr when the fix was given no k
    dim = 1;
    return conductivity;
  }
  return nullptr;
}

int FixMusenHeat::pack_forward_comm(int n, int *list, double *buf, int /*pbc_flag*/, int * /*pbc*/)
{
  const double *t = temperature();
  for (int k = 0; k < n; k++) buf[k] = t[list[k]];
  return n;
}

void FixMusenHeat::unpack_forward_comm(int n, int first, double *buf)
{
  double *t = temperature();
  for (int k = 0; k < n; k++) t[first + k] = buf[k];
}

void FixMusenHeat::grow_arrays(int nmax)
{
  memory->grow(flux, nmax, "musen/heat:flux");
}

void FixMusenHeat::set_arrays(int i)
{
  flux[i] = 0.0;
}

void FixMusenHeat::copy_arrays(int i, int j, int /*delflag*/)
{
  flux[j] = flux[i];
}

int FixMusenHeat::pack_exchange(int i, double *buf)
{
  buf[0] = flux[i];
  return 1;
}

int FixMusenHeat::unpack_exchange(int nlocal, double *buf)
{
  flux[nlocal] = buf[0];
  return 1;
}

double FixMusenHeat::memory_usage()
{
  return atom->nmax * sizeof(double);
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create_fix(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenHeat(lmp, narg, arg);
}
const style_registry::Registration registered(
    117, "musen/heat", "MUSEN contact heat flux and temperature update", &create_fix);
}    // namespace
