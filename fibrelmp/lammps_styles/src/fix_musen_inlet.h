/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenInlet (fix style musen/inlet): one of MUSEN's dynamic generators of spheres
   (CObjectsGenerator::Generate, MUSEN 1.74.2 e0ff360) inserting spheres during a run.

     fix ID group musen/inlet SEED box XLO XHI YLO YHI ZLO ZHI tries N walls WALLFIX|none
         velocity fixed VX VY VZ | velocity random MAGNITUDE
         fractions K  TYPE DIAMETER DENSITY SHARE  (K times)
           | agglomerate N  TYPE RADIUS DENSITY X Y Z  (N times)  bonds M  I J BTYPE DIAMETER  (M times)
         events M  STEP COUNT  (M times, steps ascending)
         [first_id ID] [log FILE] [groups NAME1 .. NAMEK]   (a further group per fraction)
         [volume N  X1 Y1 Z1 X2 Y2 Z2 X3 Y3 Z3  (N times)]   (a closed triangle volume)
         [geometry PARTNER VALUES K]   (agglomerates: bond_style musen/elastic's per-atom slots)
         [musen_rand TIME0]   (agglomerates: cmusen's random numbers, see below)

   At each listed STEP (MUSEN's generation times, computed by fibrelmp from cmusen's summed
   clock: the fix does not recompute it) it tries to make COUNT spheres.  Per sphere: the
   fraction is MUSEN's next_fraction (the first whose number share among the spheres made so
   far is below its SHARE, else the first), then at most N random centres uniform in the box;
   a centre is accepted when the sphere lies totally inside the box (with "volume", whose
   bounding box is BOX: MUSEN's CInsideVolumeChecker test of the triangles instead, the centre
   and 14 points at distance r inside by the parity of +x ray crossings), overlaps no sphere (sum of
   radii) and touches no triangle of fix musen/wall/mesh WALLFIX.  A sphere that finds no place
   is dropped.  Velocity: the fixed one, or a direction uniform on the unit sphere (rejection
   from the cube, as MUSEN) times MAGNITUDE, one draw per sphere.  Mass 4/3 pi r^3 rho (MUSEN's
   expression), orientation the identity (fibrelmp does not turn quaternions).

   "agglomerate" (MUSEN's generator of agglomerates, obj_type 2): each object is one rigid
   set of N spheres (TYPE, RADIUS, DENSITY, position X Y Z relative to the object's centre:
   MUSEN's agglomerate already shifted to its volume-weighted centre and scaled, by fibrelmp)
   and M solid bonds between its spheres I and J (0-based; I is MUSEN's left sphere, which
   stores the LAMMPS bond) of bond type BTYPE and diameter DIAMETER.  Per object and attempt:
   a random centre in the box (CreateRandomPoint) and a random rotation (Shoemake's uniform
   quaternion, MUSEN's CQuaternion::Random) turning every relative position; the object is
   placed when every sphere passes the sphere tests above (its own spheres may overlap each
   other, as in MUSEN's IsOverlapped), else it is redrawn (N tries) and dropped whole.  One
   velocity per object (fixed, or one random draw) for all its spheres.  IDs: the j-th object
   this fix is asked for (over its events, made or not) has IDs FIRST_ID + j N + part, so that
   fibrelmp knows every sphere's and bond's row in advance (first_id must leave room).
   "musen_rand TIME0": instead of the seeded stream below, cmusen's own: glibc's rand() seeded
   as CObjectsGenerator::Initialize seeds it from time(0) = TIME0, one stream for every fix
   with musen_rand (in definition order, as cmusen's generators share rand()), drawn in
   MUSEN's order and arithmetic (centre (rand() + 1) size / RAND_MAX, quaternion rand() /
   RAND_MAX, velocity 2 rand() / RAND_MAX - 1), kept in the restart file: with the TIME0 of a
   cmusen run the same agglomerates as that run, as long as the overlap decisions agree.  The bonds are added
   to the left sphere's bond list (newton_bond on), with the left sphere's geometry slot
   (i_PARTNERk = right sphere's ID, d2_VALUESk = DIAMETER and the initial length |x_I - x_J|,
   MUSEN's AddSolidBond) and each other's 1-2 special neighbours; the log gets "STEP ID" per
   sphere, in part order, then "STEP LEFT_ID RIGHT_ID L0" per bond of the agglomerate.

 of STEP: LAMMPS has moved the atoms to their positions of
   that step and computes the step's forces afterwards, which is where MUSEN's
   PreCalculationStep generates.  Every rank gathers the spheres near the box, draws the same
   random numbers and takes the same decisions; each rank keeps the new atoms it owns.  The
   random numbers of one generation come from SEED and STEP alone (no state carried from step
   to step), so a restarted or replayed run and any number of ranks insert the same spheres.
   New atom IDs are the next ones after the largest existing ID, the largest any musen/inlet
   fix gave and ID - 1, in order of success (fixes at the same step: in the order they were
   defined): a removed sphere's ID is never given again.  FILE: rank 0 appends a line
   "STEP ID" per new atom (fibrelmp's result writers take the activity start from it).
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_INLET_H
#define FIBRELMP_FIX_MUSEN_INLET_H

#include "fix.h"

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace LAMMPS_NS {

// glibc's rand() (random_r TYPE_3), as cmusen calls it: srand's 16807 LCG fill, 310 discarded
struct GlibcRand {
  std::uint32_t r[34];
  std::uint64_t n = 0;    // words made (the next goes to r[n % 34])
  void seed(std::uint32_t s)
  {
    std::int32_t word = static_cast<std::int32_t>(s ? s : 1);
    r[0] = static_cast<std::uint32_t>(word);
    for (int i = 1; i < 31; i++) {
      const std::int32_t hi = word / 127773, lo = word % 127773;    // C truncation
      word = 16807 * lo - 2836 * hi;
      if (word < 0) word += 2147483647;
      r[i] = static_cast<std::uint32_t>(word);
    }
    for (int i = 31; i < 34; i++) r[i] = r[i - 31];
    n = 34;
    for (int i = 0; i < 310; i++) next();
  }
  int next()
  {
    const std::uint32_t v = r[(n - 31) % 34] + r[(n - 3) % 34];
    r[n % 34] = v;
    n++;
    return static_cast<int>(v >> 1);
  }
};

class FixMusenInlet : public Fix {
 public:
  FixMusenInlet(class LAMMPS *, int, char **);
  ~FixMusenInlet() override;
  int setmask() override;
  void init() override;
  void setup_pre_exchange() override;
  void pre_exchange() override;
  double compute_scalar() override;
  tagint last_given() const { return last_id; }    // spheres this fix has inserted (all runs)
  void write_restart(FILE *) override;
  void restart(char *) override;
  // "radius" of type T: the largest radius this fix gives type T (0: none), as fix pour
  // tells granular pair styles, which size their neighbour cutoffs with it
  void *extract(const char *, int &) override;

 private:
  struct Fraction {
    int type;
    double radius, density, share;
    int groupbit;    // "groups": a further group of its spheres (0: none)
  };
  struct Event {
    bigint step;
    int count;
  };
  struct Sphere {
    double x[3], r;
  };
  std::uint64_t seed;
  double lo[3], hi[3];
  std::vector<double> volume;    // "volume": its triangles, 9 coordinates each (empty: the box)
  int tries;
  char *wall_id;
  bool random_velocity;
  double velocity[3], magnitude;
  std::vector<Fraction> fractions;
  struct Part {
    int type;
    double radius, density, x[3];
  };
  struct AggloBond {
    int left, right, type;
    double diameter;
  };
  std::vector<Part> parts;          // "agglomerate": its spheres (empty: a mixture)
  std::vector<AggloBond> bonds;     // and its bonds
  std::string partners_name, values_name;    // "geometry": the per-atom slots' names
  bool musen_rand = false;          // "musen_rand TIME0": cmusen's rand() stream (agglomerates)
  GlibcRand glibc;                  // that stream, used from the first such fix
  FixMusenInlet *stream_owner();
  int nslots = 0;
  std::vector<int> made;        // successes per fraction (MUSEN's generated mixture particles)
  std::vector<Event> events;
  std::vector<bigint> requested_before;    // objects asked for by the events before each
  bigint inserted;
  tagint first_id, last_id;     // the ID floor; the last ID this fix gave (0: none)
  FILE *log;
  double type_radius;           // extract()'s answer

  void schedule_next();
  std::vector<Sphere> spheres_near(double reach);
  std::vector<double> wall_triangles();
  int next_fraction() const;
  void insert(const Event &event);
  tagint create(const std::vector<Sphere> &made_now, const std::vector<int> &types,
                const std::vector<double> &vel, const std::vector<tagint> *tags = nullptr);
  void insert_agglomerates(const Event &event, bigint slot);
  struct Surroundings {
    std::vector<Sphere> near;
    std::vector<double> tri;
    std::vector<int> close;
  };
  Surroundings surroundings();
  void add_bonds(const std::vector<Sphere> &made_now, const std::vector<tagint> &tags);
  bool sphere_fits(const Sphere &s, const std::vector<Sphere> &near, const std::vector<double> &tri,
                   const std::vector<int> &close) const;
};

}    // namespace LAMMPS_NS

#endif
