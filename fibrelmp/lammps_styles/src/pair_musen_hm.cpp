/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/hm: MUSEN's Hertz-Mindlin particle-particle contact.  The formulas follow
   MUSEN (BSD-3, commit e0ff360) operation by operation, so that the forces equal a
   reference written from MUSEN's code to the last bit where the arithmetic allows:
     - CModelPPHertzMindlin::CalculatePP            (the force and moment law)
     - CSimplifiedScene::CalculateInteractionProperty (dAlpha from the restitution)
     - CCollisionsCalculator::CheckPPCollision       (when a contact exists; overlap, R*, m*)
   MUSEN's vector algebra (Vector3.h) is written out component-wise in the same order:
   a*b of two vectors is the cross product, Length() = sqrt(x*x + y*y + z*z),
   Normalized() divides by the length (zero vector for zero length), IsSignificant() is
   "some |component| > 1e-100".

   Ownership of a contact (newton off half list, forced by the neighbor request whatever
   `newton` says): a pair of two owned atoms is listed once and updates both atoms' history
   entries (the partner's entry holds -xi); a pair of an owned and a ghost atom is listed on
   both processors (each lists it for its own atom), each computes it and keeps only its own
   atom's force, torque and history entry.  MUSEN's law is exactly antisymmetric in IEEE
   arithmetic (swapping the two spheres negates the contact vector, the relative velocity and
   xi, and every product and sum only changes sign), so both sides compute bit-identical
   values and the two entries stay exact negatives of each other through atom migration.
   (Across a periodic boundary the two sides see images shifted by +L and -L, which round
   differently: there the two sides agree to round-off only, in serial as under MPI.)
   The price is that pairs across a processor boundary are computed twice; the gain is no
   reverse communication of history and no dependence on which atom LAMMPS lists first.
------------------------------------------------------------------------- */

#include "pair_musen_hm.h"
#include "style_registry.h"
#include "musen_startup.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix.h"
#include "fix_musen_history.h"
#include "fix_musen_verlet.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"
#include "utils.h"

#include <cmath>
#include <cstring>
#include <string>

using namespace LAMMPS_NS;

namespace {
// MUSENDefinitions.h
constexpr double MUSEN_PI = 3.14159265358979323846;
constexpr double MUSEN_2_SQRT_5_6 = 1.825741858350553711523232609336;
// Vector3.h: MinValueHelper<double>::min_value()
constexpr double MIN_SIGNIFICANT = 1e-100;

inline bool significant(const double *v)
{
  return std::fabs(v[0]) > MIN_SIGNIFICANT || std::fabs(v[1]) > MIN_SIGNIFICANT ||
      std::fabs(v[2]) > MIN_SIGNIFICANT;
}
inline double length(const double *v)
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}
inline void cross(const double *a, const double *b, double *c)
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
}    // namespace

/* ---------------------------------------------------------------------- */

void PairMusenHM::stiffness(int itype, int jtype, double overlap, double equiv_radius,
                            double &kn, double &kt, double &fn_el) const
{
  // Hertz: both stiffnesses grow with the contact area radius
  const double contact_area_radius = std::sqrt(equiv_radius * overlap);
  kn = 2 * estar[itype][jtype] * contact_area_radius;
  fn_el = -overlap * kn * 2. / 3.;
  kt = 8 * gstar[itype][jtype] * contact_area_radius;
}

PairMusenHM::PairMusenHM(LAMMPS *lmp) :
    Pair(lmp), estar(nullptr), gstar(nullptr), restitution(nullptr), alpha(nullptr),
    mu(nullptr), mu_roll(nullptr), maxrad(nullptr), history(nullptr), verlet(nullptr)
{
  // single(): the contact force at the current state, for compute pair/local
  single_enable = 1;
  single_extra = 6;
  svector = new double[single_extra];
  restartinfo = 1;
  finitecutflag = 1;
  // forces are only written to owned atoms (newton off list): f.r over ghosts would be wrong
  no_virial_fdotr_compute = 1;
}

PairMusenHM::~PairMusenHM()
{
  if (copymode) return;
  // the history belongs to this style; LAMMPS deletes pair styles before fixes
  if (history && modify && modify->get_fix_by_id(HISTORY_ID)) modify->delete_fix(HISTORY_ID);
  delete[] svector;
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
    memory->destroy(estar);
    memory->destroy(gstar);
    memory->destroy(restitution);
    memory->destroy(alpha);
    memory->destroy(mu);
    memory->destroy(mu_roll);
    delete[] maxrad;
  }
}

