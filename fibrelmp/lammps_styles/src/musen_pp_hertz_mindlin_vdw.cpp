/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "hertz/mindlin/vdw GAMMA": MUSEN's ModelPPHertzMindlinVdW.cpp
   CalculatePP (commit e0ff360), operation by operation.  GAMMA is the contact's equivalent
   surface energy sqrt(gamma1 gamma2) [J/m2] (SimplifiedScene.cpp CalculateInteractionProperty).
   Hertz-Mindlin plus a van der Waals attraction H 2R* / (12 (s + Dmin)^2) along the normal,
   H = 24 pi Dmin^2 gamma, Dmin = 7.5e-10 m, s the surface distance (capped at Dmin); the
   friction limit includes it, the rolling torque does not.
   Range: MUSEN evaluates a PP model only for a collision, which exists while the centre
   distance is below the sum of the *contact* radii (CollisionsCalculator.cpp
   CheckPPCollision; the Verlet list only pre-selects candidates).  pair musen/hm's test is
   the same with LAMMPS's radius, so with contact radius = radius (the translator refuses the
   model otherwise) s < 0 always and the force is the constant 4 pi gamma R*; MUSEN's
   long-range branch (s >= 0) is kept for s = 0 exactly, where it cannot be reached either.
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double MUSEN_PI = 3.14159265358979323846;     // MUSENDefinitions.h PI
constexpr double TWO_SQRT_5_6 = 1.825741858350553711523232609336;    // _2_SQRT_5_6

class HertzMindlinVdW final : public musen_pp::Law {
 public:
  explicit HertzMindlinVdW(double gamma) : surface_energy(gamma) {}

  void force(const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
             musen_pp::Result &r) const override
  {
    using Shape = musen_pp::MindlinShaped<HertzMindlinVdW>;
    const double *n = c.n, *vt = c.vt;
    // (Coord(dst) - Coord(src)).Length() - r1 - r2 = -overlap (same rounding up to the sum order)
    const double surface_distance = -c.overlap;
    constexpr double Dmin = 7.5e-10;
    const double hamaker = 24 * MUSEN_PI * Dmin * Dmin * surface_energy;
    const double vdw = surface_distance <= Dmin
        ? hamaker * (2 * c.equiv_radius) / (12 * Dmin * Dmin)
        : hamaker * (2 * c.equiv_radius) / (12 * std::pow(surface_distance + Dmin, 2));

    if (!(surface_distance < 0)) {    // only the long-range force
      for (int k = 0; k < 3; k++) {
        xi[k] = 0.0;
        r.fn[k] = n[k] * vdw;
        r.ft[k] = r.m1[k] = r.m2[k] = 0.0;
      }
      r.fn_len = vdw;
      return;
    }

    const double overlap = std::fabs(surface_distance);
    const double contact_area_radius = std::sqrt(c.equiv_radius * overlap);
    const double kn = 2 * m.estar * contact_area_radius;
    const double fn_el = -overlap * kn * 2. / 3.;
    const double fn_damp = -TWO_SQRT_5_6 * m.alpha * c.vn * std::sqrt(kn * c.equiv_mass);
    const double fn = fn_el + fn_damp + vdw;

    // rotate the old tangential overlap into the tangent plane, keeping its length
    const double xi_n = n[0] * xi[0] + n[1] * xi[1] + n[2] * xi[2];
    double xi_rot[3];
    for (int k = 0; k < 3; k++) xi_rot[k] = xi[k] - n[k] * xi_n;
    if (Shape::significant(xi_rot)) {
      const double scale = Shape::length(xi) / Shape::length(xi_rot);
      for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
    }
    for (int k = 0; k < 3; k++) xi[k] = xi_rot[k] + vt[k] * c.dt;

    const double kt = 8 * m.gstar * contact_area_radius;
    double ft_spring[3];
    for (int k = 0; k < 3; k++) ft_spring[k] = xi[k] * kt;
    const double damp_t = -TWO_SQRT_5_6 * m.alpha * std::sqrt(kt * c.equiv_mass);
    const double ft_spring_len = Shape::length(ft_spring);
    // the van der Waals pull raises the friction limit (MUSEN: |Fel + Fdamp + Fvdw|)
    const double friction_len = m.mu * std::fabs(fn);
    double *ft = r.ft;
    if (ft_spring_len > friction_len) {
      for (int k = 0; k < 3; k++) {
        ft[k] = ft_spring[k] * friction_len / ft_spring_len;
        xi[k] = ft[k] / kt;
      }
    } else {
      for (int k = 0; k < 3; k++) ft[k] = ft_spring[k] + vt[k] * damp_t;
    }

    // rolling torque with the elastic normal force alone
    double roll1[3] = {0.0, 0.0, 0.0}, roll2[3] = {0.0, 0.0, 0.0};
    if (Shape::significant(c.w1)) {
      const double s = -m.mu_roll * std::fabs(fn_el) * c.r1 / Shape::length(c.w1);
      for (int k = 0; k < 3; k++) roll1[k] = c.w1[k] * s;
    }
    if (Shape::significant(c.w2)) {
      const double s = -m.mu_roll * std::fabs(fn_el) * c.r2 / Shape::length(c.w2);
      for (int k = 0; k < 3; k++) roll2[k] = c.w2[k] * s;
    }

    const double nxft[3] = {n[1] * ft[2] - n[2] * ft[1], n[2] * ft[0] - n[0] * ft[2],
                            n[0] * ft[1] - n[1] * ft[0]};
    r.fn_len = fn;
    for (int k = 0; k < 3; k++) {
      r.fn[k] = n[k] * fn;
      r.m1[k] = nxft[k] * c.r1 + roll1[k];
      r.m2[k] = nxft[k] * c.r2 + roll2[k];
    }
  }

 private:
  double surface_energy;
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 1 || !(params[0] >= 0) || !std::isfinite(params[0])) {
    why = "law hertz/mindlin/vdw needs the equivalent surface energy GAMMA >= 0 [J/m2]";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new HertzMindlinVdW(params[0]));
}

const bool registered = musen_pp::add("hertz/mindlin/vdw", &create);

}    // namespace
