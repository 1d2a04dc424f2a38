/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenWallMesh: see fix_musen_wall_mesh.h.

   MUSEN's formulas are re-implemented from its sources (BSD-3-Clause, (c) MUSEN Development
   Team); each function names the MUSEN function it follows.  The arithmetic keeps MUSEN's
   operation order (and the build uses -ffp-contract=off) so independent re-implementations
   of the same formulas agree to the last bits.
------------------------------------------------------------------------- */

#include "fix_musen_wall_mesh.h"
#include "lammps_time.h"
#include "style_registry.h"
#include "fix_musen_history.h"
#include "fix_musen_leapfrog.h"
#include "musen_startup.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "group.h"
#include "modify.h"
#include "neighbor.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <functional>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {

constexpr double MUSEN_PI = 3.14159265358979323846;            // MUSENDefinitions.h PI
constexpr double MIN_SIGNIFICANT = 1e-100;     // Vector3.h MinValueHelper<double>
constexpr int NSHIFT = 27;
constexpr int GRID_CELL_CAP_MIN = 4096;

// ---- MUSEN's CVector3 arithmetic, operation by operation (Vector3.h)
inline double dot(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline void cross(const double *a, const double *b, double *c)    // CVector3 operator*
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
// (v1 - v0) x (v2 - v0) of the triangle p = {v0, v1, v2}: its normal times twice its area
inline void face_cross(const double *p, double *c)
{
  double u[3], w[3];
  for (int k = 0; k < 3; k++) {
    u[k] = p[3 + k] - p[k];
    w[k] = p[6 + k] - p[k];
  }
  cross(u, w, c);
}
// axis-aligned bounds (lo, hi) of the triangle p
inline void face_bounds(const double *p, double *lo, double *hi)
{
  for (int k = 0; k < 3; k++) {
    lo[k] = std::min(std::min(p[k], p[3 + k]), p[6 + k]);
    hi[k] = std::max(std::max(p[k], p[3 + k]), p[6 + k]);
  }
}
inline double sqlen(const double *a)
{
  return a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
}
inline bool is_zero(const double *a)
{
  return a[0] == 0 && a[1] == 0 && a[2] == 0;
}

/* What sphere_triangle needs of a triangle v that depends on v alone and costs divisions or
   products, computed once per placement of the triangle (the same operations as MUSEN's
   IsSphereIntersectTriangle does per call, so the results are the same bits): the centre,
   the dot products d00 d01 d11 of the edges e21 e31, 1 / (d00 d11 - d01^2) and the squared
   lengths of e21 e32 e13.  The edges themselves are recomputed (subtractions: cheaper than
   reading them from memory for large meshes). */
constexpr int NPRE = 10;
enum { P_CENTRE = 0, P_D00 = 3, P_D01 = 4, P_D11 = 5, P_INV_DENOM = 6, P_L21 = 7, P_L32 = 8,
       P_L13 = 9 };
inline void triangle_edges(const double *v, double *e21, double *e31, double *e32, double *e13)
{
  const double *v1 = v, *v2 = v + 3, *v3 = v + 6;
  for (int k = 0; k < 3; k++) {
    e21[k] = v2[k] - v1[k];
    e31[k] = v3[k] - v1[k];
    e32[k] = v3[k] - v2[k];
    e13[k] = v1[k] - v3[k];
  }
}
void triangle_constants(const double *v, double *pre)
{
  const double *v1 = v, *v2 = v + 3, *v3 = v + 6;
  for (int k = 0; k < 3; k++) pre[P_CENTRE + k] = (v1[k] + v2[k] + v3[k]) / 3.0;
  double e21[3], e31[3], e32[3], e13[3];
  triangle_edges(v, e21, e31, e32, e13);
  pre[P_D00] = dot(e21, e21);
  pre[P_D01] = dot(e21, e31);
  pre[P_D11] = dot(e31, e31);
  pre[P_INV_DENOM] = 1.0 / (pre[P_D00] * pre[P_D11] - pre[P_D01] * pre[P_D01]);
  pre[P_L21] = sqlen(e21);
  pre[P_L32] = sqlen(e32);
  pre[P_L13] = sqlen(e13);
}

inline bool outside_bounds(const double *lo, const double *hi, const double *p, double r)
{
  return p[0] <= lo[0] - r || p[1] <= lo[1] - r || p[2] <= lo[2] - r || p[0] >= hi[0] + r ||
      p[1] >= hi[1] + r || p[2] >= hi[2] + r;
}

int sphere_triangle(const double *v, const double *n, const double *lo, const double *hi,
                    const double *pre, const double *p, double r, double *cp)
{
  if (outside_bounds(lo, hi, p, r)) return FixMusenWallMesh::NO_CONTACT;
  const double *v1 = v, *v2 = v + 3, *v3 = v + 6;
  const double *centre = pre + P_CENTRE;
  double d[3];
  for (int k = 0; k < 3; k++) d[k] = p[k] - centre[k];
  const double ppd = dot(d, n);
  if (std::fabs(ppd) >= r) return FixMusenWallMesh::NO_CONTACT;
  double A[3], W[3], e21[3], e31[3], e32[3], e13[3];
  for (int k = 0; k < 3; k++) A[k] = p[k] - n[k] * ppd;
  triangle_edges(v, e21, e31, e32, e13);
  for (int k = 0; k < 3; k++) W[k] = A[k] - v1[k];
  const double d00 = pre[P_D00], d01 = pre[P_D01], d11 = pre[P_D11];
  const double d20 = dot(W, e21), d21 = dot(W, e31);
  const double inv_denom = pre[P_INV_DENOM];
  const double gamma = (d11 * d20 - d01 * d21) * inv_denom;
  const double betta = (d00 * d21 - d01 * d20) * inv_denom;
  const double alpha = 1.0 - gamma - betta;
  if ((gamma > 0 && gamma < 1) && (alpha > 0 && alpha < 1) && (betta > 0 && betta < 1)) {
    for (int k = 0; k < 3; k++) cp[k] = A[k];
    return FixMusenWallMesh::FACE_CONTACT;
  }
  // projection outside the triangle: nearest of the closest points on the three edges
  double t[3];
  for (int k = 0; k < 3; k++) t[k] = A[k] - v1[k];
  const double lc1 = std::min(std::max(dot(t, e21) / pre[P_L21], 0.), 1.);
  for (int k = 0; k < 3; k++) t[k] = A[k] - v2[k];
  const double lc2 = std::min(std::max(dot(t, e32) / pre[P_L32], 0.), 1.);
  for (int k = 0; k < 3; k++) t[k] = A[k] - v3[k];
  const double lc3 = std::min(std::max(dot(t, e13) / pre[P_L13], 0.), 1.);
  double C1[3], C2[3], C3[3], q[3];
  for (int k = 0; k < 3; k++) {
    C1[k] = v1[k] + lc1 * e21[k];
    C2[k] = v2[k] + lc2 * e32[k];
    C3[k] = v3[k] + lc3 * e13[k];
  }
  for (int k = 0; k < 3; k++) q[k] = C1[k] - p[k];
  const double s1 = sqlen(q);
  for (int k = 0; k < 3; k++) q[k] = C2[k] - p[k];
  const double s2 = sqlen(q);
  for (int k = 0; k < 3; k++) q[k] = C3[k] - p[k];
  const double s3 = sqlen(q);
  if (std::min({s1, s2, s3}) >= r * r) return FixMusenWallMesh::NO_CONTACT;
  const double *C;
  double lc;
  if (s1 <= s2 && s1 <= s3) {
    C = C1;
    lc = lc1;
  } else if (s2 <= s3) {
    C = C2;
    lc = lc2;
  } else {
    C = C3;
    lc = lc3;
  }
  for (int k = 0; k < 3; k++) cp[k] = C[k];
  return (lc == 0 || lc == 1) ? FixMusenWallMesh::VERTEX_CONTACT : FixMusenWallMesh::EDGE_CONTACT;
}

// ---- FILE reading: whitespace tokens with their line numbers, '#' comments
struct Tokens {
  std::vector<std::string> tok;
  std::vector<int> line;
  size_t pos = 0;
  std::string file;
  Error *error;

  Tokens(const std::string &text, const std::string &f, Error *e) : file(f), error(e)
  {
    std::istringstream in(text);
    std::string ln;
    int no = 0;
    while (std::getline(in, ln)) {
      no++;
      const auto hash = ln.find('#');
      if (hash != std::string::npos) ln.erase(hash);
      std::istringstream words(ln);
      std::string w;
      while (words >> w) {
        tok.push_back(w);
        line.push_back(no);
      }
    }
  }
  [[noreturn]] void fail(const std::string &what)
  {
    if (pos < tok.size())
      error->all(FLERR, "Fix musen/wall/mesh: {} line {}: {} (found '{}')", file, line[pos], what,
                 tok[pos]);
    error->all(FLERR, "Fix musen/wall/mesh: {}: {} (the file ends early)", file, what);
    std::abort();    // not reached
  }
  const std::string &word(const std::string &what)
  {
    if (pos >= tok.size()) fail(what);
    return tok[pos++];
  }
  bool next_is(const char *kw) const { return pos < tok.size() && tok[pos] == kw; }
  void expect(const char *kw)
  {
    if (pos >= tok.size() || tok[pos] != kw) fail(std::string("expected '") + kw + "'");
    pos++;
  }
  double number(const std::string &what)
  {
    if (pos >= tok.size()) fail(what);
    const char *s = tok[pos].c_str();
    char *end = nullptr;
    const double v = strtod(s, &end);
    if (end == s || *end != '\0' || std::isnan(v)) fail(what + ": not a number");
    pos++;
    return v;
  }
  double finite(const std::string &what)
  {
    const double v = number(what);
    if (!std::isfinite(v)) {
      pos--;
      fail(what + ": must be finite");
    }
    return v;
  }
  long integer(const std::string &what, long lo, long hi)
  {
    if (pos >= tok.size()) fail(what);
    const char *s = tok[pos].c_str();
    char *end = nullptr;
    const long v = strtol(s, &end, 10);
    if (end == s || *end != '\0') fail(what + ": not an integer");
    if (v < lo || v > hi) fail(what + fmt::format(": must be in [{}, {}]", lo, hi));
    pos++;
    return v;
  }
};

}    // namespace

