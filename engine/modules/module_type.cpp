// Name look-ups on module types (used when scripts resolve names, never per step).
#include "modules/module_type.h"

#include <cstdio>

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

namespace rm3d {

const DockSettings::Field DockSettings::kFields[12] = {
    {"capture_radius", &DockSettings::captureRadius, &DockDef::captureRadius, 1e-6, 10, "m"},
    {"capture_angle", &DockSettings::captureAngle, &DockDef::captureAngle, 1e-6, kPi, "rad"},
    {"latch_distance", &DockSettings::latchDistance, &DockDef::latchDistance, 1e-6, 10, "m"},
    {"latch_angle", &DockSettings::latchAngle, &DockDef::latchAngle, 1e-6, kPi, "rad"},
    {"capture_speed", &DockSettings::captureSpeed, &DockDef::captureSpeed, 1e-6, 100, "m/s"},
    {"capture_turn_speed", &DockSettings::captureTurnSpeed, &DockDef::captureTurnSpeed, 1e-6, 100, "rad/s"},
    {"capture_force", &DockSettings::captureForce, &DockDef::captureForce, 1e-6, 1e6, "N"},
    {"capture_torque", &DockSettings::captureTorque, &DockDef::captureTorque, 1e-6, 1e6, "N m"},
    {"capture_time", &DockSettings::captureTime, &DockDef::captureTime, 1e-6, 1e6, "s"},
    {"pull", &DockSettings::pull, &DockDef::pull, 0, 1e6, "N"},
    {"strength", &DockSettings::strength, &DockDef::strength, 1e-6, 1e9, "N"},
    {"strength_torque", &DockSettings::strengthTorque, &DockDef::strengthTorque, 1e-6, 1e9, "N m"}};

void DockSettings::applyTo(DockDef& d) const {
  if (capture) d.capture = *capture;
  for (const Field& f : kFields)
    if (this->*f.setting) d.*f.value = *(this->*f.setting);
}

void DockSettings::overlay(const DockSettings& o) {
  if (o.capture) capture = o.capture;
  for (const Field& f : kFields)
    if (o.*f.setting) this->*f.setting = o.*f.setting;
}

std::string DockSettings::key() const {
  std::string k;
  if (capture) k += *capture == DockDef::Capture::Joint ? "capture=joint;" : "capture=magnet;";
  for (const Field& f : kFields) {
    if (!(this->*f.setting)) continue;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s=%.17g;", f.key, *(this->*f.setting));
    k += buf;
  }
  return k;
}

}  // namespace rm3d
