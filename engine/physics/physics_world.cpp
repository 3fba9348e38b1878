// Bullet behind the PhysicsWorld interface: parts merged into compound rigid bodies, hinges
// with servo and velocity motors, and an overlap filter that keeps a module from colliding
// with itself.
#include "physics/physics_world.h"

#include <BulletCollision/CollisionDispatch/btInternalEdgeUtility.h>
#include <BulletCollision/CollisionShapes/btHeightfieldTerrainShape.h>
#include <BulletCollision/CollisionShapes/btTriangleInfoMap.h>
#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <LinearMath/btGeometryUtil.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>

#include "physics/bullet_layout.h"
#include "physics/cloth_system.h"
#include "physics/exact_solver.h"
#include "physics/pair_cache.h"
#include "physics/plane_contacts.h"
#include "physics/slot_pool.h"
#include "physics/solver_world.h"
#include "physics/task_dispatcher.h"

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

namespace rm3d {

namespace {

/// Fetches the cache lines of the bytes from `from` up to `to` (two places in one object).
void fetchSpan(const void* from, const void* to) {
  const char* a = static_cast<const char*>(from);
  const int bytes = int(static_cast<const char*>(to) - a);
  if (bytes > 0) bullet_layout::fetchRange(a, 0, bytes);
}

btVector3 toBt(const Vec3& v) {
  return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z()));
}
Vec3 fromBt(const btVector3& v) {
  return Vec3(v.x(), v.y(), v.z());
}
btTransform toBt(const Pose& p) {
  const Quat& q = p.rot;
  return btTransform(btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
                     toBt(p.pos));
}
Pose fromBt(const btTransform& t) {
  const btQuaternion q = t.getRotation();
  return {fromBt(t.getOrigin()), Quat(q.w(), q.x(), q.y(), q.z()).normalized()};
}

constexpr btScalar kHullMargin = 0.001f;  // Bullet's 0.04 m default would lift small links off the ground
// Below these an obstacle counts as still (Bullet's defaults, 0.8 m/s and 1 rad/s, would put a
// slowly rolling ball to sleep).
constexpr double kSleepSpeed = 0.01;         // m/s
constexpr double kSleepAngularSpeed = 0.05;  // rad/s

/// What a Bullet shape reads in place and must outlive it: a triangle mesh's arrays, a
/// heightfield's grid.
struct ShapeData {
  std::unique_ptr<btTriangleMesh> mesh;
  std::shared_ptr<const HeightGrid> grid;
  std::unique_ptr<btTriangleInfoMap> edges;  // which triangle edges are internal (see below)
};

/// Contacts with a triangle mesh or heightfield near an edge shared with a coplanar (or
/// convex-joined) neighbour get the face's normal, not one tilted towards the edge: otherwise a
/// ball resting on flat terrain near a cell edge is kicked sideways and rolls off (Bullet's
/// "internal edge" problem). Bullet calls this for bodies flagged CF_CUSTOM_MATERIAL_CALLBACK;
/// the mesh is always the manifold's second body.
bool adjustInternalEdges(btManifoldPoint& cp, const btCollisionObjectWrapper* wrap0, int, int,
                         const btCollisionObjectWrapper* wrap1, int partId1, int index1) {
  if (wrap1->getCollisionShape()->getShapeType() == TRIANGLE_SHAPE_PROXYTYPE)
    btAdjustInternalEdgeContacts(cp, wrap1, wrap0, partId1, index1);
  return true;
}

btCollisionShape* makeShape(const ShapeDef& s, ShapeData& data) {
  switch (s.kind) {
    case ShapeKind::Box:
      return new btBoxShape(toBt(s.size / 2));
    case ShapeKind::Sphere:
      return new btSphereShape(btScalar(s.radius));
    case ShapeKind::Cylinder:
      return new btCylinderShapeZ(btVector3(btScalar(s.radius), btScalar(s.radius), btScalar(s.length / 2)));
    case ShapeKind::Capsule:
      return new btCapsuleShapeZ(btScalar(s.radius), btScalar(s.length));
    case ShapeKind::Hull: {
      auto* h = new btConvexHullShape();
      for (const Vec3& p : s.points) h->addPoint(toBt(p), false);
      // The margin first: the cached bounding box takes the margin it is computed with, and
      // Bullet's default 4 cm made every hull's box 8 cm too wide (1500 ATRONs 0.16 m apart then
      // ran GJK between neighbours every step, at half the speed).
      h->setMargin(kHullMargin);
      h->recalcLocalAabb();
      return h;
    }
    case ShapeKind::TriMesh: {
      data.mesh = std::make_unique<btTriangleMesh>();
      for (size_t t = 0; t + 2 < s.triangles.size(); t += 3)
        data.mesh->addTriangle(toBt(s.points[s.triangles[t]]), toBt(s.points[s.triangles[t + 1]]),
                               toBt(s.points[s.triangles[t + 2]]), false);
      auto* shape = new btBvhTriangleMeshShape(data.mesh.get(), true);
      data.edges = std::make_unique<btTriangleInfoMap>();
      btGenerateInternalEdgeInfo(shape, data.edges.get());
      return shape;
    }
    case ShapeKind::Heightfield: {
      // Bullet centres the shape between the given minimum and maximum height, and its samples
      // one unit apart; addPart lifts the shape by half the range and the scaling sets the cells.
      data.grid = s.grid;
      const HeightGrid& g = *s.grid;
      auto* h = new btHeightfieldTerrainShape(g.nx, g.ny, g.heights.data(), btScalar(0),
                                              btScalar(g.maxHeight), 2, false);
      h->setLocalScaling(btVector3(btScalar(g.cellX()), btScalar(g.cellY()), 1));
      h->setFlipTriangleWinding(true);  // z up: Bullet's default winding faces its triangles down
      data.edges = std::make_unique<btTriangleInfoMap>();
      btGenerateInternalEdgeInfo(h, data.edges.get());
      return h;
    }
  }
  return nullptr;
}

/// What makeShape reads of a convex definition, as bytes: equal keys make equal shapes.
std::string shapeKey(const ShapeDef& s) {
  std::string k;
  auto put = [&k](const void* p, size_t n) { k.append(static_cast<const char*>(p), n); };
  put(&s.kind, sizeof s.kind);
  put(s.size.data(), 3 * sizeof(double));
  put(&s.radius, sizeof s.radius);
  put(&s.length, sizeof s.length);
  for (const Vec3& p : s.points) put(p.data(), 3 * sizeof(double));
  return k;
}

/// Where Bullet's shape sits in the ShapeDef's frame (see makeShape).
Pose bulletShapeOffset(const ShapeDef& s) {
  Pose p;
  if (s.kind == ShapeKind::Heightfield) p.pos.z() = s.grid->maxHeight / 2;
  return p;
}

/// Sets flush-to-zero and denormals-are-zero for its lifetime (x86 SSE control register).
class FlushDenormals {
 public:
#if defined(__SSE__)
  FlushDenormals() : m_saved(_mm_getcsr()) {
    _mm_setcsr(m_saved | 0x8040u);
  }
  ~FlushDenormals() {
    _mm_setcsr(m_saved);
  }

 private:
  unsigned m_saved;
#endif
};

bool isIdentity(const Pose& p) {
  return p.pos.norm() < 1e-9 && std::abs(std::abs(p.rot.w()) - 1.0) < 1e-12;
}

}  // namespace

struct PhysicsWorld::Impl {
  struct Part {
    int body = -1;
    Pose inBody;
    double mass = 0;
    Vec3 com = Vec3::Zero();                            // part frame
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about com, part frame
    std::vector<btCollisionShape*> shapes;              // owned
    std::vector<ShapeData> shapeData;                   // what the shapes read in place
    std::vector<Pose> shapePoses;                       // in part frame
    double friction = 0.8, restitution = 0, rollingFriction = 0;
    int owner = -1;
    std::vector<int> hinges;
    std::vector<int> locks;  // parts locked to this one
  };
  struct SharedCompound {
    std::unique_ptr<btCompoundShape> shape;
    int users = 0;
  };
  struct Body {
    btRigidBody* rb = nullptr;
    // Its compound when it has several shapes: its entry in `compounds` (shared by its kind).
    std::pair<const std::string, SharedCompound>* compoundEntry = nullptr;
    std::vector<int> parts;
    std::vector<int> owners;     // sorted module indices
    std::vector<int> childPart;  // compound child index -> part
  };
  struct Hinge {
    HingeDesc d;
    btHingeConstraint* c = nullptr;   // Bullet's hinge (pgs)
    std::unique_ptr<ExactLink> link;  // exact: the hinge is solved by ExactSolver
    Vec3 axisA = Vec3::UnitZ();       // in part A frame
    MotorMode mode = MotorMode::Off;
    double value = 0;
    double angle = 0;  // unwrapped
    double rawLast = 0;
    double torque = 0;                          // N m over the last step
    bool saturated = false;                     // at its rating over the last step
    std::unique_ptr<btJointFeedback> feedback;  // reactions, when load tracking is on
  };
  struct Force {
    int part;
    Vec3 force, point, torque;
  };

  /// Pairs whose bodies share a module never collide (a module's own links, docked neighbours).
  /// A body's first two owners side by side with every other body's (-1: none; second kMoreOwners:
  /// a third too, read from Body::owners). The broadphase asks the filter below about every pair
  /// of boxes that meet when a box is reinserted, thousands a substep on a long chain, most of
  /// them a module's own links or its docked neighbours': with the owners in each body's own
  /// list, each question waited on two lines from memory.
  struct OwnerPair {
    static constexpr int kMoreOwners = -2;
    int first = -1, second = -1;
  };
  struct OwnerFilter : btOverlapFilterCallback {
    const std::vector<Body>* bodies = nullptr;
    const std::vector<OwnerPair>* pairs = nullptr;
    bool needBroadphaseCollision(btBroadphaseProxy* a, btBroadphaseProxy* b) const override {
      if (!(a->m_collisionFilterGroup & b->m_collisionFilterMask) ||
          !(b->m_collisionFilterGroup & a->m_collisionFilterMask))
        return false;
      const int ia = static_cast<btCollisionObject*>(a->m_clientObject)->getUserIndex();
      const int ib = static_cast<btCollisionObject*>(b->m_clientObject)->getUserIndex();
      if (ia < 0 || ib < 0) return true;
      const OwnerPair pa = (*pairs)[size_t(ia)], pb = (*pairs)[size_t(ib)];
      if (pa.second != OwnerPair::kMoreOwners && pb.second != OwnerPair::kMoreOwners) {
        const auto shares = [&](int o) { return o >= 0 && (o == pb.first || o == pb.second); };
        return !(shares(pa.first) || shares(pa.second));
      }
      const auto& oa = (*bodies)[ia].owners;
      const auto& ob = (*bodies)[ib].owners;
      auto i = oa.begin();
      auto j = ob.begin();
      while (i != oa.end() && j != ob.end()) {
        if (*i == *j) return false;
        if (*i < *j)
          ++i;
        else
          ++j;
      }
      return true;
    }
  };

