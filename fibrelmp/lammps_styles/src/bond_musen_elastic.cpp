/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   BondMusenElastic: see bond_musen_elastic.h.

   The law follows MUSEN's CModelSBElastic::CalculateSB / CModelSBKelvin::CalculateSB and
   their ConsolidatePart term by term, in MUSEN's order of floating-point operations (its
   CVector3 operator* of two vectors is the cross product, CMatrix3 * CVector3 a row-by-row
   dot product), so a bond evolves as in MUSEN given the same positions and velocities.

   Where the bond is evaluated in a step: LAMMPS computes bonds in the force stage, after
   the positions x(t) were updated and with the velocities of the half step, exactly as
   MUSEN's leapfrog evaluates CalculateSB with x(t) and v(t - dt/2).  The break time MUSEN
   writes (EndActivity = the simulator's current time during the force stage) is the time
   of x(t): the step number LAMMPS has during this compute.

   Setup computes (update->setupflag: the start of every run command, run 0, read_restart)
   evaluate the stored state without advancing it, like LAMMPS's granular pair styles do
   with their contact history: a run split into several run commands then computes the same
   forces as one run.
------------------------------------------------------------------------- */

#include "bond_musen_elastic.h"
#include "lammps_time.h"
#include "style_registry.h"
#include "musen_startup.h"

#include "fix_musen_history.h"
#include "fix_musen_leapfrog.h"
#include "fix_musen_verlet.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "pair.h"
#include "update.h"
#include "utils.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;

namespace {

// MUSEN's PI (MUSENDefinitions.h); A and I are computed from d with it as MUSEN does
constexpr double MUSEN_PI = 3.14159265358979323846;
const char *const HISTORY_ID = "FIBRELMP_MUSEN_BOND_HISTORY";

// ---- vector helpers in MUSEN's operation order (CBasicVector3)
inline double dot(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline double length(const double *a)
{
  return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}
inline void cross(const double *a, const double *b, double *c)
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
inline void scale(const double *a, double s, double *c)
{
  c[0] = a[0] * s;
  c[1] = a[1] * s;
  c[2] = a[2] * s;
}
inline void sub(const double *a, const double *b, double *c)
{
  c[0] = a[0] - b[0];
  c[1] = a[1] - b[1];
  c[2] = a[2] - b[2];
}
inline void add(const double *a, const double *b, double *c)
{
  c[0] = a[0] + b[0];
  c[1] = a[1] + b[1];
  c[2] = a[2] + b[2];
}
// MUSEN's matrix M applied to v (CMatrix3 * CVector3)
inline void matvec(const double m[3][3], const double *v, double *c)
{
  c[0] = m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2];
  c[1] = m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2];
  c[2] = m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2];
}

// Kelvin damping capped at ratio * |elastic| (ModelSBKelvin: MAX_DAMP_RATIO, 0 = no cap)
inline void cap_damping(double *damp, double elastic_length, double ratio)
{
  if (ratio != 0.0) {
    const double dl = length(damp);
    if (dl > ratio * elastic_length) {
      const double s = ratio * elastic_length / dl;
      damp[0] *= s;
      damp[1] *= s;
      damp[2] *= s;
    }
  }
}

struct LawInput {
  const double *xl, *xr;    // left sphere, right sphere (the image closest to the left one)
  const double *vl, *vr, *wl, *wr;
  double dt, E, G, mu, Y;   // Y: the bond type's yield strength (plastic, creep)
  double time;              // MUSEN's time of the evaluation (thermal)
  const BondMusenElastic::Law *law;
};

struct LawOutput {
  double total[3];      // force on the left sphere (MUSEN TotalForce)
  double mleft[3];      // moment on the left sphere
  double mright[3];     // moment on the right sphere
  double bond[3];       // left - right
  double strain;
  double normal_force_length;
  double normal_scalar;    // the normal force along the unit bond vector (-A E strain elastic)
  double tangential_force_length;
  bool random_branch;      // weakening: MUSEN would draw rand() here (WEAKENING_FACTOR != 0)
  bool aerogel_unbroken;   // aerogel: the bond was not in a broken state before this step
  bool concrete_break;     // plastic concrete: a tension-side stress below 0 after yielding
};

/* ModelSBAerogel's normal force F (positive: tension; the vector -n F): elastic up to the
   plastic strains PSC < 0 < PST, softening beyond them with SRC / SRT (eps_p the excess times
   1 - SR); where the softened force changes sign the bond is "broken" in compression / tension
   (H_BROKEN -1 / 1, MUSEN's TangentialPlasticStrain.x) and then only resists further
   compression / tension with HRC / HRT from its furthest strain; a force above BST A E breaks
   it (unbroken bonds only). */
void aerogel_normal_force(const LawInput &in, double *h, bool advance, double strain,
                          const double *currentContact, double A, double *normalForce,
                          double &force_out)
{
  using B = BondMusenElastic;
  const double *p = in.law->p;
  double eps_p = h[B::H_PLASTIC];
  double broken = h[B::H_BROKEN];
  const double psc = -fabs(p[B::P_PSC]), pst = fabs(p[B::P_PST]);
  const double KA = A * in.E;
  double F = 0.;
  if (fabs(broken) < 0.5) {
    if ((strain < 0) && (strain < psc)) {
      const double delta = (strain - psc);
      F = psc * KA + delta * p[B::P_SRC] * KA;
      eps_p = delta * (1 - p[B::P_SRC]);
      if (F > 0) {
        broken = -1.;
        F = 0.;
      }
    } else if ((strain > 0) && (strain > pst)) {
      const double delta = (strain - pst);
      F = pst * KA + delta * p[B::P_SRT] * KA;
      eps_p = delta * (1 - p[B::P_SRT]);
      if (F < 0) {
        broken = 1.;
        F = 0.;
      }
    } else {
      F = (strain - eps_p) * KA;
    }
  } else if (broken < -0.5) {
    if (strain < eps_p) eps_p = strain;
    F = KA * p[B::P_HRC] * (strain - eps_p);
  } else if (broken > 0.5) {
    if (strain > eps_p) eps_p = strain;
    F = KA * p[B::P_HRT] * (strain - eps_p);
  }
  if (advance) {
    h[B::H_PLASTIC] = eps_p;
    h[B::H_BROKEN] = broken;
  }
  for (int k = 0; k < 3; k++) normalForce[k] = -1 * currentContact[k] * F;
  force_out = F;
}

/* ModelSBPlasticConcrete's normal force n sigma A (MUSEN's sign: a stretched bond pushes its
   spheres apart, kept), from the elastic strain strain - eps_p: in tension capped at
   0.7 Y - 0.3 E eps_p (eps_p growing by the excess times 1.3 / E; the bond breaks, with
   CONSIDER_BREAKAGE, when the stress is then below 0), in compression at -Y + 0.5 E eps_p
   (eps_p moving by the excess times 0.5 / E). */
void concrete_normal_force(const LawInput &in, double *h, bool advance, double strain,
                           const double *currentContact, double A, double *normalForce,
                           double &stress_out, bool &breaks)
{
  using B = BondMusenElastic;
  const double compr_yield = -in.Y, tens_yield = 0.7 * in.Y;
  const double beta = 0.5, alpha = 0.3, Kn = in.E;
  double eps_p = h[B::H_PLASTIC];
  double elastic = strain - eps_p;
  double stress;
  if (elastic >= 0) {    // tension
    stress = elastic * in.E;
    const double limit = tens_yield - eps_p * Kn * alpha;
    if (stress > limit) {
      eps_p += (stress - limit) * (1 + alpha) / Kn;
      elastic = strain - eps_p;
      stress = elastic * in.E;
    }
    if (in.law->breakage && stress < 0) breaks = true;
  } else {
    stress = elastic * in.E;
    const double limit = compr_yield + eps_p * Kn * beta;
    if (stress < limit) {
      eps_p += (stress - limit) * (1 - beta) / Kn;
      elastic = strain - eps_p;
      stress = elastic * in.E;
    }
  }
  if (advance) h[B::H_PLASTIC] = eps_p;
  for (int k = 0; k < 3; k++) normalForce[k] = currentContact[k] * stress * A;
  stress_out = stress;
}

