// Checks loadMesh: the generated SuperBot meshes load closed and outward-wound (positive volume,
// exact for the side plate), scale applies, meshes merge, node transforms (mirrors included)
// apply, and errors name the file.
#include "assets/mesh_loader.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "physics/shape_def.h"

namespace fs = std::filesystem;

namespace {

const std::string kRoot = RM3D_SOURCE_DIR;

/// A fresh folder under the system temp dir, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "rm3d_mesh_test_XXXXXX").string();
    REQUIRE(mkdtemp(tmpl.data()) != nullptr);
    path = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    std::ofstream(p) << text;
    return p.string();
  }
};

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

double meshVolume(const rm3d::MeshData& m) {
  rm3d::ShapeDef s;
  s.kind = rm3d::ShapeKind::Hull;
  s.points = m.points;
  s.triangles = m.triangles;
  return rm3d::shapeMassProps(s).volume;
}

/// Closed and consistently wound: every directed edge appears once, and its reverse once.
bool isClosed(const rm3d::MeshData& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t t = 0; t + 2 < m.triangles.size(); t += 3)
    for (int k = 0; k < 3; ++k) ++edges[{m.triangles[t + k], m.triangles[t + (k + 1) % 3]}];
  for (const auto& [e, n] : edges)
    if (n != 1 || edges.count({e.second, e.first}) == 0) return false;
  return true;
}

void bounds(const rm3d::MeshData& m, rm3d::Vec3& lo, rm3d::Vec3& hi) {
  lo = hi = m.points.at(0);
  for (const rm3d::Vec3& p : m.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

std::string base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t n = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) n |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) n |= uint8_t(bytes[i + 2]);
    out += kDigits[(n >> 18) & 63];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

/// A glTF file with one triangle (0,0,0), (1,0,0), (0,1,0) (normal +z) under two nodes: a
/// parent with `parentTransform` (glTF node fields) and a child scaled by 2.
std::string triangleGltf(const std::string& parentTransform) {
  std::string buf;
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint16_t idx[3] = {0, 1, 2};
  buf.append(reinterpret_cast<const char*>(pos), sizeof pos);
  buf.append(reinterpret_cast<const char*>(idx), sizeof idx);
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{)" +
         parentTransform + R"(, "children": [1]}, {"scale": [2, 2, 2], "mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
  "buffers": [{"byteLength": 42, "uri": "data:application/octet-stream;base64,)" +
         base64(buf) + R"("}]})";
}

}  // namespace

TEST_CASE("loadMesh reads the SuperBot end plate: closed, outward, chamfered box") {
  rm3d::MeshData m;
  std::string err;
  REQUIRE_MESSAGE(rm3d::loadMesh(kRoot + "/assets/meshes/superbot_end_plate.obj", 1.0, m, err), err);
  CHECK(m.points.size() == 24);
  CHECK(m.triangles.size() == 44 * 3);
  CHECK(isClosed(m));
  // assimp keeps single-precision floats: compare to about 1e-6 relative.
  rm3d::Vec3 lo, hi;
  bounds(m, lo, hi);
  CHECK(lo.isApprox(rm3d::Vec3(-0.006, -0.042, -0.042), 1e-6));
  CHECK(hi.isApprox(rm3d::Vec3(0.006, 0.042, 0.042), 1e-6));
  const double box = 0.012 * 0.084 * 0.084;
  const double v = meshVolume(m);
  CHECK(v > 0.9 * box);  // positive: wound outward; a little less than the box: chamfered
  CHECK(v < box);
}

TEST_CASE("loadMesh reads the SuperBot side plate: a D with the exact volume") {
  rm3d::MeshData m;
  std::string err;
  REQUIRE_MESSAGE(rm3d::loadMesh(kRoot + "/assets/meshes/superbot_side_plate.obj", 1.0, m, err), err);
  CHECK(m.points.size() == 38);
  CHECK(m.triangles.size() == 72 * 3);
  CHECK(isClosed(m));
  rm3d::Vec3 lo, hi;
  bounds(m, lo, hi);
  CHECK(lo.isApprox(rm3d::Vec3(-0.042, -0.006, -0.042), 1e-6));
  CHECK(hi.isApprox(rm3d::Vec3(0.052, 0.006, 0.042), 1e-6));
  // Rectangle plus a 16-segment half polygon of radius 0.042, extruded 0.012.
  const double r = 0.042;
  const double area = 0.052 * 0.084 + 16 * 0.5 * r * r * std::sin(rm3d::kPi / 16);
  CHECK(meshVolume(m) == doctest::Approx(area * 0.012).epsilon(1e-6));

  SUBCASE("scale multiplies every point") {
    rm3d::MeshData big;
    REQUIRE_MESSAGE(rm3d::loadMesh(kRoot + "/assets/meshes/superbot_side_plate.obj", 2.0, big, err), err);
    REQUIRE(big.points.size() == m.points.size());
    for (size_t i = 0; i < m.points.size(); ++i) CHECK(big.points[i].isApprox(2.0 * m.points[i], 1e-12));
    CHECK(meshVolume(big) == doctest::Approx(8 * meshVolume(m)).epsilon(1e-9));
  }
}