  /// Bullet's defaults keep 4096 contact manifolds and 4096 pair algorithms in pools made with the
  /// world, 4.5 MB written through at once: 5 to 20 ms of page faults for every world made, most of
  /// the cost of a small world (a Batch of 64 held 288 MB of them). The dispatcher takes both from
  /// pools of its own that grow as pairs meet (physics/slot_pool.h); the configuration's pools are
  /// made with room for one of each (only the algorithms' slot size is read from it).
  static btDefaultCollisionConstructionInfo poolSizes() {
    btDefaultCollisionConstructionInfo ci;
    ci.m_defaultMaxPersistentManifoldPoolSize = 1;
    ci.m_defaultMaxCollisionAlgorithmPoolSize = 1;
    return ci;
  }

  PhysicsSettings settings;
  // A soft-rigid world always: with no cloth it costs nothing measurable (README, "Cloth").
  btSoftBodyRigidBodyCollisionConfiguration config{poolSizes()};
  PlaneContactFuncs planeContacts;     // registered with the dispatcher (outlives it)
  TaskDispatcher dispatcher{&config};  // the narrowphase, on the worker threads where there are any
  PairCache pairCache;                 // the broadphase's (outlives it and the world)
  btDbvtBroadphase broadphase{&pairCache};
  ExactSolver solver;
  std::vector<std::unique_ptr<ExactSolver>> helpers;  // batch solvers on worker threads (setParallel)
  PhysicsWorld::ForEach tasks;                        // runs one task per thread
  int stepSubsteps = 1;                               // substeps of the step being taken
  SolverWorld world{&dispatcher, &broadphase, &solver, &config};
  std::unique_ptr<ClothSystem> cloth;    // made by the first cloth
  std::optional<double> groundFriction;  // set by addGroundPlane: the ground is there (cloth, particles)
  OwnerFilter filter;
  std::vector<Part> parts;
  // The bodies' memory, side by side (declared before `bodies`: it outlives them). Bullet's
  // per-substep passes (integration, bounding boxes, islands, the hinge loops) touch every body
  // once; allocated one at a time among the world's other allocations, 40,000 bodies lay
  // scattered over hundreds of megabytes and every pass streamed them from memory.
  SlotPool bodyPool{sizeof(btRigidBody), 256};
  // The bodies' compounds, one for each set of children (shapes and poses, bit for bit) and shared
  // by every body with that set: a module type's parts make the same compound in every module, so
  // the contact and bounding-box passes read one copy of its children, not one per module
  // (declared before `bodies`, which hold them). Bullet reads a compound without a box tree and
  // never changes it; the key is the children's shape pointers and their poses' bits.
  std::unordered_map<std::string, SharedCompound> compounds;
  std::vector<Body> bodies;
  std::vector<OwnerPair> ownerPairs;  // by body (OwnerFilter)
  struct Capture {
    CaptureDesc d;
    std::unique_ptr<CaptureLink> link;
    bool live = false;
  };
  std::vector<Capture> captures;
  std::vector<int> freeCaptures;
  std::vector<Hinge> hinges;
  std::vector<btCollisionShape*> extraShapes;  // ground plane
  // Every part shape this world made (freed with it). A convex shape is made once per
  // definition and shared by every part that has it (a module type's links: one bracket hull
  // for 10,000 SuperBots, not 10,000 copies scattered over memory); none changes once made.
  std::vector<btCollisionShape*> partShapes;
  std::map<std::string, btCollisionShape*> convexShapes;  // by definition (shapeKey)
  std::vector<btRigidBody*> extraBodies;
  int liveBodies = 0;
  std::vector<Force> forces;
  // Load tracking (dock breakage): state at the start of the last substep, and the contact and
  // hinge forces on each part during it (torques about the world origin).
  bool tracking = false;
  double lastH = 0;
  std::vector<Vec3> partVelBefore, bodyOmegaBefore, partExtForce, partExtTorque;
  // Contact sensors: which parts touch something at the end of the last step, read from its
  // manifolds when a sensor first asks (touchingDue), not by every step: a behaviour that reads no
  // contact sensor costs no pass over the manifolds (1.4% of a step with 10,000 SuperBots). Anything
  // that takes a body's manifolds away or renumbers its parts reads them first (settleTouching).
  bool contactTracking = false;
  mutable std::atomic<bool> touchingDue{false};
  mutable std::mutex touchingMutex;
  mutable std::vector<char> partTouching;
  // The passes of a step over every hinge, body and part, on the worker threads where they pay
  // (SolverWorld::forEachIndex, the same bits either way).
  Pace motorPace, anglePace, omegaPace, partVelocityPace;
  mutable std::mutex rayMutex;  // Debian's Bullet shares one ray-test stack per broadphase
  // Particle colliders: each hull shape's planes (part, shape ->
  // first plane and count in hullPlanes), found once per part.
  std::vector<std::vector<std::pair<int, int>>> hullPlaneRanges;
  std::vector<float> hullPlanes;

  explicit Impl(const PhysicsSettings& s) : settings(s) {
    // Bullet's one process-wide hook, set once to the same stateless function for every world.
    static std::once_flag edgeHook;
    std::call_once(edgeHook, [] { gContactAddedCallback = adjustInternalEdges; });
    planeContacts.registerWith(dispatcher);
    world.setGravity(toBt(s.gravity));
    solver.patches = s.solver == SolverKind::Exact;
    solver.wholeFactors = s.wholeFactors;
    solver.freshTrees = s.freshTrees;
    solver.everyIteration = s.everyIteration;
    solver.denseIslands = s.denseIslands;
    solver.denseCoordinates = s.denseCoordinates;
    solver.avx = s.avx && __builtin_cpu_supports("avx");
    solver.alwaysThreads = s.alwaysThreads;
    world.getSolverInfo().m_numIterations = s.solverIterations;
    world.getSolverInfo().m_erp = btScalar(s.erp);
    // Two friction directions per contact point (Bullet adds only one by default): with one, a
    // resting SuperBot crept 2 cm in 10 s; with two, 5 mm.
    world.getSolverInfo().m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
    filter.bodies = &bodies;
    filter.pairs = &ownerPairs;
    world.getPairCache()->setOverlapFilterCallback(&filter);
    // Bounding boxes of static and sleeping bodies stay as they are (transformParts updates a
    // moved one itself): hundreds of resting obstacles then cost the broadphase nothing.
    world.setForceUpdateAllAabbs(false);
  }

  ~Impl() {
    cloth.reset();
    // Every overlapping pair (and its contact manifold) in one pass: removing a body otherwise
    // walks all of the world's pairs to find its own, which made tearing down 10,000 modules take
    // seconds.
    struct RemoveAll : btOverlapCallback {
      bool processOverlap(btBroadphasePair&) override { return true; }
    } all;
    world.getPairCache()->processAllOverlappingPairs(&all, &dispatcher);
    // Then the joints and bodies out of the world (the removals below then find nothing to do).
    world.removeAllJointsAndBodies();
    for (Capture& c : captures) removeCaptureLink(c);
    for (Hinge& h : hinges) removeHinge(h);
    for (Body& b : bodies) destroyBody(b);
    for (btRigidBody* rb : extraBodies) {
      world.removeRigidBody(rb);
      delete rb;
    }
    for (btCollisionShape* s : partShapes) delete s;
    for (btCollisionShape* s : extraShapes) delete s;
  }

  /// The Bullet shape for a part's shape: a shared one for a convex definition seen before.
  btCollisionShape* shapeFor(const ShapeDef& d, ShapeData& data) {
    if (staticOnly(d.kind)) {  // meshes and heightfields: each its own (they hold per-part data)
      partShapes.push_back(makeShape(d, data));
      return partShapes.back();
    }
    std::string key = shapeKey(d);
    auto it = convexShapes.find(key);
    if (it != convexShapes.end()) return it->second;
    partShapes.push_back(makeShape(d, data));
    convexShapes.emplace(std::move(key), partShapes.back());
    return partShapes.back();
  }

  void destroyBody(Body& b) {
    if (!b.rb) return;
    world.removeRigidBody(b.rb);
    b.rb->~btRigidBody();
    bodyPool.give(b.rb);
    if (b.compoundEntry && --b.compoundEntry->second.users == 0) compounds.erase(b.compoundEntry->first);
    b.compoundEntry = nullptr;
    b.rb = nullptr;
    b.parts.clear();
    b.owners.clear();
    --liveBodies;
  }

  /// The shared compound entry with the children of `made` (a new compound): made for it if it is
  /// the first with them, else the one there is (`made` deleted). One use more either way.
  std::pair<const std::string, SharedCompound>* shareCompound(btCompoundShape* made) {
    std::string key;
    for (int c = 0; c < made->getNumChildShapes(); ++c) {
      const btCollisionShape* child = made->getChildShape(c);
      const btTransform& t = made->getChildTransform(c);
      key.append(reinterpret_cast<const char*>(&child), sizeof child);
      for (int r = 0; r < 3; ++r)
        key.append(reinterpret_cast<const char*>(&t.getBasis()[r][0]), 3 * sizeof(btScalar));
      key.append(reinterpret_cast<const char*>(&t.getOrigin()[0]), 3 * sizeof(btScalar));
    }
    auto& entry = *compounds.try_emplace(key).first;  // (its address stays while it is there)
    if (entry.second.shape)
      delete made;
    else
      entry.second.shape.reset(made);
    ++entry.second.users;
    return &entry;
  }

  Pose bodyPose(int b) const { return fromBt(bodies[b].rb->getWorldTransform()); }
  Pose partPose(int p) const { return bodyPose(parts[p].body) * parts[p].inBody; }

