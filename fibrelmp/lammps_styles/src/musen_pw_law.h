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

// a law from its parameters; sets why and returns nullptr when they are wrong
using Factory = std::unique_ptr<Law> (*)(const std::vector<double> &params, std::string &why);

bool add(const char *name, Factory factory);
std::unique_ptr<Law> create(const std::string &name, const std::vector<double> &params,
                            std::string &why);
std::string names();    // the registered laws, for messages

}    // namespace musen_pw
}    // namespace LAMMPS_NS

#endif