bool PairMusenHM::released(tagint a, tagint b) const
{
  return verlet && verlet->any_released() && verlet->released(a, b);
}

/* ---------------------------------------------------------------------- */

void PairMusenHM::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);

  // LAMMPS recomputes forces at the start of every run (setup) and for `run 0`: those
  // evaluations must not advance the tangential overlap (MUSEN advances it once per step)
  const bool advance = musen_startup::advances(update);    // musen_startup.h
  const double dt = update->dt;

  double **x = atom->x;
  double **f = atom->f;
  double **omega = atom->omega;
  double **torque = atom->torque;
  double *radius = atom->radius;
  double *rmass = atom->rmass;
  int *type = atom->type;
  tagint *tag = atom->tag;
  const int nlocal = atom->nlocal;
  const double *special_lj = force->special_lj;

  const int inum = list->inum;
  int *ilist = list->ilist;
  int *numneigh = list->numneigh;
  int **firstneigh = list->firstneigh;

  for (int ii = 0; ii < inum; ii++) {
    const int i = ilist[ii];
    const int itype = type[i];
    int *jlist = firstneigh[i];
    const int jnum = numneigh[i];

    for (int jj = 0; jj < jnum; jj++) {
      int j = jlist[jj];
      // MUSEN's "contacts between bonded particles" off: special_bonds lj 0 (checked in init);
      // a broken bond's pair is special until MUSEN's contact-list update released it
      if (special_lj[sbmask(j)] == 0.0 && !released(tag[i], tag[j & NEIGHMASK])) continue;
      j &= NEIGHMASK;
      const int jtype = type[j];

      // CheckPPCollision: src = i, dst = j; vContactVector = dst - src
      const double cv[3] = {x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]};
      const double rsq = cv[0] * cv[0] + cv[1] * cv[1] + cv[2] * cv[2];
      const double r1 = radius[i], r2 = radius[j];
      if (!((r1 + r2) * (r1 + r2) > rsq)) continue;    // no contact: its history is swept
      const double overlap = r1 + r2 - std::sqrt(rsq);
      const double equiv_radius = r1 * r2 / (r1 + r2);
      const double equiv_mass = rmass[i] * rmass[j] / (rmass[i] + rmass[j]);

      // stored tangential overlap (zero for a new contact)
      double *xi_i = nullptr;
      double xi_old[3] = {0.0, 0.0, 0.0};
      if (advance) {
        xi_i = history->get(i, tag[j]);
        xi_old[0] = xi_i[0];
        xi_old[1] = xi_i[1];
        xi_old[2] = xi_i[2];
      } else if (const double *found = history->find(i, tag[j])) {
        xi_old[0] = found[0];
        xi_old[1] = found[1];
        xi_old[2] = found[2];
      }

      // ---- CalculatePP
      const double *w1 = omega[i], *w2 = omega[j];
      double n[3], cvlen, vn, vt[3];
      kinematics(i, j, cv, n, cvlen, vn, vt);

      // rotate the old tangential overlap into the tangent plane, keeping its length
      const double xi_n = n[0] * xi_old[0] + n[1] * xi_old[1] + n[2] * xi_old[2];
      double xi_rot[3];
      for (int k = 0; k < 3; k++) xi_rot[k] = xi_old[k] - n[k] * xi_n;
      if (significant(xi_rot)) {
        const double scale = length(xi_old) / length(xi_rot);
        for (int k = 0; k < 3; k++) xi_rot[k] *= scale;
      }
      double xi[3];
      for (int k = 0; k < 3; k++) xi[k] = xi_rot[k] + vt[k] * dt;

      double fn_el, fn_damp, ft[3];
      contact_force(itype, jtype, overlap, equiv_radius, equiv_mass, vn, vt, xi, fn_el, fn_damp, ft);

      // rolling torque on each sphere's own angular velocity, with the elastic normal force
      double roll1[3] = {0.0, 0.0, 0.0}, roll2[3] = {0.0, 0.0, 0.0};
      if (significant(w1)) {
        const double c = -mu_roll[itype][jtype] * std::fabs(fn_el) * r1 / length(w1);
        for (int k = 0; k < 3; k++) roll1[k] = w1[k] * c;
      }
      if (significant(w2)) {
        const double c = -mu_roll[itype][jtype] * std::fabs(fn_el) * r2 / length(w2);
        for (int k = 0; k < 3; k++) roll2[k] = w2[k] * c;
      }

      // total force on src; moments with the full radii
      const double fn = fn_el + fn_damp;
      double ftot[3], nxft[3];
      for (int k = 0; k < 3; k++) ftot[k] = n[k] * fn + ft[k];
      cross(n, ft, nxft);

      // ---- ConsolidateSrc / ConsolidateDst
      for (int k = 0; k < 3; k++) {
        f[i][k] += ftot[k];
        torque[i][k] += nxft[k] * r1 + roll1[k];
      }
      if (j < nlocal) {
        for (int k = 0; k < 3; k++) {
          f[j][k] -= ftot[k];
          torque[j][k] += nxft[k] * r2 + roll2[k];
        }
      }

      // the entry keeps xi and, for single(), the normal and tangential force of this step
      if (advance) {
        for (int k = 0; k < 3; k++) {
          xi_i[k] = xi[k];
          xi_i[3 + k] = n[k] * fn;
          xi_i[6 + k] = ft[k];
        }
        if (j < nlocal) {
          double *xi_j = history->get(j, tag[i]);
          for (int k = 0; k < 3; k++) {
            xi_j[k] = -xi[k];
            xi_j[3 + k] = -(n[k] * fn);
            xi_j[6 + k] = -ft[k];
          }
        }
      }

      if (evflag)
        ev_tally_xyz(i, j, nlocal, 0, 0.0, 0.0, ftot[0], ftot[1], ftot[2], -cv[0], -cv[1], -cv[2]);
    }
  }

  // contacts not met this step have ended (MUSEN drops them; a new one starts at xi = 0)
  if (advance) history->sweep(nlocal);
}