/* The normal force of the plastic laws, in their operation order, from the plastic strain
   h[H_PLASTIC]; advance: update that strain as the law does (creep: after the force).
   ModelSBElasticPerfectlyPlastic / ModelSBCreep: stress (strain - eps_p) E capped at the
   yield strength Y (times RC in compression), eps_p following the cap; ModelSBLinearPlastic:
   loading with KL, unloading with KU (the bond's E, <= 2, is a factor; above 2 elastic). */
void plastic_normal_force(const LawInput &in, double *h, bool advance, double strain,
                          const double *currentContact, double A, double *normalForce,
                          double &stress_out, bool &random_branch, bool &concrete_break)
{
  using B = BondMusenElastic;
  const B::Law &law = *in.law;
  double &eps_p = h[B::H_PLASTIC];
  if (law.form == B::AEROGEL) {
    aerogel_normal_force(in, h, advance, strain, currentContact, A, normalForce, stress_out);
    return;
  }
  if (law.form == B::CONCRETE) {
    concrete_normal_force(in, h, advance, strain, currentContact, A, normalForce, stress_out,
                          concrete_break);
    return;
  }
  if (law.form == B::WEAKENING) {
    // ModelSBWeakening: beyond the yield strength eps_p = strain - stress WF rand()/RAND_MAX
    // / E; with WF = 0 that is exactly eps_p = strain (no stress), else MUSEN's random draw
    double stress = (strain - eps_p) * in.E;
    if (fabs(stress) > in.Y) {
      if (law.p[B::P_WF] != 0.0) random_branch = true;    // refused by the caller
      const double draw = 0.0;    // WF rand()/RAND_MAX with WF = 0
      const double e = strain - stress * draw / in.E;
      if (advance) eps_p = e;
      stress = (strain - e) * in.E;
    }
    for (int k = 0; k < 3; k++) normalForce[k] = currentContact[k] * stress * (-1 * A);
    stress_out = stress;
    return;
  }
  if (law.form == B::LINEAR_PLASTIC) {
    const double KL = law.p[B::P_KL], KU = law.p[B::P_KU];
    double s;
    if (in.E <= 2.0) {
      if (fabs(KU * (strain - eps_p)) > fabs(KL * strain)) {    // loading: eps_p grows
        s = -1 * A * KL * strain * in.E;
        if (advance) eps_p = strain * (1 - KL / KU);
      } else {
        s = -1 * A * KU * (strain - eps_p) * in.E;
      }
    } else {
      s = -1 * A * in.E * strain;
    }
    scale(currentContact, s, normalForce);
    stress_out = s;
    return;
  }
  double stress = (strain - eps_p) * in.E;
  double Y = in.Y;
  if (stress < 0) Y *= law.p[B::P_RC];    // compression
  if (stress > Y) {
    if (advance) eps_p = strain - Y / in.E;
    stress = Y;
  } else if (stress < -Y) {
    if (advance) eps_p = strain + Y / in.E;
    stress = -Y;
  }
  // currentContact * stress * (-1 * CrossCut): the vector times each scalar in turn
  for (int k = 0; k < 3; k++) normalForce[k] = currentContact[k] * stress * (-1 * A);
  stress_out = stress;
  if (advance && law.form == B::CREEP) {    // creep in the normal direction
    const double rate = in.dt * law.p[B::P_A] * pow(fabs(stress), law.p[B::P_M]);
    if (stress > 0)
      eps_p += rate;
    else
      eps_p -= rate;
  }
}

/* The tangential yield (and creep) of the plastic and creep laws on the just advanced
   overlap, in ModelSBElasticPerfectlyPlastic / ModelSBCreep's order.  MUSEN's CPU code
   compares the tangential stress with the unscaled yield strength but scales the overlap to
   the one of the normal stress's sign (times RC in compression): kept. */
void plastic_tangential(const LawInput &in, double *overlap, double L0, double stress)
{
  using B = BondMusenElastic;
  const B::Law &law = *in.law;
  double tau = length(overlap) * in.G / L0;
  double Y = in.Y;
  if (stress < 0) Y *= law.p[B::P_RC];
  if (law.p[B::P_TY] != 0.0 && tau > in.Y) {
    const double s = Y * L0 / (in.G * length(overlap));
    for (int k = 0; k < 3; k++) overlap[k] *= s;
    tau = Y;
  }
  if (law.form == B::CREEP) {
    const double sq = overlap[0] * overlap[0] + overlap[1] * overlap[1] + overlap[2] * overlap[2];
    if (sq > 0) {
      const double s = 1 - in.dt * law.p[B::P_A] * pow(fabs(tau), law.p[B::P_M]) * L0 /
          length(overlap);
      for (int k = 0; k < 3; k++) overlap[k] *= s;
    }
  }
}

// F_t: overlap G A / L0; ModelSBPlasticConcrete: (overlap - its tangential plastic strain,
// which only M rotates and so stays 0) G A, without the 1 / L0
void tangential_force(int form, const double *overlap, double kt, double G, double A,
                      double *force)
{
  if (form == BondMusenElastic::CONCRETE)
    for (int k = 0; k < 3; k++) force[k] = overlap[k] * G * A;
  else
    scale(overlap, kt, force);
}

/* ModelSBThermal's normal damping -MU v_n A E |strain|, capped at the normal force's size */
void thermal_normal_damping(const LawInput &in, const double *normalVelocity, double A,
                            double strain, const double *normalForce, double *dampn)
{
  using B = BondMusenElastic;
  const double mu = in.law->p[B::P_MU];
  for (int k = 0; k < 3; k++) dampn[k] = -mu * normalVelocity[k] * A * in.E * fabs(strain);
  cap_damping(dampn, length(normalForce), 1.0);
}

/* ModelSBThermal's tangential damping -MU v_t x overlap (CVector3 *: the cross product) kt,
   capped at the tangential force's size */
void thermal_tangential_damping(const LawInput &in, const double *tangentialVelocity,
                                const double *overlap, double kt, const double *tangentialForce,
                                double *dampt)
{
  using B = BondMusenElastic;
  const double mu = in.law->p[B::P_MU];
  double scaled[3], c[3];
  for (int k = 0; k < 3; k++) scaled[k] = -mu * tangentialVelocity[k];
  cross(scaled, overlap, c);
  for (int k = 0; k < 3; k++) dampt[k] = c[k] * kt;
  cap_damping(dampt, length(tangentialForce), 1.0);
}

/* One evaluation of MUSEN's solid bond on the state h (FixMusenHistory values, H_* layout).
   advance: MUSEN's CalculateSB (rotate and increment the state by one step of dt);
   otherwise the forces of the stored state (tangential overlap, moments, damping; the
   plastic laws' normal force) at the current positions.  fresh (not advancing): a bond's
   first evaluation, which has no stored damping or plastic normal force: compute and store
   them from the current positions and velocities. */
