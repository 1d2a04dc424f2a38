/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/hm: MUSEN's Hertz-Mindlin particle-particle contact
   (MUSEN commit e0ff360, Models/ParticleParticle/HertzMindlin/ModelPPHertzMindlin.cpp,
   CModelPPHertzMindlin::CalculatePP), re-implemented operation by operation.

     pair_style musen/hm [then LAW [params]] ...
     pair_coeff I J Estar Gstar e mu mu_r

   LAW: a MUSEN particle-particle law (musen_pp_law.h: hertz/mindlin, linear/elastic Kn Kt);
   musen/hm's first law is hertz/mindlin, and every law named after `then` acts on each
   contact after it, as cmusen runs several selected PP models (forces add, each law
   continues the tangential overlap the previous one left).

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
#include "musen_pp_law.h"

#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class FixMusenHistory;
namespace musen_pp {
class HertzMindlin;
}

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
  void write_restart_settings(FILE *) override;
  void read_restart_settings(FILE *) override;
  void read_restart(FILE *) override;
  void *extract(const char *, int &) override;
  double memory_usage() override;

  static constexpr const char *HISTORY_ID = "MUSEN_HM_HISTORY";
  // per contact: tangential overlap xi (3), the last step's normal and tangential force on
  // the atom (3 + 3, for single())
  static constexpr int HISTORY_VALUES = 9;
  // and after them each law's own values (musen_pp::Law::history_size, in the laws' order;
  // set_laws): the contact's whole entry
  int history_values = HISTORY_VALUES;

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

  // the laws in the order they act, and the words that named them (the first: the style's)
  std::vector<std::unique_ptr<musen_pp::Law>> laws;
  std::vector<std::string> law_words;
  // FIRST [its params] [then NAME [params]] ... from the style's arguments
  void set_laws(const std::string &first, int narg, char **arg);
  // the single law when it is hertz/mindlin (called without the list: musen/hm's speed)
  const musen_pp::HertzMindlin *only_hertz;
  // a heat law among them: fix musen/heat's flux and per-type conductivity (init_style)
  class Fix *heat_fix = nullptr;
  // d_musen_temperature's index for a law that reads temperatures without heat (or -1)
  int temperature_index = -1;
  // one contact's law values while the laws act (history_values - HISTORY_VALUES of them)
  std::vector<double> law_block;
  // every law in turn on one contact; the loop over the contacts with one of those
  // (LAW_VALUES false: no law keeps values of its own, the loop without their copies)
  void apply_laws(const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
                  musen_pp::Result &r) const;
  template <bool LAW_VALUES, class Laws> void contacts(Laws apply);

  // the contact's geometry for the laws, spheres i (src) and j (dst), cv = x_j - x_i: the unit
  // normal n (zero with cv), |cv|, and the normal and tangential relative velocity there
  inline void kinematics(int i, int j, const double cv[3], double n[3], double &cvlen, double &vn,
                  double vt[3]) const;
  void allocate();
};

}    // namespace LAMMPS_NS

#endif
#endif
