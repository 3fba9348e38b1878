// Snapshot building: one mesh per distinct shape, one item per link shape, obstacle and dock.
#include "render/world_snapshot.h"

#include <cmath>
#include <cstdio>
#include <map>

#include "docking/dock_frame.h"
#include "world/world.h"

namespace rm3d {

namespace {

Eigen::Vector3f f3(const Vec3& v) {
  return v.cast<float>();
}

RenderMesh boxMesh() {
  RenderMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? 0.5f : -0.5f, i & 2 ? 0.5f : -0.5f, i & 4 ? 0.5f : -0.5f);
  const uint32_t idx[] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                          2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  m.indices.assign(std::begin(idx), std::end(idx));
  return m;
}

/// Unit-radius cylinder along z from -0.5 to 0.5 (scaled per item).
RenderMesh cylinderMesh(int n = 24) {
  RenderMesh m;
  for (int i = 0; i < n; ++i) {
    const float a = float(2 * kPi * i / n);
    m.vertices.emplace_back(std::cos(a), std::sin(a), -0.5f);
    m.vertices.emplace_back(std::cos(a), std::sin(a), 0.5f);
  }
  const uint32_t bottom = uint32_t(m.vertices.size());
  m.vertices.emplace_back(0, 0, -0.5f);
  m.vertices.emplace_back(0, 0, 0.5f);
  for (int i = 0; i < n; ++i) {
    const uint32_t a = uint32_t(2 * i), b = uint32_t(2 * ((i + 1) % n));
    m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1, bottom, b, a, bottom + 1, a + 1, b + 1});
  }
  return m;
}

RenderMesh sphereMesh(int rings = 12, int segments = 24) {
  RenderMesh m;
  for (int r = 0; r <= rings; ++r) {
    const double th = kPi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double ph = 2 * kPi * s / segments;
      m.vertices.emplace_back(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                              float(std::cos(th)));
    }
  }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = uint32_t(r * segments + s), b = uint32_t(r * segments + (s + 1) % segments);
      const uint32_t c = a + uint32_t(segments), d = b + uint32_t(segments);
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  return m;
}

/// Mesh index and scale for a shape; hull meshes are added once per distinct point set.
struct MeshTable {
  Snapshot& snap;
  int box = -1, cylinder = -1, sphere = -1;
  std::map<const ShapeDef*, int> hulls;

  int add(RenderMesh m) {
    snap.meshes.push_back(std::move(m));
    return int(snap.meshes.size()) - 1;
  }
  int meshFor(const ShapeDef& s, Eigen::Vector3f& scale) {
    switch (s.kind) {
      case ShapeKind::Box:
        scale = f3(s.size);
        if (box < 0) box = add(boxMesh());
        return box;
      case ShapeKind::Cylinder:
        scale = Eigen::Vector3f(float(s.radius), float(s.radius), float(s.length));
        if (cylinder < 0) cylinder = add(cylinderMesh());
        return cylinder;
      case ShapeKind::Sphere:
        scale = Eigen::Vector3f::Constant(float(s.radius));
        if (sphere < 0) sphere = add(sphereMesh());
        return sphere;
      case ShapeKind::Hull: {
        scale = Eigen::Vector3f::Ones();
        auto it = hulls.find(&s);
        if (it != hulls.end()) return it->second;
        RenderMesh m;
        for (const Vec3& p : s.points) m.vertices.push_back(f3(p));
        m.indices = s.triangles;
        return hulls[&s] = add(std::move(m));
      }
    }
    return 0;
  }
};

Eigen::Matrix4f toMatrix(const Pose& p, const Eigen::Vector3f& scale) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<3, 3>(0, 0) = p.rot.toRotationMatrix().cast<float>() * scale.asDiagonal();
  m.block<3, 1>(0, 3) = f3(p.pos);
  return m;
}

}  // namespace