  /// Builds one rigid body from parts placed at the given world poses. With `angIsVelocity`,
  /// `ang` is the angular velocity, else the angular momentum about the new centre of mass.
  int buildBody(const std::vector<int>& ids, const std::vector<Pose>& world_, const Vec3& linMomentum,
                const Vec3& ang, bool angIsVelocity = false) {
    double mass = 0;
    bool isStatic = false;
    Vec3 com = Vec3::Zero();
    for (size_t i = 0; i < ids.size(); ++i) {
      const Part& p = parts[ids[i]];
      if (p.mass <= 0) isStatic = true;
      mass += p.mass;
      com += p.mass * (world_[i] * p.com);
    }
    Pose frame = world_[0];
    // A static obstacle of one shape set off in its part (a heightfield, lifted by half its
    // range) takes the shape's frame as the body's, so it needs no compound.
    if (isStatic && ids.size() == 1 && parts[ids[0]].owner < 0 && parts[ids[0]].shapes.size() == 1)
      frame = world_[0] * parts[ids[0]].shapePoses[0];
    Eigen::Vector3d principal = Eigen::Vector3d::Zero();
    // A moving body of one part (each link of a module) has its frame made in the part's own: the
    // same frame in the part, inertia and compound, bit for bit, for every part of a definition
    // wherever it stands (made from its world pose, the rounding differed from place to place).
    const bool single = !isStatic && ids.size() == 1;
    Pose inPart;  // (single: the body's frame in the part's)
    if (single) {
      const Part& p = parts[ids[0]];
      Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
      const double off = std::abs(p.inertia(0, 1)) + std::abs(p.inertia(0, 2)) + std::abs(p.inertia(1, 2));
      if (off <= 1e-9 * p.inertia.trace()) {
        principal = p.inertia.diagonal();
      } else {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(p.inertia);
        rot = es.eigenvectors();
        if (rot.determinant() < 0) rot.col(2) = -rot.col(2);
        principal = es.eigenvalues();
      }
      inPart = Pose{p.com, Quat(rot).normalized()};
      frame = world_[0] * inPart;
    } else if (!isStatic) {
      com /= mass;
      Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
      for (size_t i = 0; i < ids.size(); ++i) {
        const Part& p = parts[ids[i]];
        const Eigen::Matrix3d r = world_[i].rot.toRotationMatrix();
        const Vec3 d = world_[i] * p.com - com;
        inertia += r * p.inertia * r.transpose() +
                   p.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
      }
      // Keep the world-aligned frame when it is already principal.
      Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
      const double off = std::abs(inertia(0, 1)) + std::abs(inertia(0, 2)) + std::abs(inertia(1, 2));
      if (off <= 1e-9 * inertia.trace()) {
        principal = inertia.diagonal();
      } else {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(inertia);
        rot = es.eigenvectors();
        if (rot.determinant() < 0) rot.col(2) = -rot.col(2);
        principal = es.eigenvalues();
      }
      frame = Pose{com, Quat(rot).normalized()};
    }

    const int index = int(bodies.size());
    bodies.emplace_back();
    Body& b = bodies.back();
    b.parts = ids;
    const Pose inv = frame.inverse();
    int shapeCount = 0;
    for (int id : ids) shapeCount += int(parts[id].shapes.size());
    btCollisionShape* shape = nullptr;
    btCompoundShape* compound = nullptr;  // (made here, then shared: shareCompound)
    for (size_t i = 0; i < ids.size(); ++i) {
      Part& p = parts[ids[i]];
      p.body = index;
      p.inBody = single ? inPart.inverse() : inv * world_[i];
      if (p.owner >= 0) b.owners.push_back(p.owner);
      for (size_t k = 0; k < p.shapes.size(); ++k) {
        const Pose childPose = p.inBody * p.shapePoses[k];
        b.childPart.push_back(ids[i]);
        if (shapeCount == 1 && isIdentity(childPose)) {
          shape = p.shapes[k];
        } else {
          if (!compound) compound = new btCompoundShape(false, shapeCount);
          compound->addChildShape(toBt(childPose), p.shapes[k]);
        }
      }
    }
    if (compound) {
      b.compoundEntry = shareCompound(compound);
      shape = b.compoundEntry->second.shape.get();
    }
    std::sort(b.owners.begin(), b.owners.end());
    b.owners.erase(std::unique(b.owners.begin(), b.owners.end()), b.owners.end());
    ownerPairs.resize(bodies.size());
    OwnerPair& op = ownerPairs[size_t(index)];
    op = OwnerPair{};
    if (!b.owners.empty()) op.first = b.owners[0];
    if (b.owners.size() > 1) op.second = b.owners.size() > 2 ? OwnerPair::kMoreOwners : b.owners[1];

    const double m = isStatic ? 0.0 : mass;
    btRigidBody::btRigidBodyConstructionInfo ci(btScalar(m), nullptr, shape,
                                                isStatic ? btVector3(0, 0, 0) : toBt(principal));
    ci.m_startWorldTransform = toBt(frame);
    ci.m_friction = btScalar(parts[ids[0]].friction);
    ci.m_restitution = btScalar(parts[ids[0]].restitution);
    // Rolling resistance, and the same against spinning about the contact normal: without it a
    // ball set spinning in place spins for ever and keeps everything near it awake.
    ci.m_rollingFriction = btScalar(parts[ids[0]].rollingFriction);
    ci.m_spinningFriction = btScalar(parts[ids[0]].rollingFriction);
    b.rb = new (bodyPool.take(sizeof(btRigidBody))) btRigidBody(ci);
    b.rb->setUserIndex(index);
    for (int id : ids)
      for (const ShapeData& d : parts[id].shapeData)
        if (d.edges)
          b.rb->setCollisionFlags(b.rb->getCollisionFlags() | btCollisionObject::CF_CUSTOM_MATERIAL_CALLBACK);
    if (!isStatic) {
      // Modules never sleep (their motors act every step); obstacles do, once still for
      // Bullet's 2 s, and cost nothing until something touches them.
      if (!b.owners.empty())
        b.rb->setActivationState(DISABLE_DEACTIVATION);
      else
        b.rb->setSleepingThresholds(btScalar(kSleepSpeed), btScalar(kSleepAngularSpeed));
      b.rb->setLinearVelocity(toBt(linMomentum / mass));
      // world inertia = R diag R^T
      const Eigen::Matrix3d r = frame.rot.toRotationMatrix();
      const Eigen::Matrix3d iw = r * principal.asDiagonal() * r.transpose();
      b.rb->setAngularVelocity(toBt(angIsVelocity ? ang : Vec3(iw.ldlt().solve(ang))));
    }
    world.addRigidBody(b.rb);
    ++liveBodies;
    return index;
  }

  void makeHinge(Hinge& h) {
    const Part& a = parts[h.d.partA];
    const Part& b = parts[h.d.partB];
    if (a.body == b.body) {  // both ends inside one rigid body (a closed loop): the joint is frozen
      h.c = nullptr;
      return;
    }
    const btTransform fa = toBt(a.inBody * h.d.frameA);
    const btTransform fb = toBt(b.inBody * h.d.frameB);
    if (settings.solver == SolverKind::Exact) {
      const int id = int(&h - hinges.data());
      if (solver.joints.size() < hinges.size()) solver.joints.resize(hinges.size());
      ExactJoint& e = solver.joints[size_t(id)];
      e.a = bodies[a.body].rb;
      e.b = bodies[b.body].rb;
      e.frameA = fa;
      e.frameB = fb;
      h.link = std::make_unique<ExactLink>(*e.a, *e.b, id);
      world.addConstraint(h.link.get(), true);
      return;
    }
    h.c = new btHingeConstraint(*bodies[a.body].rb, *bodies[b.body].rb, fa, fb, false);
    // Bullet measures the hinge angle the other way round (A relative to B); RM3D's angles are
    // right-handed rotations of B about the axis, so limits, angles and speeds change sign here.
    if (h.d.limited) h.c->setLimit(btScalar(-h.d.upper), btScalar(-h.d.lower));
    if (settings.jointIterations > 0) h.c->setOverrideNumSolverIterations(settings.jointIterations);
    // Reactions are always kept: they give the motor's torque (and, with load tracking, the
    // dock loads).
    if (!h.feedback) h.feedback = std::make_unique<btJointFeedback>();
    h.c->setJointFeedback(h.feedback.get());
    world.addConstraint(h.c, true);
  }

  void removeCaptureLink(Capture& c) {
    if (!c.link) return;
    world.removeConstraint(c.link.get());
    c.link.reset();
  }

  /// Removes the links of captures on any of these parts (their bodies are about to go).
  void dropCaptureLinks(const std::vector<int>& ids) {
    for (Capture& c : captures)
      if (c.link &&
          std::any_of(ids.begin(), ids.end(), [&](int p) { return p == c.d.partA || p == c.d.partB; }))
        removeCaptureLink(c);
  }

  /// (Re)builds a capture's link and its solver entry for the bodies its parts are in now.
  void makeCapture(int id) {
    Capture& c = captures[size_t(id)];
    removeCaptureLink(c);
    const Part& a = parts[size_t(c.d.partA)];
    const Part& b = parts[size_t(c.d.partB)];
    if (a.body == b.body) return;  // one rigid body already: nothing to draw together
    if (solver.captures.size() < captures.size()) solver.captures.resize(captures.size());
    CaptureJoint& j = solver.captures[size_t(id)];
    j.a = bodies[a.body].rb;
    j.b = bodies[b.body].rb;
    j.frameA = toBt(a.inBody * c.d.frameA);
    j.frameB = toBt(b.inBody * c.d.frameB);
    j.mate = c.d.mate;
    j.speed = c.d.speed;
    j.angularSpeed = c.d.angularSpeed;
    j.gain = c.d.gain;
    j.force = c.d.force;
    j.torque = c.d.torque;
    c.link = std::make_unique<CaptureLink>(*j.a, *j.b, id);
    // The two dock links do not collide while they close (their faces meet at the end).
    world.addConstraint(c.link.get(), true);
  }

  void removeHinge(Hinge& h) {
    if (h.link) {
      world.removeConstraint(h.link.get());
      h.link.reset();
    }
    if (!h.c) return;
    world.removeConstraint(h.c);
    delete h.c;
    h.c = nullptr;
  }

