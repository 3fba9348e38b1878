// The fixed bodies (walls, floors, obstacles without mass) as one solid a particle never enters.
//
// Pushing a particle out of each shape on its own fails where two shapes overlap: at the seam of
// a tank's corner, one wall's end face lies inside the next wall, so the particle pushed out of
// one through that face lands in the other, is pushed back, and creeps along the seam out of the
// tank. Here each fixed shape a particle is in offers its ways out (a box: through each face, or
// along the normal from an edge; a hull: through each plane; round shapes: the nearest way), and
// the particle takes the shortest of the faces it came in by (those the step's start lay beyond),
// avoiding ways that land in another fixed shape or under the ground while any other is left; a
// few passes settle corners where two or three shapes meet. A last guard keeps each step's end
// at least half a radius off every fixed shape and its path from crossing one (a thin wall at
// full speed): a particle that would go through stays where the step started.
#pragma once

#include <algorithm>
#include <cmath>

#include "particles/collider_frame.h"
#include "physics/particle_colliders.h"

namespace rm3d {

/// Signed distance from q to shape s, negative inside. `faces`: the largest distance to a face's
/// plane (boxes, cylinders, hulls: a lower bound outside near edges, exact inside); otherwise
/// the distance to the nearest point outside boxes and cylinders too. A hull has only its planes.
inline float shapeSignedDistance(const ColliderSet& set, const ColliderShape& s, const float* q, bool faces) {
  float l[3];
  shapeLocal(s, q, l);
  switch (s.kind) {
    case ColliderShape::Box: {
      float m = -1e30f, out2 = 0;
      for (int a = 0; a < 3; ++a) {
        const float e = std::abs(l[a]) - s.half[a];
        m = std::max(m, e);
        if (e > 0) out2 += e * e;
      }
      return faces || out2 == 0 ? m : std::sqrt(out2);
    }
    case ColliderShape::Sphere:
      return std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]) - s.half[0];
    case ColliderShape::Capsule: {
      const float z = l[2] - std::clamp(l[2], -s.half[1], s.half[1]);
      return std::sqrt(l[0] * l[0] + l[1] * l[1] + z * z) - s.half[0];
    }
    case ColliderShape::Cylinder: {
      const float er = std::sqrt(l[0] * l[0] + l[1] * l[1]) - s.half[0], ez = std::abs(l[2]) - s.half[1];
      if (!faces && er > 0 && ez > 0) return std::sqrt(er * er + ez * ez);
      return std::max(er, ez);
    }
    case ColliderShape::Hull: {
      float m = -1e30f;
      const float* pl = set.planes.data() + 4 * s.planeBegin;
      for (int k = 0; k < s.planeCount; ++k, pl += 4)
        m = std::max(m, pl[0] * l[0] + pl[1] * l[1] + pl[2] * l[2] - pl[3]);
      return s.planeCount ? m : 1e30f;
    }
  }
  return 1e30f;
}

/// Calls way(x, n, cost, entry) for each way q can leave shape s (which it is less than r off) to
/// lie r off it: the new position x, the outward normal n (world), how far it moves, and whether
/// the step's start p lay beyond that face (so the particle came in that way).
template <class Way>
inline void shapeExits(const ColliderSet& set, const ColliderShape& s, const float* p, const float* q,
                       float r, Way&& way) {
  float l[3], lp[3];
  shapeLocal(s, q, l);
  shapeLocal(s, p, lp);
  auto emit = [&](const float* nl, float move, float cost, bool entry) {
    float n[3];
    shapeWorldDir(s, nl, n);
    const float x[3] = {q[0] + move * n[0], q[1] + move * n[1], q[2] + move * n[2]};
    way(x, n, cost, entry);
  };
  switch (s.kind) {
    case ColliderShape::Box: {
      float e[3], out2 = 0;
      for (int a = 0; a < 3; ++a) {
        e[a] = std::abs(l[a]) - s.half[a];
        if (e[a] > 0) out2 += e[a] * e[a];
      }
      if (out2 > 0) {  // the centre is outside: along the normal from the nearest face, edge or corner
        const float sd = std::sqrt(out2);
        float nl[3];
        for (int a = 0; a < 3; ++a) nl[a] = e[a] > 0 ? std::copysign(e[a], l[a]) / sd : 0.0f;
        emit(nl, r - sd, r - sd, true);
      }
      for (int a = 0; a < 3; ++a)
        for (int side = -1; side <= 1; side += 2) {
          const float move = float(side) * (s.half[a] + r) - l[a];  // along the face's normal (side)
          if (move * float(side) <= 0) continue;
          float nl[3] = {0, 0, 0};
          nl[a] = float(side);
          emit(nl, std::abs(move), std::abs(move), float(side) * lp[a] > s.half[a]);
        }
      break;
    }
    case ColliderShape::Sphere:
    case ColliderShape::Capsule: {
      // Away from the nearest point of the centre (a sphere) or of the axis segment (a capsule).
      const bool sphere = s.kind == ColliderShape::Sphere;
      const float v[3] = {l[0], l[1], sphere ? l[2] : l[2] - std::clamp(l[2], -s.half[1], s.half[1])};
      const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      float nl[3] = {sphere ? 0.0f : 1.0f, 0, sphere ? 1.0f : 0.0f};
      if (len > 1e-12f)
        for (int a = 0; a < 3; ++a) nl[a] = v[a] / len;
      emit(nl, s.half[0] + r - len, s.half[0] + r - len, true);
      break;
    }
    case ColliderShape::Cylinder: {
      const auto [er, ez, rx, ry, sz] = cylinderPoint(s, l);
      if (er > 0 && ez > 0) {  // outside, by the rim
        const float sd = std::sqrt(er * er + ez * ez);
        const float nl[3] = {rx * er / sd, ry * er / sd, sz * ez / sd};
        emit(nl, r - sd, r - sd, true);
      }
      if (er < r) {
        const float nl[3] = {rx, ry, 0};
        emit(nl, r - er, r - er, std::sqrt(lp[0] * lp[0] + lp[1] * lp[1]) > s.half[0]);
      }
      for (int side = -1; side <= 1; side += 2) {
        const float move = float(side) * (s.half[1] + r) - l[2];
        if (move * float(side) <= 0) continue;
        const float nl[3] = {0, 0, float(side)};
        emit(nl, std::abs(move), std::abs(move), float(side) * lp[2] > s.half[1]);
      }
      break;
    }
    case ColliderShape::Hull: {
      const float* pl = set.planes.data() + 4 * s.planeBegin;
      for (int k = 0; k < s.planeCount; ++k, pl += 4) {
        const float dist = pl[0] * l[0] + pl[1] * l[1] + pl[2] * l[2] - pl[3];
        if (dist >= r) continue;
        const float distP = pl[0] * lp[0] + pl[1] * lp[1] + pl[2] * lp[2] - pl[3];
        emit(pl, r - dist, r - dist, distP > 0);
      }
      break;
    }
  }
}

