// A collider shape's own frame, for the particle solvers (particle_contact.h, particle_walls.h).
#pragma once

#include <cmath>

#include "physics/particle_colliders.h"

namespace rm3d {

/// q in shape s's frame.
inline void shapeLocal(const ColliderShape& s, const float* q, float* l) {
  const float* R = s.rot;
  const float d0 = q[0] - s.pos[0], d1 = q[1] - s.pos[1], d2 = q[2] - s.pos[2];
  l[0] = R[0] * d0 + R[3] * d1 + R[6] * d2;
  l[1] = R[1] * d0 + R[4] * d1 + R[7] * d2;
  l[2] = R[2] * d0 + R[5] * d1 + R[8] * d2;
}

/// A direction in shape s's frame, in the world's.
inline void shapeWorldDir(const ColliderShape& s, const float* nl, float* n) {
  const float* R = s.rot;
  n[0] = R[0] * nl[0] + R[1] * nl[1] + R[2] * nl[2];
  n[1] = R[3] * nl[0] + R[4] * nl[1] + R[5] * nl[2];
  n[2] = R[6] * nl[0] + R[7] * nl[1] + R[8] * nl[2];
}

/// A point l (in its frame) against a cylinder along z of radius half[0] and half length half[1]:
/// how far outside its side (er) and its caps (ez), the outward radial direction (rx, ry; +x on
/// the axis) and the side of the nearer cap (sz).
struct CylinderPoint {
  float er, ez, rx, ry, sz;
};

inline CylinderPoint cylinderPoint(const ColliderShape& s, const float* l) {
  const float rho = std::sqrt(l[0] * l[0] + l[1] * l[1]);
  return {rho - s.half[0], std::abs(l[2]) - s.half[1], rho > 1e-12f ? l[0] / rho : 1.0f,
          rho > 1e-12f ? l[1] / rho : 0.0f, l[2] < 0 ? -1.0f : 1.0f};
}

}  // namespace rm3d
