/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenInlet: see fix_musen_inlet.h.
------------------------------------------------------------------------- */

#include "fix_musen_inlet.h"
#include "fix_musen_wall_mesh.h"
#include "style_registry.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "modify.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {

// splitmix64: a small portable generator; one stream per (seed, step)
struct Stream {
  std::uint64_t s;
  std::uint64_t next()
  {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double uniform() { return (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53; }    // (0, 1)
};

double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

const double GLIBC_RAND_MAX = 2147483647.0;

// squared distance from p to the triangle a b c (closest point by Voronoi regions)
double triangle_distance2(const double *p, const double *a, const double *b, const double *c)
{
  double ab[3], ac[3], ap[3], q[3];
  for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k];
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  double bp[3], cp[3];
  for (int k = 0; k < 3; k++) bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
  const double d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
  const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  double u, v;    // q = a + u ab + v ac
  if (d1 <= 0 && d2 <= 0) u = 0, v = 0;
  else if (d3 >= 0 && d4 <= d3) u = 1, v = 0;
  else if (d6 >= 0 && d5 <= d6) u = 0, v = 1;
  else if (vc <= 0 && d1 >= 0 && d3 <= 0) u = d1 / (d1 - d3), v = 0;
  else if (vb <= 0 && d2 >= 0 && d6 <= 0) u = 0, v = d2 / (d2 - d6);
  else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    u = 1 - w, v = w;
  } else {
    const double den = 1.0 / (va + vb + vc);
    u = vb * den, v = vc * den;
  }
  for (int k = 0; k < 3; k++) q[k] = a[k] + u * ab[k] + v * ac[k] - p[k];
  return dot(q, q);
}


// MUSEN's CInsideVolumeChecker::TryIntersectWithXAxis (InsideVolumeChecker.cpp), the triangle
// moved so that the tested point is the origin: does the ray along +x cross it, or does the
// ray pass (within 1e-20) through a vertex or an edge (undefined)?
void musen_x_ray(const double *p1, const double *p2, const double *p3, bool &crossing, bool &on_edge)
{
  const double e = 1e-20;
  const double c1 = p1[2] * p2[1] - p1[1] * p2[2];
  const double c2 = p2[2] * p3[1] - p2[1] * p3[2];
  const double c3 = p3[2] * p1[1] - p3[1] * p1[2];
  crossing = false;
  on_edge = true;
  if (std::fabs(p1[2]) < e && std::fabs(p1[1]) < e) return;
  if (std::fabs(p2[2]) < e && std::fabs(p2[1]) < e) return;
  if (std::fabs(p3[2]) < e && std::fabs(p3[1]) < e) return;
  // MUSEN's conditions as written (&& binds before ||; == after < and >)
  if (std::fabs(c1) < e && ((std::fabs(p1[1]) < e && ((p1[2] < 0) == (p2[2] > 0))) || ((p1[1] < 0) == (p2[1] > 0)))) return;
  if (std::fabs(c2) < e && ((std::fabs(p2[1]) < e && ((p2[2] < 0) == (p3[2] > 0))) || ((p2[1] < 0) == (p3[1] > 0)))) return;
  if (std::fabs(c3) < e && ((std::fabs(p3[1]) < e && ((p3[2] < 0) == (p1[2] > 0))) || ((p3[1] < 0) == (p1[1] > 0)))) return;
  on_edge = false;
  if (c1 == 0 || c2 == 0 || c3 == 0) return;
  crossing = (c1 < 0) == (c2 < 0) && (c1 < 0) == (c3 < 0);
  if (crossing) {
    const double A = p1[1] * (p2[2] - p3[2]) + p2[1] * (p3[2] - p1[2]) + p3[1] * (p1[2] - p2[2]);
    const double D = -(p1[0] * (p2[1] * p3[2] - p3[1] * p2[2]) + p2[0] * (p3[1] * p1[2] - p1[1] * p3[2]) +
                       p3[0] * (p1[1] * p2[2] - p2[1] * p1[2]));
    crossing = (A <= 0) == (D <= 0);
  }
}

// CInsideVolumeChecker::IsPointInside over all triangles (MUSEN's y-z grid only skips
// triangles the ray cannot meet): an odd number of crossings; false when undefined
bool musen_point_inside(const double *x, const std::vector<double> &tri, bool &undefined)
{
  int crossings = 0;
  for (size_t t = 0; t < tri.size() / 9; t++) {
    double v[9];
    for (int i = 0; i < 9; i++) v[i] = tri[9 * t + i] - x[i % 3];
    bool crossing, on_edge;
    musen_x_ray(v, v + 3, v + 6, crossing, on_edge);
    if (on_edge) {
      undefined = true;
      return false;
    }
    crossings += crossing;
  }
  return crossings % 2 == 1;
}