  /// Hinges attached to any of the parts, sorted.
  std::vector<int> hingesOf(const std::vector<int>& ids) const {
    std::vector<int> out;
    for (int id : ids)
      for (int h : parts[id].hinges) out.push_back(h);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  Vec3 partComWorld(int p) const { return partPose(p) * parts[p].com; }

  Vec3 partComVelocity(int p) const { return partVelocityAt(p, partComWorld(p)); }
  /// The velocity of the point `at` (world frame) moving with part p's body.
  Vec3 partVelocityAt(int p, const Vec3& at) const {
    const btRigidBody* rb = bodies[parts[p].body].rb;
    return fromBt(rb->getVelocityInLocalPoint(toBt(at) - rb->getCenterOfMassPosition()));
  }

  void snapshotVelocities() {
    partVelBefore.resize(parts.size());
    bodyOmegaBefore.resize(bodies.size());
    // (Each body and part writes only its own entry: on the threads where it pays.)
    world.forEachIndex(omegaPace, int(bodies.size()), 256, [&](int b) {
      if (bodies[size_t(b)].rb)
        bodyOmegaBefore[size_t(b)] = fromBt(bodies[size_t(b)].rb->getAngularVelocity());
    });
    // Static and sleeping bodies do not move: their parts' velocities are zero (and unused).
    world.forEachIndex(partVelocityPace, int(parts.size()), 256, [&](int p) {
      partVelBefore[size_t(p)] =
          bodies[size_t(parts[size_t(p)].body)].rb->isActive() ? partComVelocity(p) : Vec3::Zero();
    });
  }

  int partOfChild(int body, int child) const {
    const Body& b = bodies[size_t(body)];
    if (b.childPart.size() == 1 || child < 0 || child >= int(b.childPart.size()))
      return b.childPart.empty() ? -1 : b.childPart[0];
    return b.childPart[size_t(child)];
  }

  /// What the touch pass (step) reads of the manifolds ahead of manifold i (of n), fetched in
  /// stages, each reading only what the one before fetched: with many modules the manifolds, their
  /// bodies and the bodies' part lists lie outside the caches. (Inlined: as a function of its own,
  /// reading and fetching only, GCC takes it for one without effects and drops its calls.)
  [[gnu::always_inline]] void fetchManifoldsAhead(int i, int n) const {
    using namespace bullet_layout;
    auto manifold = [&](int k) { return dispatcher.getManifoldByIndexInternal(k); };
    if (i + 16 < n) fetch(manifold(i + 16), kManifoldBodies);  // (the bodies and the count)
    if (i + 12 < n) {
      const btPersistentManifold* m = manifold(i + 12);
      fetch(m->getBody0(), kUserIndex);
      fetch(m->getBody1(), kUserIndex);
      for (int k = 0; k < m->getNumContacts(); ++k)
        fetchRange(&m->getContactPoint(k), 0, int(sizeof(btManifoldPoint)));
    }
    if (i + 8 < n) {
      const btPersistentManifold* m = manifold(i + 8);
      for (const btCollisionObject* o : {m->getBody0(), m->getBody1()})
        if (const int b = o->getUserIndex(); b >= 0) __builtin_prefetch(&bodies[size_t(b)].childPart);
    }
    if (i + 4 < n) {
      const btPersistentManifold* m = manifold(i + 4);
      for (const btCollisionObject* o : {m->getBody0(), m->getBody1()})
        if (const int b = o->getUserIndex(); b >= 0) __builtin_prefetch(bodies[size_t(b)].childPart.data());
    }
  }

  /// The last step's touches into partTouching, if not read yet (from any thread: the first one to
  /// ask reads them, the others wait).
  void settleTouching() const {
    if (!touchingDue.load(std::memory_order_acquire)) return;
    std::lock_guard<std::mutex> hold(touchingMutex);
    if (!touchingDue.load(std::memory_order_relaxed)) return;
    partTouching.assign(parts.size(), 0);
    const int manifolds = dispatcher.getNumManifolds();
    for (int i = 0; i < manifolds; ++i) {
      fetchManifoldsAhead(i, manifolds);
      const btPersistentManifold* man = dispatcher.getManifoldByIndexInternal(i);
      const int b0 = man->getBody0()->getUserIndex(), b1 = man->getBody1()->getUserIndex();
      for (int k = 0; k < man->getNumContacts(); ++k) {
        const btManifoldPoint& pt = man->getContactPoint(k);
        if (pt.getDistance() > btScalar(0.002)) continue;  // a touch, not a near miss
        for (const int p :
             {b0 >= 0 ? partOfChild(b0, pt.m_index0) : -1, b1 >= 0 ? partOfChild(b1, pt.m_index1) : -1})
          if (p >= 0) partTouching[size_t(p)] = 1;
      }
    }
    touchingDue.store(false, std::memory_order_release);
  }

  /// Adds the contact and hinge impulses on each part during the substep just taken (h long);
  /// divided by the whole step at the end, they are the step's mean forces.
  void accumulateLoads(double h, bool first) {
    if (first) {
      partExtForce.assign(parts.size(), Vec3::Zero());
      partExtTorque.assign(parts.size(), Vec3::Zero());
    }
    auto add = [&](int part, const Vec3& f, const Vec3& at) {
      if (part < 0) return;
      partExtForce[size_t(part)] += f;
      partExtTorque[size_t(part)] += at.cross(f);
    };
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      const btPersistentManifold* man = dispatcher.getManifoldByIndexInternal(m);
      // Contacts among sleeping and static bodies were not solved (a module body is always active).
      if (!man->getBody0()->isActive() && !man->getBody1()->isActive()) continue;
      const int b0 = man->getBody0()->getUserIndex(), b1 = man->getBody1()->getUserIndex();
      for (int k = 0; k < man->getNumContacts(); ++k) {
        const btManifoldPoint& pt = man->getContactPoint(k);
        const btVector3 j = pt.m_normalWorldOnB * pt.m_appliedImpulse +
                            pt.m_lateralFrictionDir1 * pt.m_appliedImpulseLateral1 +
                            pt.m_lateralFrictionDir2 * pt.m_appliedImpulseLateral2;
        const Vec3 f = fromBt(j);  // impulse on body 0; the opposite on body 1
        if (b0 >= 0) add(partOfChild(b0, pt.m_index0), f, fromBt(pt.getPositionWorldOnA()));
        if (b1 >= 0) add(partOfChild(b1, pt.m_index1), -f, fromBt(pt.getPositionWorldOnB()));
      }
    }
    for (const Hinge& hg : hinges) {
      // (The joint 8 hinges ahead, and the bodies' poses of the one 4 ahead.)
      const size_t i = size_t(&hg - hinges.data());
      if (i + 8 < hinges.size() && hinges[i + 8].link) {
        const ExactJoint& f = solver.joints[i + 8];
        __builtin_prefetch(&f.a);
        __builtin_prefetch(f.impulseA.data());
        __builtin_prefetch(f.impulseB.data() + 5);
      }
      if (i + 4 < hinges.size() && hinges[i + 4].link) {
        bullet_layout::fetchPose(solver.joints[i + 4].a);
        bullet_layout::fetchPose(solver.joints[i + 4].b);
      }
      if (hg.link) {
        const ExactJoint& e = solver.joints[i];
        const Vec3 ca = fromBt(e.a->getCenterOfMassPosition()), cb = fromBt(e.b->getCenterOfMassPosition());
        const Vec3 fa = e.impulseA.head<3>(), fbB = e.impulseB.head<3>();
        partExtForce[size_t(hg.d.partA)] += fa;
        partExtTorque[size_t(hg.d.partA)] += Vec3(e.impulseA.tail<3>()) + ca.cross(fa);
        partExtForce[size_t(hg.d.partB)] += fbB;
        partExtTorque[size_t(hg.d.partB)] += Vec3(e.impulseB.tail<3>()) + cb.cross(fbB);
        continue;
      }
      if (!hg.c || !hg.feedback) continue;
      const btJointFeedback& fb = *hg.feedback;
      const Vec3 ca = fromBt(hg.c->getRigidBodyA().getCenterOfMassPosition());
      const Vec3 cb = fromBt(hg.c->getRigidBodyB().getCenterOfMassPosition());
      const Vec3 fa = fromBt(fb.m_appliedForceBodyA) * h, fbB = fromBt(fb.m_appliedForceBodyB) * h;
      partExtForce[size_t(hg.d.partA)] += fa;
      partExtTorque[size_t(hg.d.partA)] += fromBt(fb.m_appliedTorqueBodyA) * h + ca.cross(fa);
      partExtForce[size_t(hg.d.partB)] += fbB;
      partExtTorque[size_t(hg.d.partB)] += fromBt(fb.m_appliedTorqueBodyB) * h + cb.cross(fbB);
    }
  }

  double rawAngle(const Hinge& h) const {
    if (h.link) {  // B relative to A about A's z axis
      const ExactJoint& e = solver.joints[size_t(&h - hinges.data())];
      const btMatrix3x3 r =
          (e.a->getCenterOfMassTransform().getBasis() * e.frameA.getBasis())
              .transposeTimes(e.b->getCenterOfMassTransform().getBasis() * e.frameB.getBasis());
      return std::atan2(double(r[1][0]), double(r[0][0]));
    }
    if (!h.c) return h.rawLast;
    return -h.c->getHingeAngle();
  }

  /// Bullet's hinge: the reaction on B about the pivot, along the axis, is what the motor and
  /// the limit stop applied (the pivot rows pass through the pivot, the other angular rows are
  /// perpendicular to the axis).
  void addPgsTorque(Hinge& h) {
    const btRigidBody& rb = h.c->getRigidBodyB();
    const btJointFeedback& fb = *h.feedback;
    const Vec3 pivot = partPose(h.d.partB) * h.d.frameB.pos;
    const Vec3 axis = partPose(h.d.partA).rot * h.axisA;
    const Vec3 about = fromBt(fb.m_appliedTorqueBodyB) +
                       (fromBt(rb.getCenterOfMassPosition()) - pivot).cross(fromBt(fb.m_appliedForceBodyB));
    const double tau = about.dot(axis);
    h.torque += tau / std::max(1, stepSubsteps);
    if (h.mode != MotorMode::Off && std::abs(tau) >= 0.99 * h.d.maxTorque) h.saturated = true;
  }

  void updateAngle(Hinge& h) {
    const double raw = rawAngle(h);
    double d = raw - h.rawLast;
    if (d > kPi) d -= 2 * kPi;
    if (d < -kPi) d += 2 * kPi;
    h.angle += d;
    h.rawLast = raw;
  }

  /// The motor's speed command: a servo's proportional speed, bounded by the joint's speed and
  /// by what reaches the target within one substep (no overshoot from the command itself).
  double motorSpeed(const Hinge& h, double dtSub) const {
    if (h.mode == MotorMode::Velocity) return std::clamp(h.value, -h.d.maxSpeed, h.d.maxSpeed);
    double target = h.value;
    if (h.d.limited) target = std::clamp(target, h.d.lower, h.d.upper);
    const double err = target - h.angle;
    const double v = std::clamp(h.d.servoGain * err, -h.d.maxSpeed, h.d.maxSpeed);
    const double deadbeat = std::abs(err) / dtSub;
    return std::clamp(v, -deadbeat, deadbeat);
  }

