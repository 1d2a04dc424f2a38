/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   angle_style fibrenet: E = c (theta - theta0)^2, FibreNet's HR / HR_FL bending law
   (FibreNet/kernel.cl, kernel ResolveAngles: magnitude = -2 c1 (angle - theta0); the end
   beads get magnitude / |leg| along the in-plane normal of their leg, computed there as
   leg x (ba x bc) normalised; the middle bead gets minus their sum).

   Numerics (why not just acos(cos theta) as angle_style harmonic does):
   * For nearly straight triples (fibres at rest: theta0 = pi) cos(theta) = -1 + phi^2/2 with
     phi = pi - theta, so acos() of a rounded cosine loses phi entirely below phi ~ 1e-8, and
     LAMMPS's 1/max(sin theta, 0.001) clamp makes the force up to 100 % too small below
     phi = 1e-3.  Here phi = asin(|a x b| / (|a||b|)) and the force direction comes from
     a x b, so nothing is divided by sin(theta).
   * a x b of nearly parallel legs cancels: each component is a difference of two almost
     equal products.  It is computed with Kahan's difference-of-products algorithm (one exact
     product via fma), which is accurate to 2 ulp whatever the cancellation, so phi, theta
     and the force direction keep full relative precision.
   * Near straight, theta - theta0 = (pi - theta0) - phi with pi - theta0 taken against pi to
     ~1e-32 (pi = PI_HI + PI_LO), so e.g. theta0 = float(pi) (FibreNet parses theta0 with
     stof) keeps its 8.7e-8 offset exactly and theta0 = pi gives a force -> 0 as phi -> 0.
------------------------------------------------------------------------- */

#include "angle_fibrenet.h"
#include "style_registry.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "neighbor.h"
#include "utils.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;

namespace {

constexpr double PI_HI = 3.141592653589793116;      // the double nearest to pi
constexpr double PI_LO = 1.2246467991473532e-16;    // pi - PI_HI (to ~1e-32)

// a*b - c*d to within 2 ulp whatever the cancellation (Kahan's algorithm with one fma; error
// bound: Jeannerod, Louvet & Muller, Math. Comp. 82 (2013) 2245-2264)
inline double diff_of_products(double a, double b, double c, double d)
{
  const double w = c * d;
  const double e = std::fma(-c, d, w);    // exactly w - c*d
  const double f = std::fma(a, b, -w);
  return f + e;
}

/* The bend of one triple with legs a = x1 - x2, b = x3 - x2 (x2 the middle bead).
   Returns theta - theta0; f1 and f3 receive the forces on the end beads (the middle bead's
   is -(f1 + f3)).  dE/dtheta = 2 c (theta - theta0) and
       d theta / d x1 = (a x t) / (|a|^2 |t|),   d theta / d x3 = (t x b) / (|b|^2 |t|),
   t = a x b: the legs' unit in-plane normals over the leg lengths, as in FibreNet's kernel.
   theta itself: asin(sin theta) within 45 degrees of straight or folded (well conditioned,
   and cheap), acos(cos theta) in between (well conditioned there), never atan2 (slower). */
inline double bend(const double *a, const double *b, double c, double theta0,
                   double pi_minus_theta0, double *f1, double *f3)
{
  const double t0 = diff_of_products(a[1], b[2], a[2], b[1]);
  const double t1 = diff_of_products(a[2], b[0], a[0], b[2]);
  const double t2 = diff_of_products(a[0], b[1], a[1], b[0]);
  const double aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
  const double bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
  const double tn = std::sqrt(t0 * t0 + t1 * t1 + t2 * t2);     // |a||b| sin(theta)
  const double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];     // |a||b| cos(theta)
  const double ab = std::sqrt(aa * bb);

  double dtheta;
  if (ab == 0.0)    // a leg of zero length: no angle, so no energy and no force
    dtheta = 0.0;
  else if (tn < -d)    // theta > 3 pi / 4: theta - theta0 = (pi - theta0) - phi, phi = pi - theta
    dtheta = pi_minus_theta0 - std::asin(tn / ab);
  else if (tn < d)    // theta < pi / 4
    dtheta = std::asin(tn / ab) - theta0;
  else
    dtheta = std::acos(d / ab) - theta0;

