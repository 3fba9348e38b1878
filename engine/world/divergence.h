// Divergence: a run whose bodies reach NaN, absurd speeds or leave the world has stopped being a
// simulation. After every physics step the world scans its dynamic bodies once; the first bad
// one stops the run with a message that says what went wrong, where and when.
#pragma once

#include <string>

namespace rm3d {

class World;

/// Bounds past which a run counts as diverged: world.set{max_speed=, max_angular_speed=, bounds=}.
struct DivergenceLimits {
  double maxSpeed = 1000;          ///< m/s, linear speed of any dynamic body
  double maxAngularSpeed = 10000;  ///< rad/s
  double bounds = 10000;           ///< metres from the origin (also where things may be placed)
};

/// Checks the world's dynamic bodies against its settings' limits (one pass over the physics
/// bodies, no allocation while all is well). On the first bad body, sets `message` ("physics
/// diverged at t=... (step N): module 'm' link 'l': NaN position ...") and returns true; once a
/// message is set, returns true without checking again.
bool checkDivergence(const World& world, std::string& message);

}  // namespace rm3d
