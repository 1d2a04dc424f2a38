/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Every style (pair, bond, angle, fix, command) registers itself from its own .cpp with one
   static object, so a new style is one .cpp/.h pair and nothing else to edit:

     namespace {
     Pair *create(LAMMPS *lmp) { return new PairMusenHM(lmp); }
     const style_registry::Registration registered(
         20, "pair", "musen/hm", "MUSEN Hertz-Mindlin particle-particle contact", &create);
     }

   lammpsplugin_init (plugin.cpp) hands the list to LAMMPS sorted by the first number (then
   kind and name): static initialisation order across .cpp files is unspecified, and the order
   decides the "Loading plugin: INFO by ..." lines of log.lammps.  A new style takes any
   unused number; the info text is what log.lammps shows.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_STYLE_REGISTRY_H
#define FIBRELMP_STYLE_REGISTRY_H

#include "lammpsplugin.h"

#include <vector>

namespace LAMMPS_NS {
class LAMMPS;
class Pair;
class Bond;
class Angle;
class Fix;
class Command;

namespace style_registry {

struct Style {
  int order;                    // position in the registration (log.lammps) order
  const char *kind;             // LAMMPS's plugin style: "pair", "bond", "angle", "fix", "command"
  const char *name;             // the style name input scripts use
  const char *info;             // LAMMPS prints it when the plugin loads
  lammpsplugin_factory1 *v1;    // creator of pair, bond, angle, command styles (else nullptr)
  lammpsplugin_factory2 *v2;    // creator of fix styles (else nullptr)
};

void add(const Style &style);
std::vector<Style> sorted();    // the registered styles in registration order

// a style's static registration object; the creators return the LAMMPS base class, as
// LAMMPS's plugin loader casts them back to exactly these signatures
class Registration {
 public:
  Registration(int order, const char *kind, const char *name, const char *info,
               Pair *(*create)(LAMMPS *))
  {
    add({order, kind, name, info, (lammpsplugin_factory1 *) create, nullptr});
  }
  Registration(int order, const char *kind, const char *name, const char *info,
               Bond *(*create)(LAMMPS *))
  {
    add({order, kind, name, info, (lammpsplugin_factory1 *) create, nullptr});
  }
  Registration(int order, const char *kind, const char *name, const char *info,
               Angle *(*create)(LAMMPS *))
  {
    add({order, kind, name, info, (lammpsplugin_factory1 *) create, nullptr});
  }
  Registration(int order, const char *kind, const char *name, const char *info,
               Command *(*create)(LAMMPS *))
  {
    add({order, kind, name, info, (lammpsplugin_factory1 *) create, nullptr});
  }
  Registration(int order, const char *kind, const char *name, const char *info,
               Fix *(*create)(LAMMPS *, int, char **))
  {
    add({order, kind, name, info, nullptr, (lammpsplugin_factory2 *) create});
  }
};

}    // namespace style_registry
}    // namespace LAMMPS_NS

#endif