TEST_CASE("loadMesh merges all meshes of a scene") {
  TempDir dir;
  const std::string path = dir.write("two.obj",
                                     "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
                                     "o b\nv 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\n"
                                     "f 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n");
  rm3d::MeshData m;
  std::string err;
  REQUIRE_MESSAGE(rm3d::loadMesh(path, 1.0, m, err), err);
  CHECK(m.points.size() == 8);
  CHECK(m.triangles.size() == 8 * 3);
  CHECK(meshVolume(m) == doctest::Approx(2.0 / 6.0).epsilon(1e-9));
}

TEST_CASE("loadMesh applies node transforms and keeps mirrored faces outward") {
  TempDir dir;
  rm3d::MeshData m;
  std::string err;
  SUBCASE("translation of the parent, scale of the child") {
    const std::string path = dir.write("tri.gltf", triangleGltf(R"("translation": [0, 0, 1])"));
    REQUIRE_MESSAGE(rm3d::loadMesh(path, 1.0, m, err), err);
    REQUIRE(m.points.size() == 3);
    CHECK(m.points[0].isApprox(rm3d::Vec3(0, 0, 1)));
    CHECK(m.points[1].isApprox(rm3d::Vec3(2, 0, 1)));
    CHECK(m.points[2].isApprox(rm3d::Vec3(0, 2, 1)));
  }
  SUBCASE("a mirroring parent flips the winding back") {
    const std::string path = dir.write("mirror.gltf", triangleGltf(R"("scale": [-1, 1, 1])"));
    REQUIRE_MESSAGE(rm3d::loadMesh(path, 1.0, m, err), err);
    REQUIRE(m.triangles.size() == 3);
    const rm3d::Vec3& a = m.points[m.triangles[0]];
    const rm3d::Vec3& b = m.points[m.triangles[1]];
    const rm3d::Vec3& c = m.points[m.triangles[2]];
    CHECK(m.points[1].x() == doctest::Approx(-2));
    CHECK((b - a).cross(c - a).z() > 0);  // still facing +z, as the unmirrored triangle did
  }
}

TEST_CASE("loadMesh errors name the file and the reason") {
  TempDir dir;
  rm3d::MeshData m;
  std::string err;
  SUBCASE("missing file") {
    CHECK_FALSE(rm3d::loadMesh((dir.path / "nowhere.obj").string(), 1.0, m, err));
    CHECK_MESSAGE(contains(err, "nowhere.obj"), err);
    CHECK_MESSAGE(contains(err, "not found"), err);
  }
  SUBCASE("unreadable contents") {
    const std::string path = dir.write("garbage.stl", "solid x\n this is not an STL file at all\n");
    CHECK_FALSE(rm3d::loadMesh(path, 1.0, m, err));
    CHECK_MESSAGE(contains(err, "garbage.stl"), err);
  }
  SUBCASE("no triangles, only a line") {
    const std::string path = dir.write("line.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n");
    CHECK_FALSE(rm3d::loadMesh(path, 1.0, m, err));
    CHECK_MESSAGE(contains(err, "line.obj"), err);
    CHECK(m.points.empty());
  }
  SUBCASE("bad scale") {
    CHECK_FALSE(rm3d::loadMesh(kRoot + "/assets/meshes/superbot_end_plate.obj", 0.0, m, err));
    CHECK_MESSAGE(contains(err, "superbot_end_plate.obj"), err);
  }
}

namespace {

/// The same points and triangles, bit for bit.
bool sameBits(const rm3d::MeshData& a, const rm3d::MeshData& b) {
  if (a.points.size() != b.points.size() || a.triangles != b.triangles) return false;
  for (size_t i = 0; i < a.points.size(); ++i)
    if (std::memcmp(a.points[i].data(), b.points[i].data(), 3 * sizeof(double)) != 0) return false;
  return true;
}

}  // namespace

