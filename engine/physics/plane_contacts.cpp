// Polyhedron-plane contacts, every point in one step (see plane_contacts.h).
#include "physics/plane_contacts.h"

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/BroadphaseCollision/btCollisionAlgorithm.h>
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btBoxBoxCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btCompoundCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btDefaultCollisionConfiguration.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btPolyhedralConvexShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "physics/bullet_layout.h"
#include "physics/plane_contacts_check.h"

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
    // The hull's motion disc (Bullet's getAngularMotionDisc: its bounding sphere, through a box
    // about it, each call; shapes here do not change once made), kept for the shape it was taken of.
    if (shape != m_discShape) {
      m_disc = shape->getAngularMotionDisc();
      m_discShape = shape;
    }

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
      const btScalar arm = (hullInPlane.getOrigin() - centre).length() + m_disc;
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
                               std::abs(constant) + std::abs(margin) + m_disc;
      clear = (largest + btScalar(1)) * btScalar(1e-5);
    }
    // (A box's corners made here as btBoxShape::getVertex makes them, h x 1 - h x 0 = h and
    // h x 0 - h x 1 = -h, without its virtual call for each.)
    const bool box = shape->getShapeType() == BOX_SHAPE_PROXYTYPE;
    const btVector3 half =
        box ? static_cast<const btBoxShape*>(shape)->getHalfExtentsWithMargin() : btVector3();
    for (int i = 0; i < count; ++i) {
      if (points && along.dot(points[i]) + offset >= cutoff + clear) continue;
      btVector3 v;
      if (box)
        v.setValue(i & 1 ? -half.x() : half.x(), i & 2 ? -half.y() : half.y(), i & 4 ? -half.z() : half.z());
      else
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
  const btCollisionShape* m_discShape = nullptr;  // the shape m_disc was taken of
  btScalar m_disc = 0;                            // its angular motion disc
  btPersistentManifold* m_manifold;
  bool m_ownManifold = false;
  bool m_swapped;
};

/// Two boxes lie apart on some axis by more than a margin (1e-4 m and 1e-5 of the coordinates'
/// size: a child's box, taken through its own transform, may stick out of its compound's by a
/// float's rounding). False for anything not finite.
bool boxesApart(const btVector3& min0, const btVector3& max0, const btVector3& min1, const btVector3& max1) {
  btScalar size[3];
  for (int a = 0; a < 3; ++a)
    size[a] = std::abs(min0[a]) + std::abs(max0[a]) + std::abs(min1[a]) + std::abs(max1[a]);
  if (!std::isfinite(size[0] + size[1] + size[2])) return false;
  for (int a = 0; a < 3; ++a) {
    const btScalar slack = btScalar(1e-4) + btScalar(1e-5) * size[a];
    if (min0[a] > max1[a] + slack || min1[a] > max0[a] + slack) return true;
  }
  return false;
}

/// Bullet 3.24's box-box algorithm, which runs its separating-axis test on every pair each
/// substep, first comparing the two boxes' boxes where its manifold holds no point: apart, the
/// test would find no contact and the refresh that follows would have nothing to refresh, so
/// nothing happens either way. (In a snake, each module's inner halves and the next module's lie
/// within the broadphase's margin of each other, and never touch.)
class BoxBoxNearAlgorithm : public btBoxBoxCollisionAlgorithm {
 public:
  BoxBoxNearAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
                      const btCollisionObjectWrapper* body1)
      : btBoxBoxCollisionAlgorithm(nullptr, ci, body0, body1) {
    btManifoldArray own;
    getAllContactManifolds(own);
    m_manifold = own.size() > 0 ? own[0] : nullptr;
  }

  void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                        const btDispatcherInfo& info, btManifoldResult* result) override {
    if (m_manifold && m_manifold->getNumContacts() == 0) {
      btVector3 min0, max0, min1, max1;
      body0->getCollisionShape()->getAabb(body0->getWorldTransform(), min0, max0);
      body1->getCollisionShape()->getAabb(body1->getWorldTransform(), min1, max1);
      if (boxesApart(min0, max0, min1, max1)) return;
    }
    btBoxBoxCollisionAlgorithm::processCollision(body0, body1, info, result);
  }

 private:
  btPersistentManifold* m_manifold;  // the one the base made (if any), as getAllContactManifolds gives it
};

