/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   MUSEN particle-particle laws for pair_style musen/hm (and musen/linear).  The pair style
   finds each contact (overlap, R*, m*, unit normal, normal and tangential relative velocity,
   the stored tangential overlap); each law, in the order the style names them
   (pair_style musen/hm [then NAME [params]] ...), turns it into the force on src and the
   moments on both spheres, as MUSEN's CalculatePP does.  As in MUSEN (CPUSimulator.cpp
   CalculateForcesPP: every PP model in turn over all collisions, each writing the
   collision's vTangOverlap), a law reads the tangential overlap the previous law of this
   step left and writes its own; the forces and moments of all laws add.
   A law is one .cpp file that registers itself with one line:
     const bool registered = musen_pp::add("NAME", &create_function);
   A law that keeps its own per-contact values (history_size() > 0) gets a block of each
   contact's history: pair musen/hm stores its own values first (HISTORY_VALUES: xi and the last
   forces), then each law's block in the order the laws act, at the offset it tells the law
   (set_history_offset); the law reads and writes it through own_history(c).
------------------------------------------------------------------------- */

#ifndef FIBRELMP_MUSEN_PP_LAW_H
#define FIBRELMP_MUSEN_PP_LAW_H

#include "musen_law_registry.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {
namespace musen_pp {

// what pair musen/hm found for one contact of src (i) and dst (j)
struct Contact {
  double overlap;               // r1 + r2 - |x_j - x_i| > 0
  double equiv_radius, equiv_mass;
  double r1, r2;                // the radii of src and dst
  const double *n;              // unit normal from src to dst (zero when they coincide)
  double vn;                    // normal relative velocity (dst minus src, contact point)
  const double *vt;             // tangential relative velocity
  const double *w1, *w2;        // angular velocities of src and dst
  double dt;
  // heat laws only (fix musen/heat; zero otherwise): temperatures and thermal conductivities
  double t1 = 0, t2 = 0, k1 = 0, k2 = 0;
  // the laws' own per-contact values (Law::history_size; in/out, zero for a new contact): each
  // law's block at its offset (Law::own_history); nullptr when no law keeps any
  double *law_history = nullptr;
  bool at_time_zero = false;    // this evaluation is at MUSEN's time 0 (its `_time == 0` rule)
};

// pair_coeff of the type pair
struct Materials {
  double estar, gstar;          // effective moduli
  double alpha;                 // MUSEN's dAlpha from the restitution coefficient (<= 0)
  double mu, mu_roll;           // sliding and rolling friction
};

// one law's result: normal and tangential force on src, moments on src and dst
struct Result {
  double fn[3], ft[3], m1[3], m2[3];
  double fn_len;                // the normal force's signed size, fn = n fn_len (<= 0: repulsive)
  double heat = 0;              // heat flux into src (W; dst gets -heat), heat laws only
};

class Law {
 public:
  virtual ~Law() = default;
  // xi: the collision's tangential overlap (in: the stored one or the previous law's of this
  // step; out: this law's)
  virtual void force(const Contact &c, const Materials &m, double *xi, Result &r) const = 0;
  // whether the law needs temperatures and gives a heat flux (fix musen/heat)
  virtual bool heats() const { return false; }
  // whether the law reads the temperatures (without a heat flux: d_musen_temperature alone)
  virtual bool reads_temperature() const { return heats(); }
  // how many per-contact values the law keeps (its block of each contact's history; symmetric
  // quantities: the pair style gives both spheres' entries the same block)
  virtual int history_size() const { return 0; }
  // where the law's block starts among the laws' values (the pair style sets it)
  void set_history_offset(int offset) { history_offset = offset; }

 protected:
  // the law's history_size() values of contact c (in/out; zero for a new contact)
  double *own_history(const Contact &c) const { return c.law_history + history_offset; }