  if (tn > 0.0) {
    const double g = -2.0 * c * dtheta / (tn * aa * bb);
    const double g1 = g * bb;
    const double g3 = g * aa;
    f1[0] = g1 * (a[1] * t2 - a[2] * t1);
    f1[1] = g1 * (a[2] * t0 - a[0] * t2);
    f1[2] = g1 * (a[0] * t1 - a[1] * t0);
    f3[0] = g3 * (t1 * b[2] - t2 * b[1]);
    f3[1] = g3 * (t2 * b[0] - t0 * b[2]);
    f3[2] = g3 * (t0 * b[1] - t1 * b[0]);
  } else {    // exactly straight or folded (or a zero leg): no plane, no force (as FibreNet)
    f1[0] = f1[1] = f1[2] = 0.0;
    f3[0] = f3[1] = f3[2] = 0.0;
  }
  return dtheta;
}

}    // namespace

/* ---------------------------------------------------------------------- */

AngleFibreNet::AngleFibreNet(LAMMPS *_lmp) :
    Angle(_lmp), c(nullptr), theta0(nullptr), pi_minus_theta0(nullptr)
{
  writedata = 1;
}

AngleFibreNet::~AngleFibreNet()
{
  if (allocated && !copymode) {
    memory->destroy(setflag);
    memory->destroy(c);
    memory->destroy(theta0);
    memory->destroy(pi_minus_theta0);
  }
}

/* ---------------------------------------------------------------------- */

void AngleFibreNet::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);
  eval(eflag);
}

void AngleFibreNet::eval(int eflag)
{
  double **x = atom->x;
  double **f = atom->f;
  int **anglelist = neighbor->anglelist;
  const int nanglelist = neighbor->nanglelist;
  const int nlocal = atom->nlocal;
  const int newton_bond = force->newton_bond;

  double a[3], b[3], f1[3], f3[3];
  double eangle = 0.0;

  for (int n = 0; n < nanglelist; n++) {
    const int i1 = anglelist[n][0];
    const int i2 = anglelist[n][1];
    const int i3 = anglelist[n][2];
    const int type = anglelist[n][3];

    a[0] = x[i1][0] - x[i2][0];
    a[1] = x[i1][1] - x[i2][1];
    a[2] = x[i1][2] - x[i2][2];
    b[0] = x[i3][0] - x[i2][0];
    b[1] = x[i3][1] - x[i2][1];
    b[2] = x[i3][2] - x[i2][2];

    const double dtheta = bend(a, b, c[type], theta0[type], pi_minus_theta0[type], f1, f3);
    if (eflag) eangle = c[type] * dtheta * dtheta;

    if (newton_bond || i1 < nlocal) {
      f[i1][0] += f1[0];
      f[i1][1] += f1[1];
      f[i1][2] += f1[2];
    }
    if (newton_bond || i2 < nlocal) {
      f[i2][0] -= f1[0] + f3[0];
      f[i2][1] -= f1[1] + f3[1];
      f[i2][2] -= f1[2] + f3[2];
    }
    if (newton_bond || i3 < nlocal) {
      f[i3][0] += f3[0];
      f[i3][1] += f3[1];
      f[i3][2] += f3[2];
    }
    if (evflag)
      ev_tally(i1, i2, i3, nlocal, newton_bond, eangle, f1, f3, a[0], a[1], a[2], b[0], b[1],
               b[2]);
  }
}

/* ---------------------------------------------------------------------- */

void AngleFibreNet::allocate()
{
  allocated = 1;
  const int np1 = atom->nangletypes + 1;
  memory->create(c, np1, "angle:c");
  memory->create(theta0, np1, "angle:theta0");
  memory->create(pi_minus_theta0, np1, "angle:pi_minus_theta0");
  memory->create(setflag, np1, "angle:setflag");
  for (int i = 1; i < np1; i++) setflag[i] = 0;
}

/* ----------------------------------------------------------------------
   angle_coeff N c theta0   (E = c (theta - theta0)^2, theta0 in radians as in FibreNet's
   model files; no degree conversion, so FibreNet's value passes through unrounded)
------------------------------------------------------------------------- */