/// Bullet 3.24's compound algorithm, with the step both of the algorithms below take first as it
/// does: every child's manifolds refreshed (points that moved apart dropped), in child order.
class CompoundSteps : public btCompoundCollisionAlgorithm {
 public:
  using btCompoundCollisionAlgorithm::btCompoundCollisionAlgorithm;

 protected:
  /// A pair Bullet's own step takes: a compound with a box tree, a closest-points query, a child
  /// pair callback, or a compound changed since the children's algorithms were made.
  bool bulletsOwn(const btCompoundShape* compound, const btManifoldResult* result) const {
    return compound->getDynamicAabbTree() || result->m_closestPointDistanceThreshold > 0 ||
           gCompoundChildShapePairCallback || compound->getUpdateRevision() != m_compoundShapeRevision;
  }
  /// The compound's wrapper and the other shape's, from the pair in the dispatcher's order.
  std::pair<const btCollisionObjectWrapper*, const btCollisionObjectWrapper*> sides(
      const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1) const {
    return m_isSwapped ? std::pair{body1, body0} : std::pair{body0, body1};
  }
  static const btCompoundShape* compoundOf(const btCollisionObjectWrapper* wrap) {
    return static_cast<const btCompoundShape*>(wrap->getCollisionShape());
  }
  void refreshChildren(btManifoldResult* result) {
    for (int i = 0; i < m_childCollisionAlgorithms.size(); ++i) {
      if (!m_childCollisionAlgorithms[i]) continue;
      m_manifolds.resize(0);
      m_childCollisionAlgorithms[i]->getAllContactManifolds(m_manifolds);
      for (int m = 0; m < m_manifolds.size(); ++m)
        if (m_manifolds[m]->getNumContacts()) {
          result->setPersistentManifold(m_manifolds[m]);
          result->refreshContactPoints();
          result->setPersistentManifold(nullptr);
        }
    }
    m_manifolds.resize(0);
  }

 private:
  btManifoldArray m_manifolds;
};

/// Bullet 3.24's compound algorithm (a compound without its own box tree) against a convex shape
/// or another compound, with one box test first. Where the compound's box and the other shape's lie
/// apart, no child's box (inside the compound's) can touch the other's, and Bullet's algorithm would
/// refresh the children's manifolds, run no child, and let go of every child's algorithm, in child
/// order: that is done here without its two box tests per child. The pairs this takes are mostly
/// modules within the broadphase's margin of each other but not touching (in a snake, each module
/// and the two or three along from it). Where the boxes meet (within a margin far beyond a float's
/// rounding), Bullet's own runs.
class CompoundNearAlgorithm : public CompoundSteps {
 public:
  using CompoundSteps::CompoundSteps;

  void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                        const btDispatcherInfo& info, btManifoldResult* result) override {
    const auto [compoundWrap, otherWrap] = sides(body0, body1);
    const btCompoundShape* compound = compoundOf(compoundWrap);
    if (bulletsOwn(compound, result))
      return btCompoundCollisionAlgorithm::processCollision(body0, body1, info, result);
    btVector3 min0, max0, min1, max1;
    compound->getAabb(compoundWrap->getWorldTransform(), min0, max0);
    otherWrap->getCollisionShape()->getAabb(otherWrap->getWorldTransform(), min1, max1);
    if (!boxesApart(min0, max0, min1, max1))
      return btCompoundCollisionAlgorithm::processCollision(body0, body1, info, result);
    refreshChildren(result);
    const int children = m_childCollisionAlgorithms.size();
    for (int i = 0; i < children; ++i) {  // and its letting go of those no longer touching: all
      if (!m_childCollisionAlgorithms[i]) continue;
      m_childCollisionAlgorithms[i]->~btCollisionAlgorithm();
      m_dispatcher->freeCollisionAlgorithm(m_childCollisionAlgorithms[i]);
      m_childCollisionAlgorithms[i] = nullptr;
    }
  }
};

