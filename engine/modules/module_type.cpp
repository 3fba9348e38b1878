// Name look-ups on module types (used when scripts resolve names, never per step).
#include "modules/module_type.h"

namespace rm3d {

namespace {
template <class T>
int findByName(const std::vector<T>& v, const std::string& n) {
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i].name == n) return int(i);
  return -1;
}
}  // namespace

int ModuleTypeDef::findLink(const std::string& n) const {
  return findByName(links, n);
}
int ModuleTypeDef::findJoint(const std::string& n) const {
  return findByName(joints, n);
}
int ModuleTypeDef::findDock(const std::string& n) const {
  return findByName(docks, n);
}
int ModuleTypeDef::findSensor(const std::string& n) const {
  return findByName(sensors, n);
}

double ModuleTypeDef::mass() const {
  double m = 0;
  for (const LinkDef& l : links) m += l.mass;
  return m;
}

const char* genderName(Gender g) {
  switch (g) {
    case Gender::Male:
      return "male";
    case Gender::Female:
      return "female";
    default:
      return "none";
  }
}

}  // namespace rm3d
