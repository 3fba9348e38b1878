// Test fixture: a World built from an inline world script (Jolt's PhysicsTestContext idea).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "world/world.h"

namespace rm3d::test {

inline RunOptions options() {
  RunOptions o;
  o.projectRoot = RM3D_SOURCE_DIR;
  o.echoLog = false;
  return o;
}

inline std::unique_ptr<World> makeWorld(const std::string& script, RunOptions o = options()) {
  auto w = std::make_unique<World>(o);
  w->loadString(script, "test_world.lua");
  return w;
}

inline void stepFor(World& w, double seconds) {
  const long long n = (long long)(seconds / w.settings().dt + 0.5);
  for (long long i = 0; i < n; ++i) w.step();
}

/// The world's failed expectations, one message a line ("" when none).
inline std::string failureText(const World& w) {
  std::string text;
  for (const Failure& f : w.failures()) text += f.message + "\n";
  return text;
}

/// Rotation of link b relative to link a, as an angle about `axis` (in a's frame), radians.
inline double relativeAngle(const World& w, int m, int a, int b, const Vec3& axis) {
  const Quat rel = w.linkPose(m, a).rot.conjugate() * w.linkPose(m, b).rot;
  const Eigen::AngleAxisd aa(rel);
  return aa.angle() * aa.axis().dot(axis);
}

/// Every module's link poses and joint angles, module by module, appended to `links` and `angles`.
inline void collectPoses(const World& w, std::vector<Pose>& links, std::vector<double>& angles) {
  for (size_t m = 0; m < w.modules().size(); ++m) {
    const Module& mod = w.modules()[m];
    for (size_t l = 0; l < mod.type->links.size(); ++l) links.push_back(w.linkPose(int(m), int(l)));
    for (size_t j = 0; j < mod.type->joints.size(); ++j) angles.push_back(w.jointAngle(int(m), int(j)));
  }
}

}  // namespace rm3d::test
