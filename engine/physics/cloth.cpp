// Cloth as Bullet soft bodies: the grid built node by node (no random perturbation, no global
// state), stretch, shear and bending springs, position iterations, and the signed-distance
// collision set up fine enough for module-sized bodies.
#include <BulletCollision/CollisionShapes/btBoxShape.h>

#include <algorithm>
#include <cmath>

#include "physics/cloth_system.h"

namespace rm3d {

namespace {

/// Signed-distance grid spacing (m). Bullet's 0.25 m rounds a 5 cm module link into a blob; at
/// 2 cm flat faces are exact and edges round off by about a centimetre (1 cm: no better in the
/// tests, twice the cost of building the grid as a sheet falls).
constexpr btScalar kVoxel = 0.02f;
constexpr int kSdfHash = 65521;      // buckets of the grid's cell table
constexpr int kSdfMaxCells = 65536;  // past this the grid starts afresh (about 20 MB)
constexpr int kSdfSweepEvery = 32;   // steps between sweeps of unused cells
constexpr int kSdfLifetime = 8;      // sweeps a cell survives unused
/// Half size of the box standing in for the ground plane (cloth farther out falls off it).
constexpr btScalar kGroundHalf = 200.0f;
constexpr btScalar kGroundDepth = 1.0f;
// The substep the sheets were tuned at (dt 1/60, 4 substeps): 10 position iterations, so that
// stretch and contacts settle within a substep, and 1% of the velocity damped per substep. A
// longer substep takes proportionally more iterations and the same damping per second: at one
// substep of 1/60 s a sheet with the reference's 10 iterations hung 10% stretched and never came
// to rest.
constexpr double kReferenceSubstep = 1.0 / 240.0;
constexpr int kReferenceIterations = 10;
constexpr double kReferenceDamping = 0.01;

void configure(btSoftBody::Config& cfg, double h) {
  const double ratio = h / kReferenceSubstep;
  cfg.piterations = std::max(1, int(std::ceil(kReferenceIterations * ratio - 1e-9)));
  cfg.kDP = btScalar(1.0 - std::pow(1.0 - kReferenceDamping, ratio));
}

btVector3 toBt(const Vec3& v) {
  return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z()));
}

}  // namespace

std::vector<uint32_t> clothTriangles(int nx, int ny) {
  std::vector<uint32_t> t;
  if (nx < 2 || ny < 2) return t;
  t.reserve(size_t(nx - 1) * size_t(ny - 1) * 6);
  auto idx = [nx](int x, int y) { return uint32_t(y * nx + x); };
  for (int y = 0; y + 1 < ny; ++y)
    for (int x = 0; x + 1 < nx; ++x) {
      if ((x + y) & 1)
        t.insert(t.end(),
                 {idx(x, y), idx(x + 1, y), idx(x + 1, y + 1), idx(x, y), idx(x + 1, y + 1), idx(x, y + 1)});
      else
        t.insert(t.end(),
                 {idx(x, y + 1), idx(x, y), idx(x + 1, y), idx(x, y + 1), idx(x + 1, y), idx(x + 1, y + 1)});
    }
  return t;
}

ClothSystem::ClothSystem(btSoftRigidDynamicsWorld& world, const btVector3& gravity) : m_world(world) {
  btSoftBodyWorldInfo& info = world.getWorldInfo();
  info.m_sparsesdf.Initialize(kSdfHash, kSdfMaxCells);
  info.m_sparsesdf.setDefaultVoxelsz(kVoxel);
  info.m_sparsesdf.Reset();
  info.air_density = 0;  // no aerodynamic forces (the default model adds none at zero drag anyway)
  setGravity(gravity);
}

ClothSystem::~ClothSystem() {
  for (Cloth& c : m_cloths) {
    m_world.removeSoftBody(c.body);
    delete c.body;
  }
  if (m_ground) m_world.removeCollisionObject(m_ground.get());
}

void ClothSystem::setGravity(const btVector3& g) {
  m_world.getWorldInfo().m_gravity = g;
}

void ClothSystem::setGround(double friction) {
  if (m_ground) return;
  m_groundShape = std::make_unique<btBoxShape>(btVector3(kGroundHalf, kGroundHalf, kGroundDepth));
  m_ground = std::make_unique<btCollisionObject>();
  m_ground->setCollisionShape(m_groundShape.get());
  btTransform t;
  t.setIdentity();
  t.setOrigin(btVector3(0, 0, -kGroundDepth));
  m_ground->setWorldTransform(t);
  m_ground->setFriction(btScalar(friction));
  m_ground->setCollisionFlags(btCollisionObject::CF_STATIC_OBJECT);
  m_ground->setUserIndex(-1);
  // Its own group, seen only by cloth: rigid bodies and rays keep meeting the real plane.
  const int group = 1 << 6;
  m_world.addCollisionObject(m_ground.get(), group, kClothFilterGroup);
}

