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

namespace {

// The settings' fields, in one list: name, member.
template <typename F>
void forEachSetting(DockSettings& s, F&& f) {
  f("capture_radius", s.captureRadius);
  f("capture_angle", s.captureAngle);
  f("latch_distance", s.latchDistance);
  f("latch_angle", s.latchAngle);
  f("capture_speed", s.captureSpeed);
  f("capture_turn_speed", s.captureTurnSpeed);
  f("capture_force", s.captureForce);
  f("capture_torque", s.captureTorque);
  f("capture_time", s.captureTime);
  f("pull", s.pull);
  f("strength", s.strength);
  f("strength_torque", s.strengthTorque);
}

}  // namespace

void DockSettings::applyTo(DockDef& d) const {
  if (capture) d.capture = *capture;
  if (captureRadius) d.captureRadius = *captureRadius;
  if (captureAngle) d.captureAngle = *captureAngle;
  if (latchDistance) d.latchDistance = *latchDistance;
  if (latchAngle) d.latchAngle = *latchAngle;
  if (captureSpeed) d.captureSpeed = *captureSpeed;
  if (captureTurnSpeed) d.captureTurnSpeed = *captureTurnSpeed;
  if (captureForce) d.captureForce = *captureForce;
  if (captureTorque) d.captureTorque = *captureTorque;
  if (captureTime) d.captureTime = *captureTime;
  if (pull) d.pull = *pull;
  if (strength) d.strength = *strength;
  if (strengthTorque) d.strengthTorque = *strengthTorque;
}

void DockSettings::overlay(const DockSettings& o) {
  if (o.capture) capture = o.capture;
  DockSettings& self = *this;
  DockSettings other = o;
  std::vector<std::optional<double>*> mine, theirs;
  forEachSetting(self, [&](const char*, std::optional<double>& v) { mine.push_back(&v); });
  forEachSetting(other, [&](const char*, std::optional<double>& v) { theirs.push_back(&v); });
  for (size_t i = 0; i < mine.size(); ++i)
    if (*theirs[i]) *mine[i] = *theirs[i];
}

std::string DockSettings::key() const {
  std::string k;
  if (capture) k += *capture == DockDef::Capture::Joint ? "capture=joint;" : "capture=magnet;";
  DockSettings copy = *this;
  forEachSetting(copy, [&](const char* name, std::optional<double>& v) {
    if (!v) return;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s=%.17g;", name, *v);
    k += buf;
  });
  return k;
}

}  // namespace rm3d