/* ---------------------------------------------------------------------- */

void PairMusenHM::allocate()
{
  allocated = 1;
  const int np1 = atom->ntypes + 1;
  memory->create(setflag, np1, np1, "pair:setflag");
  for (int i = 1; i < np1; i++)
    for (int j = i; j < np1; j++) setflag[i][j] = 0;
  memory->create(cutsq, np1, np1, "pair:cutsq");
  memory->create(estar, np1, np1, "pair:estar");
  memory->create(gstar, np1, np1, "pair:gstar");
  memory->create(restitution, np1, np1, "pair:restitution");
  memory->create(alpha, np1, np1, "pair:alpha");
  memory->create(mu, np1, np1, "pair:mu");
  memory->create(mu_roll, np1, np1, "pair:mu_roll");
  maxrad = new double[np1];
}

void PairMusenHM::settings(int narg, char ** /*arg*/)
{
  if (narg != 0) error->all(FLERR, "Illegal pair_style musen/hm command: it takes no arguments");
}

void PairMusenHM::coeff(int narg, char **arg)
{
  if (narg != 7)
    error->all(FLERR, "Incorrect args for pair_style musen/hm: pair_coeff I J Estar Gstar e mu mu_r");
  if (!allocated) allocate();

  int ilo, ihi, jlo, jhi;
  utils::bounds(FLERR, arg[0], 1, atom->ntypes, ilo, ihi, error);
  utils::bounds(FLERR, arg[1], 1, atom->ntypes, jlo, jhi, error);

  const double e_star = utils::numeric(FLERR, arg[2], false, lmp);
  const double g_star = utils::numeric(FLERR, arg[3], false, lmp);
  const double e_rest = utils::numeric(FLERR, arg[4], false, lmp);
  const double mu_s = utils::numeric(FLERR, arg[5], false, lmp);
  const double mu_r = utils::numeric(FLERR, arg[6], false, lmp);
  if (!(e_star > 0.0) || !std::isfinite(e_star))
    error->all(FLERR, "pair musen/hm: effective Young's modulus Estar must be > 0, got {}", arg[2]);
  if (!(g_star >= 0.0) || !std::isfinite(g_star))
    error->all(FLERR, "pair musen/hm: effective shear modulus Gstar must be >= 0, got {}", arg[3]);
  if (!(e_rest > 0.0 && e_rest <= 1.0))
    error->all(FLERR, "pair musen/hm: restitution coefficient e must be in (0, 1], got {}", arg[4]);
  if (!(mu_s >= 0.0) || !std::isfinite(mu_s))
    error->all(FLERR, "pair musen/hm: sliding friction mu must be >= 0, got {}", arg[5]);
  if (!(mu_r >= 0.0) || !std::isfinite(mu_r))
    error->all(FLERR, "pair musen/hm: rolling friction mu_r must be >= 0, got {}", arg[6]);

  // CalculateInteractionProperty: dAlpha = log(e) / sqrt(PI*PI + pow(log(e), 2))
  const double log_e = std::log(e_rest);
  const double a = log_e / std::sqrt(MUSEN_PI * MUSEN_PI + std::pow(log_e, 2));

  int count = 0;
  for (int i = ilo; i <= ihi; i++) {
    for (int j = std::max(jlo, i); j <= jhi; j++) {
      estar[i][j] = e_star;
      gstar[i][j] = g_star;
      restitution[i][j] = e_rest;
      alpha[i][j] = a;
      mu[i][j] = mu_s;
      mu_roll[i][j] = mu_r;
      setflag[i][j] = 1;
      count++;
    }
  }
  if (count == 0) error->all(FLERR, "Incorrect args for pair coefficients (musen/hm: no type pair)");
}

