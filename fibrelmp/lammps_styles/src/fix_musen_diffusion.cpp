/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenDiffusion: see fix_musen_diffusion.h.
------------------------------------------------------------------------- */

#include "fix_musen_diffusion.h"
#include "musen_startup.h"
#include "style_registry.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "memory.h"
#include "update.h"
#include "utils.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {
constexpr double MUSEN_PI = 3.14159265358979323846;       // MUSENDefinitions.h PI
constexpr double MUSEN_KB = 1.38064852e-23;               // MUSENDefinitions.h BOLTZMANN_CONSTANT

// a generator that counts what it gives (a restart re-seeds and advances by the count)
struct Counted {
  using result_type = std::mt19937_64::result_type;
  std::mt19937_64 &engine;
  uint64_t &count;
  static constexpr result_type min() { return std::mt19937_64::min(); }
  static constexpr result_type max() { return std::mt19937_64::max(); }
  result_type operator()()
  {
    ++count;
    return engine();
  }
};
}    // namespace

FixMusenDiffusion::FixMusenDiffusion(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), last(nullptr)
{
  if (narg != 9)
    error->all(FLERR, "Illegal fix musen/diffusion command: fix ID group musen/diffusion T MU STOKES SHELL SEED ORIENT");
  temperature = utils::numeric(FLERR, arg[3], false, lmp);
  viscosity = utils::numeric(FLERR, arg[4], false, lmp);
  stokes_factor = utils::numeric(FLERR, arg[5], false, lmp);
  shell = utils::numeric(FLERR, arg[6], false, lmp);
  const double s = utils::numeric(FLERR, arg[7], false, lmp);
  orient = utils::inumeric(FLERR, arg[8], false, lmp);
  if (!(temperature > 0) || !(viscosity > 0) || !(s >= 1) || s != std::floor(s) || s > 1.8e19)
    error->all(FLERR, "Fix musen/diffusion: T and MU must be > 0 and SEED a whole number >= 1");
  fixed_seed = static_cast<uint64_t>(s);    // MUSEN: r64.seed(static_cast<size_t>(FIXED_SEED))
  restart_peratom = 1;
  FixMusenDiffusion::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  seed_atoms();
}

FixMusenDiffusion::~FixMusenDiffusion()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(last);
}

/* CModelEFLiquidDiffusion::CreateUniqueSeeds64 with FIXED_SEED, for particles 0 .. max ID - 1 */
void FixMusenDiffusion::seed_atoms()
{
  std::mt19937_64 r64(fixed_seed);
  const auto count = static_cast<unsigned>(atom->map_tag_max);
  std::vector<uint64_t> seeds(count);
  for (unsigned i = 0; i < count; ++i) {
    // MUSEN: r64()*r64() + r64() + i*i*i + i*i + i (GCC calls r64 left to right)
    const uint64_t a = r64();
    const uint64_t b = r64();
    const uint64_t c = r64();
    seeds[i] = a * b + c + i * i * i + i * i + i;
  }
  for (int i = 0; i < atom->nlocal; i++) {
    seed[i] = seeds[atom->tag[i] - 1];
    reset_engine(i);
  }
}

void FixMusenDiffusion::reset_engine(int i)
{
  engine[i].seed(seed[i]);
  draws[i] = 0;
  for (int k = 0; k < 6; k++) last[i][k] = 0.0;
}

void FixMusenDiffusion::grow_arrays(int nmax)
{
  engine.resize(nmax);
  seed.resize(nmax);
  draws.resize(nmax);
  memory->grow(last, nmax, 6, "musen/diffusion:last");
}

void FixMusenDiffusion::copy_arrays(int i, int j, int /*delflag*/)
{
  engine[j] = engine[i];
  seed[j] = seed[i];
  draws[j] = draws[i];
  for (int k = 0; k < 6; k++) last[j][k] = last[i][k];
}

void FixMusenDiffusion::set_arrays(int i)
{
  seed[i] = 0;
  reset_engine(i);
}