template <int FORM>
void musen_law_of(const LawInput &in, double *h, bool advance, bool fresh, LawOutput &out)
{
  using B = BondMusenElastic;
  // FORM >= 0: compiled for that law alone (its branches folded away; the same operations)
  const int form = FORM >= 0 ? FORM : in.law->form;
  const bool kelvin = form == B::KELVIN;
  // ModelSBThermal: the elastic bond with its rest length growing in time, MU-damped
  const bool thermal = form == B::THERMAL;
  const bool damped = kelvin || thermal;
  const bool plastic = form != B::ELASTIC && form != B::KELVIN && !thermal;
  const double d = h[B::H_DIAMETER], L0 = h[B::H_LENGTH0];
  const double A = MUSEN_PI * d * d / 4;                // CrossCut (SimplifiedScene)
  const double I = MUSEN_PI * d * d * d * d / 64;       // AxialMoment

  double relAngleVel[3], currentBond[3], rAC[3], sumAngleVelocity[3], relativeVelocity[3];
  double tmp[3], tmp2[3];
  sub(in.wl, in.wr, relAngleVel);
  sub(in.xl, in.xr, currentBond);    // GetSolidBond(right, left) = left - right
  const double dist = length(currentBond);
  scale(currentBond, 0.5, rAC);
  add(in.wl, in.wr, sumAngleVelocity);
  sub(in.vl, in.vr, tmp);
  cross(sumAngleVelocity, rAC, tmp2);
  sub(tmp, tmp2, relativeVelocity);

  double currentContact[3] = {currentBond[0] / dist, currentBond[1] / dist, currentBond[2] / dist};

  double normalVelocity[3], tangentialVelocity[3];
  scale(currentContact, dot(currentContact, relativeVelocity), normalVelocity);
  sub(relativeVelocity, normalVelocity, tangentialVelocity);

  // thermal: dInitLength = InitialLength (1 + THERM_DIFF TimeThermExpCoeff t)
  const double Lr = thermal ? L0 * (1 + in.law->p[B::P_TDIFF] * in.law->p[B::P_ALPHA] * in.time) : L0;
  const double strain = (dist - Lr) / Lr;
  double normal_scalar = -1 * A * in.E * strain;
  double normalForce[3];
  double plastic_stress = 0.0;    // plastic, creep: the normal stress after the cap
  out.random_branch = false;
  out.concrete_break = false;
  out.aerogel_unbroken = fabs(h[B::H_BROKEN]) < 0.5;
  if (!plastic) {
    scale(currentContact, normal_scalar, normalForce);
  } else {
    if (advance || fresh) {
      plastic_normal_force(in, h, advance, strain, currentContact, A, normalForce, plastic_stress,
                           out.random_branch, out.concrete_break);
      h[B::H_NFORCE] = plastic_stress;
    } else {
      // the normal force last applied (its plastic strain has moved on since): the same
      // operations on the stored stress (linear/plastic: force)
      plastic_stress = h[B::H_NFORCE];
      if (form == B::LINEAR_PLASTIC)
        scale(currentContact, plastic_stress, normalForce);
      else if (form == B::AEROGEL)
        for (int k = 0; k < 3; k++) normalForce[k] = -1 * currentContact[k] * plastic_stress;
      else if (form == B::CONCRETE)
        for (int k = 0; k < 3; k++) normalForce[k] = currentContact[k] * plastic_stress * A;
      else
        for (int k = 0; k < 3; k++) normalForce[k] = currentContact[k] * plastic_stress * (-1 * A);
    }
    normal_scalar = form == B::LINEAR_PLASTIC ? plastic_stress
        : form == B::AEROGEL                  ? -plastic_stress
        : form == B::CONCRETE                 ? plastic_stress * A
                                              : -plastic_stress * A;
  }

  double *overlap = h + B::H_OVERLAP;
  double *nmoment = h + B::H_NMOMENT;
  double *tmoment = h + B::H_TMOMENT;
  double *dampn = h + B::H_DAMPN;
  double *dampt = h + B::H_DAMPT;
  const double kt = in.G * A / L0;
  double tangentialForce[3];

  if (advance) {
    double tv[3], phi[3];
    cross(h + B::H_PREVBOND, currentBond, tv);
    scale(currentContact, dot(sumAngleVelocity, currentContact) * in.dt * 0.5, phi);
    // ModelSBElastic.cpp: the rotation of the bond frame over the step (first order)
    const double M[3][3] = {
        {1 + tv[2] * phi[2] + tv[1] * phi[1], phi[2] - tv[2] - tv[1] * phi[0],
         -phi[1] - tv[2] * phi[0] + tv[1]},
        {tv[2] - phi[2] - tv[0] * phi[1], tv[2] * phi[2] + 1 + tv[0] * phi[0],
         -tv[2] * phi[1] + phi[0] - tv[0]},
        {-tv[1] - tv[0] * phi[2] + phi[1], -tv[1] * phi[2] + tv[0] - phi[0],
         tv[1] * phi[1] + tv[0] * phi[0] + 1}};

    double normalAngleVel[3], tangAngleVel[3];
    scale(currentContact, dot(currentContact, relAngleVel), normalAngleVel);
    sub(relAngleVel, normalAngleVel, tangAngleVel);

    if (kelvin) {
      // -mu * v_n * A * E * |strain|, left to right
      for (int k = 0; k < 3; k++) dampn[k] = normalVelocity[k] * -in.mu * A * in.E * fabs(strain);
      cap_damping(dampn, length(normalForce), in.law->max_damp_ratio);
    }
    if (thermal) thermal_normal_damping(in, normalVelocity, A, strain, normalForce, dampn);

    matvec(M, overlap, tmp);
    scale(tangentialVelocity, in.dt, tmp2);
    sub(tmp, tmp2, overlap);
    if (form == B::PLASTIC || form == B::CREEP) plastic_tangential(in, overlap, L0, plastic_stress);
    if (form == B::WEAKENING) {
      // ModelSBWeakening: beyond the yield strength the overlap times WF rand()/RAND_MAX
      double t[3];
      for (int k = 0; k < 3; k++) t[k] = overlap[k] * in.G / L0;
      if (length(t) > in.Y) {
        if (in.law->p[B::P_WF] != 0.0) out.random_branch = true;
        for (int k = 0; k < 3; k++) overlap[k] *= 0.0;    // WF rand()/RAND_MAX, WF = 0
      }
    }
    tangential_force(form, overlap, kt, in.G, A, tangentialForce);

    if (kelvin) {
      const double ol = length(overlap);
      for (int k = 0; k < 3; k++) dampt[k] = tangentialVelocity[k] * -in.mu * ol * kt;
      cap_damping(dampt, length(tangentialForce), in.law->max_damp_ratio);
    }
    if (thermal) thermal_tangential_damping(in, tangentialVelocity, overlap, kt, tangentialForce, dampt);

    matvec(M, nmoment, tmp);
    if (form == B::CONCRETE)    // ModelSBPlasticConcrete: (w_n (dt 2 I G)) / L0
      for (int k = 0; k < 3; k++) tmp2[k] = normalAngleVel[k] * (in.dt * 2 * I * in.G) / L0;
    else
      scale(normalAngleVel, in.dt * 2 * I * in.G / L0, tmp2);
    sub(tmp, tmp2, nmoment);
    matvec(M, tmoment, tmp);
    if (form == B::CONCRETE)
      for (int k = 0; k < 3; k++) tmp2[k] = tangAngleVel[k] * (in.dt * in.E * I) / L0;
    else
      scale(tangAngleVel, in.dt * in.E * I / L0, tmp2);
    sub(tmp, tmp2, tmoment);
    for (int k = 0; k < 3; k++) h[B::H_PREVBOND + k] = currentBond[k];
  } else {
    tangential_force(form, overlap, kt, in.G, A, tangentialForce);
    if (kelvin && fresh) {
      for (int k = 0; k < 3; k++) dampn[k] = normalVelocity[k] * -in.mu * A * in.E * fabs(strain);
      cap_damping(dampn, length(normalForce), in.law->max_damp_ratio);
      const double ol = length(overlap);
      for (int k = 0; k < 3; k++) dampt[k] = tangentialVelocity[k] * -in.mu * ol * kt;
      cap_damping(dampt, length(tangentialForce), in.law->max_damp_ratio);
    }
    if (thermal && fresh) {
      thermal_normal_damping(in, normalVelocity, A, strain, normalForce, dampn);
      thermal_tangential_damping(in, tangentialVelocity, overlap, kt, tangentialForce, dampt);
    }
  }

  if (thermal) {
    // ModelSBThermal: vNormalForce += damping, TangentialForce += damping, both before
    // TotalForce, UnsymMoment and its breakage test
    add(normalForce, dampn, normalForce);
    add(tangentialForce, dampt, tangentialForce);
  }
  add(normalForce, tangentialForce, out.total);
  if (kelvin) {
    add(out.total, dampn, out.total);
    add(out.total, dampt, out.total);
  }
  double unsym[3], msum[3];
  cross(rAC, tangentialForce, unsym);    // MUSEN UnsymMoment: from the elastic part only (thermal: with its damping)
  add(nmoment, tmoment, msum);
  sub(msum, unsym, out.mleft);           // ConsolidatePart, left:  + (M_n + M_t) - rAC x F_t
  add(msum, unsym, out.mright);          //                 right: - ((M_n + M_t) + rAC x F_t)
  for (int k = 0; k < 3; k++) {
    out.mright[k] = -out.mright[k];
    out.bond[k] = currentBond[k];
  }
  out.strain = strain;
  out.normal_force_length = length(normalForce);
  out.normal_scalar = normal_scalar;
  out.tangential_force_length = length(tangentialForce);
}

