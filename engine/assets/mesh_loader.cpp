// assimp-backed mesh loading: triangulate, join identical vertices, flatten the node tree
// (applying node transforms) and merge all meshes into one MeshData. Plain OBJ files (the
// project's own meshes) are read here instead, to the same bits (readPlainObj).
#include "assets/mesh_loader.h"

#include <assimp/fast_atof.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string_view>

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

/// What assimp's number reader throws here (its own exception type's constructor is not exported
/// by Debian's libassimp): not a number, to be left to assimp.
struct NotANumber {
  template <class... Args>
  explicit NotANumber(Args&&...) {}
};

bool isObjPath(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".obj";
}

bool checkPath(const std::string& path, double scale, std::string& err) {
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
  return true;
}

}  // namespace

bool readPlainObj(const std::string& text, double scale, MeshData& out) {
  out = MeshData{};
  // What assimp's OBJ reader with Triangulate and JoinIdenticalVertices, then collectNode above,
  // make of such a file: one mesh under identity nodes, its face corners' positions joined, each
  // point kept where a face first uses it. Numbers are read by assimp's own reader
  // (fast_atoreal_move into ai_real, commas as decimal points), so they are the same bits.
  std::vector<aiVector3D> vertices;
  std::vector<uint32_t> corners;  // file vertex indices from 0, three a face
  bool named = false;
  char word[64];
  const char* p = text.data();
  const char* const end = p + text.size();
  while (p < end) {
    const char* eol = static_cast<const char*>(std::memchr(p, '\n', size_t(end - p)));
    if (!eol) eol = end;
    const char* lineEnd = eol;
    if (lineEnd > p && lineEnd[-1] == '\r') --lineEnd;
    // The line's words (at most 4 matter: a keyword and three values).
    const char* words[5];
    size_t lengths[5];
    int count = 0;
    for (const char* c = p; c < lineEnd;) {
      while (c < lineEnd && (*c == ' ' || *c == '\t')) ++c;
      if (c == lineEnd) break;
      const char* w = c;
      while (c < lineEnd && *c != ' ' && *c != '\t') ++c;
      if (count == 0 && *w == '#') break;  // a comment line
      if (count == 5) return false;
      words[count] = w;
      lengths[count++] = size_t(c - w);
    }
    p = eol + 1;
    if (count == 0) continue;
    const std::string_view key(words[0], lengths[0]);
    if (key == "v" && count == 4) {
      ai_real xyz[3];
      for (int k = 0; k < 3; ++k) {
        if (lengths[k + 1] >= sizeof(word)) return false;
        std::memcpy(word, words[k + 1], lengths[k + 1]);
        word[lengths[k + 1]] = 0;
        try {
          const char* rest = Assimp::fast_atoreal_move<ai_real, NotANumber>(word, xyz[k]);
          if (*rest != 0 || !std::isfinite(xyz[k])) return false;
        } catch (const NotANumber&) {
          return false;
        }
      }
      vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
    } else if (key == "f" && count == 4) {
      for (int k = 1; k < 4; ++k) {
        if (lengths[k] > 9) return false;
        uint32_t index = 0;
        for (size_t i = 0; i < lengths[k]; ++i) {
          if (words[k][i] < '0' || words[k][i] > '9') return false;  // negative, or v/vt/vn
          index = index * 10 + uint32_t(words[k][i] - '0');
        }
        if (index == 0) return false;
        corners.push_back(index - 1);
      }
      const size_t f = corners.size() - 3;
      if (corners[f] == corners[f + 1] || corners[f] == corners[f + 2] || corners[f + 1] == corners[f + 2])
        return false;  // a degenerate face
    } else if (key == "o" && !named && corners.empty()) {
      named = true;  // one object, named before its faces
    } else {
      return false;  // anything else: assimp's
    }
  }
  if (corners.empty()) return false;
  // Each used vertex's point, in the order faces first use them.
  std::vector<int64_t> remap(vertices.size(), -1);
  std::vector<uint32_t> used;
  for (const uint32_t v : corners) {
    if (v >= vertices.size()) return false;
    if (remap[v] < 0) {
      remap[v] = int64_t(used.size());
      used.push_back(v);
    }
  }
  // Two used vertices at (nearly) the same place would be joined by assimp, by its own measure of
  // near: such a file is left to it. (Sorted by x, each compared with those within kNear in x; a
  // file where that makes too many comparisons, many vertices in one plane of x, is left to
  // assimp too, so the check stays linear in the vertices.)
  std::vector<uint32_t> byX = used;
  std::sort(byX.begin(), byX.end(), [&](uint32_t a, uint32_t b) { return vertices[a].x < vertices[b].x; });
  constexpr ai_real kNear = ai_real(1e-4);
  size_t budget = 32 * byX.size() + 1024;
  for (size_t i = 0; i < byX.size(); ++i)
    for (size_t j = i + 1; j < byX.size() && vertices[byX[j]].x - vertices[byX[i]].x <= kNear; ++j) {
      if (budget-- == 0) return false;
      const aiVector3D d = vertices[byX[j]] - vertices[byX[i]];
      if (std::abs(d.y) <= kNear && std::abs(d.z) <= kNear) return false;
    }
  // As collectNode: each point through the (identity) node transform, in ai_real, then scaled.
  const aiMatrix4x4 world;
  out.points.reserve(used.size());
  for (const uint32_t v : used) {
    const aiVector3D q = world * vertices[v];
    out.points.emplace_back(double(q.x) * scale, double(q.y) * scale, double(q.z) * scale);
  }
  out.triangles.reserve(corners.size());
  for (const uint32_t v : corners) out.triangles.push_back(uint32_t(remap[v]));
  return true;
}

namespace {

/// loadMeshWithAssimp once the path and scale are checked.
bool readWithAssimp(const std::string& path, double scale, MeshData& out, std::string& err);

/// loadMesh, with the file's bytes where the caller has read them already (MeshCache).
bool loadMeshRead(const std::string& path, double scale, const std::string* bytes, MeshData& out,
                  std::string& err) {
  out = MeshData{};
  if (!checkPath(path, scale, err)) return false;
  // assimp's OBJ reader fills a 16 MiB line buffer for every file it reads: in a fresh process
  // its pages cost about 50 ms a file on the development machine, most of a short run's time.
  // A plain OBJ is read here, to the same bits; any other is assimp's.
  if (isObjPath(path)) {
    std::string text;
    if (!bytes && readTextFile(path, text)) bytes = &text;
    if (bytes && readPlainObj(*bytes, scale, out)) return true;
  }
  return readWithAssimp(path, scale, out, err);
}

}  // namespace

bool loadMesh(const std::string& path, double scale, MeshData& out, std::string& err) {
  return loadMeshRead(path, scale, nullptr, out, err);
}

bool loadMeshWithAssimp(const std::string& path, double scale, MeshData& out, std::string& err) {
  out = MeshData{};
  return checkPath(path, scale, err) && readWithAssimp(path, scale, out, err);
}

namespace {

bool readWithAssimp(const std::string& path, double scale, MeshData& out, std::string& err) {
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

}  // namespace

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
  if (!loadMeshRead(path, scale, &bytes, out, err)) return false;
  std::lock_guard<std::mutex> lock(m_mutex);
  m_entries[key] = Entry{std::move(bytes), out};
  return true;
}

}  // namespace rm3d
