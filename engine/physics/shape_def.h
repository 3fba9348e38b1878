// Plain descriptions of collision shapes, shared by module types and obstacles. Filled by the
// script loaders, turned into Bullet shapes only inside physics/.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/types.h"

namespace rm3d {

/// Capsule: a cylinder of `length` along z capped by hemispheres of `radius`. TriMesh (a concave
/// triangle mesh) and Heightfield are static only.
enum class ShapeKind { Box, Sphere, Cylinder, Hull, Capsule, TriMesh, Heightfield };

/// A regular grid of heights (a heightfield), in the shape's frame: x and y from -extent/2 to
/// +extent/2 about the origin, heights from 0 (the shape's base, z = 0) up to `maxHeight`.
/// Samples run row after row from the -y edge, each row from -x to +x. Each cell is split into two
/// triangles along its diagonal from (i+1, j) to (i, j+1), as Bullet's heightfield splits it.
struct HeightGrid {
  int nx = 0, ny = 0;          ///< samples along x and y (2 or more each)
  double sx = 1, sy = 1;       ///< m from the first sample to the last, along x and y
  double maxHeight = 1;        ///< m: a sample of 1.0 in the image
  std::vector<float> heights;  ///< nx * ny, m above the base, in [0, maxHeight]
  double cellX() const { return sx / (nx - 1); }
  double cellY() const { return sy / (ny - 1); }
  float at(int i, int j) const { return heights[size_t(j) * size_t(nx) + size_t(i)]; }
  /// Height (m above the base) of the surface over (x, y) in the shape frame, on the triangles
  /// the physics collides with; points outside are clamped to the edge.
  double heightAt(double x, double y) const;
};

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
  double length = 0.1;              ///< Cylinder (and Capsule's straight part), along the shape's z axis
  Pose pose;                        ///< shape frame in its owner's frame (link or body)
  double mass = -1;                 ///< share of the owner's mass; < 0: by volume
  /// Hull: points of the convex hull and (for drawing and inertia) its triangles, already scaled.
  /// TriMesh: the mesh itself (points and triangles).
  std::vector<Vec3> points;
  std::vector<uint32_t> triangles;
  std::string source;  ///< mesh file the hull came from (for messages)
  /// Given: used instead of the geometry's (a collision shape standing in for a link's visual
  /// shapes carries their mass properties, see massFrom).
  std::optional<MassProps> massProps;
  /// Heightfield: the grid, shared (and never changed) so that copies of the def and the physics
  /// shape, which reads the heights in place, see one array.
  std::shared_ptr<const HeightGrid> grid;
};

/// True for shapes only a static body (mass 0) can have.
inline bool staticOnly(ShapeKind k) {
  return k == ShapeKind::TriMesh || k == ShapeKind::Heightfield;
}

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
