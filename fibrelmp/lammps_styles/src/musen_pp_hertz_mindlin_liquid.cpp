/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "hertz/mindlin/liquid HMIN THETA SIGMA ETA": MUSEN's
   ModelPPHertzMindlinLiquid.cpp CalculatePP (commit e0ff360): a liquid bridge (capillary force
   pi R* SIGMA (exp(A h + B) + C) along the normal with A, B, C from the bridge volume
   pi/3 (r1^3 + r2^3) and the contact angle THETA [degrees, converted as MUSEN: * PI / 180];
   normal viscous force 6 pi ETA R*^2 / h vn; tangential 6 pi ETA R* (8/15 ln(R* / h) + 0.9588) vt
   and its moment) plus the dry Hertz-Mindlin contact while the spheres touch, h the surface
   gap capped below at HMIN.  The friction limit and the rolling torque use the dry normal
   force alone.
   Range: MUSEN evaluates a PP model only for a collision (centre distance below the sum of the
   *contact* radii, CollisionsCalculator.cpp CheckPPCollision); pair musen/hm tests the same
   with LAMMPS's one radius, so with contact radius = radius (the translator refuses the model
   otherwise) the spheres overlap whenever the law runs: h = HMIN and the dry part always acts.
   Operations follow MUSEN's order except where the pair style hands over derived values (the
   contact vector as n (r1 + r2 - overlap), the relative velocity as musen/hm computes it):
   those differ from MUSEN's by round-off.
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double MUSEN_PI = 3.14159265358979323846;     // MUSENDefinitions.h PI
constexpr double TWO_SQRT_5_6 = 1.825741858350553711523232609336;    // _2_SQRT_5_6

class HertzMindlinLiquid final : public musen_pp::Law {
 public:
  HertzMindlinLiquid(double hmin, double theta_deg, double sigma, double eta) :
      min_thickness(hmin), contact_angle(theta_deg * MUSEN_PI / 180), surface_tension(sigma),
      viscosity(eta)
  {
  }