int FixMusenDiffusion::pack_restart(int i, double *buf)
{
  buf[0] = 10;
  buf[1] = static_cast<double>(seed[i] >> 32);
  buf[2] = static_cast<double>(seed[i] & 0xffffffffu);
  buf[3] = static_cast<double>(draws[i]);    // exact below 2^53
  for (int k = 0; k < 6; k++) buf[4 + k] = last[i][k];
  return 10;
}

void FixMusenDiffusion::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; i++) m += static_cast<int>(extra[nlocal][m]);
  m++;
  seed[nlocal] = (static_cast<uint64_t>(extra[nlocal][m]) << 32) | static_cast<uint64_t>(extra[nlocal][m + 1]);
  const auto n = static_cast<uint64_t>(extra[nlocal][m + 2]);
  engine[nlocal].seed(seed[nlocal]);
  engine[nlocal].discard(n);
  draws[nlocal] = n;
  for (int k = 0; k < 6; k++) last[nlocal][k] = extra[nlocal][m + 3 + k];
}

int FixMusenDiffusion::size_restart(int /*nlocal*/)
{
  return 10;
}

int FixMusenDiffusion::maxsize_restart()
{
  return 10;
}

int FixMusenDiffusion::setmask()
{
  return PRE_FORCE;
}

void FixMusenDiffusion::init()
{
  if (comm->nprocs > 1)
    error->all(FLERR, "Fix musen/diffusion runs on one processor (its generators stay with their spheres)");
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "Fix musen/diffusion needs atom style sphere (radius, rmass, omega, torque)");
}

void FixMusenDiffusion::setup_pre_force(int vflag)
{
  pre_force(vflag);
}

/* the numbers CalculateEF draws: one fresh normal_distribution per particle and evaluation */
void FixMusenDiffusion::draw(int i)
{
  Counted gen{engine[i], draws[i]};
  std::normal_distribution<double> normal(0, 1);
  for (int k = 0; k < 3; k++) last[i][k] = normal(gen);
  if (orient == 1)
    for (int k = 3; k < 6; k++) last[i][k] = normal(gen);
}

void FixMusenDiffusion::pre_force(int /*vflag*/)
{
  const bool fresh = musen_startup::advances(update);    // a MUSEN evaluation: new numbers
  double **v = atom->v, **f = atom->f, **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  const double dt = update->dt;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    if (fresh) draw(i);
    // CalculateDiffusionModelCoefficientsCPU
    const double r_stokes = stokes_factor * radius[i] + shell;
    const double mass = rmass[i];
    double temp = 6 * MUSEN_PI * viscosity * r_stokes * dt / mass;
    const double drag = mass / dt * (1 - std::exp(-1 * temp));
    const double magnitude = std::sqrt(mass * MUSEN_KB * temperature * (1 - std::exp(-2 * temp))) / dt;
    // CalculateEF (temperature coefficient 1: no annealing; no shear flow)
    for (int k = 0; k < 3; k++) f[i][k] += 1.0 * magnitude * last[i][k] - drag * v[i][k];
    if (orient == 1) {
      const double inertia = 2.0 / 5.0 * mass * radius[i] * radius[i];
      temp = 8 * MUSEN_PI * viscosity * std::pow(r_stokes, 3) * dt / inertia;
      const double drag_rot = inertia / dt * (1 - std::exp(-1 * temp));
      const double magnitude_rot = std::sqrt(inertia * MUSEN_KB * temperature * (1 - std::exp(-2 * temp))) / dt;
      for (int k = 0; k < 3; k++) torque[i][k] += 1.0 * magnitude_rot * last[i][k + 3] - drag_rot * omega[i][k];
    }
  }
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create_fix(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenDiffusion(lmp, narg, arg);
}
const style_registry::Registration registered(
    116, "musen/diffusion", "MUSEN liquid diffusion (Brownian force, MUSEN's generators)", &create_fix);
}    // namespace
