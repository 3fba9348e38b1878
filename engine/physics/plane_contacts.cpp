// Polyhedron-plane contacts, every point in one step (see plane_contacts.h).
#include "physics/plane_contacts.h"

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/BroadphaseCollision/btCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btPolyhedralConvexShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <array>

#include "physics/bullet_layout.h"

namespace rm3d {

namespace {

constexpr int kMaxPoints = 4;       // a manifold's capacity
constexpr btScalar kBand = 0.002f;  // m: vertices this far above the deepest still count

struct Candidate {
  btVector3 point;  // on the plane, plane frame
  btScalar distance;
};

// Near-ties go to the candidate met first (the points the manifold already holds come first), so
// that a face with more than four vertices in the plane keeps the same four from step to step
// and their impulses warm-start the solver: picking afresh among equals made a resting SuperBot
// jitter at 0.2-0.4 rad/s.
constexpr btScalar kDeeper = 1e-4f;       // m
constexpr btScalar kFarther = 1e-3f;      // m
constexpr btScalar kLarger = 1.01f;       // area ratio
constexpr btScalar kSameVertex = 0.003f;  // m: a manifold point this close to a vertex is on it

/// Up to four of `c` (n of them) that span the largest area, as Box2D and Jolt reduce a manifold:
/// the deepest, the one farthest from it, the one farthest from their line, and the one that adds
/// the most area beyond an edge of that triangle. Writes their indices to `out`.
int reduce(const Candidate* c, int n, std::array<int, kMaxPoints>& out) {
  if (n <= kMaxPoints) {
    for (int i = 0; i < n; ++i) out[size_t(i)] = i;
    return n;
  }
  int a = 0;
  for (int i = 1; i < n; ++i)
    if (c[i].distance < c[a].distance - kDeeper) a = i;
  int b = -1;
  btScalar best = kFarther;
  for (int i = 0; i < n; ++i)
    if (const btScalar l = (c[i].point - c[a].point).length(); l > best + (b < 0 ? 0 : kFarther))
      best = l, b = i;
  out[0] = a;
  if (b < 0) return 1;  // all at one point
  out[1] = b;
  const btVector3 ab = c[b].point - c[a].point;
  int d = -1;
  best = 0;
  btVector3 side(0, 0, 0);
  for (int i = 0; i < n; ++i) {
    const btVector3 s = ab.cross(c[i].point - c[a].point);
    if (s.length() > best * kLarger + btScalar(1e-7)) best = s.length(), d = i, side = s;
  }
  if (d < 0) return 2;  // all on one line
  out[2] = d;
  const int tri[3] = {a, b, d};
  int e = -1;
  best = 0;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const btVector3& s = c[tri[k]].point;
      const btScalar outside = -(c[tri[(k + 1) % 3]].point - s).cross(c[i].point - s).dot(side);
      if (outside > best * kLarger + btScalar(1e-7)) best = outside, e = i;
    }
  }
  if (e < 0) return 3;
  out[3] = e;
  return 4;
}