// MUSEN's elastic bond (the common case) compiled on its own, every other law by the general code
void musen_law(const LawInput &in, double *h, bool advance, bool fresh, LawOutput &out)
{
  if (in.law->form == BondMusenElastic::ELASTIC)
    musen_law_of<BondMusenElastic::ELASTIC>(in, h, advance, fresh, out);
  else
    musen_law_of<-1>(in, h, advance, fresh, out);
}

// MUSEN's stress breakage test (ModelSBElastic: CONSIDER_BREAKAGE 1 and 2; ModelSBKelvin,
// ModelSBLinearPlastic: 1; ModelSBCreep: FRACTURE_BY_STRESS 1)
bool musen_breaks(int criterion, const double *h, const LawOutput &out, double sigma_n,
                  double tau_s)
{
  using B = BondMusenElastic;
  if (criterion == 0) return false;
  const double d = h[B::H_DIAMETER];
  const double A = MUSEN_PI * d * d / 4;
  const double I = MUSEN_PI * d * d * d * d / 64;
  double forceLength = out.normal_force_length;
  if (out.strain <= 0) forceLength *= -1;    // compression counts negative
  const double maxStress1 = forceLength / A;
  const double maxStress2 = length(h + B::H_TMOMENT) * d / (2.0 * I);
  const double maxTorque1 = out.tangential_force_length / A;
  const double maxTorque2 = length(h + B::H_NMOMENT) * d / (4.0 * I);
  if (criterion == 1)
    return maxStress1 + maxStress2 >= sigma_n || maxTorque1 + maxTorque2 >= tau_s;
  return maxStress1 >= sigma_n || (maxStress2 >= sigma_n && out.strain > 0) ||
      maxTorque1 >= tau_s || maxTorque2 >= tau_s;
}

const char *law_name(int form)
{
  static const char *const names[] = {"elastic", "kelvin", "plastic", "linear/plastic", "creep",
                                      "weakening", "aerogel", "concrete", "heat", "thermal"};
  return names[form];
}

// ModelSBAerogel: an unbroken bond whose force exceeds BST A E
bool aerogel_breaks(const BondMusenElastic::Law &law, const LawOutput &out, double d, double E)
{
  using B = BondMusenElastic;
  if (law.form != B::AEROGEL) return false;
  const double KA = MUSEN_PI * d * d / 4 * E;
  // out.normal_scalar = -F; a bond in a broken state (H_BROKEN) has no such test
  return out.aerogel_unbroken && -out.normal_scalar > (fabs(law.p[B::P_BST]) * KA);
}

// ModelSBElasticPerfectlyPlastic, ModelSBCreep: the fracture strains (FC 0: none)
bool strain_breaks(const BondMusenElastic::Law &law, double strain)
{
  using B = BondMusenElastic;
  if (law.form == B::WEAKENING)    // ModelSBWeakening: with CONSIDER_BREAKAGE on
    return law.breakage &&
        (strain > law.p[B::P_BS] || (law.p[B::P_CB] != 0.0 && strain < -2 * law.p[B::P_BS]));
  if (law.form != B::PLASTIC && law.form != B::CREEP) return false;
  return strain > law.p[B::P_FT] || (law.p[B::P_FC] != 0.0 && strain < -law.p[B::P_FC]);
}

}    // namespace

/* ---------------------------------------------------------------------- */

BondMusenElastic::BondMusenElastic(LAMMPS *lmp) :
    Bond(lmp), youngs(nullptr), shear(nullptr), sigma_n(nullptr), tau_s(nullptr),
    viscosity(nullptr), diam0(nullptr), len0(nullptr), yield(nullptr),
    first_law{ELASTIC, 1.0, 1, {}}, breaks_fp(nullptr), per_atom_geometry(0), nslots(0), nvalues_per(0),
    update_special(0), pairs_waiting(0), warned_build(0), max_length0(0.0), history(nullptr),
    history_id(HISTORY_ID), verlet(nullptr)
{
  partial_flag = 1;    // broken bonds get type 0 (the neighbor lists then skip them)
  writedata = 0;       // the per-bond geometry is not a bond type's coefficient
  single_extra = 7;    // force on the first atom (3), tangential overlap (3), |M_n + M_t|
  svector = new double[single_extra];
  born_matrix_enable = 0;
}

BondMusenElastic::~BondMusenElastic()
{
  if (copymode) return;
  delete[] svector;
  svector = nullptr;
  if (breaks_fp) fclose(breaks_fp);
  if (history && modify && modify->get_fix_by_id(history_id)) modify->delete_fix(history_id);
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(youngs);
    memory->destroy(shear);
    memory->destroy(sigma_n);
    memory->destroy(tau_s);
    memory->destroy(viscosity);
    memory->destroy(diam0);
    memory->destroy(len0);
    memory->destroy(yield);
  }
}

/* ---------------------------------------------------------------------- */

void BondMusenElastic::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);

  double **x = atom->x;
  tagint *tag = atom->tag;
  const int nlocal = atom->nlocal;
  const int newton_bond = force->newton_bond;
  int **bondlist = neighbor->bondlist;
  const int nbondlist = neighbor->nbondlist;
  const bool advance = musen_startup::advances(update);    // musen_startup.h
  note_list_build();

  for (int n = 0; n < nbondlist; n++) {
    const int i1 = bondlist[n][0];    // stores the bond: MUSEN's left sphere
    const int i2 = bondlist[n][1];    // its partner's image closest to i1
    const int type = bondlist[n][2];
    if (type <= 0) continue;

    double *h = history->find(i1, tag[i2]);
    bool fresh = false;
    if (!h) {
      h = init_entry(i1, i2, type);
      fresh = true;
    }
    double total[3] = {0.0, 0.0, 0.0}, broke_state[7] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    const bool broke = apply_laws(i1, i2, type, h, advance, fresh, total, broke_state);
    if (broke) {
      // MUSEN: Active = false, EndActivity = time; an inactive bond is not consolidated
      bondlist[n][2] = 0;
      for (int m = 0; m < atom->num_bond[i1]; m++)
        if (atom->bond_atom[i1][m] == tag[i2] && atom->bond_type[i1][m] == type) {
          atom->bond_type[i1][m] = 0;
          break;
        }
      history->erase(i1, tag[i2]);
      broken.push_back(update->ntimestep);
      broken.push_back(tag[i1]);
      broken.push_back(tag[i2]);
      broken_force.insert(broken_force.end(), broke_state, broke_state + 7);
    }
    if (evflag) {
      double del[3];
      sub(x[i1], x[i2], del);
      ev_tally_xyz(i1, i2, nlocal, newton_bond, 0.0, total[0], total[1], total[2], del[0], del[1],
                   del[2]);
    }
  }

  if (any_breakage()) process_breaks();
}

/* ----------------------------------------------------------------------
   the laws in turn on one bond (CalculateForcesSB: each model's CalculateSB, then its
   ConsolidatePart, over the bonds still active): each adds its force and moments to the
   two spheres unless its own test breaks the bond, which ends the bond for the later laws.
   Advancing, every law continues the shared state h; every law but the last then keeps its
   part (H_LAWSTATE values) for set-up evaluations, which take each law's own copy.
   total: the force on the left sphere summed over the laws applied.  Returns: broken.
------------------------------------------------------------------------- */

