// Loads triangle meshes (OBJ, STL, glTF, ... anything assimp reads) into plain points and
// triangles for convex-hull shapes. The only place in the engine that touches assimp.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>
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

/// Meshes already read, by file, scale and the file's bytes: a file read again with the same bytes
/// is not parsed again. Parsing is the cost of making a world: assimp's OBJ reader fills a 16 MiB
/// buffer for every file, about 2.7 ms, so a SuperBot world spent 8 ms of its 8.5 ms there. Owned by
/// whoever makes worlds again and again (a Simulation across restores, a Batch for its worlds),
/// never process-wide; safe to share between threads. Results are the same as loadMesh's. Only
/// the named file's bytes are compared: a change in a file it refers to alone (a glTF's .bin) is
/// not seen until the named file changes too.
class MeshCache {
 public:
  /// loadMesh, or a copy of what it returned for a file with the same bytes and scale.
  bool load(const std::string& path, double scale, MeshData& out, std::string& err);

 private:
  struct Entry {
    std::string bytes;
    MeshData mesh;
  };
  std::mutex m_mutex;
  std::map<std::pair<std::string, double>, Entry> m_entries;
};

}  // namespace rm3d