int ClothSystem::add(const ClothDesc& d) {
  const int nx = d.nx, ny = d.ny, n = nx * ny;
  std::vector<btVector3> x(static_cast<size_t>(n));
  std::vector<btScalar> m(size_t(n), 1);
  const Vec3 &c1 = d.corners[0], &c2 = d.corners[1], &c3 = d.corners[2], &c4 = d.corners[3];
  for (int iy = 0; iy < ny; ++iy) {
    const double ty = double(iy) / (ny - 1);
    const Vec3 left = c1 + (c4 - c1) * ty, right = c2 + (c3 - c2) * ty;
    for (int ix = 0; ix < nx; ++ix)
      x[size_t(iy * nx + ix)] = toBt(left + (right - left) * (double(ix) / (nx - 1)));
  }
  auto* sb = new btSoftBody(&m_world.getWorldInfo(), n, x.data(), m.data());
  btSoftBody::Material* stretch = sb->m_materials[0];
  stretch->m_kLST = btScalar(d.stiffness);
  stretch->m_kAST = btScalar(d.stiffness);
  btSoftBody::Material* bend = sb->appendMaterial();
  bend->m_kLST = btScalar(0.2 * d.stiffness);  // a sheet folds far more easily than it stretches
  bend->m_kAST = bend->m_kLST;
  auto idx = [nx](int ix, int iy) { return iy * nx + ix; };
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix) {
      if (ix + 1 < nx) sb->appendLink(idx(ix, iy), idx(ix + 1, iy), stretch);
      if (iy + 1 < ny) sb->appendLink(idx(ix, iy), idx(ix, iy + 1), stretch);
      if (ix + 1 < nx && iy + 1 < ny) {  // shear: the diagonal the cell's triangles share
        if ((ix + iy) & 1)
          sb->appendLink(idx(ix, iy), idx(ix + 1, iy + 1), stretch);
        else
          sb->appendLink(idx(ix + 1, iy), idx(ix, iy + 1), stretch);
      }
      if (ix + 2 < nx) sb->appendLink(idx(ix, iy), idx(ix + 2, iy), bend);
      if (iy + 2 < ny) sb->appendLink(idx(ix, iy), idx(ix, iy + 2), bend);
    }
  const std::vector<uint32_t> tris = clothTriangles(nx, ny);
  for (size_t i = 0; i + 2 < tris.size(); i += 3)
    sb->appendFace(int(tris[i]), int(tris[i + 1]), int(tris[i + 2]));

  btSoftBody::Config& cfg = sb->m_cfg;
  configure(cfg, m_substep > 0 ? m_substep : kReferenceSubstep);
  cfg.kDF = btScalar(d.friction);
  cfg.kCHR = 1;  // contacts with dynamic bodies: resolve the whole penetration
  cfg.kKHR = 1;  // and with static ones (Bullet's 0.1 lets a heavy sheet sink into the ground)
  cfg.collisions = btSoftBody::fCollision::SDF_RS;
  sb->getCollisionShape()->setMargin(btScalar(d.thickness));
  sb->setTotalMass(btScalar(d.mass), true);
  Cloth cloth;
  cloth.body = sb;
  cloth.mass.resize(size_t(n));
  for (int i = 0; i < n; ++i) cloth.mass[size_t(i)] = sb->getMass(i);
  for (int p : d.pinned) sb->setMass(p, 0);
  sb->setUserIndex(-1);
  m_world.addSoftBody(sb, kClothFilterGroup, btBroadphaseProxy::AllFilter);
  m_cloths.push_back(std::move(cloth));
  return int(m_cloths.size()) - 1;
}

void ClothSystem::setSubstep(double h) {
  if (h == m_substep) return;
  m_substep = h;
  for (Cloth& c : m_cloths) configure(c.body->m_cfg, h);
}

void ClothSystem::afterStep() {
  // A sweep visits every bucket: every 32nd step, dropping cells unused for 8 sweeps (256 steps).
  if (++m_steps % kSdfSweepEvery == 0) m_world.getWorldInfo().m_sparsesdf.GarbageCollect(kSdfLifetime);
}

void ClothSystem::setPinned(int c, int node, bool pin) {
  Cloth& cloth = m_cloths[size_t(c)];
  btSoftBody::Node& nd = cloth.body->m_nodes[node];
  cloth.body->setMass(node, pin ? 0 : cloth.mass[size_t(node)]);
  if (pin) nd.m_v.setZero();
  nd.m_q = nd.m_x;
}

bool ClothSystem::pinned(int c, int node) const {
  return m_cloths[size_t(c)].body->m_nodes[node].m_im == 0;
}

}  // namespace rm3d
