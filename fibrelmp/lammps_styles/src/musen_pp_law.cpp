/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   The registry of MUSEN particle-particle laws (musen_pp_law.h).
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <map>

namespace LAMMPS_NS {
namespace musen_pp {

namespace {
// a function-local map: the laws' registration lines run during static initialisation
std::map<std::string, Factory> &registry()
{
  static std::map<std::string, Factory> laws;
  return laws;
}
}    // namespace

bool add(const char *name, Factory factory)
{
  registry()[name] = factory;
  return true;
}

std::unique_ptr<Law> create(const std::string &name, const std::vector<double> &params,
                            std::string &why)
{
  const auto found = registry().find(name);
  if (found == registry().end()) {
    why = "unknown particle-particle law " + name + " (known: " + names() + ")";
    return nullptr;
  }
  return found->second(params, why);
}

std::string names()
{
  std::string out;
  for (const auto &entry : registry()) out += (out.empty() ? "" : ", ") + entry.first;
  return out;
}

}    // namespace musen_pp
}    // namespace LAMMPS_NS