// CInsideVolumeChecker::IsSphereInside, "totally inside": the centre, the 6 points at +-r on
// the axes and the 8 at r (+-1, +-1, +-1)/sqrt(3) all inside the triangle volume.  An
// undefined answer (a point on an edge within 1e-20, which MUSEN retries with a rotated point
// against the unrotated mesh) counts as not inside: another random centre is drawn.
bool musen_sphere_inside(const double *x, double r, const std::vector<double> &tri)
{
  const double s = r / 1.73205081;    // MUSEN's sqrt(3)
  const double off[15][3] = {{0, 0, 0}, {r, 0, 0}, {-r, 0, 0}, {0, r, 0}, {0, -r, 0}, {0, 0, r},
                             {0, 0, -r}, {s, s, s}, {s, s, -s}, {s, -s, s}, {s, -s, -s},
                             {-s, s, s}, {-s, s, -s}, {-s, -s, s}, {-s, -s, -s}};
  for (const auto &o : off) {
    const double p[3] = {x[0] + o[0], x[1] + o[1], x[2] + o[2]};
    bool undefined = false;
    if (!musen_point_inside(p, tri, undefined) || undefined) return false;
  }
  return true;
}

}    // namespace

FixMusenInlet::FixMusenInlet(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), wall_id(nullptr), inserted(0), first_id(1), last_id(0), log(nullptr), type_radius(0.0)
{
  const std::string usage = "fix ID group musen/inlet SEED box XLO XHI YLO YHI ZLO ZHI tries N "
      "walls WALLFIX|none velocity fixed VX VY VZ|random MAG fractions K ... events M ...";
  auto need = [&](int at, int n, const char *word) {
    if (at + n > narg || (word && strcmp(arg[at], word) != 0))
      error->all(FLERR, "Illegal fix musen/inlet command (expected '{}' at argument {}): {}",
                 word ? word : "more values", at + 1, usage);
  };
  need(3, 1, nullptr);
  seed = static_cast<std::uint64_t>(utils::bnumeric(FLERR, arg[3], false, lmp));
  need(4, 7, "box");
  for (int k = 0; k < 3; k++) {
    lo[k] = utils::numeric(FLERR, arg[5 + 2 * k], false, lmp);
    hi[k] = utils::numeric(FLERR, arg[6 + 2 * k], false, lmp);
    if (!(hi[k] > lo[k])) error->all(FLERR, "Fix musen/inlet: box needs lo < hi on every axis");
  }
  need(11, 2, "tries");
  tries = utils::inumeric(FLERR, arg[12], false, lmp);
  need(13, 2, "walls");
  if (strcmp(arg[14], "none") != 0) wall_id = utils::strdup(arg[14]);
  int at = 15;
  need(at, 2, "velocity");
  random_velocity = strcmp(arg[at + 1], "random") == 0;
  if (random_velocity) {
    need(at, 3, "velocity");
    magnitude = utils::numeric(FLERR, arg[at + 2], false, lmp);
    at += 3;
  } else {
    need(at, 5, "velocity");
    if (strcmp(arg[at + 1], "fixed") != 0) error->all(FLERR, "Fix musen/inlet: velocity fixed|random");
    for (int k = 0; k < 3; k++) velocity[k] = utils::numeric(FLERR, arg[at + 2 + k], false, lmp);
    at += 5;
  }
  if (at < narg && strcmp(arg[at], "agglomerate") == 0) {
    // the agglomerate's spheres become one "fraction" each (type, radius, density, group)
    need(at, 2, "agglomerate");
    const int npart = utils::inumeric(FLERR, arg[at + 1], false, lmp);
    if (npart < 1) error->all(FLERR, "Fix musen/inlet: an agglomerate needs at least one sphere");
    at += 2;
    need(at, 6 * npart, nullptr);
    for (int i = 0; i < npart; i++, at += 6) {
      Part p{utils::inumeric(FLERR, arg[at], false, lmp), utils::numeric(FLERR, arg[at + 1], false, lmp),
             utils::numeric(FLERR, arg[at + 2], false, lmp),
             {utils::numeric(FLERR, arg[at + 3], false, lmp), utils::numeric(FLERR, arg[at + 4], false, lmp),
              utils::numeric(FLERR, arg[at + 5], false, lmp)}};
      if (p.type < 1 || p.type > atom->ntypes) error->all(FLERR, "Fix musen/inlet: invalid atom type {}", p.type);
      if (!(p.radius > 0 && p.density > 0)) error->all(FLERR, "Fix musen/inlet: radius and density must be > 0");
      parts.push_back(p);
      fractions.push_back(Fraction{p.type, p.radius, p.density, 0.0, 0});
    }
    need(at, 2, "bonds");
    const int nb = utils::inumeric(FLERR, arg[at + 1], false, lmp);
    at += 2;
    need(at, 4 * nb, nullptr);
    for (int i = 0; i < nb; i++, at += 4) {
      AggloBond b{utils::inumeric(FLERR, arg[at], false, lmp), utils::inumeric(FLERR, arg[at + 1], false, lmp),
                  utils::inumeric(FLERR, arg[at + 2], false, lmp), utils::numeric(FLERR, arg[at + 3], false, lmp)};
      if (b.left < 0 || b.left >= npart || b.right < 0 || b.right >= npart || b.left == b.right)
        error->all(FLERR, "Fix musen/inlet: bond {} joins spheres {} and {} of an agglomerate of {}", i,
                   b.left, b.right, npart);
      if (!(b.diameter > 0)) error->all(FLERR, "Fix musen/inlet: bond diameters must be > 0");
      if (b.type < 1 || b.type > atom->nbondtypes) error->all(FLERR, "Fix musen/inlet: invalid bond type {}", b.type);
      bonds.push_back(b);
    }
  } else {
    need(at, 2, "fractions");
    const int nfrac = utils::inumeric(FLERR, arg[at + 1], false, lmp);
    at += 2;
    need(at, 4 * nfrac, nullptr);
    for (int i = 0; i < nfrac; i++, at += 4) {
      Fraction f{utils::inumeric(FLERR, arg[at], false, lmp),
                 0.5 * utils::numeric(FLERR, arg[at + 1], false, lmp),
                 utils::numeric(FLERR, arg[at + 2], false, lmp),
                 utils::numeric(FLERR, arg[at + 3], false, lmp), 0};
      if (f.type < 1 || f.type > atom->ntypes) error->all(FLERR, "Fix musen/inlet: invalid atom type {}", f.type);
      if (!(f.radius > 0 && f.density > 0)) error->all(FLERR, "Fix musen/inlet: diameter and density must be > 0");
      fractions.push_back(f);
    }
    if (fractions.empty()) error->all(FLERR, "Fix musen/inlet needs at least one fraction");
  }
  made.assign(fractions.size(), 0);
  need(at, 2, "events");
  const int nev = utils::inumeric(FLERR, arg[at + 1], false, lmp);
  at += 2;
  need(at, 2 * nev, nullptr);
  for (int i = 0; i < nev; i++, at += 2) {
    Event e{utils::bnumeric(FLERR, arg[at], false, lmp), utils::inumeric(FLERR, arg[at + 1], false, lmp)};
    if (e.step < 1 || (!events.empty() && e.step <= events.back().step))
      error->all(FLERR, "Fix musen/inlet: event steps must be >= 1 and ascending");
    events.push_back(e);
    requested_before.push_back(i ? requested_before.back() + events[i - 1].count : 0);
  }
  while (at < narg) {
    need(at, 2, nullptr);
    if (strcmp(arg[at], "first_id") == 0) {
      first_id = utils::tnumeric(FLERR, arg[at + 1], false, lmp);
    } else if (strcmp(arg[at], "groups") == 0) {    // one more group per fraction
      need(at, 1 + static_cast<int>(fractions.size()), nullptr);
      for (size_t i = 0; i < fractions.size(); i++) {
        const int g = group->find(arg[at + 1 + i]);
        if (g < 0) error->all(FLERR, "Fix musen/inlet: no group {}", arg[at + 1 + i]);
        fractions[i].groupbit = group->bitmask[g];
      }
      at += static_cast<int>(fractions.size()) - 1;
    } else if (strcmp(arg[at], "volume") == 0) {    // N triangles (9 N coordinates)
      const int ntri = utils::inumeric(FLERR, arg[at + 1], false, lmp);
      if (ntri < 1) error->all(FLERR, "Fix musen/inlet: volume needs at least one triangle");
      need(at + 2, 9 * ntri, nullptr);
      volume.resize(9 * static_cast<size_t>(ntri));
      for (size_t i = 0; i < volume.size(); i++) volume[i] = utils::numeric(FLERR, arg[at + 2 + i], false, lmp);
      at += 9 * ntri;
    } else if (strcmp(arg[at], "geometry") == 0) {    // PARTNER VALUES K
      need(at, 4, nullptr);
      partners_name = arg[at + 1];
      values_name = arg[at + 2];
      nslots = utils::inumeric(FLERR, arg[at + 3], false, lmp);
      if (nslots < 1) error->all(FLERR, "Fix musen/inlet: geometry needs K >= 1 slots");
      at += 2;
    } else if (strcmp(arg[at], "musen_rand") == 0) {    // TIME0: cmusen's srand(time(0))
      if (parts.empty()) error->all(FLERR, "Fix musen/inlet: musen_rand is for agglomerates");
      std::uint32_t t0 = static_cast<std::uint32_t>(utils::bnumeric(FLERR, arg[at + 1], false, lmp));
      switch (t0 % 5) {    // CObjectsGenerator::Initialize (unsigned arithmetic)
        case 4: t0 *= 2; break;
        case 3: t0 *= t0; break;
        case 2: t0 += t0 * t0; break;
        case 1: t0 = t0 / 2; break;
        default: break;
      }
      musen_rand = true;
      glibc.seed(t0);
    } else if (strcmp(arg[at], "log") == 0) {
      if (comm->me == 0) {
        log = fopen(arg[at + 1], "a");
        if (!log) error->one(FLERR, "Fix musen/inlet: cannot open log file {}", arg[at + 1]);
      }
    } else {
      error->all(FLERR, "Illegal fix musen/inlet command: unknown keyword {}", arg[at]);
    }
    at += 2;
  }
  if (strcmp(atom->atom_style, "sphere") != 0 && strcmp(atom->atom_style, "bpm/sphere") != 0)
    error->all(FLERR, "Fix musen/inlet needs atom style sphere or bpm/sphere, not {}", atom->atom_style);
  if (domain->triclinic) error->all(FLERR, "Fix musen/inlet needs an orthogonal box");
  if (!bonds.empty()) {
    if (!atom->molecular || !atom->bond_per_atom)
      error->all(FLERR, "Fix musen/inlet: agglomerates with bonds need an atom style with bonds "
                 "(bpm/sphere) and room for them (read_data extra/bond/per/atom)");
    if (!force->newton_bond) error->all(FLERR, "Fix musen/inlet: agglomerates with bonds need newton_bond on");
  }
  const int periodic[3] = {domain->xperiodic, domain->yperiodic, domain->zperiodic};
  for (int k = 0; k < 3; k++)    // a sphere created outside the box would be lost unseen
    if (!periodic[k] && (lo[k] < domain->boxlo[k] || hi[k] > domain->boxhi[k]))
      error->all(FLERR, "Fix musen/inlet: the generation box is not inside the simulation box on axis {}", k);
  force_reneighbor = 1;
  next_reneighbor = -1;
  scalar_flag = 1;
  extscalar = 0;
  restart_global = 1;
}

