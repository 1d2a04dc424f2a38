/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/hm: MUSEN's Hertz-Mindlin particle-particle contact
   (MUSEN commit e0ff360, Models/ParticleParticle/HertzMindlin/ModelPPHertzMindlin.cpp,
   CModelPPHertzMindlin::CalculatePP), re-implemented operation by operation.

     pair_style musen/hm
     pair_coeff I J Estar Gstar e mu mu_r

   Estar, Gstar: the effective (already mixed) Young's and shear moduli of the material pair,
   as MUSEN's CSimplifiedScene::CalculateInteractionProperty computes them; e: restitution
   coefficient (0 < e <= 1), turned into MUSEN's damping coefficient
   alpha = ln e / sqrt(pi^2 + ln^2 e); mu: sliding friction; mu_r: rolling friction.
   Every type pair needs its own pair_coeff (MUSEN has no mixing rule for e, mu, mu_r).

   The tangential overlap of each contact is kept by a FixMusenHistory (per atom, keyed by
   the partner's tag); see pair_musen_hm.cpp for how pairs are owned under MPI.
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(musen/hm,PairMusenHM);
// clang-format on
#else

#ifndef FIBRELMP_PAIR_MUSEN_HM_H
#define FIBRELMP_PAIR_MUSEN_HM_H

#include "pair.h"

namespace LAMMPS_NS {

class FixMusenHistory;

class PairMusenHM : public Pair {
 public:
  PairMusenHM(class LAMMPS *);
  ~PairMusenHM() override;

  void compute(int, int) override;
  void settings(int, char **) override;
  void coeff(int, char **) override;
  void init_style() override;
  double init_one(int, int) override;
  double single(int, int, int, int, double, double, double, double &) override;
  void write_restart(FILE *) override;
  void read_restart(FILE *) override;
  void *extract(const char *, int &) override;
  double memory_usage() override;

  static constexpr const char *HISTORY_ID = "MUSEN_HM_HISTORY";
  // per contact: tangential overlap xi (3), the last step's normal and tangential force on
  // the atom (3 + 3, for single())
  static constexpr int HISTORY_VALUES = 9;

 protected:
  double **estar, **gstar;    // effective moduli per type pair
  double **restitution;       // e, as given
  double **alpha;             // MUSEN's dAlpha = ln e / sqrt(pi^2 + ln^2 e) (<= 0)
  double **mu, **mu_roll;     // sliding and rolling friction
  double *maxrad;             // largest radius per type (neighbor cutoff)
  FixMusenHistory *history;
  class FixMusenVerlet *verlet;    // MUSEN's contact-list schedule (broken bonds' pairs), or none

  // a broken bond's pair the current neighbour list still marks special, already let into
  // the contacts by MUSEN's contact-list update (fix musen/verlet)
  bool released(tagint a, tagint b) const;

  // the law's normal and tangential stiffness and elastic normal force (<= 0) of a contact
  // of types itype, jtype at this overlap: MUSEN's Hertz-Mindlin here; a style whose law
  // differs from it only there (musen/linear) overrides this alone
  virtual void stiffness(int itype, int jtype, double overlap, double equiv_radius,
                         double &kn, double &kt, double &fn_el) const;

  // MUSEN's CalculatePP for spheres i (src) and j (dst), cv = x_j - x_i: the unit normal n
  // (zero with cv), |cv|, and the normal and tangential relative velocity at the contact point
  void kinematics(int i, int j, const double cv[3], double n[3], double &cvlen, double &vn,
                  double vt[3]) const;
  // the normal force (elastic fn_el <= 0, damping fn_damp) and tangential force ft from the
  // tangential overlap xi (this step's, shrunk to match ft when the contact slips)
  void contact_force(int itype, int jtype, double overlap, double equiv_radius,
                     double equiv_mass, double vn, const double vt[3], double xi[3],
                     double &fn_el, double &fn_damp, double ft[3]) const;

  void allocate();
};

}    // namespace LAMMPS_NS

#endif
#endif
