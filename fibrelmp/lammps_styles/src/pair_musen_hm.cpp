/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/hm: MUSEN's particle-particle contact laws (musen_pp_law.h; Hertz-Mindlin
   first).  The formulas follow MUSEN (BSD-3, commit e0ff360) operation by operation, so that
   the forces equal a reference written from MUSEN's code to the last bit where the
   arithmetic allows:
     - CModelPPHertzMindlin::CalculatePP            (the force and moment law, in the laws)
     - CCPUSimulator::CalculateForcesPP             (several laws: each in turn, forces add)
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
#include "lammps_time.h"
#include "style_registry.h"
#include "musen_startup.h"
#include "musen_pp_hertz_mindlin.h"

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

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

using namespace LAMMPS_NS;

namespace {
// MUSENDefinitions.h
constexpr double MUSEN_PI = 3.14159265358979323846;

// Vector3.h: Length()
inline double length(const double *v)
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}
// a later law's force and moments added to the earlier ones
inline void add_result(musen_pp::Result &sum, const musen_pp::Result &more)
{
  sum.fn_len += more.fn_len;
  sum.heat += more.heat;
  for (int k = 0; k < 3; k++) {
    sum.fn[k] += more.fn[k];
    sum.ft[k] += more.ft[k];
    sum.m1[k] += more.m1[k];
    sum.m2[k] += more.m2[k];
  }
}
inline void cross(const double *a, const double *b, double *c)
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
}    // namespace

/* ---------------------------------------------------------------------- */

PairMusenHM::PairMusenHM(LAMMPS *lmp) :
    Pair(lmp), estar(nullptr), gstar(nullptr), restitution(nullptr), alpha(nullptr),
    mu(nullptr), mu_roll(nullptr), maxrad(nullptr), history(nullptr), only_hertz(nullptr), verlet(nullptr)
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
  if (only_hertz) {
    // MUSEN's default, alone: its law called directly (inlined), not through the list
    const musen_pp::HertzMindlin &law = *only_hertz;
    contacts<false>([&law](const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
                    musen_pp::Result &r) { law.calculate_pp(c, m, xi, r); });
  } else if (law_block.empty() && laws.size() == 1) {
    // one law: its force directly (no loop over the laws, no second result to add)
    const musen_pp::Law &law = *laws[0];
    contacts<false>([&law](const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
                           musen_pp::Result &r) { law.force(c, m, xi, r); });
  } else if (law_block.empty()) {
    contacts<false>([this](const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
                           musen_pp::Result &r) { apply_laws(c, m, xi, r); });
  } else {
    contacts<true>([this](const musen_pp::Contact &c, const musen_pp::Materials &m, double *xi,
                    musen_pp::Result &r) { apply_laws(c, m, xi, r); });
  }
}

void PairMusenHM::apply_laws(const musen_pp::Contact &c, const musen_pp::Materials &m,
                             double *xi, musen_pp::Result &r) const
{
  laws[0]->force(c, m, xi, r);
  // later laws (MUSEN's later PP models): their forces and moments add
  for (std::size_t l = 1; l < laws.size(); l++) {
    musen_pp::Result more;
    laws[l]->force(c, m, xi, more);
    add_result(r, more);
  }
}

