// The viewer's camera: orbiting a target (left drag turns, right/middle drag pans, wheel zooms).
// Shared by `rm3d view` and `rm3d replay --view`.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/types.h"
#include "io/snapshot.h"

namespace rm3d {

/// A camera orbiting a target: left drag turns it, right/middle drag pans, the wheel zooms.
struct OrbitCamera {
  Eigen::Vector3f target{0, 0, 0};
  float yaw = 0, pitch = 0.4f, distance = 1.5f, fovyDeg = 45;

  static OrbitCamera from(const Camera& c) {
    OrbitCamera o;
    const Eigen::Vector3f d = c.eye - c.target;
    o.target = c.target;
    o.distance = std::max(d.norm(), 0.05f);
    o.yaw = std::atan2(d.y(), d.x());
    o.pitch = std::asin(std::clamp(d.z() / o.distance, -1.0f, 1.0f));
    o.fovyDeg = c.fovyDeg;
    return o;
  }
  Camera camera() const {
    Camera c;
    c.target = target;
    c.eye = target + distance * Eigen::Vector3f(std::cos(pitch) * std::cos(yaw),
                                                std::cos(pitch) * std::sin(yaw), std::sin(pitch));
    c.fovyDeg = fovyDeg;
    return c;
  }
  void orbit(float dx, float dy) {
    yaw -= dx * 0.008f;
    pitch = std::clamp(pitch + dy * 0.008f, -1.45f, 1.55f);  // short of the poles, where up flips
  }
  /// Moves the target with the cursor: a drag of the whole view height spans the visible height.
  void pan(float dx, float dy, int viewHeight) {
    const Camera c = camera();
    const Eigen::Vector3f f = (c.target - c.eye).normalized();
    const Eigen::Vector3f s = f.cross(Eigen::Vector3f::UnitZ()).normalized(), u = s.cross(f);
    const float perPixel =
        2.0f * distance * std::tan(fovyDeg * float(kPi) / 360.0f) / float(std::max(viewHeight, 1));
    target += (-dx * s + dy * u) * perPixel;
  }
  void zoom(float steps) { distance = std::clamp(distance * std::pow(0.88f, steps), 0.05f, 80.0f); }
};

}  // namespace rm3d
