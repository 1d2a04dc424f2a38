/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenWallMesh (fix style musen/wall/mesh): MUSEN's particle-wall contact against walls
   made of triangles, moving rigidly by time-dependent motion intervals.

     fix ID group musen/wall/mesh FILE [law NAME [parameters]] ...   (default law hertz/mindlin)
   (several laws act on each contact in the order given, as cmusen runs several PW models:
   their forces and torques add, each continues the contact's history the previous left)

   What it reproduces (MUSEN 1.74.2, github.com/msolids/musen e0ff360; file/function named
   where each part is implemented below):
   - the contact point of a sphere on a triangle and its kind (face / edge / vertex:
     GeometricFunctions.h IsSphereIntersectTriangle, after Su et al.), on either side of
     the triangle;
   - which of several touched triangles count: among triangles whose normals differ by
     |n_i - n_j|^2 < 1e-6 a face contact removes edge/vertex contacts, of two edge contacts
     the later one is removed, a vertex contact is removed by any later one
     (VerletList.cpp GetPWContacts; candidates in MUSEN's wall order = FILE order);
     triangles with other normals (a facet corner) all act;
   - the Hertz-Mindlin particle-wall law (ModelPWHertzMindlin.cpp CalculatePW): force along
     the WALL's normal scaled by |rc_n . n|, relative velocity with the wall's translation and
     rotation, tangential damping outside the Coulomb test, rolling torque
     -mu_r |F_n,el| R w/|w| on the sphere's own spin; R* = R, m* = m of the sphere;
   - the tangential overlap per (sphere, triangle), kept in a FixMusenHistory (key = triangle
     index): created at zero, carried over from a triangle of the same geometry sharing a
     vertex that the sphere just left (CollisionsCalculator.cpp CheckPWCollisions,
     SimplifiedScene.cpp FindAdjacentWalls), dropped when the contact ends;
   - the wall velocity MUSEN's contact law sees (CPUSimulator.cpp MoveWalls): that of the
     motion interval holding the current time (closed [t_begin, t_end]); when no interval
     moves the geometry the triangles stand still but KEEP the last velocity, rotation
     velocity and rotation centre in the contact law (MUSEN never resets them);
     "rotate around centre" rotates about the area-weighted centroid of the triangles.
   - periodic boxes: a sphere also meets the periodic images of the triangles (MUSEN's
     virtual particles), after its own contacts; a triangle touched by the sphere itself is
     not touched by an image.
   A set-up force evaluation (every run, run 0) computes forces without advancing the
   contacts (as LAMMPS's granular styles): only time steps change the tangential overlaps.
   The triangle forces a set-up evaluation finds at the step a time step already computed
   (a checkpoint's "run 0") are not kept: the step's own (made with half-step velocities)
   stay, and the restart file keeps them, so checkpointed, resumed and uninterrupted runs
   write the same triangle forces.
   Triangle positions follow the exact solution x(t) = R(t) x0 + b(t) of the motion (the
   coefficients come from FILE: fibrelmp's translation writes the same ones it reports wall
   positions with), evaluated at the current time of every force computation.

   Output: compute_array(i, j) for triangle i (FILE order): j = 0..2 force ON the triangle
   (minus the forces on the spheres), j = 3..11 its vertices now; compute_vector(3 g + k):
   total force on geometry g.  "fix_modify ID write FILE2 [append yes|no]" appends the
   per-triangle forces as a LAMMPS dump frame (ITEM: ATOMS id fx fy fz, id = triangle + 1)
   written by rank 0: a job's saved frames call it.

   FILE (text; '#' starts a comment; numbers as C strtod reads them, "inf" included):
     musen/wall/mesh 1
     laws L                      then L lines:  TYPE MATERIAL E* G* e mu mu_r
     geometries G                then per geometry:
       geometry NAME AROUND_CENTRE NSEG NINT
       NSEG lines:  seg t0 t1 w ax ay az  kr[4][3][3] (36)  kb[4][3] (12)
                    in [t0, t1): R = sum_k e_k kr[k], b = sum_k e_k kb[k] with
                    e = (1, tau, cos(w tau), sin(w tau)), tau = t - t0 (w = 0: e = (1, tau, 1, 0));
                    before the first segment R = I, b = 0; after the last, the last one.
       NINT lines:  int t_begin t_end vx vy vz cx cy cz wx wy wz   (MUSEN's intervals, sorted)
       optional:    force KIND NF   (MUSEN's motion type: 1 time, 2 force-dependent, 3 constant
                                     force), then NF lines  fint LIMIT MAX vx vy vz cx cy cz wx wy wz
                                     (MAX 1: the interval ends when the force exceeds LIMIT, 0: when
                                     it falls below)
       optional:    free FX FY FZ MASS   (free axes 0/1 and the geometry's mass)
       optional:    velocity vx vy vz    (a stepped geometry's walls' velocity at the start)
     gravity gx gy gz            (optional: the external acceleration a free geometry feels)
     triangles T                 then T lines:  GEOMETRY MATERIAL x1 y1 z1 x2 y2 z2 x3 y3 z3
   TYPE is a LAMMPS atom type, MATERIAL any integer >= 0 (a wall material), GEOMETRY the
   0-based index of a geometry line.  The triangle order is MUSEN's wall order (geometries in
   scene order, each in its `27` list order): it decides ties between touched triangles.

   A geometry with a "force" or a "free" line is STEPPED (fix_musen_wall_mesh_motion.cpp):
   it has no segments and moves as MUSEN's CPUSimulator::MoveWalls moves it, one update per
   time step from the total force the walls felt in the previous step (the z component of
   the sum of its triangles' forces switches force-dependent intervals, the whole force plus
   gravity x MASS accelerates free axes), plus MUSEN's extra update of its half-step
   prediction before the first step, so at time t its triangles are where MUSEN's are.
   With fix musen/leapfrog's variable time step, a step moves them by the dt from before that
   step's change, at the time before the step (MoveWalls gets m_currSimulationStep's old value).
   compute_array's vertices then come from this stepping, and "fix_modify write" adds each
   triangle's velocity and vertices (vx vy vz x1 .. z3) to its frame.

   Only public LAMMPS classes are used (Fix, Atom, Domain, Neighbor, Update, Comm).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(musen/wall/mesh,FixMusenWallMesh);
// clang-format on
#else

#ifndef FIBRELMP_FIX_MUSEN_WALL_MESH_H
#define FIBRELMP_FIX_MUSEN_WALL_MESH_H

#include "fix.h"
#include "musen_pw_law.h"

#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class FixMusenWallMesh : public Fix {
 public:
  FixMusenWallMesh(class LAMMPS *, int, char **);
  ~FixMusenWallMesh() override;
  int setmask() override;
  void post_constructor() override;
  void init() override;
  void setup(int) override;
  void post_force(int) override;
  double compute_array(int, int) override;
  double compute_vector(int) override;
  int modify_param(int, char **) override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  double memory_usage() override;
  // the triangles where they are now (9 numbers each: V1 V2 V3), as fix musen/inlet checks them
  const std::vector<double> &vertices_now() const { return vert; }

  // contact kinds of MUSEN's EIntersectionType
  enum { NO_CONTACT = 0, FACE_CONTACT = 1, EDGE_CONTACT = 2, VERTEX_CONTACT = 3 };

 private:
  int write_contacts(int, char **);
  int write_dump_frame(int, char **, const std::function<void(FILE *)> &);
  void dump_header(FILE *, const char *, size_t) const;
  struct Segment {
    double t0, t1, w;
    double kr[4][3][3];
    double kb[4][3];
  };
  struct Interval {
    double tb, te;
    double v[3], c[3], w[3];
    bool moves() const;
  };
  struct ForceInterval {
    double limit;
    bool max;            // MUSEN's ELimitType::MAX (else MIN)
    double v[3], c[3], w[3];
  };
  struct Geometry {
    std::string name;
    bool around_centre;
    bool rotating;                  // some segment rotates: normals follow the vertices
    std::vector<Segment> segments;
    std::vector<Interval> intervals;
    std::vector<int> tris;          // its triangles (FILE order)
    // stepped geometries (fix_musen_wall_mesh_motion.cpp)
    bool stepped = false;
    int motion_kind = 0;            // MUSEN's EMotionType: 0 none, 1 time, 2 force, 3 constant force
    std::vector<ForceInterval> fints;
    long imotion = -1;              // CGeometryMotion::m_iMotion
    double cur_v[3] = {0, 0, 0}, cur_w[3] = {0, 0, 0}, cur_c[3] = {0, 0, 0};   // m_currentMotion
    bool free_axis[3] = {false, false, false};
    double mass = 0.0;
    double start_vel[3] = {0, 0, 0};   // its walls' velocity at the start (the scene's)
    // the wall motion MUSEN's contact law sees now
    double vel[3], rotvel[3], rotcentre[3];
  };
  // the particle-wall laws, in the order they act (musen_pw_law.h)
  std::vector<std::unique_ptr<musen_pw::Law>> pw_laws;
  class Fix *heat_fix = nullptr;    // fix musen/heat when a law heats (init)
  // with heat_fix, this post_force's heat flux and temperatures (looked up once per call, not
  // per contact: both lookups search by name)
  double *heat_flux = nullptr, *heat_temperature = nullptr;
  struct Law {
    bool set;
    double estar, gstar, alpha, mu, mur;
  };
  struct Candidate {
    int tri, shift;      // shift: periodic image code of the triangle (0: none)
    int kind;
    double cp[3];        // contact point on the triangle (unshifted)
    double xs[3];        // the sphere centre moved by minus the shift (MUSEN's virtual particle)
  };

  std::string file;
  int ntri, ngeom, nmat;
  std::vector<double> x0;       // 9 per triangle, at FILE time
  std::vector<double> vert;     // 9 per triangle, now
  std::vector<double> nrm;      // 3 per triangle (unit normal (v2-v1)x(v3-v1))
  std::vector<double> tlo, thi; // bounding boxes now
  std::vector<double> tpre;     // per triangle, what sphere_triangle needs of it alone,
  std::vector<long> tpre_stamp; // valid when its stamp is tpre_epoch (bumped when walls move)
  long tpre_epoch = 0;
  const double *constants_of(int tr);
  std::vector<int> tgeom, tmat;
  std::vector<Geometry> geoms;
  std::vector<int> adj_start, adj;    // triangles sharing a vertex, same geometry (CSR)
  std::vector<Law> laws;               // (ntypes + 1) x nmat
  bool any_moving;
  double t_placed;                     // time the triangles were last placed at
  bool placed;
  bool warned_centre_on_wall = false;
  // stepped geometries: the prediction update done, ftri holds forces not yet used to move,
  // frames still show the walls as they started (between the prediction and its first step)
  bool any_stepped = false, started = false, pending = false, at_start = false;
  double gravity[3] = {0, 0, 0};
  std::vector<double> start_vert;      // vertices before the prediction update    // a sphere centre on a triangle was met (warned once)

  // per-triangle force on the walls (local sums; reduced on demand)
  std::vector<double> ftri, ftri_all, fgeom_all;
  // the last evaluation's contacts on this rank: (tag, triangle id, contact point, force on the
  // sphere) each, for MUSEN's stress tensor (fix_modify ID contacts FILE)
  std::vector<double> contact_rec;
  bigint reduced_step;
  bool reduced_valid;
  bigint ftri_step = -1;    // the time step whose contacts made ftri (-1: a set-up evaluation)

  class FixMusenHistory *history;
  std::string history_id;

  // culling grid of this rank: cells of triangle (+ periodic image) entries
  bool grid_valid;
  double grid_lo[3], grid_cell;
  int grid_n[3];
  double grid_rmax, grid_margin;
  double grid_sublo[3], grid_subhi[3];
  std::vector<double> grid_vert;       // vertices when the grid was built
  std::vector<int> cell_start, cell_entries;
  std::vector<int> all_entries;        // every (triangle, shift) entry, for spheres off the grid
  long grid_stamp = 0;                 // bumped by every build_grid
  // a static mesh: each sphere's entries within its radius + the neighbour skin, kept until a
  // sphere moved half a skin, LAMMPS re-neighboured (atoms re-indexed) or the grid changed
  // (MUSEN's Verlet list of walls); a subsequence of its cell's entries, so in their order
  std::vector<int> near_start, near_entries;
  std::vector<double> near_x;          // the spheres' centres when the lists were made
  std::vector<tagint> near_tag;
  long near_stamp = -1;
  int near_nlocal = -1;
  bool near_lists_stale(int nlocal);
  void build_near_lists(int nlocal);
  const int *entries_of(const double *x, int &nent) const;
  struct Work {
    int cand;
    double xi[3];        // tangential overlap in, updated out
  };
  std::vector<Candidate> cand;
  std::vector<Work> order;
  std::vector<char> old_mark;

  void read_file();
  void parse(const std::string &text);
  void find_adjacent();
  void place(double t);
  void motion_state(double t);
  void step_walls(double t, double dt);
  class FixMusenLeapfrog *clock = nullptr;    // a variable time step's clock (else none)
  static void update_motion(Geometry &G, double value);
  static void rotation_matrix(const double *w, double dt, double R[3][3]);
  void centroid(const Geometry &G, double *centre) const;
  std::vector<double> stepped_state() const;
  void restore_stepped(const double *list);
  void build_grid(double rmax);
  bool grid_stale(double rmax);
  void reduce_forces();
  void wall_force(int i, const Candidate &c, double *hist, double dt, double *f, double *torque);
  static int shift_code(int sx, int sy, int sz);
  void shift_vector(int code, double *s) const;
  double current_time() const;
};

}    // namespace LAMMPS_NS

#endif
#endif