bool BondMusenElastic::apply_laws(int i1, int i2, int type, double *h, bool advance, bool fresh,
                                  double *total, double *broke_state)
{
  double **f = atom->f;
  double **torque = atom->torque;
  LawInput in;
  in.xl = atom->x[i1];
  in.xr = atom->x[i2];
  in.vl = atom->v[i1];
  in.vr = atom->v[i2];
  in.wl = atom->omega[i1];
  in.wr = atom->omega[i2];
  in.dt = update->dt;
  in.time = simulation_time(update);
  in.E = youngs[type];
  in.G = shear[type];
  in.mu = viscosity[type];
  in.Y = yield[type];
  LawOutput out;
  const int nlaws = 1 + (int) then_laws.size();
  double scratch[H_SIZE];
  for (int k = 0; k < nlaws; k++) {
    const Law &law = k == 0 ? first_law : then_laws[k - 1];
    if (law.form == HEAT) {    // no force, no state: only the heat flux
      bond_heat(law, i1, i2, h[H_DIAMETER]);
      continue;
    }
    in.law = &law;
    double *own = h + H_SIZE + H_LAWSTATE * k;    // law k's copy (k < nlaws - 1)
    double *state = h;
    if (!advance && k < nlaws - 1) {    // a set-up evaluation of law k's own state
      std::copy(h, h + H_SIZE, scratch);
      std::copy(own, own + H_LAWSTATE, scratch);
      state = scratch;
    }
    musen_law(in, state, advance, fresh, out);
    if (k < nlaws - 1) std::copy(state, state + H_LAWSTATE, own);
    if (out.random_branch)
      error->one(FLERR, "Bond style musen/elastic: bond {}-{} exceeds its yield strength at step "
                 "{}, where MUSEN's weakening bond multiplies by WEAKENING_FACTOR rand()/RAND_MAX: "
                 "a random draw fibrelmp cannot reproduce (WEAKENING_FACTOR 0 is exact)",
                 atom->tag[i1], atom->tag[i2], update->ntimestep);
    if (out.concrete_break || strain_breaks(law, out.strain) ||
        aerogel_breaks(law, out, h[H_DIAMETER], in.E) ||
        musen_breaks(law.form == WEAKENING || law.form == CONCRETE ? 0 : law.breakage, state,
                     out, sigma_n[type],
                     tau_s[type])) {
      // what MUSEN's bond still holds: TotalForce, TangentialOverlap, |M_n + M_t|
      double msum[3];
      add(state + H_NMOMENT, state + H_TMOMENT, msum);
      for (int c = 0; c < 3; c++) {
        broke_state[c] = out.total[c];
        broke_state[3 + c] = state[H_OVERLAP + c];
      }
      broke_state[6] = length(msum);
      return true;
    }
    for (int c = 0; c < 3; c++) {
      f[i1][c] += out.total[c];
      torque[i1][c] += out.mleft[c];
      f[i2][c] -= out.total[c];
      torque[i2][c] += out.mright[c];
      total[c] += out.total[c];
    }
  }
  return false;
}

/* ModelSBHeatConduction::CalculateSB / ConsolidatePart: q = SCALE A K (T_right - T_left) / |x_r -
   x_l|, A = pi d^2 / 4 (SolidBond.cpp's cross-cut), into the left sphere (i1), out of the right */
void BondMusenElastic::bond_heat(const Law &law, int i1, int i2, double d)
{
  int dim, flag, cols;
  double *flux = static_cast<double *>(heat_fix->extract("flux", dim));
  const double *t = atom->dvector[atom->find_custom("musen_temperature", flag, cols)];
  const double *xl = atom->x[i1], *xr = atom->x[i2];
  const double bond[3] = {xr[0] - xl[0], xr[1] - xl[1], xr[2] - xl[2]};
  const double distance = std::sqrt(bond[0] * bond[0] + bond[1] * bond[1] + bond[2] * bond[2]);
  const double cross_cut = MUSEN_PI * d * d / 4;
  const double q = law.p[P_SCALE] * cross_cut * law.p[P_K] * (t[i2] - t[i1]) / distance;
  flux[i1] += q;
  flux[i2] -= q;    // a ghost's: fix musen/heat sends it back to its owner
}

bool BondMusenElastic::any_breakage() const
{
  // the plastic and creep laws always test their fracture strain in tension, aerogel its force
  auto breaks = [](const Law &law) {
    return law.breakage || law.form == PLASTIC || law.form == CREEP || law.form == AEROGEL;
  };
  if (breaks(first_law)) return true;
  for (const Law &law : then_laws)
    if (breaks(law)) return true;
  return false;
}

bool BondMusenElastic::uses_yield() const
{
  auto needs = [](const Law &law) {
    return law.form == PLASTIC || law.form == CREEP || law.form == WEAKENING ||
        law.form == CONCRETE;
  };
  if (needs(first_law)) return true;
  for (const Law &law : then_laws)
    if (needs(law)) return true;
  return false;
}


/* ----------------------------------------------------------------------
   the state of a bond met for the first time: its d and L0 (per-atom arrays or the type's
   coefficients; L0 <= 0: the current distance), the initial tangential overlap (per-atom
   arrays, else 0), zero moments, and the bond vector left - right as previous bond.
   (MUSEN's AddSolidBond stores right - left there, but its first, half-step "prediction"
   step calls CalculateSB with unchanged positions, where PrevBond x currentBond is exactly
   0 either way, and leaves left - right behind: what its later steps use.)
------------------------------------------------------------------------- */

double *BondMusenElastic::init_entry(int i1, int i2, int type)
{
  const tagint partner = atom->tag[i2];
  double d, L0, ov[3] = {0.0, 0.0, 0.0};
  if (per_atom_geometry) {
    int k = 0;
    while (k < nslots && atom->ivector[ipartners[k]][i1] != partner) k++;
    if (k == nslots)
      error->one(FLERR,
                 "Bond style musen/elastic: bond {}-{} has no entry in the per-atom slots i_{}1.."
                 "i_{}{} (the first atom of a bond lists its partner there)",
                 atom->tag[i1], partner, partners_name, partners_name, nslots);
    const double *val = atom->darray[ivalues[k]][i1];
    d = val[0];
    L0 = val[1];
    if (nvalues_per == 5)
      for (int c = 0; c < 3; c++) ov[c] = val[2 + c];
  } else {
    d = diam0[type];
    L0 = len0[type];
  }
  if (!(d > 0.0) || !std::isfinite(d) || !std::isfinite(L0))
    error->one(FLERR, "Bond style musen/elastic: bond {}-{} has diameter {} and length {}",
               atom->tag[i1], partner, d, L0);
  double bond[3];
  sub(atom->x[i1], atom->x[i2], bond);
  if (L0 <= 0.0) L0 = length(bond);    // RESET_INITIAL_BOND_LENGTH: the current distance
  if (!(L0 > 0.0))
    error->one(FLERR, "Bond style musen/elastic: bond {}-{} joins two spheres at one point",
               atom->tag[i1], partner);
  max_length0 = std::max(max_length0, L0);

  double *h = history->get(i1, partner);
  for (int c = 0; c < 3; c++) {
    h[H_OVERLAP + c] = ov[c];
    h[H_PREVBOND + c] = bond[c];
  }
  h[H_DIAMETER] = d;
  h[H_LENGTH0] = L0;
  for (size_t k = 0; k < then_laws.size(); k++)    // every law's copy starts from it
    std::copy(h, h + H_LAWSTATE, h + H_SIZE + H_LAWSTATE * k);
  return h;
}

/* ----------------------------------------------------------------------
   bonds broken on any rank in this compute: counted, written (rank 0, sorted, so the
   file does not depend on the domain decomposition) and, where bonded spheres do not
   interact by contact (1-2 special weights not 1), removed from the special lists
------------------------------------------------------------------------- */

