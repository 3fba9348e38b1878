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
/// Plain OBJ files (`v x y z` and `f i j k` lines with positive indices, `#` comments, one `o` before
/// the faces, no two used vertices within 1e-4 of each other) are read without assimp, to the
/// same bits assimp gives (readPlainObj); every other file goes to assimp (loadMeshWithAssimp).
bool loadMesh(const std::string& path, double scale, MeshData& out, std::string& err);

/// loadMesh through assimp alone, whatever the file.
bool loadMeshWithAssimp(const std::string& path, double scale, MeshData& out, std::string& err);

/// An OBJ file's text read as loadMesh reads a plain one; false (out empty) where the text is not
/// plain in that sense, or not valid (an index past the vertices), and assimp must read it.
bool readPlainObj(const std::string& text, double scale, MeshData& out);

/// Meshes already read, by file, scale and the file's bytes: a file read again with the same bytes
/// is not parsed again. Parsing was the cost of making a world: assimp's OBJ reader fills a 16 MiB
/// buffer for every file, about 2.7 ms (50 ms on fresh pages), so a SuperBot world spent 8 ms of
/// its 8.5 ms there (plain OBJ files no longer go to assimp: loadMesh). Owned by
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
