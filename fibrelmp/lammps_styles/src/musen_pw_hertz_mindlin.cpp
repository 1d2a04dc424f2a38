/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-wall law "hertz/mindlin": MUSEN's ModelPWHertzMindlin.cpp CalculatePW (commit
   e0ff360): force along the WALL's normal scaled by |rc_n . n|, the sphere's spin in the
   relative velocity, tangential damping outside the Coulomb test, rolling torque
   -mu_r |F_n,el| R w/|w|; R* = R, m* = m.  MUSEN's operation order is kept.
------------------------------------------------------------------------- */

#include "musen_pw_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double TWO_SQRT_5_6 = 1.825741858350553711523232609336;    // _2_SQRT_5_6
constexpr double MIN_SIGNIFICANT = 1e-100;     // Vector3.h MinValueHelper<double>

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
inline double sqlen(const double *a)
{
  return a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
}
inline bool is_significant(const double *a)
{
  return std::fabs(a[0]) > MIN_SIGNIFICANT || std::fabs(a[1]) > MIN_SIGNIFICANT ||
      std::fabs(a[2]) > MIN_SIGNIFICANT;
}

class HertzMindlin : public musen_pw::Law {
 public:
  void force(const musen_pw::Contact &c, const musen_pw::Materials &L, double *hist, double *fo,
             double *to) const override
  {
    const double R = c.radius, m = c.mass, overlap = c.overlap;
    const double *n = c.normal, *rc_n = c.rc_n, *w_p = c.omega;
    double spin[3];
    cross(rc_n, w_p, spin);
    double rel[3];
    for (int k = 0; k < 3; k++) rel[k] = c.vel[k] + spin[k] * R;
    const double vn = dot(n, rel);
    double vt[3];
    for (int k = 0; k < 3; k++) vt[k] = rel[k] - vn * n[k];

    const double a = std::sqrt(R * overlap);
    const double kn = 2 * L.estar * a;
    const double fn_el = 2. / 3. * overlap * kn * std::fabs(dot(rc_n, n));
    const double fn_damp = TWO_SQRT_5_6 * L.alpha * vn * std::sqrt(kn * m);
    double fn[3];
    for (int k = 0; k < 3; k++) fn[k] = n[k] * (fn_el + fn_damp);

    // old overlap turned into the tangent plane, its length kept
    double xi_rot[3];
    const double on = dot(n, hist);
    for (int k = 0; k < 3; k++) xi_rot[k] = hist[k] - n[k] * on;
    if (is_significant(xi_rot)) {
      const double scale = std::sqrt(sqlen(hist)) / std::sqrt(sqlen(xi_rot));
      for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
    }
    double xi_new[3];
    for (int k = 0; k < 3; k++) xi_new[k] = xi_rot[k] + vt[k] * c.dt;

    const double kt = 8 * L.gstar * a;
    double ft_shear[3], ft_damp[3], ft[3];
    for (int k = 0; k < 3; k++) ft_shear[k] = xi_new[k] * -kt;
    const double damp_t = TWO_SQRT_5_6 * L.alpha * std::sqrt(kt * m);
    for (int k = 0; k < 3; k++) ft_damp[k] = vt[k] * damp_t;
    const double shear_len = std::sqrt(sqlen(ft_shear));
    const double friction = L.mu * std::fabs(fn_el + fn_damp);
    if (shear_len > friction) {
      for (int k = 0; k < 3; k++) ft[k] = ft_shear[k] * friction / shear_len;
      for (int k = 0; k < 3; k++) xi_new[k] = ft[k] / -kt;
    } else {
      for (int k = 0; k < 3; k++) ft[k] = ft_shear[k] + ft_damp[k];
    }

    double roll[3] = {0, 0, 0};
    if (is_significant(w_p)) {
      const double s = -L.mu_roll * std::fabs(fn_el) * R / std::sqrt(sqlen(w_p));
      for (int k = 0; k < 3; k++) roll[k] = w_p[k] * s;
    }
    double nxft[3];
    cross(n, ft, nxft);
    for (int k = 0; k < 3; k++) {
      fo[k] = fn[k] + ft[k];
      to[k] = nxft[k] * -R + roll[k];
      hist[k] = xi_new[k];
    }
  }
};

std::unique_ptr<musen_pw::Law> create(const std::vector<double> &params, std::string &why)
{
  if (!params.empty()) {
    why = "law hertz/mindlin takes no parameters";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new HertzMindlin());
}

const bool registered = musen_pw::add("hertz/mindlin", &create);

}    // namespace
