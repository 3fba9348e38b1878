// Scene layout and state: the mesh table, capturing a world's state, and building a Snapshot.
#include "io/scene_state.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "particles/particle_system.h"
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

/// A capsule of the given radius with a straight part `length` long along z, centred.
RenderMesh capsuleMesh(double radius, double length, int rings = 6, int segments = 24) {
  RenderMesh m;
  // Rings from the bottom pole to the top pole; the two equator rings are `length` apart.
  std::vector<std::pair<double, double>> rz;  // ring radius, ring z
  for (int r = 0; r <= rings; ++r) {
    const double th = kPi / 2 * r / rings;
    rz.emplace_back(radius * std::sin(th), -length / 2 - radius * std::cos(th));
  }
  for (int r = rings; r >= 0; --r) {
    const double th = kPi / 2 * r / rings;
    rz.emplace_back(radius * std::sin(th), length / 2 + radius * std::cos(th));
  }
  for (const auto& [rr, z] : rz)
    for (int s = 0; s < segments; ++s) {
      const double ph = 2 * kPi * s / segments;
      m.vertices.emplace_back(float(rr * std::cos(ph)), float(rr * std::sin(ph)), float(z));
    }
  for (size_t r = 0; r + 1 < rz.size(); ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = uint32_t(r * size_t(segments) + size_t(s)),
                     b = uint32_t(r * size_t(segments) + size_t((s + 1) % segments));
      const uint32_t c = a + uint32_t(segments), d = b + uint32_t(segments);
      m.indices.insert(m.indices.end(), {a, b, c, b, d, c});
    }
  return m;
}

/// The terrain's triangles, split as the physics splits them (HeightGrid), in a frame whose
/// origin is the grid's first sample at the base: x, y from 0 to the extent, so the grid lines
/// fall on whole numbers of cells.
RenderMesh heightfieldMesh(const HeightGrid& g) {
  RenderMesh m;
  const double cx = g.cellX(), cy = g.cellY();
  m.vertices.reserve(size_t(g.nx) * size_t(g.ny));
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) m.vertices.emplace_back(float(i * cx), float(j * cy), g.at(i, j));
  m.indices.reserve(size_t(g.nx - 1) * size_t(g.ny - 1) * 6);
  for (int j = 0; j + 1 < g.ny; ++j)
    for (int i = 0; i + 1 < g.nx; ++i) {
      const uint32_t a = uint32_t(j * g.nx + i), b = a + 1, c = a + uint32_t(g.nx), d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, c, b, d, c});  // diagonal b-c: (i+1, j)-(i, j+1)
    }
  m.grid = Eigen::Vector2f(float(cx), float(cy));
  return m;
}

/// Mesh index and scale for a shape; hull, trimesh and heightfield meshes are added once per
/// shape, capsules once per size.
struct MeshTable {
  std::vector<RenderMesh>& meshes;
  int box = -1, cylinder = -1, sphere = -1;
  std::map<const ShapeDef*, int> hulls;
  std::map<std::pair<double, double>, int> capsules;

