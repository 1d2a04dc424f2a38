/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenVerlet: see fix_musen_verlet.h.
------------------------------------------------------------------------- */

#include "fix_musen_verlet.h"
#include "style_registry.h"
#include "musen_startup.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "memory.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {
constexpr double MUSEN_DEFAULT_WALL_TERM = 1e12;    // VerletList.h DEFAULT_TEOR_DISTANCE

std::pair<tagint, tagint> ordered(tagint a, tagint b)
{
  return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
}
}    // namespace

FixMusenVerlet::FixMusenVerlet(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), distance(0.0), auto_adjust(1), wall_speed(0.0), pbc_speed(0.0),
    wall_term(MUSEN_DEFAULT_WALL_TERM), updates(0), natoms_seen(0), warned(0), xref(nullptr)
{
  if (narg < 4)
    error->all(FLERR, "Illegal fix musen/verlet command: fix ID group musen/verlet DISTANCE "
                      "[auto yes|no] [wallspeed W] [pbcspeed P]");
  distance = utils::numeric(FLERR, arg[3], false, lmp);
  if (!(distance > 0.0) || !std::isfinite(distance))
    error->all(FLERR, "Fix musen/verlet: the Verlet distance must be > 0, got {}", arg[3]);
  for (int iarg = 4; iarg < narg; iarg += 2) {
    if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "fix musen/verlet", error);
    const std::string key = arg[iarg];
    if (key == "auto") {
      auto_adjust = utils::logical(FLERR, arg[iarg + 1], false, lmp);
    } else if (key == "wallspeed" || key == "pbcspeed") {
      const double value = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(value >= 0.0) || !std::isfinite(value))
        error->all(FLERR, "Fix musen/verlet: {} must be >= 0, got {}", key, arg[iarg + 1]);
      (key == "wallspeed" ? wall_speed : pbc_speed) = value;
    } else {
      error->all(FLERR, "Fix musen/verlet: unknown keyword {} (known: auto, wallspeed, pbcspeed)",
                 key);
    }
  }
  restart_global = 1;
  restart_peratom = 1;
  create_attribute = 1;
  vector_flag = 1;
  size_vector = 3;
  extvector = 0;
  natoms_seen = atom->natoms;
  FixMusenVerlet::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nlocal; i++) set_arrays(i);
}

FixMusenVerlet::~FixMusenVerlet()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(xref);
}

int FixMusenVerlet::setmask()
{
  return PRE_FORCE | POST_NEIGHBOR;
}

// MUSEN's check runs in every step it makes; LAMMPS's other set-ups are not steps
void FixMusenVerlet::setup_pre_force(int /*vflag*/)
{
  if (musen_startup::advances(update)) check();
}

void FixMusenVerlet::pre_force(int /*vflag*/)
{
  if (musen_startup::advances(update)) check();
}

// a new neighbour list marks the released pairs as ordinary ones
void FixMusenVerlet::setup_post_neighbor()
{
  post_neighbor();
}

void FixMusenVerlet::post_neighbor()
{
  released_pairs.clear();
}

/* CCPUSimulator::UpdateVerletLists: IsNeedToBeUpdated(dt, GetMaxPartVerletDistance(), wall
   speed), then UpdateList and SaveVerletCoords */

void FixMusenVerlet::check()
{
  if (atom->natoms > natoms_seen) wall_term = MUSEN_DEFAULT_WALL_TERM;    // GenerateNewObjects
  natoms_seen = atom->natoms;
  wall_term += wall_speed * update->dt;
  if (pbc_speed > 0.0) wall_term += 2 * pbc_speed;
  double **x = atom->x;
  const int *mask = atom->mask;
  double local = 0.0;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double d[3] = {x[i][0] - xref[i][0], x[i][1] - xref[i][1], x[i][2] - xref[i][2]};
    local = std::max(local, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  }
  double squared = 0.0;
  MPI_Allreduce(&local, &squared, 1, MPI_DOUBLE, MPI_MAX, world);
  const double moved = std::sqrt(squared);
  if (moved + std::max(wall_term, moved) >= distance) update_list();
}

void FixMusenVerlet::update_list()
{
  updates++;
  // AutoAdjustVerletDistance, called first in UpdateList: the 1st call only starts its clock,
  // the 2nd and 3rd grow the distance by 10 %, the later ones pick by measured speed
  if (auto_adjust && (updates == 2 || updates == 3)) distance *= 1.1;
  if (auto_adjust && updates >= 5 && !waiting.empty() && !warned) {
    if (comm->me == 0)
      error->warning(FLERR, "Fix musen/verlet: {} broken bonds' spheres join the contacts at "
                     "MUSEN's contact-list update {} (step {}); from its 4th update on MUSEN's "
                     "auto-adjusted Verlet distance follows its CPU clock, so cmusen's update "
                     "may come at another step (VERLET_AUTO 0 makes the schedule exact)",
                     waiting.size(), updates, update->ntimestep);
    warned = 1;
  }
  for (const auto &p : waiting) release(p.first, p.second);
  waiting.clear();
  std::sort(released_pairs.begin(), released_pairs.end());
  double **x = atom->x;
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < 3; k++) xref[i][k] = x[i][k];
  wall_term = 0.0;
}