  void applyMotor(Hinge& h, double dtSub) {
    const double impulse = h.d.maxTorque * dtSub;
    if (h.link) {
      ExactJoint& e = solver.joints[size_t(&h - hinges.data())];
      e.motorOn = h.mode != MotorMode::Off;
      e.targetVel = e.motorOn ? motorSpeed(h, dtSub) : 0;
      e.maxImpulse = impulse;
      // A servo commands gain x error as speed; a compliance c on that row holds a load tau at
      // c tau dt = gain x error, so the error is tau / stiffness.
      e.compliance = h.mode == MotorMode::Servo && h.d.servoStiffness > 0
                         ? std::min(h.d.servoGain, 1.0 / dtSub) / (h.d.servoStiffness * dtSub)
                         : 0;
      e.limited = h.d.limited;
      e.lower = h.d.lower;
      e.upper = h.d.upper;
      e.angle = h.angle;
      return;
    }
    if (!h.c) return;
    if (h.mode == MotorMode::Off)
      h.c->enableMotor(false);
    else
      h.c->enableAngularMotor(true, btScalar(-motorSpeed(h, dtSub)), btScalar(impulse));
  }
};

namespace {

/// Bullet's allocations, failing as C++ does. Bullet's own allocator returns null when memory
/// runs out and Bullet then writes through it (a crash inside the soft-body code at the 17th
/// large cloth under a 3 GB address-space limit); this one throws, so a world script's call
/// ends in an error with its file and line, and a step in an error naming the world.
struct BulletOutOfMemory : std::bad_alloc {
  const char* what() const noexcept override {
    return "out of memory: the physics engine could not allocate (the machine's memory or the process's "
           "address-space limit is spent; a smaller --memory-budget refuses additions before that)";
  }
};

// Bullet's aligned allocations go through these (it keeps the block's start in front of the
// aligned pointer), and the free is Bullet's default, so blocks from before the switch are freed
// alike.
void* bulletAlloc(size_t size) {
  void* p = std::malloc(size ? size : 1);
  if (!p) throw BulletOutOfMemory();
  return p;
}
void bulletFree(void* p) {
  std::free(p);
}

// Process-wide, the same for every world, and set while the program (or the Python module) loads,
// before any thread can be allocating.
[[maybe_unused]] const bool kBulletAllocator = (btAlignedAllocSetCustom(&bulletAlloc, &bulletFree), true);

}  // namespace

PhysicsWorld::PhysicsWorld(const PhysicsSettings& settings) : m(std::make_unique<Impl>(settings)) {}
PhysicsWorld::~PhysicsWorld() = default;

const PhysicsSettings& PhysicsWorld::settings() const {
  return m->settings;
}
int PhysicsWorld::partCount() const {
  return int(m->parts.size());
}
int PhysicsWorld::bodyCount() const {
  return m->liveBodies;
}
int PhysicsWorld::compoundCount() const {
  return int(m->compounds.size());
}

void PhysicsWorld::configure(const PhysicsSettings& s) {
  const bool switched = s.solver != m->settings.solver;
  if (switched)
    for (Impl::Hinge& h : m->hinges) m->removeHinge(h);
  m->settings = s;
  m->solver.patches = s.solver == SolverKind::Exact;
  m->solver.wholeFactors = s.wholeFactors;
  m->solver.freshTrees = s.freshTrees;
  m->solver.everyIteration = s.everyIteration;
  m->solver.denseIslands = s.denseIslands;
  m->solver.denseCoordinates = s.denseCoordinates;
  m->solver.avx = s.avx && __builtin_cpu_supports("avx");
  m->solver.alwaysThreads = s.alwaysThreads;
  m->world.setAlwaysThreads(s.alwaysThreads);
  m->dispatcher.setAlwaysThreads(s.alwaysThreads);
  for (auto& h : m->helpers) h->patches = m->solver.patches;
  if (switched)
    for (Impl::Hinge& h : m->hinges) {
      m->makeHinge(h);
    }
  m->world.setGravity(toBt(s.gravity));
  if (m->cloth) m->cloth->setGravity(toBt(s.gravity));
  m->world.getSolverInfo().m_numIterations = s.solverIterations;
  m->world.getSolverInfo().m_erp = btScalar(s.erp);
  for (Impl::Hinge& h : m->hinges)
    if (h.c) h.c->setOverrideNumSolverIterations(s.jointIterations > 0 ? s.jointIterations : -1);
}

void PhysicsWorld::addGroundPlane(double friction, double restitution) {
  auto* plane = new btStaticPlaneShape(btVector3(0, 0, 1), 0);
  m->extraShapes.push_back(plane);
  btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, plane);
  ci.m_friction = btScalar(friction);
  ci.m_restitution = btScalar(restitution);
  auto* rb = new btRigidBody(ci);
  rb->setUserIndex(-1);
  // Bullet's own static filter, less cloth: cloth meets a stand-in box instead (ClothSystem).
  m->world.addRigidBody(rb, btBroadphaseProxy::StaticFilter,
                        btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter ^ kClothFilterGroup);
  m->extraBodies.push_back(rb);
  m->groundFriction = friction;
  if (m->cloth) m->cloth->setGround(friction);
}

int PhysicsWorld::addCloth(const ClothDesc& desc) {
  if (!m->cloth) {
    m->cloth = std::make_unique<ClothSystem>(m->world, toBt(m->settings.gravity));
    m->dispatcher.setTasks(1, nullptr);  // cloth's pairs share its contact lists: one thread
    if (m->groundFriction) m->cloth->setGround(*m->groundFriction);
  }
  return m->cloth->add(desc);
}

int PhysicsWorld::clothCount() const {
  return m->cloth ? m->cloth->count() : 0;
}

int PhysicsWorld::clothNodeCount(int cloth) const {
  return m->cloth->body(cloth).m_nodes.size();
}

Vec3 PhysicsWorld::clothNode(int cloth, int node) const {
  return fromBt(m->cloth->body(cloth).m_nodes[node].m_x);
}

Vec3 PhysicsWorld::clothNodeVelocity(int cloth, int node) const {
  return fromBt(m->cloth->body(cloth).m_nodes[node].m_v);
}

void PhysicsWorld::setClothNodePinned(int cloth, int node, bool pinned) {
  m->cloth->setPinned(cloth, node, pinned);
}

bool PhysicsWorld::clothFinite(int cloth) const {
  double sum = 0;  // a sum of finite floats is finite in double
  const btSoftBody::tNodeArray& nodes = m->cloth->body(cloth).m_nodes;
  for (int i = 0; i < nodes.size(); ++i) {
    const btSoftBody::Node& n = nodes[i];
    sum += double(n.m_x.x()) + n.m_x.y() + n.m_x.z() + n.m_v.x() + n.m_v.y() + n.m_v.z();
  }
  return std::isfinite(sum);
}

bool PhysicsWorld::clothNodePinned(int cloth, int node) const {
  return m->cloth->pinned(cloth, node);
}

int PhysicsWorld::addPart(const PartDesc& desc) {
  const int id = int(m->parts.size());
  m->parts.emplace_back();
  Impl::Part& p = m->parts.back();
  p.mass = desc.mass;
  p.friction = desc.friction;
  p.restitution = desc.restitution;
  p.rollingFriction = desc.rollingFriction;
  p.owner = desc.owner;

  // Mass properties: each shape gets its given mass, the rest is shared by volume.
  if (desc.mass > 0) {
    const MassProps mp = compoundMassProps(desc.shapes, desc.mass);
    p.com = mp.com;
    p.inertia = mp.inertia;
  }
  for (const ShapeDef& s : desc.shapes) {
    p.shapeData.emplace_back();
    p.shapes.push_back(m->shapeFor(s, p.shapeData.back()));
    p.shapePoses.push_back(s.pose * bulletShapeOffset(s));
  }
  m->buildBody({id}, {desc.pose}, Vec3::Zero(), Vec3::Zero());
  return id;
}

int PhysicsWorld::addHinge(const HingeDesc& desc) {
  const int id = int(m->hinges.size());
  m->hinges.emplace_back();
  Impl::Hinge& h = m->hinges.back();
  h.d = desc;
  h.axisA = desc.frameA.rot * Vec3::UnitZ();
  m->parts[desc.partA].hinges.push_back(id);
  m->parts[desc.partB].hinges.push_back(id);
  m->makeHinge(h);
  h.rawLast = m->rawAngle(h);
  h.angle = h.rawLast;
  return id;
}

void PhysicsWorld::lockParts(int a, int b) {
  m->settleTouching();  // (before a body's manifolds go)
  auto& la = m->parts[a].locks;
  if (a != b && std::find(la.begin(), la.end(), b) == la.end()) {
    la.push_back(b);
    m->parts[b].locks.push_back(a);
  }
  const int ba = m->parts[a].body, bb = m->parts[b].body;
  if (ba == bb) return;
  std::vector<int> ids = m->bodies[ba].parts;
  ids.insert(ids.end(), m->bodies[bb].parts.begin(), m->bodies[bb].parts.end());
  std::vector<Pose> poses;
  Vec3 lin = Vec3::Zero(), ang = Vec3::Zero();
  // Total momentum about the new centre of mass (computed after the parts' com is known).
  double mass = 0;
  Vec3 com = Vec3::Zero();
  for (int id : ids) {
    poses.push_back(m->partPose(id));
    mass += m->parts[id].mass;
    com += m->parts[id].mass * (poses.back() * m->parts[id].com);
  }
  if (mass > 0) com /= mass;
  for (int body : {ba, bb}) {
    const btRigidBody* rb = m->bodies[body].rb;
    if (rb->getInvMass() == 0) continue;
    const double bm = 1.0 / rb->getInvMass();
    const Vec3 v = fromBt(rb->getLinearVelocity());
    const Vec3 w = fromBt(rb->getAngularVelocity());
    const Vec3 c = fromBt(rb->getCenterOfMassPosition());
    lin += bm * v;
    const Pose bp = m->bodyPose(body);
    const Eigen::Matrix3d r = bp.rot.toRotationMatrix();
    const Vec3 inv = fromBt(rb->getInvInertiaDiagLocal());
    const Vec3 diag(inv.x() > 0 ? 1 / inv.x() : 0, inv.y() > 0 ? 1 / inv.y() : 0,
                    inv.z() > 0 ? 1 / inv.z() : 0);
    ang += r * diag.asDiagonal() * r.transpose() * w + (c - com).cross(bm * v);
  }
  const std::vector<int> touched = m->hingesOf(ids);
  for (int h : touched) m->removeHinge(m->hinges[h]);
  m->dropCaptureLinks(ids);  // made anew at the next step
  m->destroyBody(m->bodies[ba]);
  m->destroyBody(m->bodies[bb]);
  m->buildBody(ids, poses, lin, ang);
  for (int h : touched) m->makeHinge(m->hinges[h]);
}