void BondMusenElastic::process_breaks()
{
  int mine = static_cast<int>(broken.size());
  int total = mine;
  if (comm->nprocs > 1) MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, world);
  if (total == 0) return;

  std::vector<bigint> all;
  std::vector<double> all_force;
  if (comm->nprocs > 1) {
    std::vector<int> counts(comm->nprocs), displs(comm->nprocs, 0);
    MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
    for (int p = 1; p < comm->nprocs; p++) displs[p] = displs[p - 1] + counts[p - 1];
    all.resize(total);
    MPI_Allgatherv(broken.data(), mine, MPI_LMP_BIGINT, all.data(), counts.data(), displs.data(),
                   MPI_LMP_BIGINT, world);
    // 7 doubles per break where there are 3 bigints
    std::vector<int> dcounts(comm->nprocs), ddispls(comm->nprocs);
    for (int p = 0; p < comm->nprocs; p++) {
      dcounts[p] = counts[p] / 3 * 7;
      ddispls[p] = displs[p] / 3 * 7;
    }
    all_force.resize((size_t) total / 3 * 7);
    MPI_Allgatherv(broken_force.data(), mine / 3 * 7, MPI_DOUBLE, all_force.data(), dcounts.data(),
                   ddispls.data(), MPI_DOUBLE, world);
  } else {
    all.swap(broken);
    all_force.swap(broken_force);
  }
  broken.clear();
  broken_force.clear();

  const int nbroken = total / 3;
  std::vector<std::array<bigint, 3>> rec(nbroken);
  std::vector<int> order(nbroken);
  for (int r = 0; r < nbroken; r++) {
    rec[r] = {all[3 * r], all[3 * r + 1], all[3 * r + 2]};
    order[r] = r;
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return rec[a] < rec[b]; });

  atom->nbonds -= nbroken;
  if (comm->me == 0 && breaks_fp && timed_breaks) {
    // MUSEN's time of this evaluation (the fix keeps atime at it: atimestep is this step)
    const double t = simulation_time(update);
    for (int k : order) {
      utils::print(breaks_fp, "{} {} {} {:.17g}", rec[k][0], rec[k][1], rec[k][2], t);
      for (int c = 0; c < 7; c++) utils::print(breaks_fp, " {:.17g}", all_force[7 * (size_t) k + c]);
      fputc('\n', breaks_fp);
    }
    fflush(breaks_fp);
  } else if (comm->me == 0 && breaks_fp) {
    for (int k : order) {
      utils::print(breaks_fp, "{} {} {}", rec[k][0], rec[k][1], rec[k][2]);
      for (int c = 0; c < 7; c++) utils::print(breaks_fp, " {:.17g}", all_force[7 * (size_t) k + c]);
      fputc('\n', breaks_fp);
    }
    fflush(breaks_fp);
  }
  if (update_special && verlet) {
    // the pair waits for MUSEN's next contact-list update (fix musen/verlet)
    std::vector<std::pair<tagint, tagint>> pairs;
    for (int k : order) pairs.emplace_back((tagint) rec[k][1], (tagint) rec[k][2]);
    verlet->add_broken(pairs);
  } else if (update_special) {
    for (int k : order) forget_special((tagint) rec[k][1], (tagint) rec[k][2]);
    pairs_waiting += nbroken;
  }
}

/* without fix musen/verlet: broken pairs join the contacts at this LAMMPS neighbor-list
   build; MUSEN adds them at its own contact-list update, which its Verlet-distance rule may
   place at another step: said once, when it happens */

void BondMusenElastic::note_list_build()
{
  if (!pairs_waiting || neighbor->ago != 0) return;
  if (!warned_build && comm->me == 0)
    error->warning(FLERR, "Bond style musen/elastic: {} broken bonds' spheres join the contact "
                   "pairs at LAMMPS's neighbor-list build of step {}; MUSEN adds them at its own "
                   "contact-list update, which may come at another step", pairs_waiting,
                   update->ntimestep);
  warned_build = 1;
  pairs_waiting = 0;
}

/* without fix musen/verlet (a hand-written input): a broken bond's spheres are no longer 1-2
   neighbours: drop each from the other's special list (owned atoms; the neighbor build reads
   those).  The pair neighbor list built while they were bonded keeps their pair marked
   special, so their contact acts from LAMMPS's next neighbor-list build.  MUSEN's acts from
   its next contact-list update (CVerletList::UpdateList: RemoveSBContacts keeps out only
   pairs of active bonds; between updates a pair left out stays out): fix musen/verlet
   emulates that schedule and takes the pairs over. */

void BondMusenElastic::forget_special(tagint a, tagint b)
{
  const int nlocal = atom->nlocal;
  for (int side = 0; side < 2; side++) {
    const tagint me = side ? b : a, other = side ? a : b;
    const int i = atom->map(me);
    if (i < 0 || i >= nlocal) continue;
    tagint *sp = atom->special[i];
    int *ns = atom->nspecial[i];
    for (int k = 0; k < ns[0]; k++)
      if (sp[k] == other) {
        for (int m = k; m < ns[2] - 1; m++) sp[m] = sp[m + 1];
        ns[0]--;
        ns[1]--;
        ns[2]--;
        break;
      }
  }
}

/* ---------------------------------------------------------------------- */

void BondMusenElastic::allocate()
{
  allocated = 1;
  const int np1 = atom->nbondtypes + 1;
  memory->create(youngs, np1, "bond:youngs");
  memory->create(shear, np1, "bond:shear");
  memory->create(sigma_n, np1, "bond:sigma_n");
  memory->create(tau_s, np1, "bond:tau_s");
  memory->create(viscosity, np1, "bond:viscosity");
  memory->create(diam0, np1, "bond:diam0");
  memory->create(len0, np1, "bond:len0");
  memory->create(yield, np1, "bond:yield");
  memory->create(setflag, np1, "bond:setflag");
  for (int i = 1; i < np1; i++) {
    setflag[i] = 0;
    diam0[i] = len0[i] = 0.0;
    yield[i] = std::nan("");    // bond_coeff ... yield Y (the plastic laws need it)
  }
}

/* the parameters of a law after its form's word: kelvin R | plastic FT FC TY RC |
   linear/plastic KL KU | creep FT FC TY RC A m (elastic: none); returns how many it read */

int BondMusenElastic::parse_law(const std::string &form, int narg, char **arg, Law &law)
{
  int n = 0;
  if (form == "elastic") {
    law.form = ELASTIC;
  } else if (form == "kelvin") {
    law.form = KELVIN;
    n = 1;
  } else if (form == "plastic") {
    law.form = PLASTIC;
    n = 4;
  } else if (form == "linear/plastic") {
    law.form = LINEAR_PLASTIC;
    n = 2;
  } else if (form == "creep") {
    law.form = CREEP;
    n = 6;
  } else if (form == "weakening") {
    law.form = WEAKENING;
    n = 3;
  } else if (form == "aerogel") {
    law.form = AEROGEL;
    n = 7;
  } else if (form == "concrete") {
    law.form = CONCRETE;
  } else if (form == "heat") {
    law.form = HEAT;
    n = 2;
  } else if (form == "thermal") {
    law.form = THERMAL;
    n = 3;
  } else {
    error->all(FLERR, "Bond style musen/elastic: unknown law {} (known: elastic, kelvin, plastic, "
                      "linear/plastic, creep, weakening, aerogel, concrete, heat, thermal)", form);
  }
  if (narg < n) utils::missing_cmd_args(FLERR, "bond_style musen/elastic " + form, error);
  double v[NPARAM] = {};
  for (int k = 0; k < n; k++) {
    v[k] = utils::numeric(FLERR, arg[k], false, lmp);
    if (!std::isfinite(v[k]))
      error->all(FLERR, "Bond style musen/elastic: {} parameters must be finite, got {}", form,
                 arg[k]);
  }
  if (law.form == KELVIN) {
    law.max_damp_ratio = v[0];
    if (law.max_damp_ratio < 0.0)
      error->all(FLERR, "Bond style musen/elastic: kelvin MAX_DAMP_RATIO must be >= 0 (0: no "
                        "cap), got {}", arg[0]);
  } else {
    std::copy(v, v + NPARAM, law.p);
  }
  if (law.form == LINEAR_PLASTIC && !(law.p[P_KU] != 0.0))
    error->all(FLERR, "Bond style musen/elastic: linear/plastic KUnLoad must not be 0");
  return n;
}

