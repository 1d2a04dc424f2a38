/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/pp: musen/hm with its first law named (see pair_musen_pp.h).
------------------------------------------------------------------------- */

#include "pair_musen_pp.h"
#include "style_registry.h"

#include "error.h"

#include <cstring>

using namespace LAMMPS_NS;

PairMusenPP::PairMusenPP(LAMMPS *lmp) : PairMusenHM(lmp) {}

void PairMusenPP::settings(int narg, char **arg)
{
  if (narg < 1 || strcmp(arg[0], "then") == 0)
    error->all(FLERR, "Illegal pair_style musen/pp command: pair_style musen/pp LAW [params] "
                      "[then LAW [params]] ... (laws: {})", musen_pp::names());
  set_laws(arg[0], narg - 1, arg + 1);
  // hertz keeps the tangential force where the others keep the tangential overlap
  if (laws.size() > 1) {
    for (int a = 0; a < narg; a++)
      if (strcmp(arg[a], "hertz") == 0 && (a == 0 || strcmp(arg[a - 1], "then") == 0))
        error->all(FLERR, "pair musen/pp: law hertz (MUSEN's ModelPPHertz keeps the "
                          "tangential force, not the overlap) must be the only law");
  }
}

void PairMusenPP::write_restart_settings(FILE *fp)
{
  // every word, the first law's name too: read_restart_settings hands them to settings()
  const int count = static_cast<int>(law_words.size());
  fwrite(&count, sizeof(int), 1, fp);
  for (const std::string &word : law_words) {
    const int len = static_cast<int>(word.size());
    fwrite(&len, sizeof(int), 1, fp);
    fwrite(word.data(), sizeof(char), len, fp);
  }
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Pair *create(LAMMPS *lmp) { return new PairMusenPP(lmp); }
const style_registry::Registration registered(
    31, "musen/pp", "MUSEN particle-particle contact (a named first law)", &create);
}    // namespace
