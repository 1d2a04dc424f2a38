/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenHeat (fix style musen/heat): MUSEN's per-particle heat flux and temperature update,
   the one owner of both for every heat model: ModelEFHeatTransfer (fix musen/field heat),
   ModelPPHeatConduction (pair musen/hm's law heat/conduction), ModelPWHeatTransfer (fix
   musen/wall/mesh's law heat/transfer) and ModelSBHeatConduction (bond musen/elastic's heat)
   all add to its flux:

     fix ID group musen/heat cp C_1 ... C_ntypes [k K_1 ... K_ntypes]

   C_k: heat capacity (J/(kg K)) of type k; K_k: its material's thermal conductivity
   (W/(m K)), from which a contact takes MUSEN's dEquivThermalConductivity
   1 / (1/K_i + 1/K_j) (SimplifiedScene.cpp); k only for pair musen/hm's heat law.  The
   temperature is the per-atom property d_musen_temperature (fix property/atom ... ghost yes:
   the contact laws read it on ghosts).

   MUSEN (CSimplifiedScene::ClearState, CCPUSimulator::CalculateForcesStep, UpdateTemperatures):
   HeatFlux = 0 before every evaluation; its models add to it (EF, PP, PW, SB in that order);
   after the move T += HeatFlux/(C m) dt (dt/2 in its prediction iteration), then
   T = max(T, 0).  Here: pre_force (LAMMPS: before the pair, bond and post_force styles)
   sends the temperatures to the ghosts and clears the flux; the styles add to it (extract
   "flux"; a bond's on a ghost sphere goes back to its owner in post_force, reverse
   communication); fix musen/field heat, defined after this fix, adds in its own pre_force,
   after the clearing and before the contact laws (MUSEN: EF first); the next
   initial_integrate updates T with the sum; the half update of the
   prediction at the second set-up at t = 0 (musen_startup.h).  The flux depends only on the
   state at the evaluation, so a set-up (restart) recomputes it exactly.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_HEAT_H
#define FIBRELMP_FIX_MUSEN_HEAT_H

#include "fix.h"

namespace LAMMPS_NS {

class FixMusenHeat : public Fix {
 public:
  FixMusenHeat(class LAMMPS *, int, char **);
  ~FixMusenHeat() override;
  int setmask() override;
  void init() override;
  void setup_pre_force(int) override;
  void pre_force(int) override;
  void initial_integrate(int) override;
  void setup(int) override;
  void post_force(int) override;
  int pack_reverse_comm(int, int, double *) override;
  void unpack_reverse_comm(int, int *, double *) override;
  void *extract(const char *, int &) override;

  int pack_forward_comm(int, int *, double *, int, int *) override;
  void unpack_forward_comm(int, int, double *) override;
  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  double memory_usage() override;

 private:
  double *heat_capacity;     // per atom type (1..ntypes)
  double *conductivity;      // per atom type (1..ntypes)
  double *flux;              // per atom (owned and ghost), this evaluation's heat flux (W)
  int startup_setups;        // set-ups at t = 0 seen (MUSEN's two evaluations there)
  double *temperature();     // d_musen_temperature
  void update_temperature(double dt);
  void start_evaluation();
};

}    // namespace LAMMPS_NS

#endif