bool FixMusenWallMesh::Interval::moves() const
{
  return !is_zero(v) || !is_zero(w);
}

/* ---------------------------------------------------------------------- */

FixMusenWallMesh::FixMusenWallMesh(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), ntri(0), ngeom(0), nmat(0), any_moving(false), t_placed(0.0),
    placed(false), reduced_step(-1), reduced_valid(false), history(nullptr), grid_valid(false),
    grid_cell(0.0), grid_rmax(0.0), grid_margin(0.0)
{
  const char *usage = "fix ID group musen/wall/mesh FILE [law NAME [parameters]] ...";
  if (narg < 4 || narg == 5 || (narg > 4 && strcmp(arg[4], "law") != 0))
    error->all(FLERR, "Illegal fix musen/wall/mesh command: {}", usage);
  file = arg[3];
  // the particle-wall laws in the order they act (MUSEN's ModelPWHertzMindlin unless named):
  // cmusen runs every selected PW model on each contact in turn (CPUSimulator.cpp
  // CalculateForcesPW), forces add and a law continues the history the previous one left
  int a = 4;
  while (a < narg || pw_laws.empty()) {
    std::string law_name = "hertz/mindlin";
    std::vector<double> law_params;
    if (a < narg) {
      if (++a == narg) error->all(FLERR, "Illegal fix musen/wall/mesh command: {}", usage);
      law_name = arg[a++];
      for (; a < narg && strcmp(arg[a], "law") != 0; a++)
        law_params.push_back(utils::numeric(FLERR, arg[a], false, lmp));
    }
    std::string why;
    auto law = musen_pw::create(law_name, law_params, why);
    if (!law) error->all(FLERR, "Fix musen/wall/mesh: {}", why);
    pw_laws.push_back(std::move(law));
  }
  if (domain->dimension != 3) error->all(FLERR, "Fix musen/wall/mesh needs a 3d simulation");
  if (domain->triclinic) error->all(FLERR, "Fix musen/wall/mesh needs an orthogonal box");
  read_file();

  array_flag = 1;
  size_array_rows = ntri;
  size_array_cols = 12;
  vector_flag = 1;
  size_vector = 3 * ngeom;
  global_freq = 1;
  restart_global = 1;
  extarray = 0;
  extvector = 0;
  history_id = std::string(id) + "_HISTORY";
  for (int k = 0; k < 3; k++) grid_lo[k] = grid_sublo[k] = grid_subhi[k] = 0.0;
  for (int k = 0; k < 3; k++) grid_n[k] = 0;
}

FixMusenWallMesh::~FixMusenWallMesh()
{
  if (copymode) return;
  if (modify && modify->get_fix_by_id(history_id)) modify->delete_fix(history_id);
}

int FixMusenWallMesh::setmask()
{
  return POST_FORCE;
}

void FixMusenWallMesh::post_constructor()
{
  // the tangential overlap of every (sphere, triangle) contact: 3 values per entry
  modify->add_fix(fmt::format("{} {} MUSEN/HISTORY 3", history_id, group->names[igroup]));
  history = dynamic_cast<FixMusenHistory *>(modify->get_fix_by_id(history_id));
  if (!history) error->all(FLERR, "Fix musen/wall/mesh: could not create its history fix");
}

/* ---------------------------------------------------------------------- */

void FixMusenWallMesh::read_file()
{
  std::string text;
  int ok = 1;
  if (comm->me == 0) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      ok = 0;
    } else {
      std::ostringstream ss;
      ss << in.rdbuf();
      text = ss.str();
    }
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, world);
  if (!ok) error->all(FLERR, "Fix musen/wall/mesh: cannot open file {}", file);
  long len = static_cast<long>(text.size());
  MPI_Bcast(&len, 1, MPI_LONG, 0, world);
  text.resize(len);
  if (len) MPI_Bcast(&text[0], static_cast<int>(len), MPI_CHAR, 0, world);
  parse(text);
  find_adjacent();
}