FixMusenInlet::~FixMusenInlet()
{
  delete[] wall_id;
  if (log) fclose(log);
}

int FixMusenInlet::setmask()
{
  return PRE_EXCHANGE;
}

void FixMusenInlet::init()
{
  if (wall_id && !dynamic_cast<FixMusenWallMesh *>(modify->get_fix_by_id(wall_id)))
    error->all(FLERR, "Fix musen/inlet: no fix musen/wall/mesh with ID {}", wall_id);
  schedule_next();
}

void FixMusenInlet::setup_pre_exchange()
{
  schedule_next();
}

void FixMusenInlet::schedule_next()
{
  // events ascend by step: a binary search (a long generation keeps ~1e5 events)
  const auto later = std::upper_bound(events.begin(), events.end(), update->ntimestep,
                                      [](bigint step, const Event &e) { return step < e.step; });
  next_reneighbor = later == events.end() ? -1 : later->step;
}

void FixMusenInlet::pre_exchange()
{
  if (next_reneighbor != update->ntimestep) return;
  const auto now = std::lower_bound(events.begin(), events.end(), update->ntimestep,
                                    [](const Event &e, bigint step) { return e.step < step; });
  if (now != events.end() && now->step == update->ntimestep) {
    if (parts.empty()) insert(*now);
    else insert_agglomerates(*now, requested_before[now - events.begin()]);
  }
  schedule_next();
}