/// Bullet 3.24's compound algorithm against a static plane, without its box tests. For each child
/// Bullet compares the child's box with the plane's (which spans everything) twice a substep, once
/// before running the child's algorithm and once to let go of algorithms no longer touching: those
/// boxes, the plane's through a virtual call each time, and a second transform per child were 3.6%
/// of a 10-module snake's step, against 6% for the plane contacts themselves. Here the children run
/// in the same order with the same wrappers and shape identifiers, their manifolds refreshed first
/// as Bullet does, so the same contacts, bit for bit; anything else (a compound with its own box
/// tree, a closest-points query, a changed compound, a pose that is not finite) goes to Bullet's.
class CompoundPlaneAlgorithm : public CompoundSteps {
 public:
  using CompoundSteps::CompoundSteps;

  void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                        const btDispatcherInfo& info, btManifoldResult* result) override {
    const auto [compoundWrap, planeWrap] = sides(body0, body1);
    const btCompoundShape* compound = compoundOf(compoundWrap);
    const btTransform& pose = compoundWrap->getWorldTransform();
    if (bulletsOwn(compound, result) || !finite(pose) ||
        planeWrap->getCollisionShape()->getShapeType() != STATIC_PLANE_PROXYTYPE)
      return btCompoundCollisionAlgorithm::processCollision(body0, body1, info, result);
    const int children = m_childCollisionAlgorithms.size();
    if (children == 0) return;
    refreshChildren(result);
    // Each child, as btCompoundLeafCallback::ProcessChildShape runs it once the boxes overlap
    // (the plane's box spans every finite child's).
    const btCollisionObject* object = compoundWrap->getCollisionObject();
    for (int i = 0; i < children; ++i) {
      const btCollisionShape* child = compound->getChildShape(i);
      const btTransform childPose = pose * compound->getChildTransform(i);
      const btCollisionObjectWrapper childWrap(compoundWrap, child, object, childPose, -1, i);
      if (!m_childCollisionAlgorithms[i])
        m_childCollisionAlgorithms[i] =
            m_dispatcher->findAlgorithm(&childWrap, planeWrap, m_sharedManifold, BT_CONTACT_POINT_ALGORITHMS);
      const btCollisionObjectWrapper* kept;
      const bool first = result->getBody0Internal() == object;
      if (first) {
        kept = result->getBody0Wrap();
        result->setBody0Wrap(&childWrap);
        result->setShapeIdentifiersA(-1, i);
      } else {
        kept = result->getBody1Wrap();
        result->setBody1Wrap(&childWrap);
        result->setShapeIdentifiersB(-1, i);
      }
      m_childCollisionAlgorithms[i]->processCollision(&childWrap, planeWrap, info, result);
      if (first)
        result->setBody0Wrap(kept);
      else
        result->setBody1Wrap(kept);
    }
    // (Bullet then lets go of the algorithms of children whose boxes left the plane's: none can.)
  }

 private:
  static bool finite(const btTransform& t) {
    const btMatrix3x3& b = t.getBasis();
    btScalar sum = t.getOrigin().x() + t.getOrigin().y() + t.getOrigin().z();
    for (int r = 0; r < 3; ++r) sum += b[r].x() + b[r].y() + b[r].z();
    return std::isfinite(sum);
  }
};

}  // namespace

namespace {

/// A PlaneContactFuncs::Func's make: algorithm A for the pair, in the dispatcher's pool.
template <class A>
btCollisionAlgorithm* make(btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
                           const btCollisionObjectWrapper* body1, bool swapped) {
  void* mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(A));
  if constexpr (std::is_same_v<A, BoxBoxNearAlgorithm>)
    return new (mem) A(ci, body0, body1);
  else
    return new (mem) A(ci, body0, body1, swapped);
}

}  // namespace

