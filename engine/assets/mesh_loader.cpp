// assimp-backed mesh loading: triangulate, join identical vertices, flatten the node tree
// (applying node transforms) and merge all meshes into one MeshData.
#include "assets/mesh_loader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>

#include "core/text_file.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

// Walks the node tree depth-first; `parent` is the accumulated transform of the node's parent.
void collectNode(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, double scale,
                 MeshData& out) {
  const aiMatrix4x4 world = parent * node->mTransformation;
  // A mirroring transform turns the winding inside out; swap two corners to keep faces outward.
  const bool mirrored = world.Determinant() < 0;
  for (unsigned mi = 0; mi < node->mNumMeshes; ++mi) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[mi]];
    // Only points that some triangle uses: stray points or line vertices would otherwise enlarge
    // the convex hull without being visible in the drawn mesh.
    std::vector<int64_t> remap(mesh->mNumVertices, -1);
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines survive triangulation; skip them
      uint32_t idx[3];
      for (int k = 0; k < 3; ++k) {
        const unsigned v = face.mIndices[k];
        if (remap[v] < 0) {
          const aiVector3D p = world * mesh->mVertices[v];
          remap[v] = int64_t(out.points.size());
          out.points.emplace_back(double(p.x) * scale, double(p.y) * scale, double(p.z) * scale);
        }
        idx[k] = uint32_t(remap[v]);
      }
      if (mirrored) std::swap(idx[1], idx[2]);
      out.triangles.insert(out.triangles.end(), idx, idx + 3);
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) collectNode(scene, node->mChildren[c], world, scale, out);
}

}  // namespace

bool loadMesh(const std::string& path, double scale, MeshData& out, std::string& err) {
  out = MeshData{};
  if (!std::isfinite(scale) || scale <= 0) {
    err = path + ": bad scale " + std::to_string(scale) + " (expected a positive number)";
    return false;
  }
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    err = path + ": file not found";
    return false;
  }
  if (!fs::is_regular_file(path, ec)) {
    err = path + ": not a regular file";
    return false;
  }
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || scene->mRootNode == nullptr) {
    const char* why = importer.GetErrorString();
    err = path + ": cannot read mesh (" + std::string(why && *why ? why : "unknown format or empty scene") +
          ")";
    return false;
  }
  collectNode(scene, scene->mRootNode, aiMatrix4x4(), scale, out);
  if (out.triangles.empty()) {
    out = MeshData{};
    err = path + ": no triangles in the file";
    return false;
  }
  return true;
}

bool MeshCache::load(const std::string& path, double scale, MeshData& out, std::string& err) {
  std::string bytes;
  // What cannot be read whole here (a missing file, over 64 MiB) goes to loadMesh, which says why.
  if (!readTextFile(path, bytes)) return loadMesh(path, scale, out, err);
  const auto key = std::make_pair(path, scale);
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    auto it = m_entries.find(key);
    if (it != m_entries.end() && it->second.bytes == bytes) {
      out = it->second.mesh;
      return true;
    }
  }
  if (!loadMesh(path, scale, out, err)) return false;
  std::lock_guard<std::mutex> lock(m_mutex);
  m_entries[key] = Entry{std::move(bytes), out};
  return true;
}

}  // namespace rm3d