class PlaneContactAlgorithm : public btCollisionAlgorithm {
 public:
  PlaneContactAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
                        const btCollisionObjectWrapper* body1, bool swapped)
      : btCollisionAlgorithm(ci), m_manifold(ci.m_manifold), m_swapped(swapped) {
    const btCollisionObjectWrapper* hull = swapped ? body1 : body0;
    const btCollisionObjectWrapper* plane = swapped ? body0 : body1;
    if (!m_manifold &&
        m_dispatcher->needsCollision(hull->getCollisionObject(), plane->getCollisionObject())) {
      m_manifold = m_dispatcher->getNewManifold(hull->getCollisionObject(), plane->getCollisionObject());
      m_ownManifold = true;
    }
    if (m_manifold) m_threshold = m_manifold->getContactBreakingThreshold();
  }
  ~PlaneContactAlgorithm() override {
    if (m_ownManifold && m_manifold) m_dispatcher->releaseManifold(m_manifold);
  }

  void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                        const btDispatcherInfo& info, btManifoldResult* result) override {
    if (!m_manifold) return;
    // The manifold's points, which its refresh below reads and writes, fetched while the hull's
    // vertices are measured (with many modules they have left the caches since the last step).
    bullet_layout::fetchRange(m_manifold, 0, bullet_layout::kManifoldCount + 4);
    const btCollisionObjectWrapper* hullWrap = m_swapped ? body1 : body0;
    const btCollisionObjectWrapper* planeWrap = m_swapped ? body0 : body1;
    const auto* shape = static_cast<const btPolyhedralConvexShape*>(hullWrap->getCollisionShape());
    const auto* plane = static_cast<const btStaticPlaneShape*>(planeWrap->getCollisionShape());
    const btVector3& normal = plane->getPlaneNormal();
    const btScalar constant = plane->getPlaneConstant();
    const btTransform hullInPlane = planeWrap->getWorldTransform().inverse() * hullWrap->getWorldTransform();
    // A box's vertices include its margin; a hull's points are inside it by the margin.
    const btScalar margin = shape->getShapeType() == BOX_SHAPE_PROXYTYPE ? btScalar(0) : shape->getMargin();
    const btScalar threshold = m_ownManifold ? m_threshold : m_manifold->getContactBreakingThreshold();
    result->setPersistentManifold(m_manifold);

    // Speculative contacts: a vertex closing on the plane makes a contact as far out as it
    // closes in kAhead steps, where that is beyond the threshold. A link falling 8 mm in a step
    // (0.5 m/s at 1/60 s) otherwise went 4 mm into the ground before it had a contact, and the
    // rebound loaded its dock 72 N in one step; the solver lets a contact that is still apart
    // close by its distance within the step, so the link lands on the plane instead. (The
    // hull's motion in the plane's frame; at rest nothing changes.)
    const btRigidBody* body = btRigidBody::upcast(hullWrap->getCollisionObject());
    bool ahead = m_ownManifold && body && info.m_timeStep > 0;
    const btMatrix3x3 toPlane = planeWrap->getWorldTransform().getBasis().transpose();
    const btVector3 linear = ahead ? toPlane * body->getLinearVelocity() : btVector3(0, 0, 0);
    const btVector3 angular = ahead ? toPlane * body->getAngularVelocity() : btVector3(0, 0, 0);
    const btVector3 centre =
        ahead ? planeWrap->getWorldTransform().invXform(body->getCenterOfMassPosition()) : btVector3(0, 0, 0);
    const btScalar stepAhead = ahead ? info.m_timeStep * kAhead : 0;
    // No vertex closes farther than this in kAhead steps (a bound, with a margin): a hull at rest,
    // or nearly, makes no speculative contact, and far vertices are not looked at.
    btScalar farthest = 0;
    if (ahead) {
      const btScalar arm = (hullInPlane.getOrigin() - centre).length() + shape->getAngularMotionDisc();
      // (w x r) . n = r . (n x w): only the turning about axes in the plane brings a point closer.
      const btScalar fastest =
          std::max(btScalar(0), -normal.dot(linear)) + normal.cross(angular).length() * arm;
      farthest = fastest * stepAhead * btScalar(1.01);
      ahead = farthest > threshold;
    }

    // Every vertex within the threshold; the deepest is kept even when the buffer is full.
    constexpr int kBuffer = 64;
    Candidate c[kBuffer];
    int n = 0;
    const int count = shape->getNumVertices();
    const btScalar cutoff = ahead ? farthest : threshold;
    // A hull's points are first measured against the plane by one dot product each (the normal
    // taken into the hull's frame): a point clear of the cutoff by more than that sum's rounding
    // error is not looked at again; the rest are measured as before (so the same points pass, with
    // the same distances).
    const btVector3* points = nullptr;
    btVector3 along(0, 0, 0);
    btScalar offset = 0, clear = 0;
    if (shape->getShapeType() == CONVEX_HULL_SHAPE_PROXYTYPE) {
      const auto* hull = static_cast<const btConvexHullShape*>(shape);
      points = hull->getUnscaledPoints();
      along = (hullInPlane.getBasis().transpose() * normal) * hull->getLocalScaling();
      offset = normal.dot(hullInPlane.getOrigin()) - constant - margin;
      // (Every term of either sum is within the hull's origin in the plane's frame plus its motion
      // disc, the plane's constant and the margin: a tilted plane's normal meets the origin's
      // far coordinates too. 1e-5 of that is about 80 times a float's rounding.)
      const btVector3& origin = hullInPlane.getOrigin();
      const btScalar largest = std::abs(origin.x()) + std::abs(origin.y()) + std::abs(origin.z()) +
                               std::abs(constant) + std::abs(margin) + shape->getAngularMotionDisc();
      clear = (largest + btScalar(1)) * btScalar(1e-5);
    }
    for (int i = 0; i < count; ++i) {
      if (points && along.dot(points[i]) + offset >= cutoff + clear) continue;
      btVector3 v;
      shape->getVertex(i, v);
      const btVector3 p = hullInPlane(v);
      const btScalar distance = normal.dot(p) - constant - margin;
      if (distance >= cutoff) continue;
      if (distance >= threshold && distance >= -normal.dot(linear + angular.cross(p - centre)) * stepAhead)
        continue;
      const Candidate cand{p - (distance + margin) * normal, distance};
      if (n < kBuffer) {
        c[n++] = cand;
        continue;
      }
      int shallowest = 0;
      for (int k = 1; k < n; ++k)
        if (c[k].distance > c[shallowest].distance) shallowest = k;
      if (cand.distance < c[shallowest].distance) c[shallowest] = cand;
    }
    // Only points near the deepest: a rounded hull (an ATRON rolling on its equator) would
    // otherwise hold speculative points on the rings above the one it rolls on.
    if (n > 1) {
      btScalar deepest = c[0].distance;
      for (int i = 1; i < n; ++i) deepest = std::min(deepest, c[i].distance);
      int m = 0;
      for (int i = 0; i < n; ++i)
        if (c[i].distance <= deepest + kBand) c[m++] = c[i];
      n = m;
    }
    // The manifold's points first (matched by the vertex they sit on).
    const btCollisionObject* hullObject = hullWrap->getCollisionObject();
    const bool hullIsA = m_manifold->getBody0() == hullObject;
    // (Each manifold point in the world once, not once per candidate.)
    btVector3 onHull[MANIFOLD_CACHE_SIZE];
    const int manifoldPoints = std::min(m_manifold->getNumContacts(), int(MANIFOLD_CACHE_SIZE));
    for (int k = 0; k < manifoldPoints; ++k) {
      const btManifoldPoint& mp = m_manifold->getContactPoint(k);
      onHull[k] = hullObject->getWorldTransform() * (hullIsA ? mp.m_localPointA : mp.m_localPointB);
    }
    int held = 0;
    for (int i = 0; i < n && held < n; ++i) {
      const btVector3 vertex =
          planeWrap->getWorldTransform() * (c[i].point + (c[i].distance + margin) * normal);
      for (int k = 0; k < manifoldPoints; ++k) {
        if ((onHull[k] - vertex).length2() < kSameVertex * kSameVertex) {
          std::swap(c[i], c[held++]);
          break;
        }
      }
    }
    // The manifold keeps (and matches old points within) its own threshold, or as far as its
    // farthest speculative point and kMargin: a hull at rest keeps its points as before.
    btScalar reach = threshold;
    for (int i = 0; i < n; ++i)
      if (c[i].distance >= threshold) reach = std::max(reach, c[i].distance + kMargin);
    if (m_ownManifold) m_manifold->setContactBreakingThreshold(reach);
    std::array<int, kMaxPoints> keep{};
    const int kept = reduce(c, n, keep);
    const btVector3 normalWorld = planeWrap->getWorldTransform().getBasis() * normal;
    for (int k = 0; k < kept; ++k) {
      const Candidate& p = c[keep[size_t(k)]];
      result->addContactPoint(normalWorld, planeWrap->getWorldTransform() * p.point, p.distance);
    }
    if (m_ownManifold && m_manifold->getNumContacts()) result->refreshContactPoints();
  }

  btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                 btManifoldResult*) override {
    return 1;
  }

  void getAllContactManifolds(btManifoldArray& manifolds) override {
    if (m_manifold && m_ownManifold) manifolds.push_back(m_manifold);
  }

 private:
  static constexpr btScalar kAhead = 1.5f;    // steps
  static constexpr btScalar kMargin = 1e-4f;  // m: the manifold keeps a point this far beyond its farthest
  btScalar m_threshold = 0;                   // the manifold's own breaking threshold
  btPersistentManifold* m_manifold;
  bool m_ownManifold = false;
  bool m_swapped;
};

}  // namespace

btCollisionAlgorithm* PlaneContactFuncs::Func::CreateCollisionAlgorithm(
    btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
    const btCollisionObjectWrapper* body1) {
  void* mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(PlaneContactAlgorithm));
  return new (mem) PlaneContactAlgorithm(ci, body0, body1, m_swapped);
}

void PlaneContactFuncs::registerWith(btCollisionDispatcher& dispatcher) {
  swapped.m_swapped = true;
  for (int type : {BOX_SHAPE_PROXYTYPE, CONVEX_HULL_SHAPE_PROXYTYPE}) {
    dispatcher.registerCollisionCreateFunc(type, STATIC_PLANE_PROXYTYPE, &plain);
    dispatcher.registerCollisionCreateFunc(STATIC_PLANE_PROXYTYPE, type, &swapped);
  }
}

}  // namespace rm3d