void FixMusenWallMesh::parse(const std::string &text)
{
  Tokens in(text, file, error);
  in.expect("musen/wall/mesh");
  in.integer("format version", 1, 1);

  const int ntypes = atom->ntypes;
  in.expect("laws");
  const long nlaw = in.integer("number of laws", 0, 1L << 30);
  struct RawLaw {
    int type, mat;
    double estar, gstar, e, mu, mur;
  };
  std::vector<RawLaw> raw;
  for (long l = 0; l < nlaw; l++) {
    RawLaw r{};
    r.type = static_cast<int>(in.integer("law: atom type", 1, ntypes));
    r.mat = static_cast<int>(in.integer("law: wall material", 0, 1L << 20));
    r.estar = in.finite("law: E*");
    r.gstar = in.finite("law: G*");
    r.e = in.finite("law: restitution coefficient");
    r.mu = in.finite("law: sliding friction");
    r.mur = in.finite("law: rolling friction");
    if (!(r.estar > 0))
      error->all(FLERR, "Fix musen/wall/mesh: {}: law for type {} / wall material {}: E* must be > 0", file, r.type, r.mat);
    if (!(r.gstar >= 0))
      error->all(FLERR, "Fix musen/wall/mesh: {}: law for type {} / wall material {}: G* must be >= 0", file, r.type, r.mat);
    if (!(r.e > 0 && r.e <= 1))
      error->all(FLERR, "Fix musen/wall/mesh: {}: law for type {} / wall material {}: restitution must be in (0, 1]", file, r.type, r.mat);
    if (r.mu < 0 || r.mur < 0)
      error->all(FLERR, "Fix musen/wall/mesh: {}: law for type {} / wall material {}: friction coefficients must be >= 0", file, r.type, r.mat);
    nmat = std::max(nmat, r.mat + 1);
    raw.push_back(r);
  }

  in.expect("geometries");
  ngeom = static_cast<int>(in.integer("number of geometries", 0, 1L << 30));
  geoms.resize(ngeom);
  for (int g = 0; g < ngeom; g++) {
    Geometry &G = geoms[g];
    in.expect("geometry");
    G.name = in.word("geometry name");
    G.around_centre = in.integer("rotate-around-centre flag", 0, 1) != 0;
    const long nseg = in.integer("number of motion segments", 0, 1L << 30);
    const long nint = in.integer("number of motion intervals", 0, 1L << 30);
    G.rotating = false;
    for (long s = 0; s < nseg; s++) {
      Segment S{};
      in.expect("seg");
      S.t0 = in.finite("segment start");
      S.t1 = in.number("segment end");
      S.w = in.finite("segment |omega|");
      for (int k = 0; k < 3; k++) in.finite("segment axis");
      for (int a = 0; a < 4; a++)
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++) S.kr[a][i][j] = in.finite("segment rotation coefficient");
      for (int a = 0; a < 4; a++)
        for (int i = 0; i < 3; i++) S.kb[a][i] = in.finite("segment translation coefficient");
      if (!(S.t1 > S.t0)) error->all(FLERR, "Fix musen/wall/mesh: {}: geometry {}: a segment ends before it starts", file, G.name);
      if (!G.segments.empty() && S.t0 < G.segments.back().t1)
        error->all(FLERR, "Fix musen/wall/mesh: {}: geometry {}: segments overlap or are not in time order", file, G.name);
      if (S.w != 0) G.rotating = true;
      G.segments.push_back(S);
    }
    for (long s = 0; s < nint; s++) {
      Interval I{};
      in.expect("int");
      I.tb = in.finite("interval start");
      I.te = in.number("interval end");
      for (int k = 0; k < 3; k++) I.v[k] = in.finite("interval velocity");
      for (int k = 0; k < 3; k++) I.c[k] = in.finite("interval rotation centre");
      for (int k = 0; k < 3; k++) I.w[k] = in.finite("interval rotation velocity");
      if (!G.intervals.empty() && I.tb < G.intervals.back().tb)
        error->all(FLERR, "Fix musen/wall/mesh: {}: geometry {}: motion intervals are not sorted by their start", file, G.name);
      G.intervals.push_back(I);
    }
    if (in.next_is("force")) {
      in.expect("force");
      G.stepped = true;
      G.motion_kind = static_cast<int>(in.integer("motion type", 1, 3));
      const long nf = in.integer("number of force intervals", 0, 1L << 30);
      for (long s = 0; s < nf; s++) {
        ForceInterval F{};
        in.expect("fint");
        F.limit = in.finite("force limit");
        F.max = in.integer("force limit type (0 MIN, 1 MAX)", 0, 1) != 0;
        for (int k = 0; k < 3; k++) F.v[k] = in.finite("force interval velocity");
        for (int k = 0; k < 3; k++) F.c[k] = in.finite("force interval rotation centre");
        for (int k = 0; k < 3; k++) F.w[k] = in.finite("force interval rotation velocity");
        G.fints.push_back(F);
      }
      if (G.motion_kind != 1 && G.fints.empty())
        error->all(FLERR, "Fix musen/wall/mesh: {}: geometry {}: force-dependent motion without intervals", file, G.name);
    }
    if (in.next_is("free")) {
      in.expect("free");
      G.stepped = true;
      for (int k = 0; k < 3; k++) G.free_axis[k] = in.integer("free-motion flag", 0, 1) != 0;
      G.mass = in.finite("geometry mass");
    }
    if (G.stepped && in.next_is("velocity")) {
      in.expect("velocity");
      for (int k = 0; k < 3; k++) G.start_vel[k] = in.finite("start velocity");
    }
    if (G.stepped) {
      if (!G.segments.empty())
        error->all(FLERR, "Fix musen/wall/mesh: {}: geometry {}: a stepped geometry has no segments", file, G.name);
      any_stepped = true;
    }
    if (!G.segments.empty() || G.stepped) any_moving = true;
    for (int k = 0; k < 3; k++) G.rotvel[k] = G.rotcentre[k] = 0.0;
    for (int k = 0; k < 3; k++) G.vel[k] = G.start_vel[k];    // MUSEN: the walls' stored velocity
  }
  if (in.next_is("gravity")) {
    in.expect("gravity");
    for (int k = 0; k < 3; k++) gravity[k] = in.finite("gravity");
  }

  in.expect("triangles");
  ntri = static_cast<int>(in.integer("number of triangles", 1, (1L << 31) / NSHIFT - 1));
  x0.resize(9 * (size_t) ntri);
  tgeom.resize(ntri);
  tmat.resize(ntri);
  for (int t = 0; t < ntri; t++) {
    tgeom[t] = static_cast<int>(in.integer("triangle geometry", 0, ngeom - 1));
    tmat[t] = static_cast<int>(in.integer("triangle material", 0, 1L << 20));
    for (int k = 0; k < 9; k++) x0[9 * (size_t) t + k] = in.finite("triangle vertex coordinate");
    geoms[tgeom[t]].tris.push_back(t);
    nmat = std::max(nmat, tmat[t] + 1);
  }
  if (in.pos != in.tok.size()) in.fail("unexpected text after the triangles");

  laws.assign((size_t) (ntypes + 1) * nmat, Law{false, 0, 0, 0, 0, 0});
  for (const auto &r : raw) {
    Law &L = laws[(size_t) r.type * nmat + r.mat];
    L.set = true;
    L.estar = r.estar;
    L.gstar = r.gstar;
    // SimplifiedScene.cpp CalculateInteractionProperty: dAlpha (negative for e < 1)
    L.alpha = std::log(r.e) / std::sqrt(MUSEN_PI * MUSEN_PI + std::pow(std::log(r.e), 2));
    L.mu = r.mu;
    L.mur = r.mur;
  }

  vert = x0;
  nrm.resize(3 * (size_t) ntri);
  tlo.resize(3 * (size_t) ntri);
  thi.resize(3 * (size_t) ntri);
  for (int t = 0; t < ntri; t++) {
    const double *v = &vert[9 * (size_t) t];
    double c[3];
    face_cross(v, c);
    const double len = std::sqrt(sqlen(c));
    if (!(len > 0))
      error->all(FLERR, "Fix musen/wall/mesh: {}: triangle {} has zero area", file, t + 1);
    for (int k = 0; k < 3; k++) nrm[3 * (size_t) t + k] = c[k] / len;
    face_bounds(v, &tlo[3 * (size_t) t], &thi[3 * (size_t) t]);
  }
  tpre.assign(NPRE * (size_t) ntri, 0.0);
  tpre_stamp.assign(ntri, -1);
  tpre_epoch = 0;
  ftri.assign(3 * (size_t) ntri, 0.0);
  ftri_all.assign(3 * (size_t) ntri, 0.0);
  fgeom_all.assign(3 * (size_t) ngeom, 0.0);
}

/* Triangles of one geometry sharing a vertex (squared distance < 1e-18), at the initial
   positions: MUSEN's SimplifiedScene::FindAdjacentWalls.  Sorted by x, so each vertex is
   compared with the few whose x is within 1e-9 (the same pairs as MUSEN's all-pairs loop). */