/* a broken bond's spheres are no longer 1-2 neighbours: each leaves the other's special list
   (owned atoms: the neighbour build reads those) and the broken bond (type 0) leaves the bond
   arrays of the atom that stored it */

void FixMusenVerlet::release(tagint a, tagint b)
{
  const int nlocal = atom->nlocal;
  for (int side = 0; side < 2; side++) {
    const tagint me = side ? b : a, other = side ? a : b;
    const int i = atom->map(me);
    if (i < 0 || i >= nlocal) continue;
    tagint *sp = atom->special[i];
    int *ns = atom->nspecial[i];
    for (int k = 0; k < ns[0]; k++)
      if (sp[k] == other) {
        for (int m = k; m < ns[2] - 1; m++) sp[m] = sp[m + 1];
        ns[0]--;
        ns[1]--;
        ns[2]--;
        break;
      }
    int &nb = atom->num_bond[i];
    for (int m = 0; m < nb; m++)
      if (atom->bond_atom[i][m] == other && atom->bond_type[i][m] == 0) {
        for (int k = m; k < nb - 1; k++) {
          atom->bond_atom[i][k] = atom->bond_atom[i][k + 1];
          atom->bond_type[i][k] = atom->bond_type[i][k + 1];
        }
        nb--;
        break;
      }
  }
  released_pairs.push_back(ordered(a, b));
}

void FixMusenVerlet::add_broken(const std::vector<std::pair<tagint, tagint>> &pairs)
{
  waiting.insert(waiting.end(), pairs.begin(), pairs.end());
}

bool FixMusenVerlet::released(tagint a, tagint b) const
{
  return std::binary_search(released_pairs.begin(), released_pairs.end(), ordered(a, b));
}

/* ---------------------------------------------------------------------- */

void FixMusenVerlet::grow_arrays(int nmax)
{
  memory->grow(xref, nmax, 3, "musen/verlet:xref");
}

// a sphere made mid-run: MUSEN updates the list in that step anyway (check())
void FixMusenVerlet::set_arrays(int i)
{
  for (int k = 0; k < 3; k++) xref[i][k] = atom->x[i][k];
}

void FixMusenVerlet::copy_arrays(int i, int j, int /*delflag*/)
{
  for (int k = 0; k < 3; k++) xref[j][k] = xref[i][k];
}

int FixMusenVerlet::pack_exchange(int i, double *buf)
{
  for (int k = 0; k < 3; k++) buf[k] = xref[i][k];
  return 3;
}

int FixMusenVerlet::unpack_exchange(int nlocal, double *buf)
{
  for (int k = 0; k < 3; k++) xref[nlocal][k] = buf[k];
  return 3;
}

int FixMusenVerlet::pack_restart(int i, double *buf)
{
  buf[0] = 4;    // this fix's values and their count (LAMMPS's per-atom restart layout)
  for (int k = 0; k < 3; k++) buf[k + 1] = xref[i][k];
  return 4;
}

void FixMusenVerlet::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; i++) m += static_cast<int>(extra[nlocal][m]);
  m++;
  for (int k = 0; k < 3; k++) xref[nlocal][k] = extra[nlocal][m++];
}

int FixMusenVerlet::size_restart(int /*nlocal*/)
{
  return 4;
}

int FixMusenVerlet::maxsize_restart()
{
  return 4;
}

/* global state: distance, wall term, updates, warned, then the waiting pairs (as doubles:
   tags are exact in a double up to 2^53) */

void FixMusenVerlet::write_restart(FILE *fp)
{
  std::vector<double> list = {distance, wall_term, static_cast<double>(updates),
                              static_cast<double>(warned), static_cast<double>(waiting.size())};
  for (const auto &p : waiting) {
    list.push_back(static_cast<double>(p.first));
    list.push_back(static_cast<double>(p.second));
  }
  if (comm->me != 0) return;
  const int size = static_cast<int>(list.size() * sizeof(double));
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list.data(), sizeof(double), list.size(), fp);
}

void FixMusenVerlet::restart(char *buf)
{
  const auto *list = reinterpret_cast<const double *>(buf);
  distance = list[0];
  wall_term = list[1];
  updates = static_cast<bigint>(list[2]);
  warned = static_cast<int>(list[3]);
  const auto n = static_cast<size_t>(list[4]);
  waiting.clear();
  for (size_t k = 0; k < n; k++)
    waiting.emplace_back(static_cast<tagint>(list[5 + 2 * k]), static_cast<tagint>(list[6 + 2 * k]));
}

// f_ID[1] contact-list updates so far, [2] the Verlet distance now, [3] broken pairs waiting
double FixMusenVerlet::compute_vector(int n)
{
  if (n == 0) return static_cast<double>(updates);
  if (n == 1) return distance;
  return static_cast<double>(waiting.size());
}

double FixMusenVerlet::memory_usage()
{
  return 3.0 * atom->nmax * sizeof(double) +
      2.0 * sizeof(tagint) * static_cast<double>(waiting.size() + released_pairs.size());
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenVerlet(lmp, narg, arg);
}
const style_registry::Registration registered(
    105, "musen/verlet", "MUSEN contact-list update schedule", &create);
}    // namespace
