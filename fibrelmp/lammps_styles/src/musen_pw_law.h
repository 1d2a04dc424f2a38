/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   MUSEN particle-wall laws for fix musen/wall/mesh.  The fix finds each contact (closest
   point, wall normal, overlap, relative velocity, history entry); a law, chosen by name
   (fix ... musen/wall/mesh FILE law NAME [params]), turns it into the force and torque on
   the sphere; several laws (... law A ... law B ...) act in turn, their forces adding.
   A law is one .cpp file that registers itself with one line:
     const bool registered = musen_pw::add("NAME", &create_function);
------------------------------------------------------------------------- */

#ifndef FIBRELMP_MUSEN_PW_LAW_H
#define FIBRELMP_MUSEN_PW_LAW_H

#include "musen_law_registry.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {
namespace musen_pw {

// what fix musen/wall/mesh found for one sphere touching one triangle
struct Contact {
  double radius, mass;     // the sphere's (MUSEN: R* = R, m* = m)
  double overlap;          // R - |rc| >= 0
  const double *normal;    // the wall's (triangle's) unit normal
  const double *rc_n;      // unit vector from the contact point to the sphere's centre
  const double *omega;     // the sphere's angular velocity
  double vel[3];           // v_sphere - v_wall + the wall's rotation velocity at the contact
  double dt;
  double temperature = 0;  // the sphere's (heat laws only: fix musen/heat)
};

// the laws line of FILE for the sphere's type and the triangle's material
struct Materials {
  double estar, gstar;     // effective moduli
  double alpha;            // MUSEN's dAlpha from the restitution coefficient (<= 0)
  double mu, mu_roll;      // sliding and rolling friction
};

class Law {
 public:
  virtual ~Law() = default;
  // force fo and torque to on the sphere; hist: the contact's 3 history values (created at
  // zero, carried across adjacent triangles by the fix), updated by the law; with several
  // laws each reads what the previous one left this step (MUSEN's one vTangOverlap)
  virtual void force(const Contact &c, const Materials &m, double *hist, double *fo,
                     double *to) const = 0;
  // heat laws: the heat flux into the sphere (W; fix musen/heat)
  virtual bool heats() const { return false; }
  virtual double heat(const Contact &) const { return 0.0; }
};

// the registry of particle-wall laws (musen_law_registry.h)
using Registry = LawRegistry<Law>;
using Factory = Registry::Factory;
inline bool add(const char *name, Factory factory) { return Registry::add(name, factory); }
inline std::unique_ptr<Law> create(const std::string &name, const std::vector<double> &params,
                                   std::string &why)
{
  return Registry::create("particle-wall", name, params, why);
}
inline std::string names() { return Registry::names(); }    // the registered laws, for messages

// MUSEN's Hertz-Mindlin wall contact with a given elastic normal force (ModelPWHertzMindlin.cpp
// CalculatePW, commit e0ff360; ModelPWJKR.cpp and ModelPWPopovJKR.cpp are the same operations
// around their normal force): the force along the WALL's normal, the sphere's spin in the
// relative velocity, tangential damping outside the Coulomb test, rolling torque
// -mu_r |F_n,el| R w/|w|; R* = R, m* = m; MUSEN's operation order kept.  Derived gives
//   double elastic(const Materials &, double overlap, double a, double R, double cos_rc) const;
// (a = sqrt(R overlap), cos_rc = |rc_n . n|).  OLD_OVERLAP_SHEAR: the tangential spring acts on
// the old tangential overlap as it came (ModelPWPopovJKR's code), the new one still stored.
template <class Derived, bool OLD_OVERLAP_SHEAR = false> class MindlinShaped : public Law {
 public:
  void force(const Contact &c, const Materials &L, double *hist, double *fo,
             double *to) const override
  {
    constexpr double TWO_SQRT_5_6 = 1.825741858350553711523232609336;    // _2_SQRT_5_6
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

    // old overlap turned into the tangent plane, its length kept
    double xi_rot[3];
    const double on = dot(n, hist);
    for (int k = 0; k < 3; k++) xi_rot[k] = hist[k] - n[k] * on;
    if (significant(xi_rot)) {
      const double scale = std::sqrt(sqlen(hist)) / std::sqrt(sqlen(xi_rot));
      for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
    }
    double xi_new[3];
    for (int k = 0; k < 3; k++) xi_new[k] = xi_rot[k] + vt[k] * c.dt;

    const double kt = 8 * L.gstar * a;
    const double *sheared = OLD_OVERLAP_SHEAR ? hist : xi_new;
    double ft_shear[3], ft_damp[3], ft[3];
    for (int k = 0; k < 3; k++) ft_shear[k] = sheared[k] * -kt;
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
    if (significant(w_p)) {
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

  // Vector3.h: Dot, CVector3 operator* (the cross product), SquaredLength, IsSignificant
  static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  static void cross(const double *a, const double *b, double *c)
  {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
  }
  static double sqlen(const double *a) { return a[0] * a[0] + a[1] * a[1] + a[2] * a[2]; }
  static bool significant(const double *a)
  {
    return std::fabs(a[0]) > 1e-100 || std::fabs(a[1]) > 1e-100 || std::fabs(a[2]) > 1e-100;
  }
};

}    // namespace musen_pw
}    // namespace LAMMPS_NS

#endif