void PlaneContactFuncs::registerWith(btCollisionDispatcher& dispatcher) {
  plain.make = swapped.make = &make<PlaneContactAlgorithm>;
  compoundPlain.make = compoundSwapped.make = &make<CompoundPlaneAlgorithm>;
  nearPlain.make = nearSwapped.make = &make<CompoundNearAlgorithm>;
  boxBox.make = &make<BoxBoxNearAlgorithm>;
  swapped.m_swapped = true;
  for (int type : {BOX_SHAPE_PROXYTYPE, CONVEX_HULL_SHAPE_PROXYTYPE}) {
    dispatcher.registerCollisionCreateFunc(type, STATIC_PLANE_PROXYTYPE, &plain);
    dispatcher.registerCollisionCreateFunc(STATIC_PLANE_PROXYTYPE, type, &swapped);
  }
  compoundSwapped.m_swapped = true;
  dispatcher.registerCollisionCreateFunc(COMPOUND_SHAPE_PROXYTYPE, STATIC_PLANE_PROXYTYPE, &compoundPlain);
  dispatcher.registerCollisionCreateFunc(STATIC_PLANE_PROXYTYPE, COMPOUND_SHAPE_PROXYTYPE, &compoundSwapped);
  nearSwapped.m_swapped = true;
  for (int type : {BOX_SHAPE_PROXYTYPE, CONVEX_HULL_SHAPE_PROXYTYPE, SPHERE_SHAPE_PROXYTYPE,
                   CYLINDER_SHAPE_PROXYTYPE, CAPSULE_SHAPE_PROXYTYPE}) {
    dispatcher.registerCollisionCreateFunc(COMPOUND_SHAPE_PROXYTYPE, type, &nearPlain);
    dispatcher.registerCollisionCreateFunc(type, COMPOUND_SHAPE_PROXYTYPE, &nearSwapped);
  }
  // Two compounds without box trees (every body made here): Bullet's compound-compound algorithm
  // hands such a pair to the compound algorithm (after making a pair cache it then leaves empty).
  dispatcher.registerCollisionCreateFunc(COMPOUND_SHAPE_PROXYTYPE, COMPOUND_SHAPE_PROXYTYPE, &nearPlain);
  dispatcher.registerCollisionCreateFunc(BOX_SHAPE_PROXYTYPE, BOX_SHAPE_PROXYTYPE, &boxBox);
}

namespace {

/// checkCompoundContacts' scene in one Bullet world: with Bullet's compound algorithms (`ours`
/// false) or with PlaneContactFuncs' (true); the plane algorithm for boxes and hulls in both.
struct CheckScene {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  PlaneContactFuncs funcs;  // (outlives the world's pairs)
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies;

  explicit CheckScene(bool ours) {
    funcs.registerWith(dispatcher);
    if (!ours) {  // Bullet's own for every pair with a compound, and for box against box
      for (int t = 0; t < MAX_BROADPHASE_COLLISION_TYPES; ++t) {
        dispatcher.registerCollisionCreateFunc(
            COMPOUND_SHAPE_PROXYTYPE, t, config.getCollisionAlgorithmCreateFunc(COMPOUND_SHAPE_PROXYTYPE, t));
        dispatcher.registerCollisionCreateFunc(
            t, COMPOUND_SHAPE_PROXYTYPE, config.getCollisionAlgorithmCreateFunc(t, COMPOUND_SHAPE_PROXYTYPE));
      }
      dispatcher.registerCollisionCreateFunc(
          BOX_SHAPE_PROXYTYPE, BOX_SHAPE_PROXYTYPE,
          config.getCollisionAlgorithmCreateFunc(BOX_SHAPE_PROXYTYPE, BOX_SHAPE_PROXYTYPE));
    }
    world.setGravity(btVector3(0, 0, btScalar(-9.81)));
    add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0, btTransform::getIdentity(), {});
    // Compounds of two boxes and a hull, as a module's links: one resting, one dropped turning, one
    // dropped on the first, one sliding up to it (their boxes apart, then meeting), one falling on
    // a box and a hull.
    add(compound(), 1.0, at(0, 0, 0.06, 0), btVector3(0, 0, 0));
    add(compound(), 1.0, at(0.6, 0, 0.4, 0.7), btVector3(0, 0, 0), btVector3(1.5, -2, 0.5));
    add(compound(), 1.0, at(0.03, 0.01, 0.25, 0.9), btVector3(0, 0, 0), btVector3(0.5, 0.3, 0));
    add(compound(), 1.0, at(-0.45, 0.02, 0.07, 0.2), btVector3(btScalar(2.5), 0, 0));
    add(compound(), 1.0, at(0, 0.8, 0.3, 1.1), btVector3(0, btScalar(-0.6), 0));
    add(std::make_unique<btBoxShape>(btVector3(0.04f, 0.04f, 0.04f)), 0.3, at(0, 0.45, 0.05, 0.3), {});
    // Two boxes: one resting, one sliding up to it (apart, then touching).
    add(std::make_unique<btBoxShape>(btVector3(0.03f, 0.02f, 0.02f)), 0.2, at(-0.5, 0.5, 0.021, 0), {});
    add(std::make_unique<btBoxShape>(btVector3(0.03f, 0.02f, 0.02f)), 0.2, at(-0.7, 0.51, 0.021, 0.3),
        btVector3(btScalar(1.6), 0, 0));
    auto hull = std::make_unique<btConvexHullShape>();
    for (float x : {-0.05f, 0.05f})
      for (float y : {-0.03f, 0.03f})
        for (float z : {-0.02f, 0.04f}) hull->addPoint(btVector3(x + 0.01f * z, y, z));
    add(std::move(hull), 0.2, at(0.1, 0.6, 0.2, -0.4), btVector3(0, 0.2f, -0.5f));
  }
  ~CheckScene() {
    for (auto& b : bodies) world.removeRigidBody(b.get());
  }