/* ---------------------------------------------------------------------- */

void PairMusenHM::init_style()
{
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "pair musen/hm requires atoms with radius, rmass, omega and torque "
                      "(atom_style sphere or bpm/sphere)");
  if (comm->ghost_velocity == 0)
    error->all(FLERR, "pair musen/hm requires ghost atoms to store velocity: comm_modify vel yes");
  for (int k = 1; k < 4; k++)
    if (force->special_lj[k] != 0.0 && force->special_lj[k] != 1.0)
      error->all(FLERR, "pair musen/hm: special_bonds lj weights must be 0 (no contact between "
                        "bonded spheres) or 1 (contact, MUSEN's default), got {}",
                 force->special_lj[k]);

  const auto verlets = modify->get_fix_by_style("^musen/verlet$");
  verlet = verlets.empty() ? nullptr : static_cast<FixMusenVerlet *>(verlets[0]);

  // size-based half list with newton off whatever `newton` says (see the file header)
  neighbor->add_request(this, NeighConst::REQ_SIZE | NeighConst::REQ_NEWTON_OFF);

  if (!history) {
    Fix *found = modify->get_fix_by_id(HISTORY_ID);
    if (!found)
      found = modify->add_fix(std::string(HISTORY_ID) + " all MUSEN/HISTORY " +
                              std::to_string(HISTORY_VALUES));
    history = dynamic_cast<FixMusenHistory *>(found);
    if (!history || history->nvalues() != HISTORY_VALUES)
      error->all(FLERR, "pair musen/hm: fix ID {} exists but is not its MUSEN/HISTORY fix",
                 HISTORY_ID);
  }

  // largest radius of each type, for the neighbor cutoff of each type pair
  const int ntypes = atom->ntypes;
  auto *local = new double[ntypes + 1];
  for (int t = 0; t <= ntypes; t++) local[t] = 0.0;
  for (int i = 0; i < atom->nlocal; i++)
    local[atom->type[i]] = std::max(local[atom->type[i]], atom->radius[i]);
  // and the spheres an inlet will insert (fix musen/inlet, as fix pour for LAMMPS's granular
  // styles): without them a run that starts before they exist would miss their contacts
  for (Fix *inlet : modify->get_fix_by_style("^musen/inlet$"))
    for (int t = 1; t <= ntypes; t++) {
      int asked = t;
      if (const auto *r = static_cast<const double *>(inlet->extract("radius", asked)))
        local[t] = std::max(local[t], *r);
    }
  MPI_Allreduce(local, maxrad, ntypes + 1, MPI_DOUBLE, MPI_MAX, world);
  delete[] local;
}