TEST_CASE("plain OBJ files are read without assimp, to the bits assimp gives") {
  // Every mesh the project ships, at two scales: the plain reader takes each (they are plain) and
  // gives assimp's points and triangles exactly.
  int plain = 0;
  for (const auto& entry : fs::directory_iterator(kRoot + "/assets/meshes")) {
    if (entry.path().extension() != ".obj") continue;
    const std::string path = entry.path().string();
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (double scale : {1.0, 0.37}) {
      CAPTURE(path);
      CAPTURE(scale);
      rm3d::MeshData fast, slow, loaded;
      std::string err;
      REQUIRE(rm3d::readPlainObj(text, scale, fast));
      REQUIRE_MESSAGE(rm3d::loadMeshWithAssimp(path, scale, slow, err), err);
      REQUIRE_MESSAGE(rm3d::loadMesh(path, scale, loaded, err), err);
      CHECK(!fast.points.empty());
      CHECK(sameBits(fast, slow));
      CHECK(sameBits(loaded, slow));
    }
    ++plain;
  }
  CHECK(plain >= 7);
  TempDir dir;
  // Plain too: CRLF line ends, tabs, comments, vertices after the faces that use them, a comma as
  // the decimal point (assimp's reader takes it), exponents, unused vertices, numbers at the
  // edge of float's precision.
  const std::string plainText =
      "# a tetrahedron\r\no t\r\nv -0 0 -0.0\r\nv\t1.0e0 0 0\r\n\r\nf 1 3 2\r\nf 1 2 4\r\nf 1 4 3\r\nf 2 3 "
      "4\r\n"
      "v 0,0 1.00000011920928955 -0\r\nv 0.1 0.2 0.3\r\nv 1e-3 2E-2 0.333333333333333333333\r\n";
  // Left to assimp: a second object, groups, materials, texture and normal indices, quads,
  // negative indices, a point and a line, a degenerate face, two vertices within 1e-4 of each
  // other (assimp joins those by its own measure), an index past the vertices, a non-number.
  const std::vector<std::string> others = {
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no second\nv 0 0 1\nf 1 2 4\n",
      "g part\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
      "usemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n",
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\nf 1 2 3\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.00005 0 0\nf 1 2 3\nf 4 3 2\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n",
      "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 # a comment after a face\n",
  };
  rm3d::MeshData fast, slow, loaded;
  std::string err;
  const std::string path = dir.write("plain.obj", plainText);
  REQUIRE(rm3d::readPlainObj(plainText, 2.0, fast));
  REQUIRE_MESSAGE(rm3d::loadMeshWithAssimp(path, 2.0, slow, err), err);
  CHECK(fast.points.size() == 4);
  CHECK(fast.triangles.size() == 12);
  CHECK(sameBits(fast, slow));
  {
    // A flat mesh of 300 x 300 points in the plane x = 0 (every vertex within 1e-4 of the others
    // in x): the plain reader gives up at once rather than compare every pair, and assimp reads it.
    std::string flat;
    const int n = 300;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) flat += "v 0 " + std::to_string(i) + " " + std::to_string(j) + "\n";
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j + 1 < n; ++j) {
        const int a = i * n + j + 1;
        flat += "f " + std::to_string(a) + " " + std::to_string(a + n) + " " + std::to_string(a + 1) + "\n";
      }
    CHECK_FALSE(rm3d::readPlainObj(flat, 1.0, fast));
    const std::string flatPath = dir.write("flat.obj", flat);
    REQUIRE_MESSAGE(rm3d::loadMesh(flatPath, 1.0, loaded, err), err);
    CHECK(loaded.triangles.size() == size_t(3 * (n - 1) * (n - 1)));
  }
  for (size_t i = 0; i < others.size(); ++i) {
    CAPTURE(others[i]);
    CHECK_FALSE(rm3d::readPlainObj(others[i], 1.0, fast));
    CHECK(fast.points.empty());
    // loadMesh still reads what assimp reads, as assimp reads it.
    const std::string other = dir.write("other" + std::to_string(i) + ".obj", others[i]);
    const bool viaAssimp = rm3d::loadMeshWithAssimp(other, 1.0, slow, err);
    CHECK(rm3d::loadMesh(other, 1.0, loaded, err) == viaAssimp);
    if (viaAssimp) CHECK(sameBits(loaded, slow));
  }
}