std::vector<int> PhysicsWorld::lockedGroup(int part, int skipA, int skipB) const {
  std::vector<int> out{part};
  std::vector<char> seen(m->parts.size(), 0);
  seen[size_t(part)] = 1;
  for (size_t k = 0; k < out.size(); ++k)
    for (int q : m->parts[size_t(out[k])].locks) {
      if ((out[k] == skipA && q == skipB) || (out[k] == skipB && q == skipA) || seen[size_t(q)]) continue;
      seen[size_t(q)] = 1;
      out.push_back(q);
    }
  std::sort(out.begin(), out.end());
  return out;
}

void PhysicsWorld::unlockParts(int a, int b) {
  m->settleTouching();  // (before a body's manifolds go)
  auto drop = [&](int from, int to) {
    auto& v = m->parts[from].locks;
    v.erase(std::remove(v.begin(), v.end(), to), v.end());
  };
  drop(a, b);
  drop(b, a);
  const int body = m->parts[a].body;
  if (body != m->parts[b].body) return;
  const std::vector<int> all = m->bodies[body].parts;
  std::vector<std::vector<int>> groups;
  std::vector<char> placed(m->parts.size(), 0);
  for (int p : all) {
    if (placed[size_t(p)]) continue;
    groups.push_back(lockedGroup(p));
    for (int q : groups.back()) placed[size_t(q)] = 1;
  }
  if (groups.size() < 2) return;  // still held together another way (a loop)
  const btRigidBody* rb = m->bodies[body].rb;
  const Vec3 v = fromBt(rb->getLinearVelocity()), w = fromBt(rb->getAngularVelocity());
  const Vec3 c = fromBt(rb->getCenterOfMassPosition());
  std::vector<Pose> poses(m->parts.size());
  for (int p : all) poses[size_t(p)] = m->partPose(p);
  const std::vector<int> touched = m->hingesOf(all);
  for (int h : touched) m->removeHinge(m->hinges[h]);
  m->dropCaptureLinks(all);  // made anew at the next step
  m->destroyBody(m->bodies[body]);
  for (const std::vector<int>& g : groups) {
    std::vector<Pose> gp;
    double mass = 0;
    Vec3 com = Vec3::Zero();
    for (int p : g) {
      gp.push_back(poses[size_t(p)]);
      mass += m->parts[p].mass;
      com += m->parts[p].mass * (poses[size_t(p)] * m->parts[p].com);
    }
    if (mass > 0) com /= mass;
    m->buildBody(g, gp, mass * (v + w.cross(com - c)), w, true);
  }
  for (int h : touched) m->makeHinge(m->hinges[h]);
}

void PhysicsWorld::addForce(int part, const Vec3& force, const Vec3& worldPoint) {
  m->forces.push_back({part, force, worldPoint, Vec3::Zero()});
}

void PhysicsWorld::addTorque(int part, const Vec3& torque) {
  m->forces.push_back({part, Vec3::Zero(), Vec3::Zero(), torque});
}

void PhysicsWorld::setParallel(int threads, ForEach forEach, bool watch) {
  // Bullet hands the solver batches of islands of at least 128 rows (with 1000 separate
  // SuperBots, about 50 a substep). With worker threads each thread's solver takes the next
  // batch (SolverWorld::solveBatches). The batches are made the same way at any thread count,
  // and a batch comes out the same whichever solver solves it (its steps after the iterations
  // touch only the clusters and islands they concern), so one thread and many give the same
  // bits. (Spreading one batch's clusters over the threads instead, with batches of 16384 rows
  // to give them work, made superbots_1000 0.81 times as fast on 2 threads as on 1: the sweeps
  // then ran over megabytes instead of batches that fit the caches.)
  m->helpers.clear();
  m->tasks = nullptr;
  std::vector<ExactSolver*> helpers;
  if (forEach && threads > 1) {
    // Every task of a step runs with denormals flushed, as the stepping thread does (step): a
    // worker thread's own mode would let a batch it solves differ in its smallest bits from the
    // same batch solved on the stepping thread. (In zero gravity, quaternion components of 1e-35
    // appear within a step, and products of them are denormal: docking_1000's results differed at
    // 2 threads, and from run to run, as batches went to one thread or the other.)
    m->tasks = [forEach](int n, FunctionRef<void(int)> fn) {
      forEach(n, [&fn](int t) {
        const FlushDenormals flush;
        fn(t);
      });
    };
    m->solver.halfHelperWatches = watch;
    for (int t = 1; t < threads; ++t) {
      m->helpers.push_back(std::make_unique<ExactSolver>());
      m->helpers.back()->shareStateOf(m->solver);
      helpers.push_back(m->helpers.back().get());
    }
  }
  m->world.setBatchSolvers(&m->solver, std::move(helpers), m->tasks);
  m->dispatcher.setTasks(m->cloth ? 1 : threads, m->tasks);  // (not with cloth: see addCloth)
  m->world.setAlwaysThreads(m->settings.alwaysThreads);
  m->dispatcher.setAlwaysThreads(m->settings.alwaysThreads);
}

void PhysicsWorld::setLoadTracking(bool on) {
  if (m->tracking == on) return;
  m->tracking = on;
}

Wrench PhysicsWorld::internalLoad(const std::vector<int>& parts, const Vec3& point) const {
  Wrench w;
  if (!m->tracking || m->lastH <= 0 || m->partExtForce.size() != m->parts.size() ||
      m->partVelBefore.size() != m->parts.size())
    return w;
  const double h = m->lastH;
  const Vec3 g = m->settings.gravity;
  Vec3 torqueOrigin = Vec3::Zero();
  for (int p : parts) {
    const Impl::Part& part = m->parts[size_t(p)];
    if (part.mass <= 0) continue;
    const int b = part.body;
    const btRigidBody* rb = m->bodies[size_t(b)].rb;
    // The part's pose made once (partComWorld and partComVelocity would each make it again).
    const Pose pose = m->partPose(p);
    const Vec3 c = pose * part.com;
    const Vec3 a = (m->partVelocityAt(p, c) - m->partVelBefore[size_t(p)]) / h;
    const Vec3 omegaBefore =
        size_t(b) < m->bodyOmegaBefore.size() ? m->bodyOmegaBefore[size_t(b)] : Vec3::Zero();
    const Vec3 alpha = (fromBt(rb->getAngularVelocity()) - omegaBefore) / h;
    const Eigen::Matrix3d r = pose.rot.toRotationMatrix();
    const Eigen::Matrix3d iw = r * part.inertia * r.transpose();
    // Bullet integrates without the gyroscopic term, so dL/dt = I alpha here.
    const Vec3 dp = part.mass * a;
    w.force += dp - part.mass * g - m->partExtForce[size_t(p)];
    torqueOrigin += c.cross(dp) + iw * alpha - c.cross(part.mass * g) - m->partExtTorque[size_t(p)];
  }
  w.torque = torqueOrigin - point.cross(w.force);
  return w;
}

double PhysicsWorld::rayCast(const Vec3& from, const Vec3& dir, double length, int ignoreOwner) const {
  struct Callback : btCollisionWorld::ClosestRayResultCallback {
    const std::vector<Impl::Body>* bodies;
    int ignore;
    Callback(const btVector3& a, const btVector3& b, const std::vector<Impl::Body>* bs, int ig)
        : ClosestRayResultCallback(a, b), bodies(bs), ignore(ig) {}
    bool needsCollision(btBroadphaseProxy* proxy) const override {
      const int b = static_cast<btCollisionObject*>(proxy->m_clientObject)->getUserIndex();
      if (b >= 0 && ignore >= 0) {
        const auto& owners = (*bodies)[size_t(b)].owners;
        if (std::binary_search(owners.begin(), owners.end(), ignore)) return false;
      }
      return ClosestRayResultCallback::needsCollision(proxy);
    }
  };
  const btVector3 a = toBt(from), b = toBt(from + dir * length);
  Callback cb(a, b, &m->bodies, ignoreOwner);
  // Bullet's default sub-simplex cast against convex shapes is off by millimetres at a metre or
  // two; the GJK cast is exact to well under a millimetre.
  cb.m_flags |= btTriangleRaycastCallback::kF_UseGjkConvexCastRaytest;
  // Rays pass through cloth: Bullet's first ray test on a soft body builds its face tree (quadratic
  // in the faces) and rebuilds its node tree, which reorders its contacts, so a range sensor read
  // (or a picture taken) would change the run.
  cb.m_collisionFilterMask = btBroadphaseProxy::AllFilter ^ kClothFilterGroup;
  {
    std::lock_guard<std::mutex> lock(m->rayMutex);
    m->world.rayTest(a, b, cb);
  }
  return cb.hasHit() ? double(cb.m_closestHitFraction) * length : -1.0;
}

void PhysicsWorld::setContactTracking(bool on) {
  m->contactTracking = on;
}

bool PhysicsWorld::partTouching(int part) const {
  m->settleTouching();
  return size_t(part) < m->partTouching.size() && m->partTouching[size_t(part)];
}

void PhysicsWorld::transformParts(const std::vector<int>& parts, const Pose& delta) {
  std::vector<int> bodies;
  for (int p : parts) bodies.push_back(m->parts[p].body);
  std::sort(bodies.begin(), bodies.end());
  bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
  for (int b : bodies) {
    btRigidBody* rb = m->bodies[b].rb;
    const Pose np = delta * m->bodyPose(b);
    rb->setWorldTransform(toBt(np));
    rb->setInterpolationWorldTransform(rb->getWorldTransform());
    rb->setLinearVelocity(toBt(delta.rot * fromBt(rb->getLinearVelocity())));
    rb->setAngularVelocity(toBt(delta.rot * fromBt(rb->getAngularVelocity())));
    m->world.updateSingleAabb(rb);
  }
}

void PhysicsWorld::setPartVelocity(int part, const Vec3& v) {
  btRigidBody* rb = m->bodies[size_t(m->parts[size_t(part)].body)].rb;
  rb->activate(true);
  rb->setLinearVelocity(toBt(v));
}

bool PhysicsWorld::partSleeping(int part) const {
  const btRigidBody* rb = m->bodies[size_t(m->parts[size_t(part)].body)].rb;
  return rb->isStaticOrKinematicObject() || rb->getActivationState() == ISLAND_SLEEPING;
}