/* every sphere (owned by any rank) whose centre lies within reach of the box */
std::vector<FixMusenInlet::Sphere> FixMusenInlet::spheres_near(double reach)
{
  std::vector<double> mine;
  for (int i = 0; i < atom->nlocal; i++) {
    const double *x = atom->x[i];
    bool near = true;
    for (int k = 0; k < 3; k++) near = near && x[k] >= lo[k] - reach && x[k] <= hi[k] + reach;
    if (near) mine.insert(mine.end(), {x[0], x[1], x[2], atom->radius[i]});
  }
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(comm->nprocs), displs(comm->nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  for (int p = 1; p < comm->nprocs; p++) displs[p] = displs[p - 1] + counts[p - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, world);
  std::vector<Sphere> out(all.size() / 4);
  for (size_t j = 0; j < out.size(); j++)
    out[j] = Sphere{{all[4 * j], all[4 * j + 1], all[4 * j + 2]}, all[4 * j + 3]};
  return out;
}

/* the wall fix's triangles now (9 numbers each), the same on every rank */
std::vector<double> FixMusenInlet::wall_triangles()
{
  if (!wall_id) return {};
  auto *walls = dynamic_cast<FixMusenWallMesh *>(modify->get_fix_by_id(wall_id));
  if (!walls) error->all(FLERR, "Fix musen/inlet: no fix musen/wall/mesh with ID {}", wall_id);
  return walls->vertices_now();
}

int FixMusenInlet::next_fraction() const
{
  int total = 0;
  for (int m : made) total += m;
  if (total == 0) return 0;
  for (size_t i = 0; i < fractions.size(); i++)
    if (static_cast<double>(made[i]) / total < fractions[i].share) return static_cast<int>(i);
  return 0;
}

/* the sphere is totally inside the volume, overlaps none of near and touches no close triangle */
bool FixMusenInlet::sphere_fits(const Sphere &s, const std::vector<Sphere> &near, const std::vector<double> &tri,
                                const std::vector<int> &close) const
{
  const double r = s.r;
  bool placed = true;
  if (volume.empty())
    for (int k = 0; k < 3; k++) placed = placed && s.x[k] - r >= lo[k] && s.x[k] + r <= hi[k];
  else
    placed = musen_sphere_inside(s.x, r, volume);
  for (size_t j = 0; placed && j < near.size(); j++) {
    double d[3] = {s.x[0] - near[j].x[0], s.x[1] - near[j].x[1], s.x[2] - near[j].x[2]};
    const double reach = r + near[j].r;
    placed = dot(d, d) >= reach * reach;
  }
  for (size_t c = 0; placed && c < close.size(); c++) {
    const double *v = &tri[9 * close[c]];
    placed = triangle_distance2(s.x, v, v + 3, v + 6) >= r * r;
  }
  return placed;
}

/* the triangles of fix musen/wall/mesh that can touch a sphere inside the box */
static std::vector<int> close_triangles(const std::vector<double> &tri, const double *lo, const double *hi)
{
  std::vector<int> close;
  for (size_t t = 0; t < tri.size() / 9; t++) {
    bool apart = false;
    for (int k = 0; k < 3 && !apart; k++) {
      const double *v = &tri[9 * t];
      const double tlo = std::min({v[k], v[3 + k], v[6 + k]}), thi = std::max({v[k], v[3 + k], v[6 + k]});
      apart = thi < lo[k] || tlo > hi[k];
    }
    if (!apart) close.push_back(static_cast<int>(t));
  }
  return close;
}

/* what a new object must not overlap: every sphere near the box (any rank's) and the wall
   triangles near it */
FixMusenInlet::Surroundings FixMusenInlet::surroundings()
{
  double rmax = 0.0;
  for (int i = 0; i < atom->nlocal; i++) rmax = std::max(rmax, atom->radius[i]);
  MPI_Allreduce(MPI_IN_PLACE, &rmax, 1, MPI_DOUBLE, MPI_MAX, world);
  Surroundings out;
  out.near = spheres_near(rmax);
  out.tri = wall_triangles();
  out.close = close_triangles(out.tri, lo, hi);
  return out;
}

void FixMusenInlet::insert(const Event &event)
{
  Surroundings around = surroundings();
  std::vector<Sphere> &near = around.near;
  const std::vector<double> &tri = around.tri;
  const std::vector<int> &close = around.close;
  Stream rng{seed * 0x9E3779B97F4A7C15ULL ^ static_cast<std::uint64_t>(event.step)};
  std::vector<Sphere> created;
  std::vector<int> types;
  std::vector<double> vel;
  for (int obj = 0; obj < event.count; obj++) {
    const int f = next_fraction();
    const double r = fractions[f].radius;
    bool placed = false;
    Sphere s{{0, 0, 0}, r};
    for (int attempt = 0; attempt < tries && !placed; attempt++) {
      for (int k = 0; k < 3; k++) s.x[k] = lo[k] + rng.uniform() * (hi[k] - lo[k]);
      placed = sphere_fits(s, near, tri, close);
    }
    if (!placed) continue;
    double u[3] = {velocity[0], velocity[1], velocity[2]};
    if (random_velocity) {
      double len;
      do {
        for (int k = 0; k < 3; k++) u[k] = 2.0 * rng.uniform() - 1.0;
        len = std::sqrt(dot(u, u));
      } while (len == 0.0 || len > 1.0);
      for (int k = 0; k < 3; k++) u[k] = u[k] / len * magnitude;
    }
    made[f]++;
    near.push_back(s);
    created.push_back(s);
    types.push_back(f);
    vel.insert(vel.end(), {u[0], u[1], u[2]});
  }
  if (!created.empty()) create(created, types, vel);
}

/* MUSEN's generator of agglomerates (CObjectsGenerator::Generate, GenerateNewObject) */
void FixMusenInlet::insert_agglomerates(const Event &event, bigint slot)
{
  Surroundings around = surroundings();
  std::vector<Sphere> &near = around.near;
  const std::vector<double> &tri = around.tri;
  const std::vector<int> &close = around.close;
  Stream rng{seed * 0x9E3779B97F4A7C15ULL ^ static_cast<std::uint64_t>(event.step)};
  // musen_rand: cmusen's one rand() stream, shared by every generator (the first fix owns it)
  GlibcRand *crand = musen_rand ? &stream_owner()->glibc : nullptr;
  const size_t n = parts.size();
  std::vector<Sphere> created, object(n);
  std::vector<int> which;
  std::vector<double> vel;
  std::vector<tagint> tags;
  // requested object j of this fix (over its events) has IDs first_id + j n + part, made or
  // not; slot = the objects requested by this fix's earlier events
  for (int obj = 0; obj < event.count; obj++, slot++) {
    bool placed = false;
    for (int attempt = 0; attempt < tries && !placed; attempt++) {
      double c[3], q[4], R[3][3];
      double u1, u2, u3;
      if (crand) {    // CreateRandomPoint, then CQuaternion::Random, as cmusen computes them
        for (int k = 0; k < 3; k++) c[k] = lo[k] + (static_cast<double>(crand->next()) + 1.0) * (hi[k] - lo[k]) / GLIBC_RAND_MAX;
        u1 = crand->next() / GLIBC_RAND_MAX;
        u2 = crand->next() / GLIBC_RAND_MAX;
        u3 = crand->next() / GLIBC_RAND_MAX;
      } else {
        for (int k = 0; k < 3; k++) c[k] = lo[k] + rng.uniform() * (hi[k] - lo[k]);
        u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
      }
      // CQuaternion::Random (Shoemake), then QuatRotateVector's ToRotmat, with MUSEN's
      // operations in MUSEN's order (three normalisations, its diagonal w1 + w2 - w3 - w4), so
      // that the same random numbers give cmusen's positions bit for bit
      q[0] = std::sqrt(1 - u1) * std::sin(2 * M_PI * u2);
      q[1] = std::sqrt(1 - u1) * std::cos(2 * M_PI * u2);
      q[2] = std::sqrt(u1) * std::sin(2 * M_PI * u3);
      q[3] = std::sqrt(u1) * std::cos(2 * M_PI * u3);
      for (int times = 0; times < 3; times++) {    // Random, QuatRotateVector, ToRotmat
        double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (q[0] < 0) len = -len;    // MUSEN's Normalize: q0 >= 0 (the same rotation)
        for (double &v : q) v /= len;
      }
      const double w1 = q[0] * q[0], w2 = q[1] * q[1], w3 = q[2] * q[2], w4 = q[3] * q[3];
      const double ij = 2 * q[1] * q[2], ik = 2 * q[1] * q[3], jk = 2 * q[2] * q[3];
      const double iw = 2 * q[1] * q[0], jw = 2 * q[2] * q[0], kw = 2 * q[3] * q[0];
      R[0][0] = w1 + w2 - w3 - w4, R[0][1] = ij - kw, R[0][2] = jw + ik;
      R[1][0] = ij + kw, R[1][1] = w1 - w2 + w3 - w4, R[1][2] = jk - iw;
      R[2][0] = ik - jw, R[2][1] = jk + iw, R[2][2] = w1 - w2 - w3 + w4;
      placed = true;
      for (size_t p = 0; p < n && placed; p++) {
        Sphere &s = object[p];
        s.r = parts[p].radius;
        for (int k = 0; k < 3; k++) s.x[k] = c[k] + dot(R[k], parts[p].x);
        placed = sphere_fits(s, near, tri, close);    // not against its own spheres
      }
    }
    if (!placed) continue;
    double u[3] = {velocity[0], velocity[1], velocity[2]};
    if (random_velocity) {
      double len;
      do {
        for (int k = 0; k < 3; k++) u[k] = crand ? 2 * static_cast<double>(crand->next()) / GLIBC_RAND_MAX - 1 : 2.0 * rng.uniform() - 1.0;
        len = std::sqrt(dot(u, u));
      } while (len == 0.0 || len > 1.0);
      for (int k = 0; k < 3; k++) u[k] = u[k] / len * magnitude;
    }
    for (size_t p = 0; p < n; p++) {
      near.push_back(object[p]);
      created.push_back(object[p]);
      which.push_back(static_cast<int>(p));
      vel.insert(vel.end(), {u[0], u[1], u[2]});
      tags.push_back(first_id + static_cast<tagint>(slot * static_cast<bigint>(n) + static_cast<bigint>(p)));
    }
  }
  if (created.empty()) return;
  // the IDs reserved for these objects must be free (another fix or a read_data could hold them)
  int taken = 0;
  for (tagint t : tags)    // (map() reads past its table above map_tag_max)
    if (t <= atom->map_tag_max) taken |= (atom->map(t) >= 0 && atom->map(t) < atom->nlocal);
  MPI_Allreduce(MPI_IN_PLACE, &taken, 1, MPI_INT, MPI_MAX, world);
  if (taken)
    error->all(FLERR, "Fix musen/inlet: an ID reserved for its agglomerates ({}..{}) is taken by "
               "another atom (first_id must leave room for every requested agglomerate)", tags.front(), tags.back());
  create(created, which, vel, &tags);
  if (!bonds.empty()) add_bonds(created, tags);
}

/* the bonds of the objects just made (their spheres have IDs first, first + 1, .. in part
   order, object after object): on the left sphere's bond list and geometry slot, and 1-2
   special neighbours of both spheres */
void FixMusenInlet::add_bonds(const std::vector<Sphere> &made_now, const std::vector<tagint> &tags)
{
  const size_t n = parts.size(), objects = made_now.size() / n;
  std::vector<int> islot(nslots, -1), ivalue(nslots, -1);
  int width = 0;
  for (int k = 0; k < nslots; k++) {
    int flag, cols;
    islot[k] = atom->find_custom(fmt::format("{}{}", partners_name, k + 1).c_str(), flag, cols);
    if (islot[k] < 0 || flag != 0 || cols != 0)
      error->all(FLERR, "Fix musen/inlet: no per-atom integer vector i_{}{}", partners_name, k + 1);
    ivalue[k] = atom->find_custom(fmt::format("{}{}", values_name, k + 1).c_str(), flag, cols);
    if (ivalue[k] < 0 || flag != 1 || cols < 2)
      error->all(FLERR, "Fix musen/inlet: no per-atom array d2_{}{}", values_name, k + 1);
    width = cols;
  }
  // a new atom's slots may hold what an atom that left this rank had there: cleared
  const tagint lowest = tags.front(), last = tags.back();
  for (int i = 0; i < atom->nlocal; i++)
    if (atom->tag[i] >= lowest && atom->tag[i] <= last)
      for (int k = 0; k < nslots; k++) {
        atom->ivector[islot[k]][i] = 0;
        for (int c = 0; c < width; c++) atom->darray[ivalue[k]][i][c] = 0.0;
      }
  for (size_t obj = 0; obj < objects; obj++) {
    const tagint base = tags[obj * n];
    for (const AggloBond &b : bonds) {
      const tagint left = base + b.left, right = base + b.right;
      const Sphere &sl = made_now[obj * n + b.left], &sr = made_now[obj * n + b.right];
      const double d[3] = {sr.x[0] - sl.x[0], sr.x[1] - sl.x[1], sr.x[2] - sl.x[2]};
      const double length0 = std::sqrt(dot(d, d));    // AddSolidBond: the current length
      if (log) fmt::print(log, "{} {} {} {:.17g}\n", update->ntimestep, left, right, length0);
      const int i = atom->map(left);
      if (i >= 0 && i < atom->nlocal) {
        if (atom->num_bond[i] == atom->bond_per_atom)
          error->one(FLERR, "Fix musen/inlet: atom {} would hold more than {} bonds (read_data "
                     "extra/bond/per/atom)", left, atom->bond_per_atom);
        const int m = atom->num_bond[i]++;
        atom->bond_type[i][m] = b.type;
        atom->bond_atom[i][m] = right;
        if (nslots) {
          int k = 0;
          while (k < nslots && atom->ivector[islot[k]][i] != 0) k++;
          if (k == nslots)
            error->one(FLERR, "Fix musen/inlet: atom {} has no free bond geometry slot of {}", left, nslots);
          atom->ivector[islot[k]][i] = right;
          double *v = atom->darray[ivalue[k]][i];
          for (int c = 0; c < width; c++) v[c] = 0.0;
          v[0] = b.diameter;
          v[1] = length0;
        }
      }
      for (tagint pair[2] = {left, right}, j = 0; j < 2; j++) {    // 1-2 special neighbours
        const int a = atom->map(pair[j]);
        if (a < 0 || a >= atom->nlocal) continue;
        if (atom->nspecial[a][0] == atom->maxspecial)
          error->one(FLERR, "Fix musen/inlet: atom {} would have more than {} special neighbours "
                     "(read_data extra/special/per/atom)", pair[j], atom->maxspecial);
        atom->special[a][atom->nspecial[a][0]++] = pair[1 - j];
        atom->nspecial[a][1] = atom->nspecial[a][2] = atom->nspecial[a][0];
      }
    }
  }
  atom->nbonds += static_cast<bigint>(objects * bonds.size());
  if (log) fflush(log);
}

/* the new atoms, through Atom::data_atoms (each rank keeps those in its sub-domain) */
tagint FixMusenInlet::create(const std::vector<Sphere> &made_now, const std::vector<int> &which,
                             const std::vector<double> &vel, const std::vector<tagint> *given)
{
  // a mixture's spheres: the next IDs, in order of success; an agglomerate's: the IDs given
  tagint maxtag = 0;
  if (!given) {
    for (int i = 0; i < atom->nlocal; i++) maxtag = std::max(maxtag, atom->tag[i]);
    MPI_Allreduce(MPI_IN_PLACE, &maxtag, 1, MPI_LMP_TAGINT, MPI_MAX, world);
    maxtag = std::max(maxtag, first_id - 1);
    for (Fix *other : modify->get_fix_by_style("^musen/inlet$"))
      maxtag = std::max(maxtag, static_cast<FixMusenInlet *>(other)->last_given());
  }
  std::vector<tagint> tags(made_now.size());
  std::unordered_map<tagint, size_t> index;
  for (size_t j = 0; j < made_now.size(); j++) {
    tags[j] = given ? (*given)[j] : maxtag + 1 + static_cast<tagint>(j);
    index[tags[j]] = j;
  }
  std::string lines;
  for (size_t j = 0; j < made_now.size(); j++) {
    const Fraction &f = fractions[which[j]];
    // the Atoms line of atom styles sphere (id type d rho x y z) and bpm/sphere (id mol ...)
    lines += fmt::format("{}{} {} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n", tags[j],
                         atom->molecule_flag ? " 0" : "", f.type, 2.0 * f.radius, f.density,
                         made_now[j].x[0], made_now[j].x[1], made_now[j].x[2]);
  }
  const int first = atom->nlocal;
  std::vector<char> buf(lines.begin(), lines.end());
  buf.push_back('\0');
  double shift[3] = {0.0, 0.0, 0.0};
  atom->data_atoms(static_cast<int>(made_now.size()), buf.data(), 0, 0, 0, 0, shift, 0, nullptr, 0);
  for (int i = first; i < atom->nlocal; i++) {
    const size_t j = index.at(atom->tag[i]);
    const Fraction &f = fractions[which[j]];
    atom->mask[i] |= groupbit | f.groupbit;
    atom->rmass[i] = 4.0 / 3.0 * M_PI * std::pow(f.radius, 3) * f.density;    // MUSEN's mass
    for (int k = 0; k < 3; k++) atom->v[i][k] = vel[3 * j + k], atom->omega[i][k] = 0.0;
    modify->create_attribute(i);
  }
  atom->natoms += static_cast<bigint>(made_now.size());
  last_id = std::max(last_id, *std::max_element(tags.begin(), tags.end()));
  if (log) {
    for (size_t j = 0; j < made_now.size(); j++) fmt::print(log, "{} {}\n", update->ntimestep, tags[j]);
    fflush(log);
  }
  inserted += static_cast<bigint>(made_now.size());
  if (atom->map_style != Atom::MAP_NONE) {
    atom->nghost = 0;
    atom->map_init();
    atom->map_set();
  }
  return tags[0];
}

void *FixMusenInlet::extract(const char *name, int &itype)
{
  if (strcmp(name, "radius") != 0) return nullptr;
  type_radius = 0.0;
  for (const Fraction &f : fractions)
    if (f.type == itype) type_radius = std::max(type_radius, f.radius);
  return &type_radius;
}

/* the fix holding cmusen's rand() stream: the first musen/inlet fix with musen_rand */
FixMusenInlet *FixMusenInlet::stream_owner()
{
  for (Fix *other : modify->get_fix_by_style("^musen/inlet$")) {
    auto *f = static_cast<FixMusenInlet *>(other);
    if (f->musen_rand) return f;
  }
  return this;
}

double FixMusenInlet::compute_scalar()
{
  return static_cast<double>(inserted);
}

/* the mixture history (successes per fraction) and the count: a restarted run continues them */
void FixMusenInlet::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  // the 4th word says how many rand() stream words follow, so that a restart never reads
  // words that were not written
  std::vector<double> list{static_cast<double>(made.size()), static_cast<double>(inserted),
                           static_cast<double>(last_id), musen_rand ? 35.0 : 0.0};
  for (int m : made) list.push_back(m);
  if (musen_rand) {    // the rand() stream: 34 words and the count (exact in doubles)
    for (std::uint32_t w : glibc.r) list.push_back(static_cast<double>(w));
    list.push_back(static_cast<double>(glibc.n));
  }
  const int size = static_cast<int>(list.size() * sizeof(double));
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list.data(), sizeof(double), list.size(), fp);
}

void FixMusenInlet::restart(char *buf)
{
  const auto *list = reinterpret_cast<const double *>(buf);
  if (static_cast<size_t>(list[0]) != made.size())
    error->all(FLERR, "Fix musen/inlet: the restart file has {} fractions, the command {}",
               static_cast<int>(list[0]), made.size());
  if ((list[3] == 35.0) != static_cast<bool>(musen_rand))
    error->all(FLERR, "Fix musen/inlet: the restart file was written {} musen_rand, the command "
               "is {} it", list[3] == 35.0 ? "with" : "without", musen_rand ? "with" : "without");
  inserted = static_cast<bigint>(list[1]);
  last_id = static_cast<tagint>(list[2]);
  for (size_t i = 0; i < made.size(); i++) made[i] = static_cast<int>(list[4 + i]);
  if (musen_rand) {
    const double *w = list + 4 + made.size();
    for (int k = 0; k < 34; k++) glibc.r[k] = static_cast<std::uint32_t>(w[k]);
    glibc.n = static_cast<std::uint64_t>(w[34]);
  }
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenInlet(lmp, narg, arg);
}
const style_registry::Registration registered(
    110, "musen/inlet", "MUSEN dynamic generator (inlet) of spheres", &create);
}    // namespace
