// A particle against the ground and the bodies' convex shapes: signed distance in the shape's
// frame, push out along the normal to the particle's radius, then friction on the motion along
// the surface relative to the surface's own motion (static: undone; kinetic: reduced).
#pragma once

#include <algorithm>
#include <cmath>

#include "particles/collider_frame.h"
#include "physics/particle_colliders.h"

namespace rm3d {

struct ContactParams {
  float radius = 0.01f;
  float dt = 1.0f / 60;
  float mus = 0, muk = 0;  ///< static and kinetic friction
  bool friction = false;
  /// Debris: the least load friction is limited by (|g| dt^2: what gravity presses a resting
  /// grain in by in a step, which the density constraint has mostly taken out by the contact).
  float minLoad = 0;
};

/// Friction on q's motion since p along a surface of normal n that itself moved by `surface`,
/// given the depth of the push just made; adds what it changes to q and push.
inline void contactFriction(const ContactParams& cp, const float* p, const float* n, const float* surface,
                            float depth, float* q, float* push) {
  if (!cp.friction) return;
  depth = std::max(depth, cp.minLoad);
  float t[3];
  const float rn = (q[0] - p[0] - surface[0]) * n[0] + (q[1] - p[1] - surface[1]) * n[1] +
                   (q[2] - p[2] - surface[2]) * n[2];
  for (int a = 0; a < 3; ++a) t[a] = q[a] - p[a] - surface[a] - rn * n[a];
  const float t2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
  float f = 1.0f;
  if (t2 > (cp.mus * depth) * (cp.mus * depth)) f = std::min(cp.muk * depth / std::sqrt(t2), 1.0f);
  for (int a = 0; a < 3; ++a) {
    q[a] -= f * t[a];
    push[a] -= f * t[a];
  }
}

/// The plane z = 0 (q is below the particle's radius).
inline void groundContact(const ContactParams& cp, const float* p, float* q) {
  const float depth = std::max(cp.radius - q[2], 0.0f);
  q[2] += depth;
  const float n[3] = {0, 0, 1}, still[3] = {0, 0, 0};
  float push[3] = {0, 0, depth};
  contactFriction(cp, p, n, still, depth, q, push);
}

/// Signed distance from q to the shape's surface and the outward normal (world), when below
/// `limit`; false otherwise. `p` (the start of the step) picks the face a particle came in by.
inline bool shapeDistance(const ColliderSet& set, const ColliderShape& s, const float* p, const float* q,
                          float limit, float& sd, float* n) {
  const float* R = s.rot;
  float l[3];
  shapeLocal(s, q, l);
  const float r = limit;
  float nl[3] = {0, 0, 1};
  sd = 0;
  switch (s.kind) {
    case ColliderShape::Box: {
      float e[3], out2 = 0, inside = -1e30f;
      int axis = 0;
      // A fixed box standing on the ground: never leave it downwards (the ground would put the
      // particle back inside).
      const bool onGround = set.ground && !s.dynamic && s.lo[2] < limit;
      for (int a = 0; a < 3; ++a) {
        e[a] = std::abs(l[a]) - s.half[a];
        if (e[a] > 0) out2 += e[a] * e[a];
        const bool down = onGround && R[6 + a] * (l[a] < 0 ? -1.0f : 1.0f) < -0.7f;
        if (e[a] > inside && !(down && e[a] <= 0)) {
          inside = e[a];
          axis = a;
        }
      }
      if (inside >= r) return false;
      if (out2 > 0) {
        sd = std::sqrt(out2);
        if (sd >= r) return false;
        for (int a = 0; a < 3; ++a) nl[a] = e[a] > 0 ? std::copysign(e[a], l[a]) / sd : 0.0f;
      } else {
        // Inside: deeper than `limit`, leave through the face the particle came in by (where it
        // was outside at the step's start: it may have passed the middle of a thin wall), else
        // through the nearest face.
        float lp[3];
        shapeLocal(s, p, lp);
        float best = 0;
        int entry = -1;
        for (int a = 0; a < 3; ++a) {
          const float o = std::abs(lp[a]) - s.half[a];
          if (onGround && R[6 + a] * (lp[a] < 0 ? -1.0f : 1.0f) < -0.7f) continue;
          if (o > best) {
            best = o;
            entry = a;
          }
        }
        float side = l[axis];
        if (entry >= 0 && inside < -r) {  // shallow: the nearest face (a wall's end, a corner)
          axis = entry;
          side = lp[entry];
        }
        sd = std::abs(l[axis]) - s.half[axis];
        if (side * l[axis] < 0) sd = -std::abs(l[axis]) - s.half[axis];  // came from the far side
        nl[0] = nl[1] = nl[2] = 0;
        nl[axis] = side < 0 ? -1.0f : 1.0f;
      }
      break;
    }
    case ColliderShape::Sphere: {
      const float len = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
      sd = len - s.half[0];
      if (sd >= r) return false;
      if (len > 1e-12f)
        for (int a = 0; a < 3; ++a) nl[a] = l[a] / len;
      break;
    }
    case ColliderShape::Cylinder: {
      const auto [er, ez, rx, ry, sz] = cylinderPoint(s, l);
      if (er > 0 && ez > 0) {
        sd = std::sqrt(er * er + ez * ez);
        if (sd >= r) return false;
        nl[0] = rx * er / sd;
        nl[1] = ry * er / sd;
        nl[2] = sz * ez / sd;
      } else if (er > ez) {
        sd = er;
        if (sd >= r) return false;
        nl[0] = rx;
        nl[1] = ry;
        nl[2] = 0;
      } else {
        sd = ez;
        if (sd >= r) return false;
        nl[0] = nl[1] = 0;
        nl[2] = sz;
      }
      break;
    }
    case ColliderShape::Capsule: {
      const float z = std::clamp(l[2], -s.half[1], s.half[1]);
      const float v[3] = {l[0], l[1], l[2] - z};
      const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      sd = len - s.half[0];
      if (sd >= r) return false;
      if (len > 1e-12f)
        for (int a = 0; a < 3; ++a) nl[a] = v[a] / len;
      break;
    }
    case ColliderShape::Hull: {
      // The largest plane distance: exact inside, a lower bound outside (near an edge a particle
      // may be pushed a little early).
      sd = -1e30f;
      const float* pl = set.planes.data() + 4 * s.planeBegin;
      for (int k = 0; k < s.planeCount; ++k, pl += 4) {
        const float dist = pl[0] * l[0] + pl[1] * l[1] + pl[2] * l[2] - pl[3];
        if (dist > sd) {
          sd = dist;
          nl[0] = pl[0];
          nl[1] = pl[1];
          nl[2] = pl[2];
        }
      }
      if (s.planeCount == 0 || sd >= r) return false;
      break;
    }
  }
  shapeWorldDir(s, nl, n);
  return true;
}

/// Pushes q out to the particle's radius from a surface at signed distance sd < radius with
/// normal n, then applies friction against the surface's motion; `push` gets the change of q.
inline void shapeContact(const ContactParams& cp, const ColliderSet& set, const ColliderShape& s,
                         const float* p, float sd, const float* n, float* q, float* push) {
  const float depth = std::max(cp.radius - sd, 0.0f);
  for (int a = 0; a < 3; ++a) {
    q[a] += depth * n[a];
    push[a] = depth * n[a];
  }
  float surface[3] = {0, 0, 0};
  if (s.dynamic && cp.friction) {
    const ColliderBody& b = set.bodies[size_t(s.body)];
    const float x = q[0] - float(b.com[0]), y = q[1] - float(b.com[1]), z = q[2] - float(b.com[2]);
    const float w[3] = {float(b.angVel[0]), float(b.angVel[1]), float(b.angVel[2])};
    surface[0] = (float(b.linVel[0]) + w[1] * z - w[2] * y) * cp.dt;
    surface[1] = (float(b.linVel[1]) + w[2] * x - w[0] * z) * cp.dt;
    surface[2] = (float(b.linVel[2]) + w[0] * y - w[1] * x) * cp.dt;
  }
  contactFriction(cp, p, n, surface, depth, q, push);
}

}  // namespace rm3d