int PhysicsWorld::activeBodyCount() const {
  int n = 0;
  const btAlignedObjectArray<btRigidBody*>& rbs = m->world.getNonStaticRigidBodies();
  for (int i = 0; i < rbs.size(); ++i) n += rbs[i]->isActive() ? 1 : 0;
  return n;
}

int PhysicsWorld::threadedPairs() const {
  return m->dispatcher.threadedPairs();
}

int PhysicsWorld::threadedBodies() const {
  return m->world.threadedBodies();
}

namespace {

/// A count summed over the world's exact solvers: the primary and the batch solvers.
template <class Count, class Solvers>
Count sumOverSolvers(const ExactSolver& primary, const Solvers& helpers,
                     Count (ExactSolver::*count)() const) {
  Count n = (primary.*count)();
  for (const auto& h : helpers) n += ((*h).*count)();
  return n;
}

}  // namespace

int PhysicsWorld::halvedSweeps() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::halvedSweepCount);
}

int PhysicsWorld::halvedLists() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::halvedListCount);
}

long PhysicsWorld::reusedTrees() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::reusedTreeCount);
}

long PhysicsWorld::solvedBatches() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::solvedBatchCount);
}

long PhysicsWorld::finishedBatches() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::finishedBatchCount);
}

long PhysicsWorld::islandSweeps() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::islandSweepCount);
}

long PhysicsWorld::sparedSweeps() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::sparedSweepCount);
}

long PhysicsWorld::chordPasses() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::chordPassCount);
}

long PhysicsWorld::newtonPasses() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::newtonPassCount);
}

long PhysicsWorld::denseIslands() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::denseIslandCount);
}

long PhysicsWorld::partialFactors() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::partialFactorCount);
}

int PhysicsWorld::splitTrees() const {
  return sumOverSolvers(m->solver, m->helpers, &ExactSolver::splitTreeCount);
}

double PhysicsWorld::partMass(int part) const {
  return m->parts[size_t(part)].mass;
}

int PhysicsWorld::addCapture(const CaptureDesc& desc) {
  int id;
  if (!m->freeCaptures.empty()) {
    id = m->freeCaptures.back();
    m->freeCaptures.pop_back();
  } else {
    id = int(m->captures.size());
    m->captures.emplace_back();
  }
  Impl::Capture& c = m->captures[size_t(id)];
  c.d = desc;
  c.live = true;
  m->solver.captures.resize(std::max(m->solver.captures.size(), m->captures.size()));
  m->solver.captures[size_t(id)] = CaptureJoint{};
  m->makeCapture(id);
  return id;
}

void PhysicsWorld::removeCapture(int id) {
  Impl::Capture& c = m->captures[size_t(id)];
  if (!c.live) return;
  m->removeCaptureLink(c);
  c.live = false;
  m->freeCaptures.push_back(id);
}

void PhysicsWorld::fetchMotor(int hinge) const {
  if (hinge >= 0 && size_t(hinge) < m->hinges.size()) {
    const Impl::Hinge& h = m->hinges[size_t(hinge)];
    __builtin_prefetch(&h.mode, 1);
    __builtin_prefetch(&h.value, 1);
  }
}

void PhysicsWorld::setMotor(int hinge, MotorMode mode, double value) {
  Impl::Hinge& h = m->hinges[hinge];
  h.mode = mode;
  h.value = value;
}

void PhysicsWorld::step(double dt, int substeps) {
  // Flush denormals to zero while Bullet runs: velocities decaying towards zero (a module
  // floating in zero gravity) otherwise reach denormal floats, which cost 10-100 times more per
  // operation. The caller's floating-point mode is restored on the way out.
  const FlushDenormals flush;
  // The last step's touches: unread, they are made anew at this step's end; where this step keeps
  // none, read now, before its manifolds replace them.
  if (m->contactTracking)
    m->touchingDue.store(false, std::memory_order_relaxed);
  else
    m->settleTouching();
  const int n = std::max(1, substeps);
  const double h = dt / n;
  m->stepSubsteps = n;
  if (m->cloth) m->cloth->setSubstep(h);
  const bool exact = m->settings.solver == SolverKind::Exact;
  // Capture joints whose parts have been merged or split into other bodies since: built anew.
  for (size_t id = 0; id < m->captures.size(); ++id) {
    const Impl::Capture& c = m->captures[id];
    if (!c.live) continue;
    const btRigidBody* ra = m->bodies[size_t(m->parts[size_t(c.d.partA)].body)].rb;
    const btRigidBody* rb = m->bodies[size_t(m->parts[size_t(c.d.partB)].body)].rb;
    const CaptureJoint& j = m->solver.captures[id];
    if (c.link ? (j.a != ra || j.b != rb) : ra != rb) m->makeCapture(int(id));
  }
  const int hinges = int(m->hinges.size());
  for (int s = 0; s < n; ++s) {
    // Each hinge's motor (each writes only its own joint), the step's sums cleared first.
    m->world.forEachIndex(m->motorPace, hinges, 64, [&](int i) {
      // (With many modules the hinge 4 ahead and its joint, which the motor writes, have left the
      // caches since the last step.)
      // (The joints are as many as the hinges up to the last one made a link: frozen hinges
      // after it have none.)
      // (Only what the motor reads and writes: of the hinge, its ratings on; of the joint, its
      // motor's inputs. The rest of each would be fetched for nothing: at 10,000 modules the
      // joints have left the caches again before the solve reads them.)
      if (i + 4 < hinges) {
        const Impl::Hinge& ahead = m->hinges[size_t(i + 4)];
        fetchSpan(&ahead.d.limited, &ahead.feedback);
      }
      if (exact && size_t(i + 4) < m->solver.joints.size()) {
        const ExactJoint& ahead = m->solver.joints[size_t(i + 4)];
        fetchSpan(&ahead.motorOn, &ahead.axialImpulse);
      }
      Impl::Hinge& hg = m->hinges[size_t(i)];
      if (s == 0) {
        hg.torque = 0;
        hg.saturated = false;
      }
      m->applyMotor(hg, h);
    });
    if (exact) {
      m->solver.beginSubstep();
      for (auto& hs : m->helpers) hs->beginSubstep();
    }
    for (const Impl::Force& f : m->forces) {
      btRigidBody* rb = m->bodies[size_t(m->parts[size_t(f.part)].body)].rb;
      rb->applyForce(toBt(f.force), toBt(f.point) - rb->getCenterOfMassPosition());
      rb->applyTorque(toBt(f.torque));
    }
    if (m->tracking && s == 0) m->snapshotVelocities();
    m->world.setFinishBatches(exact && m->settings.finishBatches ? &m->solver : nullptr);
    m->world.stepSimulation(btScalar(h), 0, btScalar(h));
    // (Every batch finished after its solve: nothing left for the passes over them all.)
    const bool finished =
        m->solver.batchesFinished() && std::all_of(m->helpers.begin(), m->helpers.end(),
                                                   [](const auto& hs) { return hs->batchesFinished(); });
    if (exact && !finished) {
      m->solver.notePatchPoses();
      if (std::none_of(m->helpers.begin(), m->helpers.end(), [](auto& s) { return s->hasClusters(); })) {
        // Everything was solved on the primary (a long tree's halves on two threads).
        if (m->solver.hasSplitTrees())
          m->solver.runWithHalfHelper(
              m->tasks, [&] { m->solver.postStabilise(); }, ExactSolver::HalfSite::Stabilise);
        else
          m->solver.postStabilise();
      } else {  // each solver's own clusters, which no other solver touches
        m->tasks(1 + int(m->helpers.size()),
                 [&](int t) { (t == 0 ? m->solver : *m->helpers[size_t(t - 1)]).postStabilise(); });
      }
      m->solver.followPatchPoses();
    }
    // Each hinge's load and angle (each hinge writes only its own).
    m->world.forEachIndex(m->anglePace, hinges, 64, [&](int i) {
      // The bodies' poses of the hinge 4 ahead fetched now, and its joint and what this pass reads
      // of the hinge 8 ahead (from `c` on): with many modules they have left the caches since the
      // integration and the solve, and reading the hinge 4 ahead's link waited on memory.
      if (i + 8 < hinges) {
        const Impl::Hinge* ahead = &m->hinges[size_t(i + 8)];
        fetchSpan(&ahead->c, ahead + 1);
      }
      if (exact && size_t(i + 8) < m->solver.joints.size()) {  // (its bodies, frames and outputs)
        const ExactJoint& ahead = m->solver.joints[size_t(i + 8)];
        fetchSpan(&ahead, &ahead.impulseA);
      }
      if (exact && i + 4 < hinges && m->hinges[size_t(i + 4)].link) {
        const ExactJoint& f = m->solver.joints[size_t(i + 4)];
        bullet_layout::fetchPose(f.a);
        bullet_layout::fetchPose(f.b);
      }
      Impl::Hinge& hg = m->hinges[size_t(i)];
      if (exact && hg.link) {
        const ExactJoint& e = m->solver.joints[size_t(i)];
        hg.torque += std::clamp(e.axialImpulse, -e.maxImpulse, e.maxImpulse) / dt;
        hg.saturated = hg.saturated || e.saturated;
      }
      if (hg.c && hg.feedback) m->addPgsTorque(hg);
      m->updateAngle(hg);
    });
    if (m->tracking) m->accumulateLoads(h, s == 0);
  }
  // (Read when a contact sensor asks: settleTouching.)
  if (m->contactTracking) m->touchingDue.store(true, std::memory_order_release);
  m->forces.clear();
  if (m->cloth) m->cloth->afterStep();
  if (m->tracking) {
    // Mean forces over the whole step: a contact's impulse spread over dt, not over one substep.
    m->lastH = dt;
    for (Vec3& f : m->partExtForce) f /= dt;
    for (Vec3& t : m->partExtTorque) t /= dt;
  }
}

Pose PhysicsWorld::partPose(int part) const {
  return m->partPose(part);
}

void PhysicsWorld::fetchPartPose(int part) const {
  if (part < 0 || size_t(part) >= m->parts.size()) return;
  const int body = m->parts[size_t(part)].body;
  if (body >= 0 && size_t(body) < m->bodies.size() && m->bodies[size_t(body)].rb)
    bullet_layout::fetchPose(m->bodies[size_t(body)].rb);
}

