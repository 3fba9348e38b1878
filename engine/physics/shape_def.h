// Plain descriptions of collision shapes, shared by module types and obstacles. Filled by the
// script loaders, turned into Bullet shapes only inside physics/.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/types.h"

namespace rm3d {

enum class ShapeKind { Box, Sphere, Cylinder, Hull };

/// Mass properties of a shape at unit density, in the shape's own frame.
struct MassProps {
  double volume = 0;
  Vec3 com = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about com, per unit density
};

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
  /// Given: used instead of the geometry's (a collision shape standing in for a link's visual
  /// shapes carries their mass properties, see massFrom).
  std::optional<MassProps> massProps;
};

/// The shape's mass properties: `massProps` when given, else from its geometry.
MassProps shapeMassProps(const ShapeDef& s);

/// Mass properties of a rigid part made of `shapes` with total `mass`, in the part frame: each
/// shape gets its own `mass` when given (>= 0), the rest is shared by volume. `com` is the centre
/// of mass and `inertia` the inertia tensor about it in kg m^2 (not per unit density); `volume`
/// is the summed volume.
MassProps compoundMassProps(const std::vector<ShapeDef>& shapes, double mass);

/// Copies of `collision` that, built into a part of the given mass, give the same mass, centre of
/// mass and inertia as `visual` would (to rounding): the first shape carries all of it (explicit
/// `massProps`), the others none. For links whose collision geometry differs from what they are
/// made of, so that contact geometry changes and dynamics do not.
std::vector<ShapeDef> massFrom(const std::vector<ShapeDef>& visual, std::vector<ShapeDef> collision,
                               double mass);

}  // namespace rm3d