double PairMusenHM::init_one(int i, int j)
{
  if (setflag[i][j] == 0)
    error->all(FLERR, "pair musen/hm: no pair_coeff for types {} {} (MUSEN's interaction "
                      "properties are given per material pair; there is no mixing rule)",
               i, j);
  estar[j][i] = estar[i][j];
  gstar[j][i] = gstar[i][j];
  restitution[j][i] = restitution[i][j];
  alpha[j][i] = alpha[i][j];
  mu[j][i] = mu[i][j];
  mu_roll[j][i] = mu_roll[i][j];
  return maxrad[i] + maxrad[j];
}

void PairMusenHM::kinematics(int i, int j, const double cv[3], double n[3], double &cvlen,
                             double &vn, double vt[3]) const
{
  double **v = atom->v;
  double **omega = atom->omega;
  const double r1 = atom->radius[i], r2 = atom->radius[j];
  const double *w1 = omega[i], *w2 = omega[j];
  const double s1 = r1 / (r1 + r2);
  const double s2 = -r2 / (r1 + r2);
  const double rc1[3] = {cv[0] * s1, cv[1] * s1, cv[2] * s1};
  const double rc2[3] = {cv[0] * s2, cv[1] * s2, cv[2] * s2};
  n[0] = n[1] = n[2] = 0.0;
  cvlen = length(cv);
  if (cvlen != 0) {
    n[0] = cv[0] / cvlen;
    n[1] = cv[1] / cvlen;
    n[2] = cv[2] / cvlen;
  }

  // normal and tangential relative velocity (dst minus src at the contact point)
  double w2rc2[3], w1rc1[3];
  cross(w2, rc2, w2rc2);
  cross(w1, rc1, w1rc1);
  double rel[3];
  for (int k = 0; k < 3; k++) rel[k] = (v[j][k] + w2rc2[k]) - (v[i][k] + w1rc1[k]);
  vn = n[0] * rel[0] + n[1] * rel[1] + n[2] * rel[2];
  for (int k = 0; k < 3; k++) vt[k] = rel[k] - vn * n[k];
}

void PairMusenHM::contact_force(int itype, int jtype, double overlap, double equiv_radius,
                                double equiv_mass, double vn, const double vt[3], double xi[3],
                                double &fn_el, double &fn_damp, double ft[3]) const
{
  // normal force with damping (negative: pushes src away from dst)
  double kn, kt;
  stiffness(itype, jtype, overlap, equiv_radius, kn, kt, fn_el);
  fn_damp = -MUSEN_2_SQRT_5_6 * alpha[itype][jtype] * vn * std::sqrt(kn * equiv_mass);

  // tangential force with damping
  double ft_spring[3];
  for (int k = 0; k < 3; k++) ft_spring[k] = xi[k] * kt;
  const double damp_t = -MUSEN_2_SQRT_5_6 * alpha[itype][jtype] * std::sqrt(kt * equiv_mass);

  // MUSEN tests the spring force alone against mu |Fn_el + Fn_damp|; when it slips the
  // force is the capped spring force (no damping) and xi shrinks to match it
  const double ft_spring_len = length(ft_spring);
  const double friction_len = mu[itype][jtype] * std::fabs(fn_el + fn_damp);
  if (ft_spring_len > friction_len) {
    for (int k = 0; k < 3; k++) {
      ft[k] = ft_spring[k] * friction_len / ft_spring_len;
      xi[k] = ft[k] / kt;
    }
  } else {
    for (int k = 0; k < 3; k++) ft[k] = ft_spring[k] + vt[k] * damp_t;
  }
}

/* ----------------------------------------------------------------------
   The contact force on i (compute pair/local, between runs): the force compute() applied
   in the last step, as its history entry keeps it (a contact is swept the step it ends, so
   an entry is this step's).  Without an entry (a contact no step has advanced yet: the
   force of the first run's setup, step 0, is not stored) the force compute() gives at the
   current state without advancing: xi = 0 + vt dt.
   fforce: the normal force on i over the distance along x_i - x_j (pair/local's fx fy fz);
   svector: the tangential force on i (3), x_i - x_j (3).  Returns 0 (no energy).
------------------------------------------------------------------------- */