void FixMusenWallMesh::find_adjacent()
{
  std::vector<std::vector<int>> nb(ntri);
  struct P {
    double x[3];
    int tri;
  };
  for (const auto &G : geoms) {
    std::vector<P> pts;
    pts.reserve(3 * G.tris.size());
    for (int t : G.tris)
      for (int a = 0; a < 3; a++) {
        P p;
        for (int k = 0; k < 3; k++) p.x[k] = x0[9 * (size_t) t + 3 * a + k];
        p.tri = t;
        pts.push_back(p);
      }
    std::sort(pts.begin(), pts.end(), [](const P &a, const P &b) { return a.x[0] < b.x[0]; });
    for (size_t i = 0; i < pts.size(); i++)
      for (size_t j = i + 1; j < pts.size(); j++) {
        const double dx = pts[j].x[0] - pts[i].x[0];
        if (!(dx * dx < 1e-18)) break;
        if (pts[i].tri == pts[j].tri) continue;
        double d[3];
        for (int k = 0; k < 3; k++) d[k] = pts[i].x[k] - pts[j].x[k];
        if (sqlen(d) < 1e-18) {
          nb[pts[i].tri].push_back(pts[j].tri);
          nb[pts[j].tri].push_back(pts[i].tri);
        }
      }
  }
  adj_start.assign(ntri + 1, 0);
  adj.clear();
  for (int t = 0; t < ntri; t++) {
    auto &l = nb[t];
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    adj_start[t] = static_cast<int>(adj.size());
    adj.insert(adj.end(), l.begin(), l.end());
  }
  adj_start[ntri] = static_cast<int>(adj.size());
}

/* ---------------------------------------------------------------------- */

void FixMusenWallMesh::init()
{
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "Fix musen/wall/mesh needs per-atom radius, rmass, omega and torque (atom_style sphere or bpm/sphere)");
  if (!history) error->all(FLERR, "Fix musen/wall/mesh: its history fix is missing");
  clock = nullptr;
  for (const auto &fix : modify->get_fix_list()) {
    auto *leapfrog = dynamic_cast<FixMusenLeapfrog *>(fix);
    if (leapfrog && leapfrog->variable_step()) clock = leapfrog;
  }
  heat_fix = nullptr;
  for (const auto &law : pw_laws)
    if (law->heats()) {
      const auto heats = modify->get_fix_by_style("^musen/heat$");
      if (heats.size() != 1)
        error->all(FLERR, "Fix musen/wall/mesh: its heat law needs one fix musen/heat (found {})",
                   heats.size());
      heat_fix = heats[0];
    }
  // every sphere type in the group needs a law with every wall material in use
  std::vector<char> used(nmat, 0);
  for (int t = 0; t < ntri; t++) used[tmat[t]] = 1;
  int bad_type = 0, bad_mat = -1;
  for (int i = 0; i < atom->nlocal && !bad_type; i++) {
    if (!(atom->mask[i] & groupbit)) continue;
    for (int m = 0; m < nmat; m++)
      if (used[m] && !laws[(size_t) atom->type[i] * nmat + m].set) {
        bad_type = atom->type[i];
        bad_mat = m;
        break;
      }
  }
  int any = 0;
  MPI_Allreduce(&bad_type, &any, 1, MPI_INT, MPI_MAX, world);
  if (any) {
    int m = -1;
    MPI_Allreduce(&bad_mat, &m, 1, MPI_INT, MPI_MAX, world);
    error->all(FLERR, "Fix musen/wall/mesh: {} has no law for atom type {} and wall material {}",
               file, any, m);
  }
  grid_valid = false;
}

void FixMusenWallMesh::setup(int vflag)
{
  if (any_stepped && !started) {
    // MUSEN's prediction iteration: its forces with the walls where and as they start, then
    // MoveWalls from those wall forces (CBaseSimulator::StartSimulation)
    start_vert = vert;    // a frame before the first step shows them here (MUSEN saves first)
    post_force(vflag);
    step_walls(current_time(), update->dt);
    started = true;
    pending = false;
    at_start = true;
    return;
  }
  // a set-up that is MUSEN's first step (musen_startup.h) counts as a time step; another
  // set-up at the step of a time step (run 0 after a checkpoint, a resumed run) adds the wall
  // forces to the atoms again but keeps the triangle forces of that step, which an
  // uninterrupted run writes in its next frame
  if (musen_startup::advances(update) || ftri_step != update->ntimestep) {
    if (any_stepped && ftri_step != update->ntimestep) pending = true;
    post_force(vflag);
    return;
  }
  std::vector<double> kept(ftri);
  post_force(vflag);
  ftri.swap(kept);
  reduced_valid = false;
}

double FixMusenWallMesh::current_time() const
{
  return simulation_time(update);
}

/* Triangle positions at time t: x = R(t) x0 + b(t) per moving geometry (the solution of
   MUSEN's motion equation dx/dt = v + w x (x - c) that fibrelmp's frames report). */
void FixMusenWallMesh::place(double t)
{
  if (placed && t == t_placed) return;
  for (auto &G : geoms) {
    if (G.segments.empty()) continue;
    double R[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, b[3] = {0, 0, 0};
    if (t >= G.segments.front().t0) {
      const Segment *S = &G.segments.back();
      for (const auto &s : G.segments)
        if (s.t0 <= t && t < s.t1) {
          S = &s;
          break;
        }
      const double tau = t - S->t0;
      double e[4];
      e[0] = 1.0;
      e[1] = tau;
      if (S->w == 0) {
        e[2] = 1.0;
        e[3] = 0.0;
      } else {
        e[2] = std::cos(S->w * tau);
        e[3] = std::sin(S->w * tau);
      }
      for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
          R[i][j] = e[0] * S->kr[0][i][j] + e[1] * S->kr[1][i][j] + e[2] * S->kr[2][i][j] +
              e[3] * S->kr[3][i][j];
        b[i] = e[0] * S->kb[0][i] + e[1] * S->kb[1][i] + e[2] * S->kb[2][i] + e[3] * S->kb[3][i];
      }
    }
    for (int tr : G.tris) {
      const double *p0 = &x0[9 * (size_t) tr];
      double *p = &vert[9 * (size_t) tr];
      for (int a = 0; a < 3; a++)
        for (int i = 0; i < 3; i++)
          p[3 * a + i] = p0[3 * a] * R[i][0] + p0[3 * a + 1] * R[i][1] + p0[3 * a + 2] * R[i][2] + b[i];
      if (G.rotating) {    // MUSEN recomputes normals only while a geometry rotates
        double c[3];
        face_cross(p, c);
        const double len = std::sqrt(sqlen(c));
        for (int k = 0; k < 3; k++) nrm[3 * (size_t) tr + k] = c[k] / len;
      }
      face_bounds(p, &tlo[3 * (size_t) tr], &thi[3 * (size_t) tr]);
    }
  }
  t_placed = t;
  placed = true;
}

/* The wall motion MUSEN's contact law sees at time t (CPUSimulator::MoveWalls with
   CGeometryMotion::UpdateMotionInfo): the interval with t_begin <= t <= t_end; when that
   interval does not move the geometry (or there is none), MoveWalls skips the geometry and
   its walls keep the velocity, rotation velocity and centre they last had. */
