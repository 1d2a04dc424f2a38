/* fibrenet/read_data: a FibreNet job's box and topology from fibrelmp's binary file (see the
   header for the file and for what it reproduces of read_data).
   Part of fibrelmp; GPL-2.0-or-later like LAMMPS (see ../LICENSE). */

#include "fibrenet_read_data.h"
#include "style_registry.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "input.h"
#include "library.h"
#include "utils.h"

#include <mpi.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

using namespace LAMMPS_NS;

namespace {
constexpr char MAGIC[8] = {'F', 'L', 'M', 'P', 'T', 'O', 'P', '1'};
constexpr int64_t HEAD = 11;          // int64 counts after the magic
constexpr int64_t CHUNK = 1 << 18;    // records per broadcast (a few MB)
enum {
  NATOMS, NBONDS, NANGLES, NTYPES, NBONDTYPES, NANGLETYPES, VELOCITIES,
  BOND_PER, ANGLE_PER,             // the most any atom stores with newton_bond on
  BOND_PER_OFF, ANGLE_PER_OFF      // ... with newton_bond off (every atom of a bond or angle)
};
}    // namespace

/* ---------------------------------------------------------------------- */

FibreNetReadData::~FibreNetReadData()
{
  if (fp) fclose(fp);
}

/* ---------------------------------------------------------------------- */

void FibreNetReadData::read(void *buf, size_t bytes, const char *what)
{
  // rank 0 reads, every rank learns whether it worked, then gets the bytes
  int ok = 1;
  if (comm->me == 0) ok = fread(buf, 1, bytes, fp) == bytes;
  MPI_Bcast(&ok, 1, MPI_INT, 0, world);
  if (!ok) error->all(FLERR, "fibrenet/read_data: {} ends inside its {} (cut short?)", path, what);
  // MPI counts are ints: broadcast in pieces below 1 GiB
  for (size_t done = 0; done < bytes;) {
    const size_t n = std::min<size_t>(bytes - done, size_t(1) << 30);
    MPI_Bcast(static_cast<char *>(buf) + done, (int) n, MPI_CHAR, 0, world);
    done += n;
  }
}

template <class Body>
void FibreNetReadData::each_chunk(int64_t count, int64_t width, const char *what, Body body)
{
  std::vector<int64_t> rec(std::min(count, CHUNK) * width);
  for (int64_t first = 0; first < count; first += CHUNK) {
    const int64_t n = std::min(CHUNK, count - first);
    read(rec.data(), n * width * sizeof(int64_t), what);
    body(first, n, rec.data());
  }
}

