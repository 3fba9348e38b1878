// The divergence check: PhysicsWorld scans the bodies; this file turns the first bad one into a
// message naming the module and link (or the obstacle), the quantity, and the time and step.
#include "world/divergence.h"

#include <cstdio>

#include "world/world.h"

namespace rm3d {

namespace {

const char* shapeName(ShapeKind k) {
  switch (k) {
    case ShapeKind::Box:
      return "box";
    case ShapeKind::Sphere:
      return "sphere";
    case ShapeKind::Cylinder:
      return "cylinder";
    case ShapeKind::Hull:
      return "mesh";
    case ShapeKind::Capsule:
      return "capsule";
    case ShapeKind::TriMesh:
      return "concave mesh";
    case ShapeKind::Heightfield:
      return "heightfield";
  }
  return "body";
}

/// "module 'name' (type) link 'link'" or "obstacle 3 (a box)", for a physics part.
std::string whereIs(const World& w, int part, int partsInBody) {
  std::string where = "a body";
  bool found = false;
  for (const Module& m : w.modules()) {
    for (size_t l = 0; l < m.parts.size() && !found; ++l)
      if (m.parts[l] == part) {
        where = "module '" + m.name + "' (" + m.type->name + ") link '" + m.type->links[l].name + "'";
        found = true;
      }
    if (found) break;
  }
  for (size_t i = 0; i < w.obstacles().size() && !found; ++i)
    if (w.obstacles()[i].part == part) {
      where = "obstacle " + std::to_string(i + 1) + " (a " + shapeName(w.obstacles()[i].shape.kind) +
              "; obstacles count from 1 in the order the world script made them)";
      found = true;
    }
  if (partsInBody > 1) where += " (docked: one body of " + std::to_string(partsInBody) + " links)";
  return where;
}

}  // namespace

bool checkDivergence(const World& w, std::string& message) {
  if (!message.empty()) return true;
  const DivergenceLimits& lim = w.settings().limits;
  const BodyDivergence d = w.physicsConst().divergenceScan(lim.maxSpeed, lim.maxAngularSpeed, lim.bounds);
  // (The time and step formatted only for a message: every step runs this check, and the
  // formatting alone was 0.3% of a 10-module snake's step.)
  auto when = [&] {
    char text[96];
    std::snprintf(text, sizeof text, "physics diverged at t=%.4g s (step %lld): ", w.time(),
                  (long long)w.steps());
    return std::string(text);
  };
  if (d.kind == BodyDivergence::Kind::None) {
    for (size_t c = 0; c < w.cloths().size(); ++c)
      if (!w.physicsConst().clothFinite(int(c))) {
        message = when() + "cloth " + std::to_string(c + 1) +
                  " (cloths count from 1 in the order the world script made them): NaN or infinite node "
                  "position or velocity (smaller dt or more substeps, a lower stiffness, more nodes)";
        return true;
      }
    return false;
  }
  char what[256];
  switch (d.kind) {
    case BodyDivergence::Kind::Position:
      std::snprintf(what, sizeof what, "NaN or infinite position");
      break;
    case BodyDivergence::Kind::Orientation:
      std::snprintf(what, sizeof what, "NaN or infinite orientation");
      break;
    case BodyDivergence::Kind::Velocity:
      std::snprintf(what, sizeof what, "NaN or infinite velocity");
      break;
    case BodyDivergence::Kind::Speed:
      std::snprintf(what, sizeof what, "speed %.6g m/s, above max_speed %g m/s", d.value, lim.maxSpeed);
      break;
    case BodyDivergence::Kind::AngularSpeed:
      std::snprintf(what, sizeof what, "angular speed %.6g rad/s, above max_angular_speed %g rad/s", d.value,
                    lim.maxAngularSpeed);
      break;
    default:
      std::snprintf(what, sizeof what, "left the world bounds: %.6g m from the origin, beyond bounds %g m",
                    d.value, lim.bounds);
      break;
  }
  message =
      when() + whereIs(w, d.part, d.partsInBody) + ": " + what +
      " (smaller dt or more substeps, smaller forces, or world.set{max_speed=, max_angular_speed=, bounds=})";
  return true;
}

}  // namespace rm3d