Snapshot buildSnapshot(const World& w) {
  Snapshot snap;
  MeshTable table{snap, -1, -1, -1, {}};
  for (size_t i = 0; i < w.modules().size(); ++i) {
    const Module& m = w.modules()[i];
    const bool faulted = !m.fault.empty();
    for (size_t l = 0; l < m.type->links.size(); ++l) {
      const LinkDef& link = m.type->links[l];
      const Pose lp = w.linkPose(int(i), int(l));
      for (const ShapeDef& s : link.shapes) {
        RenderItem item;
        Eigen::Vector3f scale;
        item.mesh = table.meshFor(s, scale);
        item.transform = toMatrix(lp * s.pose, scale);
        item.color = link.color;
        item.tag = int(i);
        if (faulted) item.color = {0.85f, 0.1f, 0.1f, 1.0f};
        snap.items.push_back(item);
      }
    }
    // Dock faces: green engaged, grey free, red disabled.
    for (size_t d = 0; d < m.type->docks.size(); ++d) {
      const DockDef& dock = m.type->docks[d];
      const DockState& st = m.docks[d];
      RenderItem item;
      Eigen::Vector3f unused;
      item.mesh = table.meshFor(ShapeDef{}, unused);
      Pose face = w.dockPose(int(i), int(d));
      face.pos += face.rot * Vec3(-0.0005, 0, 0);
      item.transform = toMatrix(face, Eigen::Vector3f(0.002f, float(dock.size), float(dock.size)));
      item.tag = int(i);
      item.color = !st.enabled  ? std::array<float, 4>{0.9f, 0.15f, 0.1f, 1}
                   : st.engaged ? std::array<float, 4>{0.2f, 0.8f, 0.3f, 1}
                                : std::array<float, 4>{0.55f, 0.55f, 0.6f, 1};
      snap.items.push_back(item);
    }
  }
  // Range sensors as lines: to the hit (red) or over their whole range (yellow).
  for (size_t i = 0; i < w.modules().size(); ++i) {
    const Module& m = w.modules()[i];
    for (const SensorDef& sd : m.type->sensors) {
      if (sd.kind != SensorKind::Range) continue;
      const Pose lp = w.linkPose(int(i), sd.link);
      const Vec3 dir = lp.rot * sd.dir, from = lp * sd.pos;
      const double hit =
          w.physicsConst().rayCast(from + dir * sd.minRange, dir, sd.maxRange - sd.minRange, int(i));
      RenderLine line;
      line.a = f3(from);
      line.b = f3(from + dir * (hit >= 0 ? hit + sd.minRange : sd.maxRange));
      line.color = hit >= 0 ? std::array<float, 4>{0.95f, 0.2f, 0.15f, 1}
                            : std::array<float, 4>{0.95f, 0.85f, 0.1f, 1};
      snap.lines.push_back(line);
    }
  }
  for (const World::Obstacle& o : w.obstacles()) {
    RenderItem item;
    Eigen::Vector3f scale;
    item.mesh = table.meshFor(o.shape, scale);
    item.transform = toMatrix(w.obstaclePose(o.part) * o.shape.pose, scale);
    item.color = o.mass > 0 ? std::array<float, 4>{0.35f, 0.55f, 0.85f, 1}
                            : std::array<float, 4>{0.6f, 0.6f, 0.62f, 1};
    snap.items.push_back(item);
  }
  snap.ground = w.hasGround();
  char line[160];
  std::snprintf(line, sizeof line, "t = %.2f s   step %lld   %zu modules   %d faults", w.time(),
                (long long)w.steps(), w.modules().size(), w.faultCount());
  snap.overlay.push_back(line);
  return snap;
}

Camera worldCamera(const World& w) {
  Camera cam;
  const World::CameraDef& def = w.camera();
  Vec3 lo(-0.5, -0.5, 0), hi(0.5, 0.5, 0.2);
  if (!w.modules().empty()) {
    lo = hi = w.modulePose(0).pos;
    for (size_t i = 0; i < w.modules().size(); ++i) {
      const Vec3 p = w.modulePose(int(i)).pos;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  Vec3 target = (lo + hi) / 2;
  if (def.follow >= 0) target = w.modulePose(def.follow).pos;
  if (def.target) target = *def.target;
  const double extent = std::max(0.6, (hi - lo).norm() + 0.3);
  Vec3 eye = target + Vec3(0.55, -1.0, 0.6).normalized() * extent * 0.9;
  if (def.eye) eye = def.follow >= 0 && !def.target ? target + *def.eye : *def.eye;
  cam.eye = f3(eye);
  cam.target = f3(target);
  cam.fovyDeg = float(def.fovDeg);
  return cam;
}

}  // namespace rm3d