// inline in contacts(): called for every contact of every step
[[gnu::always_inline]] inline void PairMusenHM::kinematics(int i, int j, const double cv[3], double n[3], double &cvlen,
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

template <bool LAW_VALUES, class Laws> void PairMusenHM::contacts(Laws apply)
{
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
  // heat laws (fix musen/heat): temperatures, per-type conductivity, the flux to add to
  double *temp = nullptr, *flux = nullptr, *conductivity = nullptr;
  if (heat_fix) {
    int dim, flag, cols;
    flux = static_cast<double *>(heat_fix->extract("flux", dim));
    conductivity = static_cast<double *>(heat_fix->extract("conductivity", dim));
    temp = atom->dvector[atom->find_custom("musen_temperature", flag, cols)];
  } else if (temperature_index >= 0) {
    temp = atom->dvector[temperature_index];
  }
  // the laws' own per-contact values: the entry's own when the step advances (get() made it,
  // zero for a new contact), else a copy (law_block) the laws may change without effect
  const int law_values = LAW_VALUES ? history_values - HISTORY_VALUES : 0;
  double *block = law_block.data();
  // MUSEN's time of this evaluation (its `_time == 0` rule)
  const bool at_time_zero = simulation_time(update) == 0.0;

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

      // stored tangential overlap and law values (zero for a new contact)
      double *xi_i = nullptr;
      double xi[3] = {0.0, 0.0, 0.0};
      const double *stored = nullptr;
      if (advance) {
        xi_i = history->get(i, tag[j]);
        stored = xi_i;
      } else {
        stored = history->find(i, tag[j]);
      }
      if (stored) {
        xi[0] = stored[0];
        xi[1] = stored[1];
        xi[2] = stored[2];
      }
      double *own_values = nullptr;
      if (LAW_VALUES) {
        if (advance) {
          own_values = xi_i + HISTORY_VALUES;
        } else {
          for (int v = 0; v < law_values; v++) block[v] = stored ? stored[HISTORY_VALUES + v] : 0.0;
          own_values = block;
        }
      }

      // ---- CalculatePP of each law in turn (MUSEN's order), each continuing xi
      double n[3], cvlen, vn, vt[3];
      kinematics(i, j, cv, n, cvlen, vn, vt);
      musen_pp::Contact c{overlap, equiv_radius, equiv_mass, r1, r2, n, vn, vt,
                          omega[i], omega[j], dt};
      c.law_history = own_values;
      c.at_time_zero = at_time_zero;
      if (temp) {
        c.t1 = temp[i];
        c.t2 = temp[j];
      }
      if (heat_fix) {
        c.k1 = conductivity[itype];
        c.k2 = conductivity[jtype];
      }
      const musen_pp::Materials mats{estar[itype][jtype], gstar[itype][jtype],
                                     alpha[itype][jtype], mu[itype][jtype],
                                     mu_roll[itype][jtype]};
      musen_pp::Result r;
      apply(c, mats, xi, r);
      // ConsolidateSrc / ConsolidateDst of a heat law: HeatFlux += / -= the contact's
      if (heat_fix) {
        flux[i] += r.heat;
        if (j < nlocal) flux[j] -= r.heat;
      }

      // ---- ConsolidateSrc / ConsolidateDst
      double ftot[3];
      for (int k = 0; k < 3; k++) {
        ftot[k] = r.fn[k] + r.ft[k];
        f[i][k] += ftot[k];
        torque[i][k] += r.m1[k];
      }
      if (j < nlocal) {
        for (int k = 0; k < 3; k++) {
          f[j][k] -= ftot[k];
          torque[j][k] += r.m2[k];
        }
      }

      // the entry keeps xi and, for single(), the normal and tangential force of this step
      if (advance) {
        for (int k = 0; k < 3; k++) {
          xi_i[k] = xi[k];
          xi_i[3 + k] = r.fn[k];
          xi_i[6 + k] = r.ft[k];
        }
        if (j < nlocal) {
          double *xi_j = history->get(j, tag[i]);
          for (int k = 0; k < 3; k++) {
            xi_j[k] = -xi[k];
            xi_j[3 + k] = -r.fn[k];
            xi_j[6 + k] = -r.ft[k];
          }
          // the partner's entry: the same law values (symmetric, musen_pp_law.h); xi_i stays
          // valid (another atom's entries)
          for (int v = 0; v < law_values; v++) xi_j[HISTORY_VALUES + v] = xi_i[HISTORY_VALUES + v];
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

void PairMusenHM::settings(int narg, char **arg)
{
  set_laws("hertz/mindlin", narg, arg);
}

void PairMusenHM::set_laws(const std::string &first, int narg, char **arg)
{
  // FIRST [params] then NAME [params] then ...: the words, kept for restart files
  law_words.assign(1, first);
  for (int a = 0; a < narg; a++) law_words.emplace_back(arg[a]);
  laws.clear();
  std::size_t w = 0;
  while (w < law_words.size()) {
    const std::string name = law_words[w++];
    std::vector<double> params;
    for (; w < law_words.size() && law_words[w] != "then"; w++)
      params.push_back(utils::numeric(FLERR, law_words[w], false, lmp));
    if (w < law_words.size() && ++w == law_words.size())
      error->all(FLERR, "pair {}: 'then' needs a law name (known: {})", force->pair_style,
                 musen_pp::names());
    std::string why;
    auto law = musen_pp::create(name, params, why);
    if (!law) error->all(FLERR, "pair {}: {}", force->pair_style, why);
    laws.push_back(std::move(law));
  }
  // each law's block of the contact's history after the style's own values, in the laws' order
  int law_values = 0;
  for (const auto &law : laws) {
    law->set_history_offset(law_values);
    law_values += law->history_size();
  }
  history_values = HISTORY_VALUES + law_values;
  law_block.assign(law_values, 0.0);
  only_hertz = laws.size() == 1 ? dynamic_cast<const musen_pp::HertzMindlin *>(laws[0].get())
                                : nullptr;
}

void PairMusenHM::write_restart_settings(FILE *fp)
{
  const int count = static_cast<int>(law_words.size()) - 1;    // the first is the style's
  fwrite(&count, sizeof(int), 1, fp);
  for (int w = 1; w <= count; w++) {
    const int len = static_cast<int>(law_words[w].size());
    fwrite(&len, sizeof(int), 1, fp);
    fwrite(law_words[w].data(), sizeof(char), len, fp);
  }
}

void PairMusenHM::read_restart_settings(FILE *fp)
{
  int count = 0;
  if (comm->me == 0) utils::sfread(FLERR, &count, sizeof(int), 1, fp, nullptr, error);
  MPI_Bcast(&count, 1, MPI_INT, 0, world);
  std::vector<std::string> words(count);
  for (auto &word : words) {
    int len = 0;
    if (comm->me == 0) utils::sfread(FLERR, &len, sizeof(int), 1, fp, nullptr, error);
    MPI_Bcast(&len, 1, MPI_INT, 0, world);
    word.resize(len);
    if (comm->me == 0 && len) utils::sfread(FLERR, &word[0], sizeof(char), len, fp, nullptr, error);
    if (len) MPI_Bcast(&word[0], len, MPI_CHAR, 0, world);
  }
  std::vector<char *> args;
  for (auto &word : words) args.push_back(&word[0]);
  settings(count, args.data());
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

  heat_fix = nullptr;
  for (const auto &law : laws)
    if (law->heats()) {
      const auto heats = modify->get_fix_by_style("^musen/heat$");
      if (heats.size() != 1)
        error->all(FLERR, "pair {}: its heat law needs one fix musen/heat (found {})",
                   force->pair_style, heats.size());
      heat_fix = heats[0];
      int dim;
      if (!heat_fix->extract("conductivity", dim))
        error->all(FLERR, "pair {}: its heat law needs the conductivities: fix musen/heat cp ... k ...",
                   force->pair_style);
    }

  // a law that reads temperatures without a heat flux: d_musen_temperature alone
  temperature_index = -1;
  for (const auto &law : laws)
    if (law->reads_temperature() && !law->heats()) {
      int flag, cols;
      temperature_index = atom->find_custom("musen_temperature", flag, cols);
      if (temperature_index < 0 || flag != 1 || cols != 0)
        error->all(FLERR, "pair {}: its law reads the spheres' temperatures: define fix "
                          "property/atom d_musen_temperature", force->pair_style);
    }

  // size-based half list with newton off whatever `newton` says (see the file header)
  neighbor->add_request(this, NeighConst::REQ_SIZE | NeighConst::REQ_NEWTON_OFF);

  if (!history) {
    Fix *found = modify->get_fix_by_id(HISTORY_ID);
    if (!found)
      found = modify->add_fix(std::string(HISTORY_ID) + " all MUSEN/HISTORY " +
                              std::to_string(history_values));
    history = dynamic_cast<FixMusenHistory *>(found);
    if (!history || history->nvalues() != history_values)
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
  musen_pp::Contact c{overlap, equiv_radius, equiv_mass, r1, r2, n, vn, vt,
                      atom->omega[i], atom->omega[j], update->dt};
  if (temperature_index >= 0) {
    c.t1 = atom->dvector[temperature_index][i];
    c.t2 = atom->dvector[temperature_index][j];
  }
  const musen_pp::Materials mats{estar[itype][jtype], gstar[itype][jtype], alpha[itype][jtype],
                                 mu[itype][jtype], mu_roll[itype][jtype]};
  double xi[3] = {0.0, 0.0, 0.0};    // a new contact's, and its law values
  std::fill(law_block.begin(), law_block.end(), 0.0);
  if (!law_block.empty()) c.law_history = law_block.data();
  musen_pp::Result r;
  apply_laws(c, mats, xi, r);
  const double fn_len = r.fn_len;
  for (int k = 0; k < 3; k++) svector[k] = r.ft[k];

  // normal force on i: n fn_len = (x_i - x_j) fforce
  if (cvlen != 0) fforce = -fn_len / cvlen;
  return 0.0;
}

/* ---------------------------------------------------------------------- */

void PairMusenHM::write_restart(FILE *fp)
{
  write_restart_settings(fp);    // LAMMPS calls only write_restart / read_restart
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
  read_restart_settings(fp);
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