void FixMusenWallMesh::motion_state(double t)
{
  for (auto &G : geoms) {
    if (G.stepped) continue;    // step_walls keeps its motion
    const Interval *cur = nullptr;
    for (const auto &I : G.intervals)
      if (I.tb <= t && t <= I.te) {
        cur = &I;
        break;
      }
    if (!cur || !cur->moves()) {
      cur = nullptr;
      for (const auto &I : G.intervals)
        if (I.tb <= t && I.moves()) cur = &I;     // the last one that moved it
    }
    if (!cur) {
      for (int k = 0; k < 3; k++) G.vel[k] = G.rotvel[k] = G.rotcentre[k] = 0.0;
      continue;
    }
    for (int k = 0; k < 3; k++) {
      G.vel[k] = cur->v[k];
      G.rotvel[k] = cur->w[k];
      G.rotcentre[k] = cur->c[k];
    }
    if (G.around_centre) {
      // area-weighted centroid of the triangles now (MoveWalls, RotateAroundCenter)
      double area_sum = 0.0, wc[3] = {0, 0, 0};
      for (int tr : G.tris) {
        const double *p = &vert[9 * (size_t) tr];
        double c[3];
        face_cross(p, c);
        const double area = 0.5 * std::sqrt(sqlen(c));
        area_sum += area;
        for (int k = 0; k < 3; k++) wc[k] += area * ((p[k] + p[3 + k] + p[6 + k]) / 3.);
      }
      for (int k = 0; k < 3; k++) G.rotcentre[k] = area_sum != 0.0 ? wc[k] / area_sum : 0.0;
    }
  }
}

/* ---------------------------------------------------------------------- */

int FixMusenWallMesh::shift_code(int sx, int sy, int sz)
{
  return ((sx + 1) + 3 * (sy + 1) + 9 * (sz + 1) + 14) % NSHIFT;    // no shift -> 0
}

void FixMusenWallMesh::shift_vector(int code, double *s) const
{
  const int raw = (code + 13) % NSHIFT;
  const int sx = raw % 3 - 1, sy = (raw / 3) % 3 - 1, sz = raw / 9 - 1;
  s[0] = sx * domain->prd[0];
  s[1] = sy * domain->prd[1];
  s[2] = sz * domain->prd[2];
}

bool FixMusenWallMesh::grid_stale(double rmax)
{
  if (!grid_valid || rmax > grid_rmax) return true;
  for (int k = 0; k < 3; k++)
    if (domain->sublo[k] != grid_sublo[k] || domain->subhi[k] != grid_subhi[k]) return true;
  if (any_moving) {
    double most = 0.0;
    for (size_t k = 0; k < vert.size(); k++) most = std::max(most, std::fabs(vert[k] - grid_vert[k]));
    if (most * std::sqrt(3.0) > grid_margin) return true;
  }
  return false;
}

/* Cells over this rank's sub-domain (plus the neighbour skin, how far owned spheres drift
   between re-neighbourings), each listing the triangles (and periodic images of triangles)
   that come within rmax + margin of it, in MUSEN's order: triangles in FILE order, their
   images after them.  A sphere off the grid tests every entry. */
void FixMusenWallMesh::build_grid(double rmax)
{
  grid_rmax = rmax;
  grid_margin = std::max(0.5 * rmax, 1e-300);
  const double reach = grid_rmax + grid_margin;
  const double pad = neighbor->skin + reach;
  double lo[3], hi[3];
  for (int k = 0; k < 3; k++) {
    grid_sublo[k] = domain->sublo[k];
    grid_subhi[k] = domain->subhi[k];
    lo[k] = domain->sublo[k] - pad;
    hi[k] = domain->subhi[k] + pad;
  }
  double cs = std::max(reach, 1e-300);
  const double cap = std::max<double>(GRID_CELL_CAP_MIN, 4.0 * atom->nlocal);
  for (int it = 0; it < 200; it++) {
    double cells = 1.0;
    for (int k = 0; k < 3; k++) cells *= std::max(1.0, std::ceil((hi[k] - lo[k]) / cs));
    if (cells <= cap) break;
    cs *= std::max(1.01, std::cbrt(cells / cap));
  }
  grid_cell = cs;
  for (int k = 0; k < 3; k++) {
    grid_lo[k] = lo[k];
    grid_n[k] = static_cast<int>(std::max(1.0, std::ceil((hi[k] - lo[k]) / cs)));
  }
  const size_t ncell = (size_t) grid_n[0] * grid_n[1] * grid_n[2];

  // shifts: periodic axes only
  std::vector<int> codes{0};
  const int per[3] = {domain->xperiodic, domain->yperiodic, domain->zperiodic};
  for (int sz = -1; sz <= 1; sz++)
    for (int sy = -1; sy <= 1; sy++)
      for (int sx = -1; sx <= 1; sx++) {
        if (!sx && !sy && !sz) continue;
        if ((sx && !per[0]) || (sy && !per[1]) || (sz && !per[2])) continue;
        codes.push_back(shift_code(sx, sy, sz));
      }
  std::sort(codes.begin() + 1, codes.end());

  const double half_diag = 0.5 * std::sqrt(3.0) * cs;
  auto for_cells = [&](int tr, int code, auto &&visit) {
    double s[3];
    shift_vector(code, s);
    int c0[3], c1[3];
    for (int k = 0; k < 3; k++) {
      const double a = tlo[3 * (size_t) tr + k] + s[k] - reach - grid_lo[k];
      const double b = thi[3 * (size_t) tr + k] + s[k] + reach - grid_lo[k];
      if (b < 0 || a > grid_n[k] * cs) return false;
      c0[k] = std::max(0, static_cast<int>(std::floor(a / cs)));
      c1[k] = std::min(grid_n[k] - 1, static_cast<int>(std::floor(b / cs)));
      if (c1[k] < c0[k]) return false;
    }
    const double *n = &nrm[3 * (size_t) tr];
    const double *v1 = &vert[9 * (size_t) tr];
    bool any = false;
    for (int iz = c0[2]; iz <= c1[2]; iz++)
      for (int iy = c0[1]; iy <= c1[1]; iy++)
        for (int ix = c0[0]; ix <= c1[0]; ix++) {
          const double cc[3] = {grid_lo[0] + (ix + 0.5) * cs, grid_lo[1] + (iy + 0.5) * cs,
                                grid_lo[2] + (iz + 0.5) * cs};
          double d[3];
          for (int k = 0; k < 3; k++) d[k] = cc[k] - (v1[k] + s[k]);
          if (std::fabs(dot(d, n)) > half_diag + reach + grid_margin) continue;    // far from the plane
          visit(((size_t) iz * grid_n[1] + iy) * grid_n[0] + ix);
          any = true;
        }
    return any;
  };
  cell_start.assign(ncell + 1, 0);
  for (int code : codes)
    for (int tr = 0; tr < ntri; tr++) for_cells(tr, code, [&](size_t c) { cell_start[c + 1]++; });
  for (size_t c = 0; c < ncell; c++) cell_start[c + 1] += cell_start[c];
  cell_entries.assign(cell_start[ncell], 0);
  std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
  for (int code : codes)
    for (int tr = 0; tr < ntri; tr++)
      for_cells(tr, code, [&](size_t c) { cell_entries[fill[c]++] = tr * NSHIFT + code; });
  all_entries.clear();
  for (int code : codes)
    for (int tr = 0; tr < ntri; tr++) all_entries.push_back(tr * NSHIFT + code);
  grid_vert = vert;
  grid_valid = true;
  grid_stamp++;
}

/* The grid entries a sphere at x tests: its cell's, or every entry off the grid. */
const int *FixMusenWallMesh::entries_of(const double *x, int &nent) const
{
  int c[3];
  for (int k = 0; k < 3; k++) {
    const double u = (x[k] - grid_lo[k]) / grid_cell;
    if (!(u >= 0) || u >= grid_n[k]) {
      nent = static_cast<int>(all_entries.size());
      return all_entries.data();
    }
    c[k] = std::min(grid_n[k] - 1, static_cast<int>(u));
  }
  const size_t cell = ((size_t) c[2] * grid_n[1] + c[1]) * grid_n[0] + c[0];
  nent = cell_start[cell + 1] - cell_start[cell];
  return cell_entries.data() + cell_start[cell];
}

