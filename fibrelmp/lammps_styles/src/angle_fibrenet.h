/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   AngleFibreNet (angle_style fibrenet): FibreNet's bending law

       E = c (theta - theta0)^2,     angle_coeff N c theta0     (theta0 in RADIANS)

   as FibreNet's ResolveAngles kernel (FibreNet/kernel.cl) applies it: the force on each end
   bead is -dE/dtheta = -2 c (theta - theta0) times the unit vector in the angle's plane,
   perpendicular to that bead's leg, divided by the leg's length (the exact gradient), and
   the middle bead takes minus their sum.

   Unlike angle_style harmonic (and lepton), nothing clamps sin(theta): theta and the force
   direction come from the cross product t = a x b of the two legs, computed with an error-
   free difference of products, so forces stay exact (to a few ulp) for triples arbitrarily
   close to straight (theta -> pi) or folded (theta -> 0).  A triple that is exactly straight
   (t = 0) gets no force, as in FibreNet (its -0.999999 clamp of cos(theta) < -1 after
   rounding is not reproduced: see docs/fibrenet.md).
------------------------------------------------------------------------- */

#ifdef ANGLE_CLASS
// clang-format off
AngleStyle(fibrenet,AngleFibreNet);
// clang-format on
#else

#ifndef FIBRELMP_ANGLE_FIBRENET_H
#define FIBRELMP_ANGLE_FIBRENET_H

#include "angle.h"

// The force loop is compiled twice on x86-64 Linux with GCC: with hardware fma (chosen at load
// time where the CPU has it) and without (fma then comes from libm: same results, slower).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(__FMA__)
#define FIBRELMP_FMA_CLONES __attribute__((target_clones("fma", "default")))
#else
#define FIBRELMP_FMA_CLONES
#endif

namespace LAMMPS_NS {

class AngleFibreNet : public Angle {
 public:
  AngleFibreNet(class LAMMPS *);
  ~AngleFibreNet() override;
  void compute(int, int) override;
  void coeff(int, char **) override;
  void init_style() override;
  double equilibrium_angle(int) override;
  void write_restart(FILE *) override;
  void read_restart(FILE *) override;
  void write_data(FILE *) override;
  double single(int, int, int, int) override;
  void *extract(const char *, int &) override;

 protected:
  double *c;                // stiffness: E = c (theta - theta0)^2
  double *theta0;           // rest angle (radians)
  double *pi_minus_theta0;  // pi - theta0 to double precision of the true pi (see init_style)

  void allocate();
  FIBRELMP_FMA_CLONES void eval(int eflag);
};

}    // namespace LAMMPS_NS

#endif
#endif
