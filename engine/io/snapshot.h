// A read-only picture of a world at one instant: what the renderer draws (render/). io/world_snapshot.h fills
// it; the renderer never sees the World itself. Frames: z up, metres.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace rm3d {

/// Triangle mesh in its own local frame (a link shape, an obstacle).
struct RenderMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<uint32_t> indices;  ///< three per triangle, counter-clockwise seen from outside
  /// Grid lines drawn on the mesh where its local x or y is a whole number of these (terrain
  /// cells); 0: none.
  Eigen::Vector2f grid{0, 0};
};

/// One drawn instance of a mesh.
struct RenderItem {
  int mesh = 0;                                             ///< index into Snapshot::meshes
  Eigen::Matrix4f transform = Eigen::Matrix4f::Identity();  ///< mesh frame -> world (may scale)
  std::array<float, 4> color{0.8f, 0.8f, 0.8f, 1.0f};       ///< linear RGBA
  int tag = -1;  ///< what it belongs to (a module index for module links and docks, else -1)
};

/// A line segment in world space (range-sensor rays, dock markers).
struct RenderLine {
  Eigen::Vector3f a, b;
  std::array<float, 4> color{1, 1, 0, 1};
};

/// A set of equal spheres drawn instanced (fluid and debris particles): one draw call per set.
struct RenderSpheres {
  std::vector<Eigen::Vector3f> centers;  ///< world space
  float radius = 0.01f;
  std::array<float, 4> color{0.2f, 0.45f, 0.9f, 1.0f};  ///< linear RGBA
};

/// Text drawn at a point of the scene (a module's name with --labels), centred above it.
struct RenderLabel {
  Eigen::Vector3f at;
  std::string text;
};

struct Camera {
  Eigen::Vector3f eye{1.5f, -1.5f, 1.0f};
  Eigen::Vector3f target{0, 0, 0};
  Eigen::Vector3f up{0, 0, 1};
  float fovyDeg = 45.0f;
};

struct Snapshot {
  std::vector<RenderMesh> meshes;
  std::vector<RenderItem> items;
  std::vector<RenderLine> lines;
  std::vector<RenderSpheres> spheres;  ///< particle systems
  bool ground = true;                  ///< draw the plane z = 0 with a 0.1 m / 1 m grid
  std::vector<std::string> overlay;    ///< text lines drawn top-left (sim time, modules, ...)
  std::vector<RenderLabel> labels;     ///< text at scene points, drawn over everything
};

}  // namespace rm3d