/// Whether the segment from p to q passes into shape s grown by `grow` (boxes, cylinders and
/// hulls grown face by face).
inline bool segmentEnters(const ColliderSet& set, const ColliderShape& s, const float* p, const float* q,
                          float grow) {
  float a[3], b[3];
  shapeLocal(s, p, a);
  shapeLocal(s, q, b);
  const float d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  float t0 = 0, t1 = 1;
  // Keeps the part of the segment where f(t) = f0 + t (f1 - f0) < 0; false when none is left.
  auto clip = [&](float f0, float f1) {
    if (f0 >= 0 && f1 >= 0) return false;
    if (f0 < 0 && f1 < 0) return true;
    const float t = f0 / (f0 - f1);
    if (f0 >= 0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
    return t0 < t1;
  };
  // The points of the segment within `radius` of the local segment from c0 to c1.
  auto nearSegment = [&](const float* c0, const float* c1, float radius) {
    // Closest points of two segments (Ericson, Real-Time Collision Detection 5.1.9).
    const float e[3] = {c1[0] - c0[0], c1[1] - c0[1], c1[2] - c0[2]};
    const float w[3] = {a[0] - c0[0], a[1] - c0[1], a[2] - c0[2]};
    const float A = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], E = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    const float F = e[0] * w[0] + e[1] * w[1] + e[2] * w[2], C = d[0] * w[0] + d[1] * w[1] + d[2] * w[2];
    float sp = 0, tc = 0;
    if (A <= 1e-20f && E <= 1e-20f) {
    } else if (A <= 1e-20f) {
      tc = std::clamp(F / E, 0.0f, 1.0f);
    } else if (E <= 1e-20f) {
      sp = std::clamp(-C / A, 0.0f, 1.0f);
    } else {
      const float B = d[0] * e[0] + d[1] * e[1] + d[2] * e[2], den = A * E - B * B;
      sp = den > 1e-20f ? std::clamp((B * F - C * E) / den, 0.0f, 1.0f) : 0.0f;
      tc = (B * sp + F) / E;
      if (tc < 0) {
        tc = 0;
        sp = std::clamp(-C / A, 0.0f, 1.0f);
      } else if (tc > 1) {
        tc = 1;
        sp = std::clamp((B - C) / A, 0.0f, 1.0f);
      }
    }
    float g2 = 0;
    for (int k = 0; k < 3; ++k) {
      const float g = a[k] + sp * d[k] - c0[k] - tc * e[k];
      g2 += g * g;
    }
    return g2 < radius * radius;
  };
  switch (s.kind) {
    case ColliderShape::Box:
      for (int k = 0; k < 3; ++k) {
        const float h = s.half[k] + grow;
        if (!clip(a[k] - h, b[k] - h) || !clip(-a[k] - h, -b[k] - h)) return false;
      }
      return true;
    case ColliderShape::Sphere: {
      const float c[3] = {0, 0, 0};
      return nearSegment(c, c, s.half[0] + grow);
    }
    case ColliderShape::Capsule: {
      const float c0[3] = {0, 0, -s.half[1]}, c1[3] = {0, 0, s.half[1]};
      return nearSegment(c0, c1, s.half[0] + grow);
    }
    case ColliderShape::Cylinder: {
      const float h = s.half[1] + grow, R = s.half[0] + grow;
      if (!clip(a[2] - h, b[2] - h) || !clip(-a[2] - h, -b[2] - h)) return false;
      // |xy(t)|^2 < R^2 on [t0, t1]: a quadratic in t.
      const float A = d[0] * d[0] + d[1] * d[1], B = a[0] * d[0] + a[1] * d[1],
                  C = a[0] * a[0] + a[1] * a[1] - R * R;
      if (A <= 1e-20f) return C < 0;
      const float disc = B * B - A * C;
      if (disc <= 0) return false;
      const float sq = std::sqrt(disc);
      return std::max(t0, (-B - sq) / A) < std::min(t1, (-B + sq) / A);
    }
    case ColliderShape::Hull: {
      if (s.planeCount == 0) return false;
      const float* pl = set.planes.data() + 4 * s.planeBegin;
      for (int k = 0; k < s.planeCount; ++k, pl += 4) {
        const float fa = pl[0] * a[0] + pl[1] * a[1] + pl[2] * a[2] - pl[3] - grow;
        const float fb = pl[0] * b[0] + pl[1] * b[1] + pl[2] * b[2] - pl[3] - grow;
        if (!clip(fa, fb)) return false;
      }
      return true;
    }
  }
  return false;
}

}  // namespace rm3d
