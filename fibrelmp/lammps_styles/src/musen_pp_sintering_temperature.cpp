/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "sintering/temperature DB ETA OMEGA Q TMIN CMAX GAMMA": MUSEN's
   ModelPPSinteringTemperature.cpp CalculatePP (commit e0ff360, Models/ParticleParticle/
   SinteringTemperature), operation by operation.  T = (T_src + T_dst)/2 (d_musen_temperature),
   max = CMAX 2R*:
     T >= TMIN and overlap < max: Bouvard and McMeeking's sintering as law "sintering" with
       D = OMEGA/(kB T) DB exp(-Q/(R_gas T)); xi = 0, initial overlap = overlap
     T <= TMIN: Hertz-like spring towards the contact's initial overlap (max once overlap >= max),
       MUSEN's damping, tangential spring and damping, no friction limit, no moments
     else (T > TMIN, overlap >= max): normal spring towards max with damping; xi = 0, initial
       overlap = overlap
   The initial overlap is the contact's stored one (the law's one-value block of the contact's
   history, musen_pp_law.h history_size): zero for a new contact, the overlap at MUSEN's time 0
   (its `_time == 0` rule) for one present then.
   Velocities are the centres' (MUSEN's Particles().Vel, no spin term).
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

// MUSENDefinitions.h
constexpr double MUSEN_PI = 3.14159265358979323846;
constexpr double TWO_SQRT_5_6 = 1.825741858350553711523232609336;
constexpr double BOLTZMANN_CONSTANT = 1.38064852e-23;
constexpr double GAS_CONSTANT = 8.314462618;

class SinteringTemperature final : public musen_pp::Law {
 public:
  explicit SinteringTemperature(const std::vector<double> &p) :
      grain_diffusion(p[0]), viscous(p[1]), atomic_volume(p[2]), activation_energy(p[3]),
      min_temperature(p[4]), max_overlap_coeff(p[5]), surface_energy(p[6])
  {
  }
  bool reads_temperature() const override { return true; }
  int history_size() const override { return 1; }    // the contact's initial overlap

  void force(const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
             musen_pp::Result &r) const override
  {
    const double *n = c.n;
    double vn_m, vt_m[3];    // normRelVelLen, tangRelVel
    musen_pp::centre_relative_velocity(c, vn_m, vt_m);

    const double temperature = (c.t1 + c.t2) / 2;
    const double max_overlap = max_overlap_coeff * 2 * c.equiv_radius;
    double &initial = own_history(c)[0];
    // MUSEN: "set initial overlap as equilibrium value" at _time == 0
    if (c.at_time_zero) {
      for (int k = 0; k < 3; k++) xi[k] = 0.0;
      initial = c.overlap;
    }
    for (int k = 0; k < 3; k++) r.m1[k] = r.m2[k] = 0.0;

    if (temperature >= min_temperature && c.overlap < max_overlap) {
      for (int k = 0; k < 3; k++) xi[k] = 0.0;
      initial = c.overlap;
      const double diffusion = atomic_volume / (BOLTZMANN_CONSTANT * temperature) *
          grain_diffusion * std::exp(-activation_energy / (GAS_CONSTANT * temperature));
      const double squared_contact_radius = 4 * c.equiv_radius * c.overlap;
      const double viscous_n = -MUSEN_PI * std::pow(squared_contact_radius, 2) / 8 / diffusion;
      const double viscous_t = -viscous * MUSEN_PI * squared_contact_radius *
          std::pow(2 * c.equiv_radius, 2) / 8 / diffusion;
      for (int k = 0; k < 3; k++) {
        const double sintering = n[k] * 1.125 * MUSEN_PI * 2 * c.equiv_radius * surface_energy;
        r.fn[k] = sintering + vn_m * n[k] * viscous_n;
        r.ft[k] = vt_m[k] * viscous_t;
      }
      r.fn_len = 1.125 * MUSEN_PI * 2 * c.equiv_radius * surface_energy + vn_m * viscous_n;
    } else if (temperature <= min_temperature) {
      const double contact_area_radius = std::sqrt(c.equiv_radius * c.overlap);
      const double kn = 2 * m.estar * contact_area_radius;
      const double delta = c.overlap >= max_overlap ? max_overlap : initial;
      const double fn_el = -(c.overlap - delta) * kn * 2. / 3.;
      const double fn_damp = -TWO_SQRT_5_6 * m.alpha * -1 * vn_m * std::sqrt(kn * c.equiv_mass);
      // rotate the old tangential overlap into the tangent plane, keeping its length
      const double xi_n = n[0] * xi[0] + n[1] * xi[1] + n[2] * xi[2];
      double xi_rot[3];
      for (int k = 0; k < 3; k++) xi_rot[k] = xi[k] - n[k] * xi_n;
      if (significant(xi_rot)) {
        const double scale = length(xi) / length(xi_rot);
        for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
      }
      const double kt = 8 * m.gstar * contact_area_radius;
      const double damp_t = -TWO_SQRT_5_6 * m.alpha * std::sqrt(kt * c.equiv_mass);
      for (int k = 0; k < 3; k++) {
        xi[k] = xi_rot[k] + -1 * vt_m[k] * c.dt;
        r.fn[k] = n[k] * (fn_el + fn_damp);
        r.ft[k] = xi[k] * kt + -1 * vt_m[k] * damp_t;
      }
      r.fn_len = fn_el + fn_damp;
    } else {
      for (int k = 0; k < 3; k++) xi[k] = 0.0;
      initial = c.overlap;
      const double contact_area_radius = std::sqrt(c.equiv_radius * c.overlap);
      const double kn = 2 * m.estar * contact_area_radius;
      const double fn_el = -(c.overlap - max_overlap) * kn * 2. / 3.;
      const double fn_damp = -TWO_SQRT_5_6 * m.alpha * -1 * vn_m * std::sqrt(kn * c.equiv_mass);
      for (int k = 0; k < 3; k++) {
        r.fn[k] = n[k] * (fn_el + fn_damp);
        r.ft[k] = 0.0;
      }
      r.fn_len = fn_el + fn_damp;
    }
  }

 private:
  // Vector3.h: IsSignificant(), Length()
  static bool significant(const double *v)
  {
    return std::fabs(v[0]) > 1e-100 || std::fabs(v[1]) > 1e-100 || std::fabs(v[2]) > 1e-100;
  }
  static double length(const double *v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
  double grain_diffusion, viscous, atomic_volume, activation_energy, min_temperature,
      max_overlap_coeff, surface_energy;
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &p, std::string &why)
{
  bool ok = p.size() == 7;
  for (double v : p) ok = ok && std::isfinite(v);
  if (!ok || !(p[2] > 0) || !(p[6] >= 0) || !(p[5] >= 0)) {
    why = "law sintering/temperature needs GRAINBOUND_DIFFUSION VISCOUS_PARAMETER ATOMIC_VOLUME > 0 "
          "ACTIVATION_ENERGY MINIMAL_TEMPERATURE MAX_OVERLAP_COEFF >= 0 and the equivalent "
          "surface energy GAMMA >= 0 [J/m2], all finite";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new SinteringTemperature(p));
}

const bool registered = musen_pp::add("sintering/temperature", &create);

}    // namespace
