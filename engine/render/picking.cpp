// Ray picking against snapshot items: slab test on the mesh bounds in the mesh frame, then
// Moller-Trumbore on the triangles, so thin or concave shapes are not picked through their gaps.
#include "render/picking.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rm3d {

namespace {

/// Entry distance of o + t d into box (t >= 0), or +inf. d need not be unit.
float slab(const Eigen::AlignedBox3f& box, const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  float t0 = 0.0f, t1 = std::numeric_limits<float>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12f) {
      if (o[i] < box.min()[i] || o[i] > box.max()[i]) return std::numeric_limits<float>::infinity();
      continue;
    }
    float a = (box.min()[i] - o[i]) / d[i], b = (box.max()[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return std::numeric_limits<float>::infinity();
  }
  return t0;
}

/// Distance t >= 0 where o + t d crosses triangle abc (either side), or +inf.
float triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
               const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  const Eigen::Vector3f e1 = b - a, e2 = c - a, p = d.cross(e2);
  const float det = e1.dot(p);
  if (std::abs(det) < 1e-20f) return std::numeric_limits<float>::infinity();
  const float inv = 1.0f / det;
  const Eigen::Vector3f s = o - a;
  const float u = s.dot(p) * inv;
  if (u < 0.0f || u > 1.0f) return std::numeric_limits<float>::infinity();
  const Eigen::Vector3f q = s.cross(e1);
  const float v = d.dot(q) * inv;
  if (v < 0.0f || u + v > 1.0f) return std::numeric_limits<float>::infinity();
  const float t = e2.dot(q) * inv;
  return t >= 0.0f ? t : std::numeric_limits<float>::infinity();
}

}  // namespace

Picker::Picker(const Snapshot& s) : m_snapshot(s) {
  for (const RenderMesh& m : s.meshes) {
    Eigen::AlignedBox3f box;
    for (const Eigen::Vector3f& v : m.vertices) box.extend(v);
    m_meshBounds.push_back(box);
  }
  m_items.resize(s.items.size());
  for (size_t i = 0; i < s.items.size(); ++i) {
    const RenderItem& it = s.items[i];
    if (it.mesh < 0 || it.mesh >= int(s.meshes.size()) || m_meshBounds[size_t(it.mesh)].isEmpty()) continue;
    // A zero scale (a flattened item) has no inverse and nothing to click on.
    if (std::abs(it.transform.topLeftCorner<3, 3>().determinant()) < 1e-18f) continue;
    m_items[i].worldToMesh = it.transform.inverse();
    m_items[i].valid = true;
  }
}

PickHit Picker::pick(const Ray& ray) const {
  PickHit best;
  float bestT = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < m_items.size(); ++i) {
    const ItemData& item = m_items[i];
    if (!item.valid) continue;
    // In the mesh frame the direction is not unit, which keeps t a world distance.
    const Eigen::Vector3f o = (item.worldToMesh * ray.origin.homogeneous()).head<3>();
    const Eigen::Vector3f d = item.worldToMesh.topLeftCorner<3, 3>() * ray.dir;
    const RenderItem& it = m_snapshot.items[i];
    if (slab(m_meshBounds[size_t(it.mesh)], o, d) >= bestT) continue;
    const RenderMesh& mesh = m_snapshot.meshes[size_t(it.mesh)];
    for (size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
      const uint32_t a = mesh.indices[k], b = mesh.indices[k + 1], c = mesh.indices[k + 2];
      if (std::max({a, b, c}) >= mesh.vertices.size()) continue;
      const float t = triangle(mesh.vertices[a], mesh.vertices[b], mesh.vertices[c], o, d);
      if (t < bestT) {
        bestT = t;
        best = {int(i), t};
      }
    }
  }
  return best;
}

}  // namespace rm3d