void AngleFibreNet::coeff(int narg, char **arg)
{
  if (narg != 3)
    error->all(FLERR, "angle_coeff for angle_style fibrenet needs 3 arguments: N c theta0 "
                      "(E = c (theta - theta0)^2, theta0 in radians), got {}", narg);
  if (!allocated) allocate();

  int ilo, ihi;
  utils::bounds(FLERR, arg[0], 1, atom->nangletypes, ilo, ihi, error);
  // utils::numeric refuses nan, inf and out-of-range numbers with a LAMMPS error
  const double c_one = utils::numeric(FLERR, arg[1], false, lmp);
  const double theta0_one = utils::numeric(FLERR, arg[2], false, lmp);

  int count = 0;
  for (int i = ilo; i <= ihi; i++) {
    c[i] = c_one;
    theta0[i] = theta0_one;
    setflag[i] = 1;
    count++;
  }
  if (count == 0)
    error->all(FLERR, "angle_coeff {} (angle_style fibrenet) names no angle type", arg[0]);
  init_style();
}

/* ----------------------------------------------------------------------
   derived per-type values; also after fix adapt changed c or theta0 (Angle::reinit -> init)
------------------------------------------------------------------------- */

void AngleFibreNet::init_style()
{
  if (!allocated) return;
  // PI_HI - theta0 is exact for theta0 in [pi/2, 2 pi] (Sterbenz), where the (pi - theta0)
  // - phi cancellation needs it; elsewhere one rounding of a value >= pi/2 is harmless
  for (int i = 1; i <= atom->nangletypes; i++)
    if (setflag[i]) pi_minus_theta0[i] = (PI_HI - theta0[i]) + PI_LO;
}

/* ---------------------------------------------------------------------- */

double AngleFibreNet::equilibrium_angle(int i)
{
  return theta0[i];
}

/* ---------------------------------------------------------------------- */

void AngleFibreNet::write_restart(FILE *fp)
{
  fwrite(&c[1], sizeof(double), atom->nangletypes, fp);
  fwrite(&theta0[1], sizeof(double), atom->nangletypes, fp);
}

void AngleFibreNet::read_restart(FILE *fp)
{
  allocate();
  if (comm->me == 0) {
    utils::sfread(FLERR, &c[1], sizeof(double), atom->nangletypes, fp, nullptr, error);
    utils::sfread(FLERR, &theta0[1], sizeof(double), atom->nangletypes, fp, nullptr, error);
  }
  MPI_Bcast(&c[1], atom->nangletypes, MPI_DOUBLE, 0, world);
  MPI_Bcast(&theta0[1], atom->nangletypes, MPI_DOUBLE, 0, world);
  for (int i = 1; i <= atom->nangletypes; i++) setflag[i] = 1;
  init_style();
}

/* ----------------------------------------------------------------------
   Angle Coeffs of write_data: full precision (read back by angle_coeff unchanged)
------------------------------------------------------------------------- */

void AngleFibreNet::write_data(FILE *fp)
{
  for (int i = 1; i <= atom->nangletypes; i++)
    fprintf(fp, "%d %.17g %.17g\n", i, c[i], theta0[i]);
}

/* ----------------------------------------------------------------------
   energy of one angle (compute angle/local, compute pe/atom checks, ...)
------------------------------------------------------------------------- */

double AngleFibreNet::single(int type, int i1, int i2, int i3)
{
  double **x = atom->x;
  double a[3] = {x[i1][0] - x[i2][0], x[i1][1] - x[i2][1], x[i1][2] - x[i2][2]};
  double b[3] = {x[i3][0] - x[i2][0], x[i3][1] - x[i2][1], x[i3][2] - x[i2][2]};
  domain->minimum_image(FLERR, a);
  domain->minimum_image(FLERR, b);
  double f1[3], f3[3];
  const double dtheta = bend(a, b, c[type], theta0[type], pi_minus_theta0[type], f1, f3);
  return c[type] * dtheta * dtheta;
}

/* ----------------------------------------------------------------------
   per-type arrays for fix adapt ("c", "theta0" in radians)
------------------------------------------------------------------------- */

void *AngleFibreNet::extract(const char *str, int &dim)
{
  dim = 1;
  if (strcmp(str, "c") == 0) return (void *) c;
  if (strcmp(str, "theta0") == 0) return (void *) theta0;
  return nullptr;
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Angle *create(LAMMPS *lmp) { return new AngleFibreNet(lmp); }
const style_registry::Registration registered(
    60, "fibrenet", "FibreNet bending law", &create);
}    // namespace