double PhysicsWorld::lowestPoint(const std::vector<int>& parts) const {
  double low = std::numeric_limits<double>::infinity();
  for (int id : parts) {
    const Impl::Part& p = m->parts[size_t(id)];
    const Pose pose = m->partPose(id);
    for (size_t k = 0; k < p.shapes.size(); ++k) {
      const btCollisionShape* s = p.shapes[k];
      const Pose sp = pose * p.shapePoses[k];
      if (s->isConvex()) {  // the support point straight down: exact for any convex shape
        const Vec3 down = sp.rot.conjugate() * Vec3(0, 0, -1);
        const btVector3 v = static_cast<const btConvexShape*>(s)->localGetSupportingVertex(toBt(down));
        low = std::min(low, (sp * fromBt(v)).z());
      } else {
        btVector3 lo, hi;
        s->getAabb(toBt(sp), lo, hi);
        low = std::min(low, double(lo.z()));
      }
    }
  }
  return low;
}

Vec3 PhysicsWorld::partLinearVelocity(int part) const {
  const btRigidBody* rb = m->bodies[m->parts[part].body].rb;
  const Vec3 p = m->partPose(part) * m->parts[part].com;
  return fromBt(rb->getVelocityInLocalPoint(toBt(p) - rb->getCenterOfMassPosition()));
}

Vec3 PhysicsWorld::partAngularVelocity(int part) const {
  return fromBt(m->bodies[m->parts[part].body].rb->getAngularVelocity());
}

bool PhysicsWorld::sameBody(int a, int b) const {
  return m->parts[a].body == m->parts[b].body;
}

double PhysicsWorld::hingeAngle(int hinge) const {
  return m->hinges[hinge].angle;
}

double PhysicsWorld::hingeVelocity(int hinge) const {
  const Impl::Hinge& h = m->hinges[hinge];
  const int ba = m->parts[h.d.partA].body, bb = m->parts[h.d.partB].body;
  const Vec3 axis = m->partPose(h.d.partA).rot * h.axisA;
  return (fromBt(m->bodies[bb].rb->getAngularVelocity()) - fromBt(m->bodies[ba].rb->getAngularVelocity()))
      .dot(axis);
}

double PhysicsWorld::hingeTorque(int hinge) const {
  return m->hinges[size_t(hinge)].torque;
}

bool PhysicsWorld::hingeSaturated(int hinge) const {
  return m->hinges[size_t(hinge)].saturated;
}

HingeQuality PhysicsWorld::hingeQuality() const {
  HingeQuality q;
  for (const Impl::Hinge& h : m->hinges) {
    if (!h.c && !h.link) continue;
    const Pose a = m->partPose(h.d.partA) * h.d.frameA;
    const Pose b = m->partPose(h.d.partB) * h.d.frameB;
    q.maxGap = std::max(q.maxGap, (a.pos - b.pos).norm());
    q.maxAngle = std::max(q.maxAngle, angleBetween(a.rot * Vec3::UnitZ(), b.rot * Vec3::UnitZ()));
  }
  return q;
}

BodyDivergence PhysicsWorld::divergenceScan(double maxSpeed, double maxAngularSpeed,
                                            double maxDistance) const {
  BodyDivergence out;
  const btAlignedObjectArray<btRigidBody*>& rbs = m->world.getNonStaticRigidBodies();
  const double v2max = maxSpeed * maxSpeed, w2max = maxAngularSpeed * maxAngularSpeed,
               d2max = maxDistance * maxDistance;
  auto sq = [](const btVector3& a) {
    return double(a.x()) * a.x() + double(a.y()) * a.y() + double(a.z()) * a.z();
  };
  auto sum = [](const btVector3& a) { return double(a.x()) + double(a.y()) + double(a.z()); };
  for (int i = 0, n = rbs.size(); i < n; ++i) {
    if (i + 4 < n) {  // with many modules the bodies have left the caches: the one 4 ahead's lines
      using namespace bullet_layout;
      fetchPose(rbs[i + 4]);
      fetch(rbs[i + 4], kActivation);
      fetchRange(rbs[i + 4], kVelocities, kVelocities + 32);
    }
    const btRigidBody* rb = rbs[i];
    if (rb->isStaticOrKinematicObject() || !rb->isActive()) continue;  // asleep: checked when it moved
    const btTransform& t = rb->getWorldTransform();
    const btVector3& p = t.getOrigin();
    const btMatrix3x3& r = t.getBasis();
    const btVector3& v = rb->getLinearVelocity();
    const btVector3& w = rb->getAngularVelocity();
    // Fast path: a sum of finite floats is finite in double, so one test covers 18 values; NaN
    // fails every comparison, so the bounds are tested as "not within".
    const double all = sum(p) + sum(r[0]) + sum(r[1]) + sum(r[2]) + sum(v) + sum(w);
    const double d2 = sq(p), v2 = sq(v), w2 = sq(w);
    if (std::isfinite(all) && d2 <= d2max && v2 <= v2max && w2 <= w2max) continue;
    auto finite = [](const btVector3& a) {
      return std::isfinite(a.x()) && std::isfinite(a.y()) && std::isfinite(a.z());
    };
    using K = BodyDivergence::Kind;
    if (!finite(p))
      out.kind = K::Position;
    else if (!finite(r[0]) || !finite(r[1]) || !finite(r[2]))
      out.kind = K::Orientation;
    else if (!finite(v) || !finite(w))
      out.kind = K::Velocity;
    else if (!(v2 <= v2max))
      out.kind = K::Speed, out.value = std::sqrt(v2);
    else if (!(w2 <= w2max))
      out.kind = K::AngularSpeed, out.value = std::sqrt(w2);
    else if (!(d2 <= d2max))
      out.kind = K::Bounds, out.value = std::sqrt(d2);
    else
      continue;  // a finite sum that overflowed (double-precision Bullet): nothing wrong
    const int b = rb->getUserIndex();
    if (b >= 0 && !m->bodies[size_t(b)].parts.empty()) {
      out.part = m->bodies[size_t(b)].parts.front();
      out.partsInBody = int(m->bodies[size_t(b)].parts.size());
    }
    return out;
  }
  return out;
}

void PhysicsWorld::collectColliders(ColliderSet& out) const {
  out.shapes.clear();
  out.bodies.clear();
  out.planes.clear();
  out.ground = m->groundFriction.has_value();
  out.groundFriction = float(m->groundFriction.value_or(0));
  // Hull planes of parts added since the last call (parts are never removed).
  for (size_t p = m->hullPlaneRanges.size(); p < m->parts.size(); ++p) {
    std::vector<std::pair<int, int>> ranges;
    for (btCollisionShape* s : m->parts[p].shapes) {
      const int begin = int(m->hullPlanes.size() / 4);
      if (s->getShapeType() == CONVEX_HULL_SHAPE_PROXYTYPE) {
        const auto* h = static_cast<const btConvexHullShape*>(s);
        btAlignedObjectArray<btVector3> points, planes;
        for (int i = 0; i < h->getNumPoints(); ++i) points.push_back(h->getUnscaledPoints()[i]);
        btGeometryUtil::getPlaneEquationsFromVertices(points, planes);
        for (int i = 0; i < planes.size(); ++i)  // n . x + w <= 0 inside
          for (float v :
               {float(planes[i].x()), float(planes[i].y()), float(planes[i].z()), float(-planes[i][3])})
            m->hullPlanes.push_back(v);
      }
      ranges.emplace_back(begin, int(m->hullPlanes.size() / 4) - begin);
    }
    m->hullPlaneRanges.push_back(std::move(ranges));
  }
  for (const Impl::Body& b : m->bodies) {
    if (!b.rb) continue;
    const btRigidBody* rb = b.rb;
    const bool dynamic = rb->getInvMass() > 0;
    const int bodyIndex = int(out.bodies.size());
    ColliderBody cb;
    cb.part = b.parts.front();
    cb.dynamic = dynamic;
    const btVector3 com = rb->getCenterOfMassPosition(), v = rb->getLinearVelocity(),
                    w = rb->getAngularVelocity();
    for (int k = 0; k < 3; ++k) {
      cb.com[k] = com[k];
      cb.linVel[k] = v[k];
      cb.angVel[k] = w[k];
    }
    out.bodies.push_back(cb);
    const btTransform bodyT = rb->getWorldTransform();
    for (int partId : b.parts) {
      const Impl::Part& p = m->parts[size_t(partId)];
      for (size_t k = 0; k < p.shapes.size(); ++k) {
        const btCollisionShape* s = p.shapes[k];
        ColliderShape c;
        c.dynamic = dynamic;
        c.body = bodyIndex;
        c.friction = float(p.friction);
        switch (s->getShapeType()) {
          case BOX_SHAPE_PROXYTYPE: {
            c.kind = ColliderShape::Box;
            const btVector3 e = static_cast<const btBoxShape*>(s)->getHalfExtentsWithMargin();
            for (int a = 0; a < 3; ++a) c.half[a] = float(e[a]);
            break;
          }
          case SPHERE_SHAPE_PROXYTYPE:
            c.kind = ColliderShape::Sphere;
            c.half[0] = float(static_cast<const btSphereShape*>(s)->getRadius());
            break;
          case CYLINDER_SHAPE_PROXYTYPE: {
            c.kind = ColliderShape::Cylinder;
            const btVector3 e = static_cast<const btCylinderShape*>(s)->getHalfExtentsWithMargin();
            c.half[0] = float(e.x());
            c.half[1] = float(e.z());
            break;
          }
          case CAPSULE_SHAPE_PROXYTYPE: {
            const auto* cap = static_cast<const btCapsuleShape*>(s);
            c.kind = ColliderShape::Capsule;
            c.half[0] = float(cap->getRadius());
            c.half[1] = float(cap->getHalfHeight());
            break;
          }
          case CONVEX_HULL_SHAPE_PROXYTYPE: {
            c.kind = ColliderShape::Hull;
            const auto [first, count] = m->hullPlaneRanges[size_t(partId)][k];
            c.planeBegin = int(out.planes.size() / 4);
            c.planeCount = count;
            out.planes.insert(out.planes.end(), m->hullPlanes.begin() + 4 * first,
                              m->hullPlanes.begin() + 4 * (first + count));
            break;
          }
          default:
            continue;  // shapes particles do not know (none today)
        }
        const btTransform t = bodyT * toBt(p.inBody * p.shapePoses[k]);
        const btMatrix3x3& r = t.getBasis();
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) c.rot[3 * i + j] = float(r[i][j]);
          c.pos[i] = float(t.getOrigin()[i]);
        }
        btVector3 lo, hi;
        s->getAabb(t, lo, hi);
        for (int i = 0; i < 3; ++i) {
          c.lo[i] = float(lo[i]);
          c.hi[i] = float(hi[i]);
        }
        out.shapes.push_back(c);
      }
    }
  }
}

}  // namespace rm3d