  static btTransform at(double x, double y, double z, double turn) {
    return btTransform(btQuaternion(btVector3(0.3f, 0.2f, 1).normalized(), btScalar(turn)),
                       btVector3(btScalar(x), btScalar(y), btScalar(z)));
  }

  std::unique_ptr<btCollisionShape> compound() {
    auto c = std::make_unique<btCompoundShape>(false, 3);
    auto box = std::make_unique<btBoxShape>(btVector3(0.05f, 0.03f, 0.02f));
    c->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(-0.06f, 0, 0)), box.get());
    auto box2 = std::make_unique<btBoxShape>(btVector3(0.02f, 0.04f, 0.03f));
    c->addChildShape(btTransform(btQuaternion(btVector3(0, 0, 1), 0.4f), btVector3(0.05f, 0.01f, 0.01f)),
                     box2.get());
    auto hull = std::make_unique<btConvexHullShape>();
    for (float x : {-0.03f, 0.03f})
      for (float y : {-0.02f, 0.02f})
        for (float z : {-0.02f, 0.02f}) hull->addPoint(btVector3(x, y + 0.3f * x, z));
    c->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0.01f, 0.05f, -0.01f)), hull.get());
    shapes.push_back(std::move(box));
    shapes.push_back(std::move(box2));
    shapes.push_back(std::move(hull));
    return c;
  }

  void add(std::unique_ptr<btCollisionShape> shape, double mass, const btTransform& pose, btVector3 velocity,
           btVector3 spin = btVector3(0, 0, 0)) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shape->calculateLocalInertia(btScalar(mass), inertia);
    btRigidBody::btRigidBodyConstructionInfo ci(btScalar(mass), nullptr, shape.get(), inertia);
    ci.m_startWorldTransform = pose;
    ci.m_friction = btScalar(0.8);
    auto body = std::make_unique<btRigidBody>(ci);
    body->setLinearVelocity(velocity);
    body->setAngularVelocity(spin);
    body->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(body.get());
    shapes.push_back(std::move(shape));
    bodies.push_back(std::move(body));
  }
};

bool sameBits(const btVector3& a, const btVector3& b) {
  return std::memcmp(&a, &b, 3 * sizeof(btScalar)) == 0;
}

}  // namespace

