/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-wall law "hertz/mindlin/liquid HMIN THETA SIGMA ETA": MUSEN's
   ModelPWHertzMindlinLiquid.cpp CalculatePW (commit e0ff360): MUSEN's particle-wall
   Hertz-Mindlin (musen_pw_hertz_mindlin.cpp) plus a liquid bridge: capillary force
   n pi R SIGMA (exp(A h + B) + C) along the wall normal (A, B, C from the volume pi/3 R^3 and
   the contact angle THETA in degrees), normal viscous force -6 pi ETA R^2 / h v_n n,
   tangential 6 pi ETA R (8/15 ln(R / h) + 0.9588) v_t and its moment rc x F; friction limit and
   rolling torque with the dry normal force alone.  As in MUSEN, h = max(|rc|, HMIN) with |rc|
   the distance from the sphere's centre to the contact point (about R, not the gap: MUSEN's
   law as it is, kept).
   Range: MUSEN finds sphere-wall contacts with the contact radius (VerletList GetPWContacts),
   fix musen/wall/mesh with LAMMPS's one radius: the same when contact radius = radius (the
   translator refuses the model otherwise), where the sphere overlaps the wall whenever the law
   runs.  The contact vector rc is handed over as rc_n (R - overlap): round-off from MUSEN's.
------------------------------------------------------------------------- */

#include "musen_pw_law.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double MUSEN_PI = 3.14159265358979323846;     // MUSENDefinitions.h PI
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

class HertzMindlinLiquid : public musen_pw::Law {
 public:
  HertzMindlinLiquid(double hmin, double theta_deg, double sigma, double eta) :
      min_thickness(hmin), contact_angle(theta_deg * MUSEN_PI / 180), surface_tension(sigma),
      viscosity(eta)
  {
  }

  void force(const musen_pw::Contact &c, const musen_pw::Materials &L, double *hist, double *fo,
             double *to) const override
  {
    const double R = c.radius, m = c.mass, overlap = c.overlap;
    const double *n = c.normal, *rc_n = c.rc_n, *w_p = c.omega;
    const double rc_len = R - overlap;
    double rc[3];
    for (int k = 0; k < 3; k++) rc[k] = rc_n[k] * rc_len;
    const double bond_length = std::max(rc_len, min_thickness);

    double spin[3];
    cross(rc_n, w_p, spin);
    double rel[3];
    for (int k = 0; k < 3; k++) rel[k] = c.vel[k] + spin[k] * R;
    const double vn = dot(n, rel);
    double vt[3];
    for (int k = 0; k < 3; k++) vt[k] = rel[k] - vn * n[k];

    // wet contact
    const double bond_volume = MUSEN_PI / 3.0 * std::pow(R, 3);
    const double A = -1.1 * std::pow(bond_volume, -0.53);
    const double ln_volume = std::log(bond_volume);
    const double B = (-0.34 * ln_volume - 0.96) * contact_angle * contact_angle -
        0.019 * ln_volume + 0.48;
    const double C = 0.0042 * ln_volume + 0.078;
    const double cap_size = std::exp(A * bond_length + B) + C;
    const double visc_n = 6 * MUSEN_PI * viscosity * R * R / bond_length;
    const double visc_t = 6 * MUSEN_PI * viscosity * R *
        (8.0 / 15.0 * std::log(R / bond_length) + 0.9588);
    double cap[3], fn_visc[3], ft_liq[3], moment_liq[3];
    for (int k = 0; k < 3; k++) {
      cap[k] = n[k] * MUSEN_PI * R * surface_tension * cap_size;
      fn_visc[k] = vn * n[k] * -1 * visc_n;
      ft_liq[k] = vt[k] * visc_t;
    }
    cross(rc, ft_liq, moment_liq);

    // dry contact
    double fn_dry[3] = {0, 0, 0}, ft_dry[3] = {0, 0, 0}, roll[3] = {0, 0, 0};
    double xi_new[3] = {0, 0, 0};
    if (overlap >= 0) {
      const double a = std::sqrt(R * overlap);
      const double kn = 2 * L.estar * a;
      const double fn_el = 2 / 3. * overlap * kn * std::fabs(dot(rc_n, n));
      const double fn_damp = TWO_SQRT_5_6 * L.alpha * vn * std::sqrt(kn * m);
      for (int k = 0; k < 3; k++) fn_dry[k] = n[k] * (fn_el + fn_damp);

      double xi_rot[3];
      const double on = dot(n, hist);
      for (int k = 0; k < 3; k++) xi_rot[k] = hist[k] - n[k] * on;
      if (is_significant(xi_rot)) {
        const double scale = std::sqrt(sqlen(hist)) / std::sqrt(sqlen(xi_rot));
        for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
      }
      for (int k = 0; k < 3; k++) xi_new[k] = xi_rot[k] + vt[k] * c.dt;

      const double kt = 8 * L.gstar * a;
      double ft_shear[3];
      for (int k = 0; k < 3; k++) ft_shear[k] = xi_new[k] * -kt;
      const double damp_t = TWO_SQRT_5_6 * L.alpha * std::sqrt(kt * m);
      const double shear_len = std::sqrt(sqlen(ft_shear));
      const double friction = L.mu * std::fabs(fn_el + fn_damp);
      if (shear_len > friction) {
        for (int k = 0; k < 3; k++) ft_dry[k] = ft_shear[k] * friction / shear_len;
        for (int k = 0; k < 3; k++) xi_new[k] = ft_dry[k] / -kt;
      } else {
        for (int k = 0; k < 3; k++) ft_dry[k] = ft_shear[k] + vt[k] * damp_t;
      }
      if (is_significant(w_p)) {
        const double s = -L.mu_roll * std::fabs(fn_el) * R / std::sqrt(sqlen(w_p));
        for (int k = 0; k < 3; k++) roll[k] = w_p[k] * s;
      }
    }

    double ft[3], nxft[3];
    for (int k = 0; k < 3; k++) ft[k] = ft_dry[k] + ft_liq[k];
    cross(n, ft, nxft);
    for (int k = 0; k < 3; k++) {
      fo[k] = fn_dry[k] + ft[k] + cap[k] + fn_visc[k];
      to[k] = nxft[k] * -R + roll[k] - moment_liq[k];
      hist[k] = xi_new[k];
    }
  }

 private:
  double min_thickness, contact_angle, surface_tension, viscosity;
};

std::unique_ptr<musen_pw::Law> create(const std::vector<double> &params, std::string &why)
{
  // MUSEN divides by h and takes log(R / h): HMIN must be > 0
  bool ok = params.size() == 4;
  for (std::size_t k = 0; ok && k < 4; k++) ok = std::isfinite(params[k]);
  if (!ok || !(params[0] > 0) || !(params[2] >= 0) || !(params[3] >= 0)) {
    why = "law hertz/mindlin/liquid needs HMIN > 0 [m], THETA [degrees], SIGMA >= 0 [N/m], "
          "ETA >= 0 [Pa s]";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(
      new HertzMindlinLiquid(params[0], params[1], params[2], params[3]));
}

const bool registered = musen_pw::add("hertz/mindlin/liquid", &create);

}    // namespace
