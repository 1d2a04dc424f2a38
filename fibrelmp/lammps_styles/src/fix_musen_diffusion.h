/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenDiffusion (fix style musen/diffusion): MUSEN's ModelEFLiquidDiffusion (MUSEN 1.74.2
   e0ff360; Depta et al., J. Chem. Inf. Model. 59 (2019) 386) on every sphere of the group, with
   MUSEN's random numbers:

     fix ID group musen/diffusion T MU STOKES SHELL SEED ORIENT

   r_s = STOKES r + SHELL; per sphere a = 6 pi MU r_s dt / m, drag m/dt (1 - e^-a), random
   force magnitude sqrt(m kB T (1 - e^-2a))/dt (kB = 1.38064852e-23, MUSEN's); the force
   magnitude N(0,1) - drag v per axis; with ORIENT 1 the same for the torque with
   8 pi MU r_s^3 and I = 2/5 m r^2.  Random numbers: MUSEN's std::mt19937_64 per particle,
   seeded (FIXED_SEED = SEED) from a mt19937_64 seeded with SEED: seed_i = r()r() + r() + i^3 +
   i^2 + i (i the particle's index, here the atom ID - 1: MUSEN's particle order, unsigned
   32-bit powers), and a fresh std::normal_distribution(0, 1) per particle and evaluation
   drawing x, y, z (then the torque's x, y, z), as CModelEFLiquidDiffusion::CalculateEF.
   MUSEN draws at every force evaluation, its two at t = 0 included (musen_startup.h): so
   does this fix, in pre_force; a set-up that is not a MUSEN evaluation (a checkpoint's, a
   later run's) reuses the last numbers.  Restart files keep each sphere's seed, how many
   numbers its generator gave and the last numbers (the generator is re-seeded and advanced).
   Serial runs only (the generators do not migrate between processors).
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_DIFFUSION_H
#define FIBRELMP_FIX_MUSEN_DIFFUSION_H

#include "fix.h"

#include <cstdint>
#include <random>
#include <vector>

namespace LAMMPS_NS {

class FixMusenDiffusion : public Fix {
 public:
  FixMusenDiffusion(class LAMMPS *, int, char **);
  ~FixMusenDiffusion() override;
  int setmask() override;
  void init() override;
  void setup_pre_force(int) override;
  void pre_force(int) override;

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;

 private:
  double temperature, viscosity, stokes_factor, shell;
  uint64_t fixed_seed;
  int orient;
  std::vector<std::mt19937_64> engine;    // per atom
  std::vector<uint64_t> seed, draws;      // per atom: its seed, numbers drawn from its engine
  double **last;                          // per atom: the last evaluation's 6 normal numbers
  void seed_atoms();
  void reset_engine(int i);
  void draw(int i);
  void apply();
};

}    // namespace LAMMPS_NS

#endif