 private:
  int history_offset = 0;
};

// the registry of particle-particle laws (musen_law_registry.h)
using Registry = LawRegistry<Law>;
using Factory = Registry::Factory;
inline bool add(const char *name, Factory factory) { return Registry::add(name, factory); }
inline std::unique_ptr<Law> create(const std::string &name, const std::vector<double> &params,
                                   std::string &why)
{
  return Registry::create("particle-particle", name, params, why);
}
inline std::string names() { return Registry::names(); }    // the registered laws, for messages

// MUSEN's Hertz-Mindlin-shaped CalculatePP (ModelPPHertzMindlin.cpp, ModelPPLinearElastic.cpp:
// the same operations around their stiffnesses): Derived gives
//   void stiffness(const Materials &, double overlap, double equiv_radius,
//                  double &kn, double &kt, double &fn_el) const;
// (CRTP: one virtual call per contact and law, none for the stiffness)
template <class Derived> class MindlinShaped : public Law {
 public:
  void force(const Contact &c, const Materials &m, double *xi, Result &r) const override
  {
    calculate_pp(c, m, xi, r);
  }

  // the law itself (MUSEN's CalculatePP), inlined where a caller knows the law (pair
  // musen/hm alone)
  [[gnu::always_inline]] inline void calculate_pp(const Contact &c, const Materials &m,
                                                  double *xi, Result &r) const
  {
    constexpr double TWO_SQRT_5_6 = 1.825741858350553711523232609336;    // _2_SQRT_5_6
    const double *n = c.n, *vt = c.vt;

    // rotate the old tangential overlap into the tangent plane, keeping its length
    const double xi_n = n[0] * xi[0] + n[1] * xi[1] + n[2] * xi[2];
    double xi_rot[3];
    for (int k = 0; k < 3; k++) xi_rot[k] = xi[k] - n[k] * xi_n;
    if (significant(xi_rot)) {
      const double scale = length(xi) / length(xi_rot);
      for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
    }
    for (int k = 0; k < 3; k++) xi[k] = xi_rot[k] + vt[k] * c.dt;

    // normal force with damping (negative: pushes src away from dst)
    double kn, kt, fn_el;
    static_cast<const Derived *>(this)->stiffness(m, c.overlap, c.equiv_radius, kn, kt, fn_el);
    const double fn_damp = -TWO_SQRT_5_6 * m.alpha * c.vn * std::sqrt(kn * c.equiv_mass);

    // tangential force with damping; MUSEN tests the spring force alone against
    // mu |Fn_el + Fn_damp|; when it slips the force is the capped spring force (no damping)
    // and xi shrinks to match it
    double ft_spring[3];
    for (int k = 0; k < 3; k++) ft_spring[k] = xi[k] * kt;
    const double damp_t = -TWO_SQRT_5_6 * m.alpha * std::sqrt(kt * c.equiv_mass);
    const double ft_spring_len = length(ft_spring);
    const double friction_len = m.mu * std::fabs(fn_el + fn_damp);
    double *ft = r.ft;
    if (ft_spring_len > friction_len) {
      for (int k = 0; k < 3; k++) {
        ft[k] = ft_spring[k] * friction_len / ft_spring_len;
        xi[k] = ft[k] / kt;
      }
    } else {
      for (int k = 0; k < 3; k++) ft[k] = ft_spring[k] + vt[k] * damp_t;
    }

    // rolling torque on each sphere's own angular velocity, with the elastic normal force
    double roll1[3] = {0.0, 0.0, 0.0}, roll2[3] = {0.0, 0.0, 0.0};
    if (significant(c.w1)) {
      const double s = -m.mu_roll * std::fabs(fn_el) * c.r1 / length(c.w1);
      for (int k = 0; k < 3; k++) roll1[k] = c.w1[k] * s;
    }
    if (significant(c.w2)) {
      const double s = -m.mu_roll * std::fabs(fn_el) * c.r2 / length(c.w2);
      for (int k = 0; k < 3; k++) roll2[k] = c.w2[k] * s;
    }

    // moments with the full radii (CVector3 operator*: the cross product n x ft)
    const double fn = fn_el + fn_damp;
    const double nxft[3] = {n[1] * ft[2] - n[2] * ft[1], n[2] * ft[0] - n[0] * ft[2],
                            n[0] * ft[1] - n[1] * ft[0]};
    r.fn_len = fn;
    for (int k = 0; k < 3; k++) {
      r.fn[k] = n[k] * fn;
      r.m1[k] = nxft[k] * c.r1 + roll1[k];
      r.m2[k] = nxft[k] * c.r2 + roll2[k];
    }
  }

  // Vector3.h: IsSignificant() is "some |component| > 1e-100"; Length() = sqrt(x*x+y*y+z*z)
  static bool significant(const double *v)
  {
    return std::fabs(v[0]) > 1e-100 || std::fabs(v[1]) > 1e-100 || std::fabs(v[2]) > 1e-100;
  }
  static double length(const double *v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
};

/* MUSEN's relative velocity of the centres, relVel = v_src - v_dst, from the contact-point
   velocity of dst minus src the pair style gives: the spin terms w x rc are perpendicular to n,
   so only the tangential part changes: vt_centres = vt - (w2 x rc2 - w1 x rc1),
   rc1 = n d r1/(r1+r2), rc2 = -n d r2/(r1+r2).  vn_m = normRelVelLen, vt_m = tangRelVel
   (the sintering laws). */
inline void centre_relative_velocity(const Contact &c, double &vn_m, double vt_m[3])
{
  const double *n = c.n;
  const double dist = c.r1 + c.r2 - c.overlap;
  const double s1 = dist * c.r1 / (c.r1 + c.r2), s2 = -dist * c.r2 / (c.r1 + c.r2);
  double spin[3];
  for (int k = 0; k < 3; k++) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    const double w2rc2 = (c.w2[a] * n[b] - c.w2[b] * n[a]) * s2;
    const double w1rc1 = (c.w1[a] * n[b] - c.w1[b] * n[a]) * s1;
    spin[k] = w2rc2 - w1rc1;
  }
  vn_m = -c.vn;
  for (int k = 0; k < 3; k++) vt_m[k] = -(c.vt[k] - spin[k]);
}

}    // namespace musen_pp
}    // namespace LAMMPS_NS

#endif
