// Loads triangle meshes (OBJ, STL, glTF, ... anything assimp reads) into plain points and
// triangles for convex-hull shapes. The only place in the engine that touches assimp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"

namespace rm3d {

struct MeshData {
  std::vector<Vec3> points;         ///< already scaled, in the file's root frame
  std::vector<uint32_t> triangles;  ///< three indices into points per triangle, winding as in the file
};

/// Reads every mesh of the file's scene, each transformed by its node's accumulated transform,
/// into one point/triangle list, multiplied by scale. Only points used by triangles are kept.
/// On failure returns false and sets err to "<path>: <reason>" (missing file, unreadable,
/// no triangles, bad scale); out is then left empty.
bool loadMesh(const std::string& path, double scale, MeshData& out, std::string& err);

}  // namespace rm3d