// the records stored on all ranks together are the expected number (read_data's check)
void FibreNetReadData::check_stored(bigint stored, bigint expected, const char *what)
{
  bigint total = 0;
  MPI_Allreduce(&stored, &total, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  if (total != expected)
    error->all(FLERR, "fibrenet/read_data: {}: {} assigned incorrectly", path, what);
}

/* ---------------------------------------------------------------------- */

void FibreNetReadData::command(int narg, char **arg)
{
  if (narg != 1) error->all(FLERR, "Illegal fibrenet/read_data command: fibrenet/read_data FILE");
  if (domain->box_exist) error->all(FLERR, "fibrenet/read_data: the simulation box already exists");
  if (!utils::strmatch(atom->atom_style, "^angle$"))
    error->all(FLERR, "fibrenet/read_data needs atom_style angle, not {}", atom->atom_style);
  path = arg[0];
  int opened = 1;
  if (comm->me == 0) {
    fp = fopen(path.c_str(), "rb");
    opened = fp != nullptr;
  }
  MPI_Bcast(&opened, 1, MPI_INT, 0, world);
  if (!opened) error->all(FLERR, "fibrenet/read_data: cannot open {}: {}", path, utils::getsyserror());

  char magic[8];
  read(magic, sizeof(magic), "header");
  if (memcmp(magic, MAGIC, sizeof(MAGIC)) != 0)
    error->all(FLERR, "fibrenet/read_data: {} is not a fibrelmp topology file", path);
  int64_t head[HEAD];
  double box[6];
  read(head, sizeof(head), "header");
  read(box, sizeof(box), "header");
  for (int64_t count : head)
    if (count < 0) error->all(FLERR, "fibrenet/read_data: {}: a negative count", path);
  if (head[NTYPES] < 1 || head[NTYPES] > 1 << 20)
    error->all(FLERR, "fibrenet/read_data: {}: {} atom types", path, head[NTYPES]);
  if (head[NATOMS] > MAXTAGINT || head[NBONDTYPES] > MAXSMALLINT || head[NANGLETYPES] > MAXSMALLINT ||
      head[BOND_PER_OFF] > MAXSMALLINT || head[ANGLE_PER_OFF] > MAXSMALLINT)
    error->all(FLERR, "fibrenet/read_data: {}: more atoms or types than this LAMMPS holds", path);
  std::vector<double> mass(head[NTYPES]);
  read(mass.data(), mass.size() * sizeof(double), "masses");

  make_box(head, box, mass);
  create_atoms(head[NATOMS], head[VELOCITIES] != 0);
  add_bonds(head[NBONDS]);
  add_angles(head[NANGLES]);
  if (fp) fclose(fp);
  fp = nullptr;
  if (comm->me == 0)
    utils::logmesg(lmp, "  {} atoms, {} bonds, {} angles from {}\n", atom->natoms, atom->nbonds,
                   atom->nangles, path);
}

/* ---------------------------------------------------------------------- */

void FibreNetReadData::make_box(const int64_t *head, const double *box,
                                const std::vector<double> &mass)
{
  // the box as read_data's header sets it ({} prints the shortest text that reads back as the
  // same double); per-atom room for the bonds and angles each atom will store
  input->one(fmt::format("region fibrelmp_box block {} {} {} {} {} {} units box", box[0], box[1],
                         box[2], box[3], box[4], box[5]));
  const bool newton = force->newton_bond;
  std::string create = fmt::format("create_box {} fibrelmp_box", head[NTYPES]);
  if (head[NBONDTYPES])
    create += fmt::format(" bond/types {} extra/bond/per/atom {}", head[NBONDTYPES],
                          std::max<int64_t>(head[newton ? BOND_PER : BOND_PER_OFF], 1));
  if (head[NANGLETYPES])
    create += fmt::format(" angle/types {} extra/angle/per/atom {}", head[NANGLETYPES],
                          std::max<int64_t>(head[newton ? ANGLE_PER : ANGLE_PER_OFF], 1));
  input->one(create);
  input->one("region fibrelmp_box delete");
  for (int64_t t = 0; t < head[NTYPES]; t++) atom->set_mass(FLERR, (int) t + 1, mass[t]);
}

/* ---------------------------------------------------------------------- */

void FibreNetReadData::create_atoms(int64_t natoms, bool velocities)
{
  // per record: id molecule type (int64), x y z [vx vy vz] (double)
  const int64_t width = velocities ? 9 : 6;
  std::vector<tagint> ids;
  std::vector<int> types;
  std::vector<imageint> image;
  std::vector<double> x, v;
  const imageint centre = ((imageint) IMGMAX << IMG2BITS) | ((imageint) IMGMAX << IMGBITS) | IMGMAX;
  each_chunk(natoms, width, "atoms", [&](int64_t first, int64_t n, const int64_t *rec) {
    ids.resize(n);
    types.resize(n);
    image.assign(n, centre);
    x.resize(3 * n);
    v.resize(velocities ? 3 * n : 0);
    for (int64_t k = 0; k < n; k++) {
      const int64_t *r = &rec[k * width];
      if (r[0] != first + k + 1)
        error->all(FLERR, "fibrenet/read_data: {}: atom {} has id {}, expected ids 1..N in order",
                   path, first + k + 1, r[0]);
      if (r[2] < 1 || r[2] > atom->ntypes)
        error->all(FLERR, "fibrenet/read_data: {}: atom {} has type {}", path, r[0], r[2]);
      ids[k] = (tagint) r[0];
      types[k] = (int) r[2];
      memcpy(&x[3 * k], r + 3, 3 * sizeof(double));
      if (velocities) memcpy(&v[3 * k], r + 6, 3 * sizeof(double));
      // read_data remaps the unwrapped coordinates into a periodic box and sets the image
      // flags; done here, so the library call below only decides which rank owns the atom
      domain->remap(&x[3 * k], image[k]);
    }
    const int before = atom->nlocal;
    if (lammps_create_atoms(lmp, (int) n, ids.data(), types.data(), x.data(),
                            velocities ? v.data() : nullptr, image.data(), 0) < 0)
      error->all(FLERR, "fibrenet/read_data: {}: creating atoms failed", path);
    for (int i = before; i < atom->nlocal; i++) {
      const int64_t k = atom->tag[i] - 1 - first;
      atom->molecule[i] = (tagint) rec[k * width + 1];
    }
  });
  if (atom->natoms != natoms)
    error->all(FLERR, "fibrenet/read_data: {}: {} of {} atoms are inside the box", path,
               atom->natoms, natoms);
  // read_data shrink-wraps the box around the atoms it read (the runs start from that box)
  if (domain->nonperiodic == 2) domain->reset_box();
}

/* ---------------------------------------------------------------------- */

void FibreNetReadData::add_bonds(int64_t nbonds)
{
  // Atom::data_bonds: with the first atom, and with newton_bond off also with the second
  const int nlocal = atom->nlocal;
  bigint stored = 0;
  auto put = [&](int m, int type, tagint other) {
    if (atom->num_bond[m] == atom->bond_per_atom)
      error->one(FLERR, "fibrenet/read_data: {}: atom {} has more bonds than its {} slots", path,
                 atom->tag[m], atom->bond_per_atom);
    atom->bond_type[m][atom->num_bond[m]] = type;
    atom->bond_atom[m][atom->num_bond[m]++] = other;
    stored++;
  };
  each_chunk(nbonds, 3, "bonds", [&](int64_t first, int64_t n, const int64_t *rec) {
    for (int64_t k = 0; k < n; k++) {
      const int64_t *r = &rec[3 * k];
      if (r[0] < 1 || r[0] > atom->nbondtypes || r[1] < 1 || r[1] > atom->natoms || r[2] < 1 ||
          r[2] > atom->natoms)
        error->all(FLERR, "fibrenet/read_data: {}: bond {} is invalid", path, first + k + 1);
      int m = atom->map((tagint) r[1]);
      if (m >= 0 && m < nlocal) put(m, (int) r[0], (tagint) r[2]);
      if (!force->newton_bond) {
        m = atom->map((tagint) r[2]);
        if (m >= 0 && m < nlocal) put(m, (int) r[0], (tagint) r[1]);
      }
    }
  });
  check_stored(stored, (force->newton_bond ? 1 : 2) * nbonds, "bonds");
  atom->nbonds = nbonds;
}

/* ---------------------------------------------------------------------- */

void FibreNetReadData::add_angles(int64_t nangles)
{
  // Atom::data_angles: with the middle atom, and with newton_bond off also with the others
  const int nlocal = atom->nlocal;
  bigint stored = 0;
  each_chunk(nangles, 4, "angles", [&](int64_t first, int64_t n, const int64_t *rec) {
    for (int64_t k = 0; k < n; k++) {
      const int64_t *r = &rec[4 * k];
      if (r[0] < 1 || r[0] > atom->nangletypes || r[1] < 1 || r[1] > atom->natoms || r[2] < 1 ||
          r[2] > atom->natoms || r[3] < 1 || r[3] > atom->natoms)
        error->all(FLERR, "fibrenet/read_data: {}: angle {} is invalid", path, first + k + 1);
      const int order[3] = {2, 1, 3};
      for (int j : order) {
        if (j != 2 && force->newton_bond) continue;
        const int m = atom->map((tagint) r[j]);
        if (m < 0 || m >= nlocal) continue;
        if (atom->num_angle[m] == atom->angle_per_atom)
          error->one(FLERR, "fibrenet/read_data: {}: atom {} has more angles than its {} slots",
                     path, atom->tag[m], atom->angle_per_atom);
        const int s = atom->num_angle[m]++;
        atom->angle_type[m][s] = (int) r[0];
        atom->angle_atom1[m][s] = (tagint) r[1];
        atom->angle_atom2[m][s] = (tagint) r[2];
        atom->angle_atom3[m][s] = (tagint) r[3];
        stored++;
      }
    }
  });
  check_stored(stored, (force->newton_bond ? 1 : 3) * nangles, "angles");
  atom->nangles = nangles;
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Command *create_read_data(LAMMPS *lmp)
{
  return new FibreNetReadData(lmp);
}
const style_registry::Registration registered(
    85, "fibrenet/read_data", "FibreNet box and topology from fibrelmp's binary file",
    &create_read_data);
}    // namespace