bool FixMusenWallMesh::near_lists_stale(int nlocal)
{
  // never made (near_stamp -1), or the grid, the atoms or their indices changed
  if (near_stamp != grid_stamp || near_nlocal != nlocal || neighbor->lastcall == update->ntimestep)
    return true;
  const double half_skin = 0.5 * neighbor->skin;
  const double limit = half_skin * half_skin;
  double **x = atom->x;
  const int *mask = atom->mask;
  const tagint *tag = atom->tag;
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double *x0 = &near_x[3 * (size_t) i];
    const double d[3] = {x[i][0] - x0[0], x[i][1] - x0[1], x[i][2] - x0[2]};
    if (!(sqlen(d) <= limit) || tag[i] != near_tag[i]) return true;    // NaN: stale too
  }
  return false;
}

/* Each sphere's entries that come within its radius + the skin: a sphere that moves less than
   half a skin cannot touch any other (sphere_triangle with the larger radius is the distance
   test: contact iff the triangle's nearest point is closer). */
void FixMusenWallMesh::build_near_lists(int nlocal)
{
  double **x = atom->x;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  const double skin = neighbor->skin;
  near_start.assign(nlocal + 1, 0);
  near_entries.clear();
  near_x.resize(3 * (size_t) nlocal);
  near_tag.assign(atom->tag, atom->tag + nlocal);
  double cp[3];
  for (int i = 0; i < nlocal; i++) {
    near_start[i] = static_cast<int>(near_entries.size());
    for (int k = 0; k < 3; k++) near_x[3 * (size_t) i + k] = x[i][k];
    if (!(mask[i] & groupbit)) continue;
    const double reach = radius[i] + skin;
    int nent;
    const int *ent = entries_of(x[i], nent);
    for (int e = 0; e < nent; e++) {
      const int tr = ent[e] / NSHIFT, code = ent[e] % NSHIFT;
      double s[3] = {0, 0, 0};
      if (code) shift_vector(code, s);
      const double xs[3] = {x[i][0] - s[0], x[i][1] - s[1], x[i][2] - s[2]};
      if (outside_bounds(&tlo[3 * (size_t) tr], &thi[3 * (size_t) tr], xs, reach)) continue;
      if (sphere_triangle(&vert[9 * (size_t) tr], &nrm[3 * (size_t) tr], &tlo[3 * (size_t) tr],
                          &thi[3 * (size_t) tr], constants_of(tr), xs, reach, cp) == NO_CONTACT)
        continue;
      near_entries.push_back(ent[e]);
    }
  }
  near_start[nlocal] = static_cast<int>(near_entries.size());
  near_stamp = grid_stamp;
  near_nlocal = nlocal;
}

/* ---------------------------------------------------------------------- */

const double *FixMusenWallMesh::constants_of(int tr)
{
  if (tpre_stamp[tr] != tpre_epoch) {
    triangle_constants(&vert[9 * (size_t) tr], &tpre[NPRE * (size_t) tr]);
    tpre_stamp[tr] = tpre_epoch;
  }
  return &tpre[NPRE * (size_t) tr];
}

void FixMusenWallMesh::post_force(int /*vflag*/)
{
  // a time step first moves the stepped geometries by the previous step's wall forces
  if (any_stepped && pending && !update->setupflag) {
    if (clock)    // MoveWalls(dt before MoveParticles changed it), at the time before the step
      step_walls(clock->step_start_time(), clock->previous_dt());
    else
      step_walls(current_time() - update->dt, update->dt);
    pending = false;
  }
  at_start = false;
  contact_rec.clear();
  const double t = current_time();
  const bool placing = any_moving || !placed;
  if (placing) place(t);
  motion_state(t);
  // triangles just placed, or moved step by step (or restored), need their constants anew
  // (computed when first tested: a large moving mesh pays only for triangles near spheres);
  // a static mesh keeps the ones of its first placement
  if (placing || any_stepped) tpre_epoch++;

  double **x = atom->x, **f = atom->f, **torque = atom->torque;
  double *radius = atom->radius;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;

  double rmax = 0.0;
  for (int i = 0; i < nlocal; i++)
    if (mask[i] & groupbit) rmax = std::max(rmax, radius[i]);
  if (grid_stale(rmax)) build_grid(rmax);

  std::fill(ftri.begin(), ftri.end(), 0.0);
  reduced_valid = false;
  const double dt = update->dt;
  // time steps and MUSEN's two evaluations at t = 0 (musen_startup.h) advance the contacts;
  // other set-ups (run, run 0) leave them as they were
  const bool commit = musen_startup::advances(update);
  if (heat_fix) {
    int dim, flag, cols;
    heat_flux = static_cast<double *>(heat_fix->extract("flux", dim));
    heat_temperature = atom->dvector[atom->find_custom("musen_temperature", flag, cols)];
  }

  // a static mesh: the spheres' lists of nearby entries (made again when stale)
  const bool listed = !any_moving && !any_stepped;
  if (listed && near_lists_stale(nlocal)) build_near_lists(nlocal);

  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double r = radius[i];
    // --- candidates: the sphere's list, or this rank's cell of the sphere (every entry off
    // the grid)
    const int *ent;
    int nent;
    if (listed) {
      ent = near_entries.data() + near_start[i];
      nent = near_start[i + 1] - near_start[i];
      if (!nent && !history->count(i)) continue;
    } else {
      ent = entries_of(x[i], nent);
    }
    cand.clear();
    for (int e = 0; e < nent; e++) {
      Candidate cd;
      cd.tri = ent[e] / NSHIFT;
      cd.shift = ent[e] % NSHIFT;
      double s[3] = {0, 0, 0};
      if (cd.shift) shift_vector(cd.shift, s);
      for (int k = 0; k < 3; k++) cd.xs[k] = x[i][k] - s[k];
      const size_t tr = cd.tri;
      // the bounding box first: most candidates end there, before their constants are read
      if (outside_bounds(&tlo[3 * tr], &thi[3 * tr], cd.xs, r)) continue;
      cd.kind = sphere_triangle(&vert[9 * tr], &nrm[3 * tr], &tlo[3 * tr], &thi[3 * tr],
                                constants_of(cd.tri), cd.xs, r, cd.cp);
      if (cd.kind != NO_CONTACT) cand.push_back(cd);
    }
    const int nc = static_cast<int>(cand.size());
    if (nc > 1) {
      // one contact per flat patch (VerletList::GetPWContacts), in candidate order
      for (int a = 0; a < nc - 1; a++) {
        if (cand[a].kind == NO_CONTACT) continue;
        const double *na = &nrm[3 * (size_t) cand[a].tri];
        for (int b = a + 1; b < nc; b++) {
          if (cand[b].kind == NO_CONTACT) continue;
          const double *nb = &nrm[3 * (size_t) cand[b].tri];
          const double dn[3] = {na[0] - nb[0], na[1] - nb[1], na[2] - nb[2]};
          if (!(sqlen(dn) < 1e-6)) continue;
          switch (cand[a].kind) {
            case FACE_CONTACT:
              if (cand[b].kind == EDGE_CONTACT || cand[b].kind == VERTEX_CONTACT)
                cand[b].kind = NO_CONTACT;
              break;
            case EDGE_CONTACT:
              if (cand[b].kind == EDGE_CONTACT)
                cand[b].kind = NO_CONTACT;
              else if (cand[b].kind == FACE_CONTACT)
                cand[a].kind = NO_CONTACT;
              else
                cand[b].kind = NO_CONTACT;
              break;
            case VERTEX_CONTACT:
              cand[a].kind = NO_CONTACT;
              break;
            default:
              break;
          }
        }
      }
      // a triangle touched by the sphere itself is not touched by its periodic image too;
      // and one contact per triangle (two images reaching one triangle: the first counts)
      for (int a = 0; a < nc; a++) {
        if (cand[a].kind == NO_CONTACT) continue;
        for (int b = 0; b < nc; b++) {
          if (b == a || cand[b].kind == NO_CONTACT || cand[b].tri != cand[a].tri) continue;
          if ((cand[a].shift && !cand[b].shift) || (b < a && cand[a].shift && cand[b].shift)) {
            cand[a].kind = NO_CONTACT;
            break;
          }
        }
      }
    }

    // --- contacts and their tangential overlap (CollisionsCalculator::CheckPWCollisions), in
    // MUSEN's collision order: contacts that existed go first (in the order they were made),
    // new ones after them in candidate order; a new one starts from the overlap of a contact
    // that just ended on a triangle sharing a vertex with it, else from zero
    int nkept = 0;
    for (int a = 0; a < nc; a++)
      if (cand[a].kind != NO_CONTACT) nkept++;
    const int nold = history->count(i);
    if (!nkept && !nold) continue;
    order.clear();
    std::vector<char> &is_old = old_mark;
    is_old.assign(nc, 0);
    for (int s = 0; s < nold; s++) {
      const int tr = static_cast<int>(history->key(i, s));
      for (int a = 0; a < nc; a++)
        if (cand[a].kind != NO_CONTACT && cand[a].tri == tr) {
          Work w;
          w.cand = a;
          std::copy(history->values(i, s), history->values(i, s) + 3, w.xi);
          order.push_back(w);
          is_old[a] = 1;
          break;
        }
    }
    for (int a = 0; a < nc; a++) {
      if (cand[a].kind == NO_CONTACT || is_old[a]) continue;
      Work w;
      w.cand = a;
      w.xi[0] = w.xi[1] = w.xi[2] = 0.0;
      const int tn = cand[a].tri;
      for (int s = 0; s < nold; s++) {
        const int to = static_cast<int>(history->key(i, s));
        bool ended = true;
        for (int b = 0; b < nc; b++)
          if (cand[b].kind != NO_CONTACT && cand[b].tri == to) {
            ended = false;
            break;
          }
        if (!ended) continue;
        if (!std::binary_search(adj.begin() + adj_start[tn], adj.begin() + adj_start[tn + 1], to))
          continue;
        std::copy(history->values(i, s), history->values(i, s) + 3, w.xi);
        break;
      }
      order.push_back(w);
    }

    // --- forces (ModelPWHertzMindlin), summed in that order
    for (auto &w : order) {
      const Candidate &cd = cand[w.cand];
      double fo[3], to[3];
      wall_force(i, cd, w.xi, dt, fo, to);
      for (int k = 0; k < 3; k++) {
        f[i][k] += fo[k];
        torque[i][k] += to[k];
        ftri[3 * (size_t) cd.tri + k] -= fo[k];
      }
      const double rec[8] = {(double) atom->tag[i], (double) cd.tri + 1, cd.cp[0], cd.cp[1],
                             cd.cp[2], fo[0], fo[1], fo[2]};
      contact_rec.insert(contact_rec.end(), rec, rec + 8);
    }
    // a set-up force evaluation (run, run 0) leaves the contacts as they were: only time
    // steps advance them (as LAMMPS's own granular styles do)
    if (commit)
      for (const auto &w : order) {
        double *h = history->get(i, cand[w.cand].tri);
        std::copy(w.xi, w.xi + 3, h);
      }
  }
  if (commit) {
    history->sweep(nlocal);
    ftri_step = update->ntimestep;
    pending = any_stepped;
  }
}