  int add(RenderMesh m) {
    meshes.push_back(std::move(m));
    return int(meshes.size()) - 1;
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
      case ShapeKind::Capsule: {
        scale = Eigen::Vector3f::Ones();
        const std::pair<double, double> key{s.radius, s.length};
        auto it = capsules.find(key);
        if (it != capsules.end()) return it->second;
        return capsules[key] = add(capsuleMesh(s.radius, s.length));
      }
      case ShapeKind::Hull:
      case ShapeKind::TriMesh:
      case ShapeKind::Heightfield: {
        scale = Eigen::Vector3f::Ones();
        auto it = hulls.find(&s);
        if (it != hulls.end()) return it->second;
        // Obstacles made from one file at one scale share a mesh.
        if (!s.source.empty() && s.kind != ShapeKind::Heightfield)
          for (const auto& [other, index] : hulls)
            if (other->source == s.source && other->kind == s.kind && other->points == s.points &&
                other->triangles == s.triangles)
              return hulls[&s] = index;
        RenderMesh m;
        if (s.kind == ShapeKind::Heightfield) {
          m = heightfieldMesh(*s.grid);
        } else {
          for (const Vec3& p : s.points) m.vertices.push_back(f3(p));
          m.indices = s.triangles;
        }
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

/// Radius of a sphere about the owner's frame origin that holds the shape.
double shapeRadius(const ShapeDef& s) {
  double r = 0;
  switch (s.kind) {
    case ShapeKind::Box:
      r = s.size.norm() / 2;
      break;
    case ShapeKind::Cylinder:
      r = std::hypot(s.radius, s.length / 2);
      break;
    case ShapeKind::Sphere:
      r = s.radius;
      break;
    case ShapeKind::Capsule:
      r = s.radius + s.length / 2;
      break;
    case ShapeKind::Hull:
    case ShapeKind::TriMesh:
      for (const Vec3& p : s.points) r = std::max(r, p.norm());
      break;
    case ShapeKind::Heightfield:
      r = std::hypot(s.grid->sx / 2, s.grid->sy / 2, s.grid->maxHeight);
      break;
  }
  return r + s.pose.pos.norm();
}

constexpr std::array<float, 4> kTerrainColor{0.52f, 0.47f, 0.36f, 1};
constexpr std::array<float, 4> kFluidColor{0.2f, 0.45f, 0.9f, 1.0f};
constexpr std::array<float, 4> kDebrisColor{0.76f, 0.62f, 0.38f, 1.0f};
constexpr double kSceneryRadius = 5.0;  // bodies larger than 10 m across are scenery, not framed

}  // namespace

void completeLayout(SceneLayout& lay) {
  lay.dockReach.assign(lay.items.size(), Eigen::Vector2f::Zero());
  // The link items of each module link, then each dock's reach over them.
  std::map<std::pair<int, int>, std::vector<size_t>> linkItems;
  for (size_t i = 0; i < lay.items.size(); ++i)
    if (lay.items[i].kind == SceneLayout::Kind::Link)
      linkItems[{lay.items[i].owner, lay.items[i].link}].push_back(i);
  for (size_t i = 0; i < lay.items.size(); ++i) {
    const SceneLayout::Item& dock = lay.items[i];
    if (dock.kind != SceneLayout::Kind::Dock) continue;
    const Pose toDock = dock.local.inverse();
    Eigen::Vector2f reach(0.5f * dock.scale.y(), 0.5f * dock.scale.z());
    const auto found = linkItems.find({dock.owner, dock.link});
    if (found != linkItems.end())
      for (size_t k : found->second) {
        const SceneLayout::Item& it = lay.items[k];
        if (it.mesh < 0 || it.mesh >= int(lay.meshes.size())) continue;
        const Pose itemInDock = toDock * it.local;
        for (const Eigen::Vector3f& v : lay.meshes[size_t(it.mesh)].vertices) {
          const Vec3 p = itemInDock * v.cwiseProduct(it.scale).cast<double>();
          reach = reach.cwiseMax(Eigen::Vector2f(float(std::abs(p.y())), float(std::abs(p.z()))));
        }
      }
    lay.dockReach[i] = reach;
  }
}

std::array<Eigen::Matrix4f, 2> dockMarkTransforms(const SceneLayout& lay, size_t item, const Pose& linkPose) {
  const SceneLayout::Item& it = lay.items[item];
  const Eigen::Vector2f reach = item < lay.dockReach.size() ? lay.dockReach[item] : Eigen::Vector2f::Zero();
  const Pose at = linkPose * it.local * Pose{Vec3(kDockMark.shift, 0, 0), Quat::Identity()};
  const float thick = kDockMark.thickness * it.scale.y();
  return {toMatrix(at, Eigen::Vector3f(kDockMark.depth, 2 * (reach.x() + kDockMark.overhang), thick)),
          toMatrix(at, Eigen::Vector3f(kDockMark.depth, thick, 2 * (reach.y() + kDockMark.overhang)))};
}

SceneLayout sceneLayout(const World& w) {
  SceneLayout lay;
  MeshTable table{lay.meshes, -1, -1, -1, {}, {}};
  for (size_t i = 0; i < w.modules().size(); ++i) {
    const Module& m = w.modules()[i];
    SceneLayout::ModuleInfo info;
    info.name = m.name;
    info.type = m.type->name;
    info.id = m.id;
    info.rootLink = m.type->rootLink;
    info.firstLink = lay.linkCount;
    info.firstJoint = lay.jointCount;
    info.firstDock = lay.dockCount;
    info.links = int(m.type->links.size());
    for (const JointDef& j : m.type->joints) info.joints.push_back(j.name);
    for (const DockDef& d : m.type->docks) info.docks.push_back(d.name);
    lay.linkCount += info.links;
    lay.jointCount += int(info.joints.size());
    lay.dockCount += int(info.docks.size());
    lay.modules.push_back(std::move(info));
    for (size_t l = 0; l < m.type->links.size(); ++l) {
      const LinkDef& link = m.type->links[l];
      for (const ShapeDef& s : link.shapes) {
        SceneLayout::Item item;
        item.kind = SceneLayout::Kind::Link;
        item.owner = int(i);
        item.link = int(l);
        item.mesh = table.meshFor(s, item.scale);
        item.local = s.pose;
        item.color = link.color;
        lay.items.push_back(item);
      }
    }
    // Dock faces, just inside the face (so an engaged pair does not flicker).
    for (size_t d = 0; d < m.type->docks.size(); ++d) {
      const DockDef& dock = m.type->docks[d];
      SceneLayout::Item item;
      item.kind = SceneLayout::Kind::Dock;
      item.owner = int(i);
      item.link = dock.link;
      item.dock = int(d);
      Eigen::Vector3f unused;
      item.mesh = table.meshFor(ShapeDef{}, unused);
      Pose shift;
      shift.pos = Vec3(-0.0005, 0, 0);
      item.local = dock.frame * shift;
      item.scale = Eigen::Vector3f(0.002f, float(dock.size), float(dock.size));
      lay.items.push_back(item);
    }
    for (const SensorDef& sd : m.type->sensors)
      if (sd.kind == SensorKind::Range)
        lay.ranges.push_back({int(i), sd.link, sd.pos, sd.dir, sd.minRange, sd.maxRange});
  }
  for (size_t b = 0; b < w.obstacles().size(); ++b) {
    const World::Obstacle& o = w.obstacles()[b];
    SceneLayout::Item item;
    item.kind = SceneLayout::Kind::Body;
    item.owner = int(b);
    item.mesh = table.meshFor(o.shape, item.scale);
    item.local = o.shape.pose;
    item.color = o.mass > 0 ? std::array<float, 4>{0.35f, 0.55f, 0.85f, 1}
                            : std::array<float, 4>{0.6f, 0.6f, 0.62f, 1};
    if (o.shape.kind == ShapeKind::Heightfield) {
      // The mesh starts at the grid's first sample; the shape frame sits at its centre.
      item.local =
          o.shape.pose * Pose{Vec3(-o.shape.grid->sx / 2, -o.shape.grid->sy / 2, 0), Quat::Identity()};
      item.color = kTerrainColor;
    }
    lay.items.push_back(item);
    lay.bodyRadius.push_back(shapeRadius(o.shape));
  }
  for (const World::Cloth& c : w.cloths())
    lay.cloths.push_back({c.nx * c.ny, clothTriangles(c.nx, c.ny), c.color});
  for (const auto& ps : w.particleSystems())
    lay.particles.push_back(
        {ps->count(), ps->radius(), ps->def().kind == ParticleDef::Kind::Fluid ? kFluidColor : kDebrisColor});
  lay.ground = w.hasGround();
  lay.dt = w.settings().dt;
  const World::CameraDef& c = w.camera();
  lay.camera = {c.eye, c.target, c.follow, c.fovDeg};
  completeLayout(lay);
  return lay;
}

void captureState(const World& w, const SceneLayout& lay, SceneState& out) {
  out.time = w.time();
  out.steps = w.steps();
  out.faults = w.faultCount();
  out.links.resize(size_t(lay.linkCount));
  out.joints.resize(size_t(lay.jointCount));
  out.docks.resize(size_t(lay.dockCount));
  out.faulted.resize(lay.modules.size());
  for (size_t i = 0; i < lay.modules.size(); ++i) {
    const SceneLayout::ModuleInfo& info = lay.modules[i];
    const Module& m = w.modules()[i];
    for (int l = 0; l < info.links; ++l) out.links[size_t(info.firstLink + l)] = w.linkPose(int(i), l);
    for (size_t j = 0; j < info.joints.size(); ++j)
      out.joints[size_t(info.firstJoint) + j] = w.jointAngle(int(i), int(j));
    for (size_t d = 0; d < info.docks.size(); ++d)
      out.docks[size_t(info.firstDock) + d] =
          uint8_t((m.docks[d].enabled ? 1 : 0) | (m.docks[d].engaged ? 2 : 0));
    out.faulted[i] = m.fault.empty() ? 0 : 1;
  }
  out.rangeHits.resize(lay.ranges.size());
  for (size_t r = 0; r < lay.ranges.size(); ++r) {
    const SceneLayout::Range& s = lay.ranges[r];
    const Pose lp = w.linkPose(s.module, s.link);
    const Vec3 dir = lp.rot * s.dir, from = lp * s.pos;
    out.rangeHits[r] =
        w.physicsConst().rayCast(from + dir * s.minRange, dir, s.maxRange - s.minRange, s.module);
  }
  size_t nodes = 0;
  for (const SceneLayout::Cloth& c : lay.cloths) nodes += size_t(c.nodes);
  out.clothNodes.resize(nodes);
  size_t at = 0;
  for (size_t c = 0; c < lay.cloths.size(); ++c)
    for (int i = 0; i < lay.cloths[c].nodes; ++i)
      out.clothNodes[at++] = f3(w.physicsConst().clothNode(int(c), i));
  // Particles: the centres, and a box around each system for the automatic camera. A system
  // made after the layout was taken is not drawn.
  size_t centres = 0;
  for (const SceneLayout::Particles& p : lay.particles) centres += size_t(p.count);
  out.particles.resize(centres);
  out.particleBounds.resize(lay.particles.size());
  at = 0;
  for (size_t k = 0; k < lay.particles.size() && k < w.particleSystems().size(); ++k) {
    const ParticleSystem& ps = *w.particleSystems()[k];
    Eigen::AlignedBox3d box;
    for (int i = 0; i < lay.particles[k].count && i < ps.count(); ++i) {
      out.particles[at + size_t(i)] =
          Eigen::Vector3f(ps.x()[size_t(i)], ps.y()[size_t(i)], ps.z()[size_t(i)]);
      if (out.particles[at + size_t(i)].allFinite()) box.extend(out.particles[at + size_t(i)].cast<double>());
    }
    if (!box.isEmpty())
      box = Eigen::AlignedBox3d(box.min().array() - ps.radius(), box.max().array() + ps.radius());
    out.particleBounds[k] = box;
    at += size_t(lay.particles[k].count);
  }
  out.bodies.resize(w.obstacles().size());
  for (size_t b = 0; b < w.obstacles().size(); ++b) out.bodies[b] = w.obstaclePose(w.obstacles()[b].part);
}

Snapshot buildSnapshot(const SceneLayout& lay, const SceneState& st) {
  Snapshot snap;
  snap.meshes = lay.meshes;
  snap.items.reserve(lay.items.size());
  std::vector<RenderItem> bars;  // engaged docks' bars, after the layout's items
  for (const SceneLayout::Item& it : lay.items) {
    RenderItem item;
    item.mesh = it.mesh;
    item.color = it.color;
    Pose frame;
    if (it.kind == SceneLayout::Kind::Body) {
      frame = st.bodies[size_t(it.owner)];
    } else {
      const SceneLayout::ModuleInfo& info = lay.modules[size_t(it.owner)];
      item.tag = it.owner;
      if (it.kind == SceneLayout::Kind::Link) {
        if (st.faulted[size_t(it.owner)]) item.color = kFaultColor;
      } else {
        const uint8_t flags = st.docks[size_t(info.firstDock + it.dock)];
        item.color = !(flags & 1) ? kDockDisabledColor : (flags & 2) ? kDockEngagedColor : kDockFreeColor;
        if ((flags & 3) == 3)
          for (const Eigen::Matrix4f& m : dockMarkTransforms(lay, size_t(&it - lay.items.data()),
                                                             st.links[size_t(info.firstLink + it.link)])) {
            RenderItem bar = item;
            bar.transform = m;
            bars.push_back(bar);
          }
      }
      frame = st.links[size_t(info.firstLink + it.link)];
    }
    item.transform = toMatrix(frame * it.local, it.scale);
    snap.items.push_back(item);
  }
  snap.items.insert(snap.items.end(), bars.begin(), bars.end());
  // Cloth: a mesh per cloth with this frame's node positions (the renderer uploads meshes every
  // frame and shades both sides). A recording without cloth nodes draws none.
  size_t first = 0;
  for (const SceneLayout::Cloth& c : lay.cloths) {
    if (first + size_t(c.nodes) > st.clothNodes.size()) break;
    RenderMesh mesh;
    mesh.vertices.assign(st.clothNodes.begin() + long(first),
                         st.clothNodes.begin() + long(first + size_t(c.nodes)));
    mesh.indices = c.triangles;
    first += size_t(c.nodes);
    RenderItem item;
    item.mesh = int(snap.meshes.size());
    item.color = c.color;
    snap.meshes.push_back(std::move(mesh));
    snap.items.push_back(item);
  }
  // Particle systems: a set of spheres each (a recording without their centres draws none).
  first = 0;
  for (const SceneLayout::Particles& p : lay.particles) {
    if (first + size_t(p.count) > st.particles.size()) break;
    RenderSpheres s;
    s.radius = p.radius;
    s.color = p.color;
    s.centers.assign(st.particles.begin() + long(first),
                     st.particles.begin() + long(first + size_t(p.count)));
    first += size_t(p.count);
    snap.spheres.push_back(std::move(s));
  }
  // Range sensors as lines: to the hit (red) or over their whole range (yellow).
  for (size_t r = 0; r < lay.ranges.size(); ++r) {
    const SceneLayout::Range& s = lay.ranges[r];
    const Pose& lp = st.links[size_t(lay.modules[size_t(s.module)].firstLink + s.link)];
    const Vec3 dir = lp.rot * s.dir, from = lp * s.pos;
    const double hit = st.rangeHits[r];
    RenderLine line;
    line.a = f3(from);
    line.b = f3(from + dir * (hit >= 0 ? hit + s.minRange : s.maxRange));
    line.color =
        hit >= 0 ? std::array<float, 4>{0.95f, 0.2f, 0.15f, 1} : std::array<float, 4>{0.95f, 0.85f, 0.1f, 1};
    snap.lines.push_back(line);
  }
  snap.ground = lay.ground;
  char line[160];
  std::snprintf(line, sizeof line, "t = %.2f s   step %lld   %zu modules   %d faults", st.time,
                (long long)st.steps, lay.modules.size(), st.faults);
  snap.overlay.push_back(line);
  return snap;
}

void addModuleLabels(const SceneLayout& lay, const SceneState& st, Snapshot& snap) {
  for (const SceneLayout::ModuleInfo& m : lay.modules) {
    const size_t root = size_t(m.firstLink + m.rootLink);
    if (root >= st.links.size()) continue;
    snap.labels.push_back({f3(st.links[root].pos) + Eigen::Vector3f(0, 0, 0.07f), m.name});
  }
}

Camera sceneCamera(const SceneLayout& lay, const SceneState& start, const SceneState& now) {
  Camera cam;
  const SceneLayout::CameraDef& def = lay.camera;
  auto root = [&](const SceneState& s, size_t i) -> const Vec3& {
    return s.links[size_t(lay.modules[i].firstLink + lay.modules[i].rootLink)].pos;
  };
  Vec3 lo(-0.5, -0.5, 0), hi(0.5, 0.5, 0.2);
  bool any = false;
  auto extend = [&](const Vec3& a, const Vec3& b) {
    lo = any ? lo.cwiseMin(a) : a;
    hi = any ? hi.cwiseMax(b) : b;
    any = true;
  };
  // The scene at the start: modules, bodies (not scenery) and particles, then the modules now.
  for (size_t i = 0; i < lay.modules.size(); ++i) extend(root(start, i), root(start, i));
  for (size_t b = 0; b < start.bodies.size() && b < lay.bodyRadius.size(); ++b) {
    const double r = lay.bodyRadius[b];
    if (r > kSceneryRadius) continue;
    extend(start.bodies[b].pos - Vec3::Constant(r), start.bodies[b].pos + Vec3::Constant(r));
  }
  for (const Eigen::AlignedBox3d& box : start.particleBounds)
    if (!box.isEmpty()) extend(box.min(), box.max());
  for (size_t i = 0; i < lay.modules.size(); ++i) extend(root(now, i), root(now, i));
  Vec3 target = (lo + hi) / 2;
  const bool follow = def.follow >= 0 && def.follow < int(lay.modules.size());
  if (follow) target = root(now, size_t(def.follow));
  if (def.target) target = *def.target;
  const double extent = std::max(0.6, (hi - lo).norm() + 0.3);
  Vec3 eye = target + Vec3(0.55, -1.0, 0.6).normalized() * extent * 0.9;
  if (def.eye) eye = follow && !def.target ? target + *def.eye : *def.eye;
  cam.eye = f3(eye);
  cam.target = f3(target);
  cam.fovyDeg = float(def.fovDeg);
  return cam;
}

}  // namespace rm3d
