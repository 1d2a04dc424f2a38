/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   The registry of MUSEN laws by name, one per law family (musen_pp::Law for pair musen/hm,
   musen_pw::Law for fix musen/wall/mesh): each law's .cpp adds its factory with one static
   line, the styles create laws by the names their input gives.  A header template, so each
   family's registry is LawRegistry<ItsLaw> with nothing to compile per family.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_MUSEN_LAW_REGISTRY_H
#define FIBRELMP_MUSEN_LAW_REGISTRY_H

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

template <class Law> class LawRegistry {
 public:
  // a law from its parameters; sets why and returns nullptr when they are wrong
  using Factory = std::unique_ptr<Law> (*)(const std::vector<double> &params, std::string &why);

  static bool add(const char *name, Factory factory)
  {
    laws()[name] = factory;
    return true;
  }

  // kind: what the family's laws are, for the message of an unknown name
  static std::unique_ptr<Law> create(const char *kind, const std::string &name,
                                     const std::vector<double> &params, std::string &why)
  {
    const auto found = laws().find(name);
    if (found == laws().end()) {
      why = "unknown " + std::string(kind) + " law " + name + " (known: " + names() + ")";
      return nullptr;
    }
    return found->second(params, why);
  }

  // the registered names, sorted, for messages
  static std::string names()
  {
    std::string out;
    for (const auto &entry : laws()) out += (out.empty() ? "" : ", ") + entry.first;
    return out;
  }

 private:
  // a function-local map: the laws' registration lines run during static initialisation, in
  // an unspecified order across files (one map per Law in the whole plugin: an inline function)
  static std::map<std::string, Factory> &laws()
  {
    static std::map<std::string, Factory> registered;
    return registered;
  }
};

}    // namespace LAMMPS_NS

#endif