/* MUSEN's CalculatePW for sphere i and one contact, up to the law (musen_pw_law.h): the
   contact's geometry and relative velocity; the laws, in turn, give force fo and torque to on
   the sphere (summed) and update hist, the contact's history (tangential overlap). */
void FixMusenWallMesh::wall_force(int i, const Candidate &cd, double *hist, double dt, double *fo,
                                  double *to)
{
  const int tr = cd.tri;
  const Geometry &G = geoms[tgeom[tr]];
  const Law &L = laws[(size_t) atom->type[i] * nmat + tmat[tr]];
  if (!L.set)
    error->one(FLERR, "Fix musen/wall/mesh: no law for atom type {} and wall material {}",
               atom->type[i], tmat[tr]);
  const double *xi = cd.xs;
  const double R = atom->radius[i];
  const double m = atom->rmass[i];
  const double *w_p = atom->omega[i];
  const double *n = &nrm[3 * (size_t) tr];
  const double *cp = cd.cp;
  for (int k = 0; k < 3; k++) fo[k] = to[k] = 0.0;

  double rc[3];
  for (int k = 0; k < 3; k++) rc[k] = xi[k] - cp[k];
  const double rc_len = std::sqrt(sqlen(rc));
  double rc_n[3];
  if (rc_len > 0) {
    for (int k = 0; k < 3; k++) rc_n[k] = rc[k] / rc_len;
  } else {
    // the centre is on the triangle (face, edge or vertex): MUSEN divides by the zero
    // distance and its results turn to nan; fibrelmp takes the face normal as the contact
    // direction (docs/granular.md) and warns once
    for (int k = 0; k < 3; k++) rc_n[k] = n[k];
    if (!warned_centre_on_wall) {
      warned_centre_on_wall = true;
      error->warning(FLERR, "Fix musen/wall/mesh: sphere {} has its centre exactly on wall "
                     "triangle {} at step {}: its contact direction is the triangle's normal "
                     "(MUSEN's results turn to nan here)", atom->tag[i], tr + 1,
                     update->ntimestep);
    }
  }
  const double overlap = R - rc_len;
  // MUSEN returns here and re-applies the collision's previous force; with one radius per
  // sphere (LAMMPS) a detected contact always has overlap >= 0
  if (overlap < 0) return;

  double rot_vel[3] = {0, 0, 0};
  if (!is_zero(G.rotvel)) {
    double arm[3];
    for (int k = 0; k < 3; k++) arm[k] = cp[k] - G.rotcentre[k];
    cross(arm, G.rotvel, rot_vel);
  }
  musen_pw::Contact c;
  c.radius = R;
  c.mass = m;
  c.overlap = overlap;
  c.normal = n;
  c.rc_n = rc_n;
  c.omega = w_p;
  for (int k = 0; k < 3; k++) c.vel[k] = atom->v[i][k] - G.vel[k] + rot_vel[k];
  c.dt = dt;
  const musen_pw::Materials mats{L.estar, L.gstar, L.alpha, L.mu, L.mur};
  pw_laws[0]->force(c, mats, hist, fo, to);
  for (std::size_t l = 1; l < pw_laws.size(); l++) {
    double fo_more[3], to_more[3];
    pw_laws[l]->force(c, mats, hist, fo_more, to_more);
    for (int k = 0; k < 3; k++) {
      fo[k] += fo_more[k];
      to[k] += to_more[k];
    }
  }
  // heat laws (ConsolidatePart: HeatFlux += the contact's), in the laws' order
  if (heat_fix) {
    c.temperature = heat_temperature[i];
    for (const auto &law : pw_laws)
      if (law->heats()) heat_flux[i] += law->heat(c);
  }
}

/* ---------------------------------------------------------------------- */

