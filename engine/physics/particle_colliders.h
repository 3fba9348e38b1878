// What particle systems collide with: every rigid body's collision shapes at their poses now, as
// plain floats (no Bullet types), gathered once per step by PhysicsWorld::collectColliders.
// Particles push back on the dynamic ones through PhysicsWorld::addForce/addTorque.
#pragma once

#include <cstdint>
#include <vector>

namespace rm3d {

/// One convex collision shape in the world.
struct ColliderShape {
  enum Kind : uint8_t { Box, Sphere, Cylinder, Capsule, Hull };
  Kind kind = Box;
  bool dynamic = false;  ///< on a body with mass (it takes the particles' push)
  int body = 0;          ///< index into ColliderSet::bodies
  /// Box: half extents; Sphere: radius; Cylinder, Capsule: radius, half length (along local z).
  float half[3] = {0, 0, 0};
  float rot[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< shape frame -> world, row-major
  float pos[3] = {0, 0, 0};                    ///< shape origin, world
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  ///< world bounding box
  int planeBegin = 0, planeCount = 0;          ///< Hull: planes (nx, ny, nz, d) in ColliderSet::planes
  float friction = 0.5f;
};

/// The rigid body a shape belongs to: where a push on it goes.
struct ColliderBody {
  int part = -1;  ///< any part of the body (addForce takes a part)
  bool dynamic = false;
  double com[3] = {0, 0, 0};     ///< centre of mass, world
  double linVel[3] = {0, 0, 0};  ///< m/s
  double angVel[3] = {0, 0, 0};  ///< rad/s
};

struct ColliderSet {
  std::vector<ColliderShape> shapes;
  std::vector<ColliderBody> bodies;
  std::vector<float> planes;  ///< hull planes, 4 floats each, local frame: n . x <= d inside
  bool ground = false;        ///< the plane z = 0
  float groundFriction = 0.8f;
};

}  // namespace rm3d