CompoundContactsCheck checkCompoundContacts(int steps) {
  CompoundContactsCheck out;
  CheckScene bullet(false), ours(true);
  auto fail = [&](int step, const std::string& what) {
    out.mismatch = "step " + std::to_string(step) + ": " + what;
  };
  for (int step = 0; step < steps && out.mismatch.empty(); ++step) {
    bullet.world.stepSimulation(btScalar(1.0 / 60), 0, btScalar(1.0 / 60));
    ours.world.stepSimulation(btScalar(1.0 / 60), 0, btScalar(1.0 / 60));
    ++out.steps;
    for (size_t i = 0; i < bullet.bodies.size() && out.mismatch.empty(); ++i) {
      const btRigidBody& a = *bullet.bodies[i];
      const btRigidBody& b = *ours.bodies[i];
      bool same = sameBits(a.getWorldTransform().getOrigin(), b.getWorldTransform().getOrigin()) &&
                  sameBits(a.getLinearVelocity(), b.getLinearVelocity()) &&
                  sameBits(a.getAngularVelocity(), b.getAngularVelocity());
      for (int r = 0; r < 3; ++r)
        same = same && sameBits(a.getWorldTransform().getBasis()[r], b.getWorldTransform().getBasis()[r]);
      if (!same) fail(step, "body " + std::to_string(i) + "'s pose or velocity");
    }
    if (!out.mismatch.empty()) break;
    if (bullet.dispatcher.getNumManifolds() != ours.dispatcher.getNumManifolds()) {
      fail(step, "manifolds " + std::to_string(bullet.dispatcher.getNumManifolds()) + " and " +
                     std::to_string(ours.dispatcher.getNumManifolds()));
      break;
    }
    for (int m = 0; m < bullet.dispatcher.getNumManifolds() && out.mismatch.empty(); ++m) {
      const btPersistentManifold* a = bullet.dispatcher.getManifoldByIndexInternal(m);
      const btPersistentManifold* b = ours.dispatcher.getManifoldByIndexInternal(m);
      if (a->getNumContacts() != b->getNumContacts()) {
        fail(step, "manifold " + std::to_string(m) + "'s points");
        break;
      }
      for (int k = 0; k < a->getNumContacts(); ++k) {
        const btManifoldPoint &pa = a->getContactPoint(k), &pb = b->getContactPoint(k);
        if (!sameBits(pa.m_positionWorldOnB, pb.m_positionWorldOnB) ||
            pa.m_appliedImpulse != pb.m_appliedImpulse || pa.m_index0 != pb.m_index0 ||
            pa.m_index1 != pb.m_index1)
          fail(step, "manifold " + std::to_string(m) + " point " + std::to_string(k));
      }
      out.contacts += a->getNumContacts();
      const int type0 = a->getBody0()->getCollisionShape()->getShapeType();
      const int type1 = a->getBody1()->getCollisionShape()->getShapeType();
      out.compoundTouches +=
          a->getNumContacts() > 0 && type0 == COMPOUND_SHAPE_PROXYTYPE && type1 == COMPOUND_SHAPE_PROXYTYPE;
      out.boxTouches +=
          a->getNumContacts() > 0 && type0 == BOX_SHAPE_PROXYTYPE && type1 == BOX_SHAPE_PROXYTYPE;
    }
    // Pairs in the broadphase whose boxes lie apart: with a compound (the way CompoundNearAlgorithm
    // skips Bullet's child boxes), or two boxes (BoxBoxNearAlgorithm's).
    const btBroadphasePairArray& pairs = ours.broadphase.getOverlappingPairCache()->getOverlappingPairArray();
    for (int p = 0; p < pairs.size(); ++p) {
      const auto* o0 = static_cast<const btCollisionObject*>(pairs[p].m_pProxy0->m_clientObject);
      const auto* o1 = static_cast<const btCollisionObject*>(pairs[p].m_pProxy1->m_clientObject);
      // Which pairs these algorithms took (in Bullet's world, none can be).
      btCollisionAlgorithm* algorithm = pairs[p].m_algorithm;
      out.planeTaken += dynamic_cast<CompoundPlaneAlgorithm*>(algorithm) != nullptr;
      out.nearTaken += dynamic_cast<CompoundNearAlgorithm*>(algorithm) != nullptr;
      out.boxTaken += dynamic_cast<BoxBoxNearAlgorithm*>(algorithm) != nullptr;
      const int type0 = o0->getCollisionShape()->getShapeType(),
                type1 = o1->getCollisionShape()->getShapeType();
      if (type0 == STATIC_PLANE_PROXYTYPE || type1 == STATIC_PLANE_PROXYTYPE) continue;
      btVector3 min0, max0, min1, max1;
      o0->getCollisionShape()->getAabb(o0->getWorldTransform(), min0, max0);
      o1->getCollisionShape()->getAabb(o1->getWorldTransform(), min1, max1);
      const bool apart = !TestAabbAgainstAabb2(min0, max0, min1, max1);
      if (type0 == COMPOUND_SHAPE_PROXYTYPE || type1 == COMPOUND_SHAPE_PROXYTYPE) out.nearSkips += apart;
      if (type0 == BOX_SHAPE_PROXYTYPE && type1 == BOX_SHAPE_PROXYTYPE) out.boxSkips += apart;
    }
  }
  return out;
}

}  // namespace rm3d
