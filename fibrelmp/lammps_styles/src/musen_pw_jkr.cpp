/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-wall laws "jkr GAMMA" and "popov/jkr SIGMA": MUSEN's ModelPWJKR.cpp and
   ModelPWPopovJKR.cpp CalculatePW (commit e0ff360): ModelPWHertzMindlin's operations
   (musen_pw_hertz_mindlin.cpp; R* = R, m* = m) with another elastic normal force, as written:
     jkr:       4 a^3 E* / (3 R) - sqrt(8 pi E* GAMMA a^3) |rc_n . n|  (MUSEN scales only the
                adhesive term by |rc_n . n|: C++ precedence, kept);
     popov/jkr: Fadh (-1 + 0.12 (overlap / s + 1)^(5/3)) |rc_n . n|, Fadh = 3/2 SIGMA pi R,
                s = (0.4626 (SIGMA / E*)^2 R)^(1/3); and its tangential spring force is
                -Kt times the OLD tangential overlap (as it came, not rotated nor advanced;
                MUSEN's code), the new overlap still being stored.
   GAMMA: the equivalent surface energy sqrt(g_wall g_sphere) [J/m2]; SIGMA the equivalent
   surface tension [N/m] (MUSEN's interaction properties, CalculateInteractionProperty).
------------------------------------------------------------------------- */

#include "musen_pw_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double TWO_SQRT_5_6 = 1.825741858350553711523232609336;    // _2_SQRT_5_6
constexpr double MIN_SIGNIFICANT = 1e-100;     // Vector3.h MinValueHelper<double>
constexpr double MUSEN_PI = 3.14159265358979323846;    // MUSENDefinitions.h PI

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

// Popov: true (its tangential spring acts on the old overlap); the elastic normal force from
// Derived::elastic(materials, overlap, a, R, |rc_n . n|)
template <class Derived, bool OLD_OVERLAP_SHEAR> class AdhesiveShaped : public musen_pw::Law {
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
    const double fn_el =
        static_cast<const Derived *>(this)->elastic(L, overlap, a, R, std::fabs(dot(rc_n, n)));
    const double fn_damp = TWO_SQRT_5_6 * L.alpha * vn * std::sqrt(kn * m);
    double fn[3];
    for (int k = 0; k < 3; k++) fn[k] = n[k] * (fn_el + fn_damp);

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
    const double *sheared = OLD_OVERLAP_SHEAR ? hist : xi_new;
    double ft_shear[3], ft_damp[3], ft[3];
    for (int k = 0; k < 3; k++) ft_shear[k] = -kt * sheared[k];
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

class JKR : public AdhesiveShaped<JKR, false> {
 public:
  explicit JKR(double gamma) : surface_energy(gamma) {}
  double elastic(const musen_pw::Materials &L, double, double a, double R, double cos_rc) const
  {
    return 4. * std::pow(a, 3.) * L.estar / (3. * R) -
        std::sqrt(8. * MUSEN_PI * L.estar * surface_energy * std::pow(a, 3.)) * cos_rc;
  }

 private:
  double surface_energy;
};

class PopovJKR : public AdhesiveShaped<PopovJKR, true> {
 public:
  explicit PopovJKR(double sigma) : surface_tension(sigma) {}
  double elastic(const musen_pw::Materials &L, double overlap, double, double R,
                 double cos_rc) const
  {
    const double adh_force = 3. / 2. * surface_tension * MUSEN_PI * R;
    const double s_adh = std::pow(0.4626 * std::pow(surface_tension / L.estar, 2) * R, 1. / 3.);
    return adh_force * (-1 + 0.12 * std::pow(overlap / s_adh + 1, 5. / 3.)) * cos_rc;
  }

 private:
  double surface_tension;
};

std::unique_ptr<musen_pw::Law> create_jkr(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 1 || !(params[0] >= 0) || !std::isfinite(params[0])) {
    why = "law jkr needs the equivalent surface energy GAMMA >= 0 [J/m2]";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new JKR(params[0]));
}

std::unique_ptr<musen_pw::Law> create_popov(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 1 || !(params[0] > 0) || !std::isfinite(params[0])) {
    why = "law popov/jkr needs the equivalent surface tension SIGMA > 0 [N/m]";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new PopovJKR(params[0]));
}

const bool registered_jkr = musen_pw::add("jkr", &create_jkr);
const bool registered_popov = musen_pw::add("popov/jkr", &create_popov);

}    // namespace