/* bond_style musen/elastic [breakage 0|1|2] [LAW ...] [then FORM B ...] [geometry PARTNERS
   VALUES K] [breaks FILE] (bond_musen_elastic.h) */

void BondMusenElastic::settings(int narg, char **arg)
{
  then_laws.clear();    // a repeated bond_style command (e.g. after read_restart) restates them
  first_law = Law{ELASTIC, 1.0, 1, {}};
  int iarg = 0;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "breakage") {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "bond_style musen/elastic breakage", error);
      first_law.breakage = utils::inumeric(FLERR, arg[iarg + 1], false, lmp);
      if (first_law.breakage < 0 || first_law.breakage > 2)
        error->all(FLERR, "Bond style musen/elastic: breakage must be 0 (none), 1 (MUSEN's two "
                          "stress sums) or 2 (each stress term alone), got {}", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "kelvin" || key == "plastic" || key == "linear/plastic" || key == "creep" ||
               key == "weakening" || key == "aerogel" || key == "concrete" || key == "thermal") {
      iarg += 1 + parse_law(key, narg - iarg - 1, arg + iarg + 1, first_law);
    } else if (key == "then") {
      // then FORM BREAKAGE [parameters]: one more law
      if (iarg + 3 > narg) utils::missing_cmd_args(FLERR, "bond_style musen/elastic then", error);
      const std::string form = arg[iarg + 1];
      Law law{ELASTIC, 0.0, utils::inumeric(FLERR, arg[iarg + 2], false, lmp),
              {}};
      iarg += 3 + parse_law(form, narg - iarg - 3, arg + iarg + 3, law);
      then_laws.push_back(law);
    } else if (key == "geometry") {
      if (iarg + 4 > narg) utils::missing_cmd_args(FLERR, "bond_style musen/elastic geometry", error);
      partners_name = arg[iarg + 1];
      values_name = arg[iarg + 2];
      nslots = utils::inumeric(FLERR, arg[iarg + 3], false, lmp);
      if (nslots < 1)
        error->all(FLERR, "Bond style musen/elastic: geometry needs K >= 1 slots, got {}",
                   arg[iarg + 3]);
      per_atom_geometry = 1;
      iarg += 4;
    } else if (key == "breaks") {
      if (iarg + 2 > narg) utils::missing_cmd_args(FLERR, "bond_style musen/elastic breaks", error);
      breaks_file = arg[iarg + 1];
      iarg += 2;
    } else {
      error->all(FLERR, "Bond style musen/elastic: unknown keyword {} (known: breakage, kelvin, "
                        "plastic, linear/plastic, creep, weakening, aerogel, concrete, then, "
                        "geometry, breaks)", key);
    }
  }
  // the stress criteria each law has (MUSEN: Kelvin, linear plastic, creep one, weakening its
  // strain test; plastic, aerogel none)
  auto most_of = [](int form) {
    return form == ELASTIC ? 2 : (form == PLASTIC || form == AEROGEL || form == HEAT) ? 0 : 1;
  };
  for (const Law &law : then_laws) {
    const int most = most_of(law.form);
    if (law.breakage < 0 || law.breakage > most)
      error->all(FLERR, "Bond style musen/elastic: then {}: breakage must be 0..{}, got {}",
                 law_name(law.form), most, law.breakage);
  }
  if (first_law.form == HEAT)
    error->all(FLERR, "Bond style musen/elastic: heat is a later law (then heat 0 SCALE K)");
  const int most = most_of(first_law.form);
  if (first_law.breakage > most)
    error->all(FLERR, "Bond style musen/elastic: {} takes breakage 0..{}, got {}",
               law_name(first_law.form), most, first_law.breakage);
}

/* bond_coeff N E G sigma_n tau_s mu [d L0] [yield Y] */

void BondMusenElastic::coeff(int narg, char **arg)
{
  double Y = std::nan("");
  if (narg >= 2 && strcmp(arg[narg - 2], "yield") == 0) {
    Y = utils::numeric(FLERR, arg[narg - 1], false, lmp);
    if (!(Y >= 0.0) || !std::isfinite(Y))
      error->all(FLERR, "Bond style musen/elastic: yield strength must be >= 0, got {}",
                 arg[narg - 1]);
    narg -= 2;
  }
  const int want = per_atom_geometry ? 6 : 8;
  if (narg != want)
    error->all(FLERR, "Bond style musen/elastic: bond_coeff needs {}: type E G sigma_n tau_s mu{}",
               per_atom_geometry ? "6 values" : "8 values",
               per_atom_geometry ? " (d and L0 come per bond from the geometry arrays)" : " d L0");
  if (!allocated) allocate();
  int ilo, ihi;
  utils::bounds(FLERR, arg[0], 1, atom->nbondtypes, ilo, ihi, error);
  const double E = utils::numeric(FLERR, arg[1], false, lmp);
  const double G = utils::numeric(FLERR, arg[2], false, lmp);
  const double sn = utils::numeric(FLERR, arg[3], false, lmp);
  const double ts = utils::numeric(FLERR, arg[4], false, lmp);
  const double mu = utils::numeric(FLERR, arg[5], false, lmp);
  double d = 0.0, L0 = 0.0;
  if (!per_atom_geometry) {
    d = utils::numeric(FLERR, arg[6], false, lmp);
    L0 = utils::numeric(FLERR, arg[7], false, lmp);
    if (!(d > 0.0) || !std::isfinite(d))
      error->all(FLERR, "Bond style musen/elastic: bond diameter must be > 0, got {}", arg[6]);
    if (!std::isfinite(L0))
      error->all(FLERR, "Bond style musen/elastic: L0 must be finite (<= 0: the distance at the "
                        "first use), got {}", arg[7]);
  }
  if (!(E > 0.0) || !std::isfinite(E) || !(G > 0.0) || !std::isfinite(G))
    error->all(FLERR, "Bond style musen/elastic: E and G must be > 0, got {} {}", arg[1], arg[2]);
  if (std::isnan(sn) || std::isnan(ts) || !(mu >= 0.0))
    error->all(FLERR, "Bond style musen/elastic: strengths must be numbers and mu >= 0, got {} "
                      "{} {}", arg[3], arg[4], arg[5]);

  int count = 0;
  for (int i = ilo; i <= ihi; i++) {
    youngs[i] = E;
    shear[i] = G;
    sigma_n[i] = sn;
    tau_s[i] = ts;
    viscosity[i] = mu;
    diam0[i] = d;
    len0[i] = L0;
    yield[i] = Y;
    setflag[i] = 1;
    count++;
  }
  if (count == 0) error->all(FLERR, "Incorrect args for bond coefficients");
}

/* ---------------------------------------------------------------------- */

