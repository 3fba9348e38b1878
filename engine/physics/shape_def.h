// Plain descriptions of collision shapes, shared by module types and obstacles. Filled by the
// script loaders, turned into Bullet shapes only inside physics/.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"

namespace rm3d {

enum class ShapeKind { Box, Sphere, Cylinder, Hull };

struct ShapeDef {
  ShapeKind kind = ShapeKind::Box;
  Vec3 size = Vec3(0.1, 0.1, 0.1);  ///< Box: full extents along x, y, z
  double radius = 0.05;             ///< Sphere, Cylinder
  double length = 0.1;              ///< Cylinder, along the shape's z axis
  Pose pose;                        ///< shape frame in its owner's frame (link or body)
  double mass = -1;                 ///< share of the owner's mass; < 0: by volume
  /// Hull: points of the convex hull and (for drawing and inertia) its triangles, already scaled.
  std::vector<Vec3> points;
  std::vector<uint32_t> triangles;
  std::string source;  ///< mesh file the hull came from (for messages)
};

/// Mass properties of a shape at unit density, in the shape's own frame.
struct MassProps {
  double volume = 0;
  Vec3 com = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about com, per unit density
};

MassProps shapeMassProps(const ShapeDef& s);

}  // namespace rm3d
