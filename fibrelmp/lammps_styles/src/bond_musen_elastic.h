/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   bond_style musen/elastic: MUSEN's elastic solid bond (and, with the kelvin keyword, its
   Kelvin bond; with plastic, linear/plastic or creep its elastic-perfectly-plastic, linear
   plastic, creep, weakening, aerogel or plastic concrete bond) with MUSEN's breakage criteria.  Re-implemented from MUSEN's
   Models/SolidBonds/BondModel{Elastic,Kelvin,ElasticPerfectlyPlastic,LinearPlastic,Creep,
   Weakening,Aerogel,PlasticConcrete}/
   ModelSB*.cpp (CalculateSB, ConsolidatePart);
   MUSEN is BSD-3-Clause, (c) MUSEN Development Team.

     bond_style musen/elastic [breakage B] [LAW]  [then FORM B PARAMETERS] ...
                              [geometry PARTNER VALUES K] [breaks FILE]
       (FILE: "step id1 id2 fx fy fz ox oy oz m" per broken bond: the force on id1 its law
       computed as it broke (MUSEN's TotalForce), the tangential overlap and |M_n + M_t|, what
       cmusen's next save still holds for it; with fix musen/leapfrog's variable time step
       MUSEN's time of that step, %.17g, which a step number no longer gives, comes 4th:
       "step id1 id2 time fx fy fz ox oy oz m")
       LAW = FORM PARAMETERS: kelvin MAX_DAMP_RATIO | plastic FT FC TY RC |
            linear/plastic KL KU | creep FT FC TY RC A m | weakening CB BS WF |
            aerogel PSC PST SRC SRT BST HRC HRT | concrete (then elastic B, then concrete B:
            no parameters)
       B: the stress criterion (CONSIDER_BREAKAGE; creep: FRACTURE_BY_STRESS; weakening: its
       CONSIDER_BREAKAGE, which turns its strain test on; concrete: its CONSIDER_BREAKAGE,
       the tension-side sign test; plastic, aerogel: 0);
       weakening: CB compressive break 0|1, BS breakage strain, WF weakening factor (random
       branch refused unless 0); aerogel: MUSEN's seven parameters in its order;
       FT FC: fracture strains in tension / compression (0: none); TY: tangential yield 0|1;
       RC: ratio compressive / tensile yield; KL KU: loading / unloading stiffness;
       A m: creep parameters
     bond_coeff N E G sigma_n tau_s mu [d L0] [yield Y]
       Y: the yield strength (MUSEN's material property 15) the plastic and creep laws need

   The law is incremental: every bond keeps MUSEN's state (tangential overlap, twisting and
   bending moments, the previous bond vector; see the H_* offsets) in a FixMusenHistory
   entry on the atom that stores the bond (newton_bond on: the first atom of the Bonds line,
   MUSEN's "left" sphere) keyed by the partner's tag, together with the bond's own diameter
   and initial length.  Those come from K slots of per-atom values (fix property/atom
   i_PARTNERk d2_VALUESk 2|5, k = 1..K: a partner tag, and d, L0 [and the initial tangential
   overlap] of the bond to it; one slot per line of a read_data section, whose lines LAMMPS
   limits to 256 characters) or, without the geometry keyword, from the bond type's d and L0.
   L0 <= 0 means "the distance at the first use" (MUSEN's RESET_INITIAL_BOND_LENGTH).

   A broken bond gets type 0.  Where bonded spheres do not touch (special_bonds lj 0), its
   pair stays special until fix musen/verlet (MUSEN's contact-list updates) releases it;
   without that fix the pair joins the contacts at LAMMPS's next neighbour-list build.

   Several laws (cmusen runs every active SB model: CCPUSimulator::CalculateForcesSB): the
   first law is given by breakage/kelvin, each "then" adds one after it.  Every step each law
   in turn advances the bond's one shared state from where the previous law left it, adds its
   own force and applies its own breakage test; a bond one law breaks gets no later law.
   A set-up (non-advancing) evaluation needs each law's state, so every law but the last keeps
   a copy of its part of the state (H_LAWSTATE values) after the H_SIZE values of the entry.
------------------------------------------------------------------------- */

#ifdef BOND_CLASS
// clang-format off
BondStyle(musen/elastic,BondMusenElastic);
// clang-format on
#else

#ifndef FIBRELMP_BOND_MUSEN_ELASTIC_H
#define FIBRELMP_BOND_MUSEN_ELASTIC_H

#include "bond.h"

#include <cstdio>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class BondMusenElastic : public Bond {
 public:
  BondMusenElastic(class LAMMPS *);
  ~BondMusenElastic() override;
  void compute(int, int) override;
  void settings(int, char **) override;
  void coeff(int, char **) override;
  void init_style() override;
  double equilibrium_distance(int) override;
  void write_restart(FILE *) override;
  void read_restart(FILE *) override;
  void write_restart_settings(FILE *) override;
  void read_restart_settings(FILE *) override;
  double single(int, double, int, int, double &) override;
  double memory_usage() override;

  // per-bond history: offsets into a FixMusenHistory entry
  enum {
    H_OVERLAP = 0,      // tangential overlap (MUSEN TangentialOverlap), 3
    H_NMOMENT = 3,      // twisting moment (MUSEN NormalMoment), 3
    H_TMOMENT = 6,      // bending moment (MUSEN TangentialMoment), 3
    H_PREVBOND = 9,     // bond vector left - right of the last update (MUSEN PrevBond), 3
    H_DAMPN = 12,       // Kelvin normal damping force of the last update, 3
    H_DAMPT = 15,       // Kelvin tangential damping force of the last update, 3
    H_PLASTIC = 18,     // normal plastic strain (MUSEN NormalPlasticStrain)
    H_NFORCE = 19,      // plastic laws: the normal stress last applied (linear/plastic,
                        // aerogel: force)
    H_BROKEN = 20,      // aerogel: -1 / 1 broken in compression / tension (MUSEN keeps it in
                        // TangentialPlasticStrain.x)
    H_DIAMETER = 21,    // the bond's diameter d
    H_LENGTH0 = 22,     // its initial length L0
    H_SIZE = 23,
    H_LAWSTATE = 21     // the per-law part: offsets 0..20
  };

  // MUSEN's SB models this style runs
  enum Form { ELASTIC = 0, KELVIN, PLASTIC, LINEAR_PLASTIC, CREEP, WEAKENING, AEROGEL, CONCRETE, HEAT, THERMAL };
  // parameters of the plastic laws (Law::p)
  enum { P_FT = 0, P_FC, P_TY, P_RC, P_A, P_M };                  // plastic, creep
  enum { P_KL = 0, P_KU };                                        // linear/plastic
  enum { P_CB = 0, P_BS, P_WF };                                  // weakening
  enum { P_PSC = 0, P_PST, P_SRC, P_SRT, P_BST, P_HRC, P_HRT };   // aerogel
  enum { P_SCALE = 0, P_K };                                      // heat (no force)
  enum { P_TDIFF = 0, P_MU, P_ALPHA };                            // thermal
  enum { NPARAM = 7 };

  struct Law {
    int form;                // Form
    double max_damp_ratio;   // Kelvin: its MAX_DAMP_RATIO (0: no cap)
    int breakage;            // the stress criterion: CONSIDER_BREAKAGE (creep: FRACTURE_BY_STRESS)
    double p[NPARAM];        // the law's parameters (P_*)
  };

 protected:
  // per bond type: material constants
  double *youngs, *shear, *sigma_n, *tau_s, *viscosity, *diam0, *len0, *yield;
  Law first_law;             // the first law (breakage: 0 none, 1 sums, 2 each term)
  std::vector<Law> then_laws;   // laws acting after the first one, in cmusen's order
  std::string partners_name, values_name;    // per-atom geometry slots (empty: coefficients)
  std::string breaks_file;   // "step id1 id2" per broken bond (rank 0 appends)
  int timed_breaks = 0;      // fix musen/leapfrog's variable time step: "step id1 id2 time"
  FILE *breaks_fp;
  int per_atom_geometry;
  int nslots, nvalues_per;                     // K slots of nvalues_per values
  std::vector<int> ipartners, ivalues;         // their custom-property indices (init_style)
  int update_special;        // 1-2 weights not 1: a broken bond's pair must become a contact
  bigint pairs_waiting;      // broken pairs not yet through a neighbor-list build
  int warned_build;          // the build-schedule warning was printed
  double max_length0;        // longest L0 seen (equilibrium_distance)
  class FixMusenHistory *history;
  class Fix *heat_fix = nullptr;    // fix musen/heat when a law is heat (init_style)
  void bond_heat(const Law &law, int i1, int i2, double d);
  std::string history_id;
  class FixMusenVerlet *verlet;    // MUSEN's contact-list schedule for broken pairs (or none)

  std::vector<bigint> broken;    // (step, tag left, tag right) found on this rank this call
  // each one's force on the left sphere, tangential overlap and |M_n + M_t| when it broke (7)
  std::vector<double> broken_force;

  int entry_size() const { return H_SIZE + H_LAWSTATE * (int) then_laws.size(); }
  bool apply_laws(int i1, int i2, int type, double *h, bool advance, bool fresh, double *total,
                  double *broke_state);
  bool any_breakage() const;
  bool uses_yield() const;
  int parse_law(const std::string &form, int narg, char **arg, Law &law);
  void allocate();
  double *init_entry(int i1, int i2, int type);
  void process_breaks();
  void note_list_build();
  void forget_special(tagint, tagint);
};

}    // namespace LAMMPS_NS

#endif
#endif