void BondMusenElastic::init_style()
{
  heat_fix = nullptr;
  bool heats = first_law.form == HEAT;
  for (const Law &law : then_laws) heats = heats || law.form == HEAT;
  if (heats) {
    const auto found = modify->get_fix_by_style("^musen/heat$");
    if (found.size() != 1)
      error->all(FLERR, "Bond style musen/elastic: its heat law needs one fix musen/heat (found {})",
                 found.size());
    heat_fix = found[0];
  }
  timed_breaks = 0;
  for (const auto &fix : modify->get_fix_list()) {
    auto *leapfrog = dynamic_cast<FixMusenLeapfrog *>(fix);
    if (leapfrog && leapfrog->variable_step()) timed_breaks = 1;
  }
  if (!atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "Bond style musen/elastic needs an atom style with omega and torque "
                      "(e.g. bpm/sphere)");
  if (atom->molecular != Atom::MOLECULAR)
    error->all(FLERR, "Bond style musen/elastic needs a molecular atom style (bonds stored per atom)");
  if (!force->newton_bond)
    error->all(FLERR, "Bond style musen/elastic needs newton_bond on (each bond is computed once, "
                      "on the atom that stores it and its history)");
  if (!comm->ghost_velocity)
    error->all(FLERR, "Bond style musen/elastic needs comm_modify vel yes (velocities and "
                      "angular velocities of the partner atoms)");

  if (per_atom_geometry) {
    ipartners.assign(nslots, -1);
    ivalues.assign(nslots, -1);
    nvalues_per = 0;
    for (int k = 0; k < nslots; k++) {
      const std::string pname = fmt::format("{}{}", partners_name, k + 1);
      const std::string vname = fmt::format("{}{}", values_name, k + 1);
      int flag, cols;
      ipartners[k] = atom->find_custom(pname.c_str(), flag, cols);
      if (ipartners[k] < 0 || flag != 0 || cols != 0)
        error->all(FLERR, "Bond style musen/elastic: no per-atom integer vector i_{} (fix "
                          "property/atom i_{} d2_{} 2)", pname, pname, vname);
      ivalues[k] = atom->find_custom(vname.c_str(), flag, cols);
      if (ivalues[k] < 0 || flag != 1 || (cols != 2 && cols != 5))
        error->all(FLERR, "Bond style musen/elastic: no per-atom double array d2_{} with 2 "
                          "(d L0) or 5 (d L0 and the initial tangential overlap) columns", vname);
      if (k > 0 && cols != nvalues_per)
        error->all(FLERR, "Bond style musen/elastic: the geometry slots have {} and {} columns",
                   nvalues_per, cols);
      nvalues_per = cols;
    }
  }

  if (uses_yield())
    for (int i = 1; i <= atom->nbondtypes; i++)
      if (setflag[i] && !std::isfinite(yield[i]))
        error->all(FLERR, "Bond style musen/elastic: the plastic, creep, weakening and concrete "
                          "laws need each bond type's yield strength (bond_coeff ... yield Y); type {} has none", i);

  update_special = (force->special_lj[1] != 1.0 || force->special_coul[1] != 1.0) ? 1 : 0;
  const auto verlets = modify->get_fix_by_style("^musen/verlet$");
  if (verlets.size() > 1) error->all(FLERR, "Bond style musen/elastic: more than one fix musen/verlet");
  verlet = verlets.empty() ? nullptr : static_cast<FixMusenVerlet *>(verlets[0]);

  if (!history) {
    Fix *fix = modify->get_fix_by_id(history_id);
    if (!fix)
      fix = modify->add_fix(fmt::format("{} all MUSEN/HISTORY {}", history_id, entry_size()));
    if (strcmp(fix->style, "MUSEN/HISTORY") != 0)
      error->all(FLERR, "Bond style musen/elastic: fix {} is not its history", history_id);
    history = static_cast<FixMusenHistory *>(fix);
    if (history->nvalues() != entry_size())
      error->all(FLERR, "Bond style musen/elastic: its history fix holds {} values per bond, "
                        "not {}", history->nvalues(), entry_size());
  }

  if (comm->me == 0 && !breaks_file.empty() && !breaks_fp) {
    // appended to: a resumed run continues the file (fibrelmp cuts it back to its checkpoint)
    breaks_fp = fopen(breaks_file.c_str(), "a");
    if (!breaks_fp)
      error->one(FLERR, "Bond style musen/elastic: cannot open {}: {}", breaks_file,
                 utils::getsyserror());
  }
}

double BondMusenElastic::equilibrium_distance(int i)
{
  return std::max(len0[i], max_length0);
}

/* ---------------------------------------------------------------------- */

void BondMusenElastic::write_restart(FILE *fp)
{
  const int n = atom->nbondtypes;
  for (double *a : {youngs, shear, sigma_n, tau_s, viscosity, diam0, len0, yield})
    fwrite(&a[1], sizeof(double), n, fp);
}

void BondMusenElastic::read_restart(FILE *fp)
{
  allocate();
  const int n = atom->nbondtypes;
  for (double *a : {youngs, shear, sigma_n, tau_s, viscosity, diam0, len0, yield}) {
    if (comm->me == 0) utils::sfread(FLERR, &a[1], sizeof(double), n, fp, nullptr, error);
    MPI_Bcast(&a[1], n, MPI_DOUBLE, 0, world);
  }
  for (int i = 1; i <= n; i++) setflag[i] = 1;
}

void BondMusenElastic::write_restart_settings(FILE *fp)
{
  const int nthen = (int) then_laws.size();
  fwrite(&nthen, sizeof(int), 1, fp);
  fwrite(&first_law, sizeof(Law), 1, fp);
  if (nthen) fwrite(then_laws.data(), sizeof(Law), nthen, fp);
}

void BondMusenElastic::read_restart_settings(FILE *fp)
{
  int nthen = 0;
  if (comm->me == 0) {
    utils::sfread(FLERR, &nthen, sizeof(int), 1, fp, nullptr, error);
    utils::sfread(FLERR, &first_law, sizeof(Law), 1, fp, nullptr, error);
  }
  MPI_Bcast(&nthen, 1, MPI_INT, 0, world);
  MPI_Bcast(&first_law, sizeof(Law), MPI_CHAR, 0, world);
  then_laws.resize(nthen);
  if (nthen) {
    if (comm->me == 0)
      utils::sfread(FLERR, then_laws.data(), sizeof(Law), nthen, fp, nullptr, error);
    MPI_Bcast(then_laws.data(), (int) (sizeof(Law) * nthen), MPI_CHAR, 0, world);
  }
}

/* ----------------------------------------------------------------------
   for compute bond/local: the forces of the stored state at the current positions (what
   the last compute applied when nothing moved since).  svector: force on atom i (3),
   tangential overlap seen from i (3), |twisting + bending moment| (MUSEN's TotalTorque).
   fforce: the normal force along the bond vector i - j divided by the distance.
------------------------------------------------------------------------- */

double BondMusenElastic::single(int type, double /*rsq*/, int i, int j, double &fforce)
{
  fforce = 0.0;
  for (int k = 0; k < single_extra; k++) svector[k] = 0.0;
  if (type <= 0 || !history) return 0.0;
  tagint *tag = atom->tag;
  double sign = 1.0;
  int left = i, right = j;
  double *h = (i < atom->nlocal) ? history->find(i, tag[j]) : nullptr;
  if (!h && j < atom->nlocal) {
    h = history->find(j, tag[i]);
    sign = -1.0;
    left = j;
    right = i;
  }
  if (!h) return 0.0;

  // the right sphere's image closest to the left one, as the bond list has it
  double del[3];
  sub(atom->x[left], atom->x[right], del);
  domain->minimum_image(FLERR, del);
  double xr[3];
  sub(atom->x[left], del, xr);

  LawInput in;
  in.xl = atom->x[left];
  in.xr = xr;
  in.vl = atom->v[left];
  in.vr = atom->v[right];
  in.wl = atom->omega[left];
  in.wr = atom->omega[right];
  in.dt = update->dt;
  in.E = youngs[type];
  in.G = shear[type];
  in.mu = viscosity[type];
  in.Y = yield[type];
  // several laws: the last one's force, which is what MUSEN keeps as the bond's TotalForce
  in.law = then_laws.empty() ? &first_law : &then_laws.back();
  double copy[H_SIZE];    // evaluating must not touch the state
  std::copy(h, h + H_SIZE, copy);
  LawOutput out;
  musen_law(in, copy, false, false, out);

  const double dist = length(out.bond);
  fforce = out.normal_scalar / dist;
  for (int k = 0; k < 3; k++) {
    svector[k] = sign * out.total[k];
    svector[3 + k] = sign * copy[H_OVERLAP + k];
  }
  double msum[3];
  add(copy + H_NMOMENT, copy + H_TMOMENT, msum);
  svector[6] = length(msum);
  return 0.0;
}

double BondMusenElastic::memory_usage()
{
  double bytes = Bond::memory_usage();
  bytes += 9.0 * (atom->nbondtypes + 1) * sizeof(double);
  return bytes;
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Bond *create(LAMMPS *lmp) { return new BondMusenElastic(lmp); }
const style_registry::Registration registered(
    40, "musen/elastic", "MUSEN elastic/Kelvin solid bond with breakage", &create);
}    // namespace
