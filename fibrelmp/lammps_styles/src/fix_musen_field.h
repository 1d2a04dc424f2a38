/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenField (fix style musen/field): MUSEN's external-force (EF) models on every sphere of
   the group, operation by operation as MUSEN 1.74.2 (e0ff360) computes them:

     fix ID group musen/field viscous NU RHO
         ModelEFViscousField: drag on the sphere's velocity v (the medium at rest):
         Re = 2 r |v| / NU (NU: kinematic viscosity, m2/s); Cd = 24/Re (Re < 0.5),
         27/Re^0.8 (Re < 10.1), else 17/Re^0.6; F -= v/|v| Cd pi r^2 RHO/2 |v|^2; none at Re = 0
     fix ID group musen/field centrifugal OMEGA RHO MU
         ModelEFCentrifugalCasting: a sphere in a liquid (density RHO, dynamic viscosity MU)
         turning at OMEGA rad/s about y: buoyant centrifugal force (m - 4/3 pi r^3 RHO)
         OMEGA^2 (x, 0, z) plus Stokes drag 6 pi MU r (u - v) towards the liquid's velocity
         u = OMEGA (z, 0, -x)
     fix ID group musen/field heat T0 T1 TIME ALPHA EPS SCALE
         ModelEFHeatTransfer: heat flux from the surrounding air into each sphere,
         SCALE (ALPHA pi r^2 (Tenv - T) + EPS pi r^2 (Tenv^4 - T^4)) (MUSEN's formula: no
         Stefan-Boltzmann constant, EPS carries it), Tenv = T0 + t (T1 - T0)/TIME up to
         t = TIME, T1 after; the temperature T is the custom per-atom property
         d_musen_temperature (fix property/atom).  The flux is added to the per-atom heat
         flux of fix musen/heat (defined before this fix), which clears it before every
         evaluation, lets the contact heat laws add to it and updates T (MUSEN's HeatFlux and
         CCPUSimulator::UpdateTemperatures, in fix_musen_heat.h): one flux per sphere, EF
         first, as MUSEN sums it.  The flux is a function of T, t and r only: a set-up
         (restart) recomputes it exactly.

   Where MUSEN adds it: CCPUSimulator::CalculateForcesStep runs the EF models first, on the
   cleared forces, before the particle-particle, particle-wall and bond forces, and
   MoveParticles adds gravity after all of them; every evaluation (its prediction iteration at
   t = 0 too) uses the positions and velocities the forces are computed at.  This fix adds its
   force in pre_force (and setup_pre_force), which LAMMPS calls right after clearing the
   forces and before the pair, bond and fix post_force (gravity, walls) forces, with x and v
   of that evaluation.  Several such fixes act in the order they are defined (MUSEN: its EF
   models in the model manager's order).  No law adds torque; none keeps a per-atom value.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_FIELD_H
#define FIBRELMP_FIX_MUSEN_FIELD_H

#include "fix.h"

namespace LAMMPS_NS {

class FixMusenField : public Fix {
 public:
  FixMusenField(class LAMMPS *, int, char **);
  ~FixMusenField() override;
  int setmask() override;
  void init() override;
  void setup_pre_force(int) override;
  void pre_force(int) override;

 private:
  enum Law { VISCOUS, CENTRIFUGAL, HEAT };
  Law law;
  double nu, medium_density;                            // viscous
  double omega, liquid_density, liquid_viscosity;       // centrifugal
  double air_t0, air_t1, heating_time, heat_alpha, emissivity, heat_scale;   // heat
  class Fix *heat_fix;       // heat: fix musen/heat, owner of the flux (init)
  void viscous();
  void centrifugal();
  void heat();
};

}    // namespace LAMMPS_NS

#endif