double PairMusenHM::single(int i, int j, int itype, int jtype, double rsq, double /*factor_coul*/,
                           double factor_lj, double &fforce)
{
  double **x = atom->x;
  double *radius = atom->radius;
  double *rmass = atom->rmass;
  tagint *tag = atom->tag;

  const double cv[3] = {x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]};
  fforce = 0.0;
  for (int k = 0; k < 3; k++) {
    svector[k] = 0.0;
    svector[3 + k] = -cv[k];
  }
  const double r1 = radius[i], r2 = radius[j];
  if ((factor_lj == 0.0 && !released(tag[i], tag[j])) || !((r1 + r2) * (r1 + r2) > rsq)) return 0.0;
  const double overlap = r1 + r2 - std::sqrt(rsq);
  const double equiv_radius = r1 * r2 / (r1 + r2);
  const double equiv_mass = rmass[i] * rmass[j] / (rmass[i] + rmass[j]);
  if (const double *found = history ? history->find(i, tag[j]) : nullptr) {
    // normal force n fn along -(x_i - x_j): fforce = (n fn) . (x_i - x_j) / |x_i - x_j|^2
    fforce = -(found[3] * cv[0] + found[4] * cv[1] + found[5] * cv[2]) / rsq;
    for (int k = 0; k < 3; k++) svector[k] = found[6 + k];
    return 0.0;
  }

  double n[3], cvlen, vn, vt[3];
  kinematics(i, j, cv, n, cvlen, vn, vt);
  double xi[3];
  for (int k = 0; k < 3; k++) xi[k] = 0.0 + vt[k] * update->dt;    // a new contact's first xi
  double fn_el, fn_damp, ft[3];
  contact_force(itype, jtype, overlap, equiv_radius, equiv_mass, vn, vt, xi, fn_el, fn_damp, ft);

  // normal force on i: n (fn_el + fn_damp) = (x_i - x_j) fforce
  if (cvlen != 0) fforce = -(fn_el + fn_damp) / cvlen;
  for (int k = 0; k < 3; k++) svector[k] = ft[k];
  return 0.0;
}

/* ---------------------------------------------------------------------- */

void PairMusenHM::write_restart(FILE *fp)
{
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      fwrite(&setflag[i][j], sizeof(int), 1, fp);
      if (setflag[i][j]) {
        fwrite(&estar[i][j], sizeof(double), 1, fp);
        fwrite(&gstar[i][j], sizeof(double), 1, fp);
        fwrite(&restitution[i][j], sizeof(double), 1, fp);
        fwrite(&alpha[i][j], sizeof(double), 1, fp);
        fwrite(&mu[i][j], sizeof(double), 1, fp);
        fwrite(&mu_roll[i][j], sizeof(double), 1, fp);
      }
    }
}

void PairMusenHM::read_restart(FILE *fp)
{
  allocate();
  const int me = comm->me;
  for (int i = 1; i <= atom->ntypes; i++)
    for (int j = i; j <= atom->ntypes; j++) {
      if (me == 0) utils::sfread(FLERR, &setflag[i][j], sizeof(int), 1, fp, nullptr, error);
      MPI_Bcast(&setflag[i][j], 1, MPI_INT, 0, world);
      if (setflag[i][j]) {
        double vals[6];
        if (me == 0) utils::sfread(FLERR, vals, sizeof(double), 6, fp, nullptr, error);
        MPI_Bcast(vals, 6, MPI_DOUBLE, 0, world);
        estar[i][j] = vals[0];
        gstar[i][j] = vals[1];
        restitution[i][j] = vals[2];
        alpha[i][j] = vals[3];
        mu[i][j] = vals[4];
        mu_roll[i][j] = vals[5];
      }
    }
}

void *PairMusenHM::extract(const char *str, int &dim)
{
  dim = 2;
  if (strcmp(str, "estar") == 0) return (void *) estar;
  if (strcmp(str, "gstar") == 0) return (void *) gstar;
  if (strcmp(str, "e") == 0) return (void *) restitution;
  if (strcmp(str, "alpha") == 0) return (void *) alpha;
  if (strcmp(str, "mu") == 0) return (void *) mu;
  if (strcmp(str, "mu_r") == 0) return (void *) mu_roll;
  return nullptr;
}

double PairMusenHM::memory_usage()
{
  const double np1 = atom->ntypes + 1;
  return np1 * np1 * (sizeof(int) + 7 * sizeof(double)) + np1 * sizeof(double);
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Pair *create(LAMMPS *lmp) { return new PairMusenHM(lmp); }
const style_registry::Registration registered(
    20, "musen/hm", "MUSEN Hertz-Mindlin particle-particle contact", &create);
}    // namespace