void FixMusenWallMesh::reduce_forces()
{
  if (reduced_valid && reduced_step == update->ntimestep) return;
  MPI_Allreduce(ftri.data(), ftri_all.data(), 3 * ntri, MPI_DOUBLE, MPI_SUM, world);
  std::fill(fgeom_all.begin(), fgeom_all.end(), 0.0);
  for (int t = 0; t < ntri; t++)
    for (int k = 0; k < 3; k++) fgeom_all[3 * (size_t) tgeom[t] + k] += ftri_all[3 * (size_t) t + k];
  reduced_valid = true;
  reduced_step = update->ntimestep;
}

double FixMusenWallMesh::compute_array(int i, int j)
{
  if (i < 0 || i >= ntri || j < 0 || j >= 12) return 0.0;
  if (j < 3) {
    reduce_forces();
    return ftri_all[3 * (size_t) i + j];
  }
  if (!placed) place(current_time());
  return vert[9 * (size_t) i + (j - 3)];
}

double FixMusenWallMesh::compute_vector(int i)
{
  if (i < 0 || i >= 3 * ngeom) return 0.0;
  reduce_forces();
  return fgeom_all[i];
}

/* fix_modify ID KEYWORD FILE [append yes|no]: rank 0 opens FILE (for appending with append
   yes) and write_body writes one dump frame into it; every rank learns whether that worked.
   Returns the words used. */
int FixMusenWallMesh::write_dump_frame(int narg, char **arg,
                                       const std::function<void(FILE *)> &write_body)
{
  if (narg < 2)
    error->all(FLERR, "Illegal fix_modify {} {} command: {} FILE [append yes|no]", id, arg[0], arg[0]);
  bool append = false;
  int used = 2;
  if (narg >= 4 && strcmp(arg[2], "append") == 0) {
    append = utils::logical(FLERR, arg[3], false, lmp) != 0;
    used = 4;
  }
  int ok = 1;
  if (comm->me == 0) {
    FILE *fp = fopen(arg[1], append ? "a" : "w");
    if (!fp) {
      ok = 0;
    } else {
      write_body(fp);
      if (fclose(fp) != 0) ok = 0;
    }
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, world);
  if (!ok) error->all(FLERR, "Fix musen/wall/mesh: cannot write {}", arg[1]);
  return used;
}

/* a dump frame's items up to its ATOMS (or ENTRIES: KIND) line: this step, N rows, the box */
void FixMusenWallMesh::dump_header(FILE *fp, const char *kind, size_t n) const
{
  fmt::print(fp, "ITEM: TIMESTEP\n{}\nITEM: NUMBER OF {}\n{}\nITEM: BOX BOUNDS ff ff ff\n",
             update->ntimestep, kind, n);
  for (int k = 0; k < 3; k++) fmt::print(fp, "{:.17g} {:.17g}\n", domain->boxlo[k], domain->boxhi[k]);
}

/* fix_modify ID contacts FILE [append yes|no]: the last evaluation's sphere-wall contacts as
   one local-dump frame (id tri cpx cpy cpz fx fy fz: the sphere, the triangle, the contact
   point, the force on the sphere), gathered on rank 0 (MUSEN's stress tensor) */
int FixMusenWallMesh::write_contacts(int narg, char **arg)
{
  int mine = static_cast<int>(contact_rec.size());
  std::vector<int> counts(comm->nprocs), displs(comm->nprocs, 0);
  MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  std::vector<double> all;
  if (comm->me == 0) {
    for (int p = 1; p < comm->nprocs; p++) displs[p] = displs[p - 1] + counts[p - 1];
    all.resize((size_t) displs[comm->nprocs - 1] + counts[comm->nprocs - 1]);
  }
  MPI_Gatherv(contact_rec.data(), mine, MPI_DOUBLE, all.data(), counts.data(), displs.data(),
              MPI_DOUBLE, 0, world);
  return write_dump_frame(narg, arg, [&](FILE *fp) {
    const size_t n = all.size() / 8;
    dump_header(fp, "ENTRIES", n);
    fputs("ITEM: ENTRIES id tri cpx cpy cpz fx fy fz\n", fp);
    for (size_t r = 0; r < n; r++) {
      const double *v = &all[8 * r];
      fprintf(fp, "%.0f %.0f %.17g %.17g %.17g %.17g %.17g %.17g\n", v[0], v[1], v[2], v[3], v[4],
              v[5], v[6], v[7]);
    }
  });
}

/* fix_modify ID write FILE [append yes|no]: one dump frame of the per-triangle forces */
int FixMusenWallMesh::modify_param(int narg, char **arg)
{
  if (strcmp(arg[0], "contacts") == 0) return write_contacts(narg, arg);
  if (strcmp(arg[0], "write") != 0) return 0;
  reduce_forces();
  return write_dump_frame(narg, arg, [&](FILE *fp) {
    dump_header(fp, "ATOMS", (size_t) ntri);
    fputs(any_stepped ? "ITEM: ATOMS id fx fy fz vx vy vz x1 y1 z1 x2 y2 z2 x3 y3 z3\n"
                      : "ITEM: ATOMS id fx fy fz\n", fp);
    for (int t = 0; t < ntri; t++) {
      fprintf(fp, "%d %.17g %.17g %.17g", t + 1, ftri_all[3 * (size_t) t],
              ftri_all[3 * (size_t) t + 1], ftri_all[3 * (size_t) t + 2]);
      if (any_stepped) {
        // before the first time step MUSEN's frame precedes its prediction update: the
        // walls where and as they started
        const bool first = at_start && !start_vert.empty();
        const double *gv = first ? geoms[tgeom[t]].start_vel : geoms[tgeom[t]].vel;
        const double *p = first ? &start_vert[9 * (size_t) t] : &vert[9 * (size_t) t];
        fprintf(fp, " %.17g %.17g %.17g", gv[0], gv[1], gv[2]);
        for (int k = 0; k < 9; k++) fprintf(fp, " %.17g", p[k]);
      }
      fputc('\n', fp);
    }
  });
}

/* the triangle forces of the last time step (restart files: a resumed run writes them in a
   frame taken right after its checkpoint); rank 0 writes and, on reading, holds the sums */
void FixMusenWallMesh::write_restart(FILE *fp)
{
  reduce_forces();
  if (comm->me != 0) return;
  std::vector<double> list;
  list.reserve(2 + ftri_all.size());
  list.push_back(static_cast<double>(ftri_step));
  list.push_back(static_cast<double>(ntri));
  list.insert(list.end(), ftri_all.begin(), ftri_all.end());
  const std::vector<double> state = stepped_state();    // empty without stepped geometries
  list.insert(list.end(), state.begin(), state.end());
  const int size = static_cast<int>(list.size() * sizeof(double));
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list.data(), sizeof(double), list.size(), fp);
}

void FixMusenWallMesh::restart(char *buf)
{
  const auto *list = reinterpret_cast<const double *>(buf);
  if (static_cast<int>(list[1]) != ntri) return;    // another wall file: forces recomputed
  std::fill(ftri.begin(), ftri.end(), 0.0);
  if (comm->me == 0) std::copy(list + 2, list + 2 + 3 * (size_t) ntri, ftri.begin());
  ftri_step = static_cast<bigint>(list[0]);
  reduced_valid = false;
  // a job with stepped geometries always writes their state after the forces
  if (any_stepped) restore_stepped(list + 2 + 3 * (size_t) ntri);
}

double FixMusenWallMesh::memory_usage()
{
  double bytes = sizeof(double) * (x0.size() + vert.size() + nrm.size() + tlo.size() + thi.size() + tpre.size() +
                                   tpre_stamp.size() +
                                   ftri.size() + ftri_all.size() + grid_vert.size());
  bytes += sizeof(int) * (cell_start.size() + cell_entries.size() + all_entries.size() + adj.size());
  return bytes;
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenWallMesh(lmp, narg, arg);
}
const style_registry::Registration registered(
    50, "musen/wall/mesh", "MUSEN particle-wall contact with triangle walls", &create);
}    // namespace