  void force(const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
             musen_pp::Result &r) const override
  {
    using Shape = musen_pp::MindlinShaped<HertzMindlinLiquid>;
    const double *n = c.n, *vt = c.vt;
    const double r1 = c.r1, r2 = c.r2, req = c.equiv_radius;
    const double cvlen = r1 + r2 - c.overlap;
    const double bond_length = std::max(cvlen - r1 - r2, min_thickness);
    const double real_overlap = c.overlap;    // contact radius = radius

    // wet contact
    const double bond_volume = MUSEN_PI / 3. * (std::pow(r1, 3) + std::pow(r2, 3));
    const double A = -1.1 * std::pow(bond_volume, -0.53);
    const double ln_volume = std::log(bond_volume);
    const double B = (-0.34 * ln_volume - 0.96) * contact_angle * contact_angle -
        0.019 * ln_volume + 0.48;
    const double C = 0.0042 * ln_volume + 0.078;
    const double cap = MUSEN_PI * req * surface_tension * (std::exp(A * bond_length + B) + C);
    const double visc_n = c.vn * (6 * MUSEN_PI * viscosity * req * req / bond_length);
    const double visc_t = 6 * MUSEN_PI * viscosity * req *
        (8. / 15. * std::log(req / bond_length) + 0.9588);
    double ft_liq[3], moment_liq[3];
    for (int k = 0; k < 3; k++) ft_liq[k] = vt[k] * visc_t;
    // rAC x ft_liq with rAC = -0.5 * contact vector
    const double rac[3] = {-0.5 * (n[0] * cvlen), -0.5 * (n[1] * cvlen), -0.5 * (n[2] * cvlen)};
    moment_liq[0] = rac[1] * ft_liq[2] - rac[2] * ft_liq[1];
    moment_liq[1] = rac[2] * ft_liq[0] - rac[0] * ft_liq[2];
    moment_liq[2] = rac[0] * ft_liq[1] - rac[1] * ft_liq[0];

    // dry contact
    double fn_dry = 0.0, ft_dry[3] = {0.0, 0.0, 0.0};
    double roll1[3] = {0.0, 0.0, 0.0}, roll2[3] = {0.0, 0.0, 0.0};
    if (real_overlap >= 0) {
      const double contact_radius = std::sqrt(req * real_overlap);
      const double kn = 2 * m.estar * contact_radius;
      const double fn_el = -2 / 3. * real_overlap * kn;
      const double fn_damp = -TWO_SQRT_5_6 * m.alpha * c.vn * std::sqrt(kn * c.equiv_mass);
      fn_dry = fn_el + fn_damp;

      const double xi_n = n[0] * xi[0] + n[1] * xi[1] + n[2] * xi[2];
      double xi_rot[3];
      for (int k = 0; k < 3; k++) xi_rot[k] = xi[k] - n[k] * xi_n;
      if (Shape::significant(xi_rot)) {
        const double scale = Shape::length(xi) / Shape::length(xi_rot);
        for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
      }
      for (int k = 0; k < 3; k++) xi[k] = xi_rot[k] + vt[k] * c.dt;

      const double kt = 8 * m.gstar * contact_radius;
      double ft_spring[3];
      for (int k = 0; k < 3; k++) ft_spring[k] = xi[k] * kt;
      const double damp_t = -TWO_SQRT_5_6 * m.alpha * std::sqrt(kt * c.equiv_mass);
      const double ft_spring_len = Shape::length(ft_spring);
      const double friction_len = m.mu * std::fabs(fn_el + fn_damp);
      if (ft_spring_len > friction_len) {
        for (int k = 0; k < 3; k++) {
          ft_dry[k] = ft_spring[k] * friction_len / ft_spring_len;
          xi[k] = ft_dry[k] / kt;
        }
      } else {
        for (int k = 0; k < 3; k++) ft_dry[k] = ft_spring[k] + vt[k] * damp_t;
      }
      if (Shape::significant(c.w1)) {
        const double s = -m.mu_roll * std::fabs(fn_el) * r1 / Shape::length(c.w1);
        for (int k = 0; k < 3; k++) roll1[k] = c.w1[k] * s;
      }
      if (Shape::significant(c.w2)) {
        const double s = -m.mu_roll * std::fabs(fn_el) * r2 / Shape::length(c.w2);
        for (int k = 0; k < 3; k++) roll2[k] = c.w2[k] * s;
      }
    } else {
      xi[0] = xi[1] = xi[2] = 0.0;
    }

    // final forces and moments (normal: dry + capillary + viscous; tangential: dry + liquid)
    double *ft = r.ft;
    for (int k = 0; k < 3; k++) ft[k] = ft_dry[k] + ft_liq[k];
    const double nxft[3] = {n[1] * ft[2] - n[2] * ft[1], n[2] * ft[0] - n[0] * ft[2],
                            n[0] * ft[1] - n[1] * ft[0]};
    r.fn_len = fn_dry + cap + visc_n;
    for (int k = 0; k < 3; k++) {
      r.fn[k] = n[k] * fn_dry + n[k] * cap + n[k] * visc_n;
      r.m1[k] = nxft[k] * r1 + roll1[k] - moment_liq[k];
      r.m2[k] = nxft[k] * r2 + roll2[k] - moment_liq[k];
    }
  }

 private:
  double min_thickness, contact_angle, surface_tension, viscosity;
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  // MUSEN divides by the gap and takes its logarithm: HMIN must be > 0
  bool ok = params.size() == 4;
  for (std::size_t k = 0; ok && k < 4; k++) ok = std::isfinite(params[k]);
  if (!ok || !(params[0] > 0) || !(params[2] >= 0) || !(params[3] >= 0)) {
    why = "law hertz/mindlin/liquid needs HMIN > 0 [m], THETA [degrees], SIGMA >= 0 [N/m], "
          "ETA >= 0 [Pa s]";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(
      new HertzMindlinLiquid(params[0], params[1], params[2], params[3]));
}

const bool registered = musen_pp::add("hertz/mindlin/liquid", &create);

}    // namespace
