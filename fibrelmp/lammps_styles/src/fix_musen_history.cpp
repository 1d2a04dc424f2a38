/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenHistory: see fix_musen_history.h.
------------------------------------------------------------------------- */

#include "fix_musen_history.h"
#include "style_registry.h"

#include "atom.h"
#include "error.h"
#include "memory.h"
#include "utils.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixMusenHistory::FixMusenHistory(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), num(nullptr), cap(nullptr), data(nullptr)
{
  if (narg != 4) error->all(FLERR, "Illegal fix MUSEN/HISTORY command: fix ID group MUSEN/HISTORY N");
  nval = utils::inumeric(FLERR, arg[3], false, lmp);
  if (nval < 1) error->all(FLERR, "Fix MUSEN/HISTORY needs N >= 1 values per entry");
  restart_peratom = 1;
  create_attribute = 1;
  nmax_alloc = 0;
  FixMusenHistory::grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
  for (int i = 0; i < atom->nmax; i++) num[i] = 0;
}

FixMusenHistory::~FixMusenHistory()
{
  if (copymode) return;
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  for (int i = 0; i < nmax_alloc; i++) free(data[i]);
  free(data);
  memory->destroy(num);
  memory->destroy(cap);
}

int FixMusenHistory::setmask()
{
  return 0;
}

/* ---------------------------------------------------------------------- */

double *FixMusenHistory::insert(int i, double kd)
{
  const int st = stride();
  reserve(i, num[i] + 1);
  double *e = data[i] + num[i] * st;
  e[0] = kd;
  e[1] = 1.0;
  std::fill(e + 2, e + st, 0.0);
  num[i]++;
  return e + 2;
}

void FixMusenHistory::erase(int i, tagint k)
{
  const int st = stride();
  double *d = data[i];
  const double kd = static_cast<double>(k);
  for (int s = 0; s < num[i]; s++)
    if (d[s * st] == kd) {
      // keep the order of the others: the owning style's sums stay independent of erasures
      std::memmove(d + s * st, d + (s + 1) * st, sizeof(double) * (num[i] - s - 1) * st);
      num[i]--;
      return;
    }
}

void FixMusenHistory::sweep(int n)
{
  const int st = stride();
  for (int i = 0; i < n; i++) {
    double *d = data[i];
    int kept = 0;
    for (int s = 0; s < num[i]; s++) {
      if (d[s * st + 1] == 0.0) continue;
      if (kept != s) std::memmove(d + kept * st, d + s * st, sizeof(double) * st);
      d[kept * st + 1] = 0.0;
      kept++;
    }
    num[i] = kept;
  }
}

void FixMusenHistory::clear_all()
{
  for (int i = 0; i < atom->nmax && i < nmax_alloc; i++) num[i] = 0;
}

void FixMusenHistory::reserve(int i, int n)
{
  if (n <= cap[i]) return;
  int c = std::max(4, cap[i]);
  while (c < n) c *= 2;
  auto *p = static_cast<double *>(realloc(data[i], sizeof(double) * (size_t) c * stride()));
  if (!p) error->one(FLERR, "Fix MUSEN/HISTORY: out of memory for {} entries", c);
  data[i] = p;
  cap[i] = c;
}

/* ---------------------------------------------------------------------- */

double FixMusenHistory::memory_usage()
{
  double bytes = (double) nmax_alloc * (2 * sizeof(int) + sizeof(double *));
  for (int i = 0; i < atom->nlocal; i++) bytes += (double) cap[i] * stride() * sizeof(double);
  return bytes;
}

void FixMusenHistory::grow_arrays(int nmax)
{
  memory->grow(num, nmax, "musen/history:num");
  memory->grow(cap, nmax, "musen/history:cap");
  auto *p = static_cast<double **>(realloc(data, sizeof(double *) * std::max(nmax, 1)));
  if (!p) error->one(FLERR, "Fix MUSEN/HISTORY: out of memory for {} atoms", nmax);
  data = p;
  for (int i = nmax_alloc; i < nmax; i++) {
    data[i] = nullptr;
    cap[i] = 0;
    num[i] = 0;
  }
  nmax_alloc = std::max(nmax_alloc, nmax);
}

void FixMusenHistory::copy_arrays(int i, int j, int /*delflag*/)
{
  // a deep copy: LAMMPS's atom sort uses copies through a spare slot, so i stays valid
  reserve(j, num[i]);
  if (num[i]) std::memcpy(data[j], data[i], sizeof(double) * (size_t) num[i] * stride());
  num[j] = num[i];
}

void FixMusenHistory::set_arrays(int i)
{
  num[i] = 0;
}

int FixMusenHistory::pack_exchange(int i, double *buf)
{
  const int n = num[i] * stride();
  buf[0] = num[i];
  if (n) std::memcpy(buf + 1, data[i], sizeof(double) * n);
  return n + 1;
}

int FixMusenHistory::unpack_exchange(int nlocal, double *buf)
{
  const int cnt = static_cast<int>(buf[0]);
  reserve(nlocal, cnt);
  if (cnt) std::memcpy(data[nlocal], buf + 1, sizeof(double) * (size_t) cnt * stride());
  num[nlocal] = cnt;
  return cnt * stride() + 1;
}

int FixMusenHistory::pack_restart(int i, double *buf)
{
  const int n = num[i] * stride();
  buf[0] = n + 2;        // LAMMPS convention: the count of values, itself included
  buf[1] = num[i];
  if (n) std::memcpy(buf + 2, data[i], sizeof(double) * n);
  return n + 2;
}

void FixMusenHistory::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += static_cast<int>(extra[nlocal][m]);
  m++;
  const int cnt = static_cast<int>(extra[nlocal][m++]);
  reserve(nlocal, cnt);
  if (cnt) std::memcpy(data[nlocal], &extra[nlocal][m], sizeof(double) * (size_t) cnt * stride());
  num[nlocal] = cnt;
}

int FixMusenHistory::size_restart(int i)
{
  return num[i] * stride() + 2;
}

int FixMusenHistory::maxsize_restart()
{
  // the largest over every rank (as LAMMPS's FixNeighHistory): the restart file holds one
  // per-atom width for all atoms, and read_restart sizes atom->extra by it; rank 0's own
  // largest cut off the entries of atoms with more contacts on other ranks
  int most = 0;
  for (int i = 0; i < atom->nlocal; i++) most = std::max(most, num[i]);
  int most_all = most;
  MPI_Allreduce(&most, &most_all, 1, MPI_INT, MPI_MAX, world);
  return most_all * stride() + 2;
}

// registration with LAMMPS when the plugin loads (style_registry.h); the MUSEN styles create
// this fix, input scripts do not
namespace {
Fix *create(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenHistory(lmp, narg, arg);
}
const style_registry::Registration registered(
    10, "MUSEN/HISTORY", "per-atom contact/bond history of fibrelmp styles", &create);
}    // namespace
