// Where Bullet 3.24 (Debian 12's) keeps the fields that the passes over many bodies read, for
// fetching them ahead (__builtin_prefetch). With 10,000 modules the bodies, manifolds and
// broadphase proxies no longer fit in the caches, and a pass that reaches them in an order other
// than memory's waits on each. The fields are protected or private, so their places are written
// here (measured with offsetof, and checked by tests/engine/physics/bullet_layout_test.cpp); a
// fetch of the wrong line is only a fetch wasted, never a wrong result.
#pragma once

#include <string>

namespace rm3d::bullet_layout {

// btCollisionObject (a btRigidBody begins with one).
constexpr int kPose = 8;            ///< m_worldTransform: 64 bytes
constexpr int kShape = 200;         ///< m_collisionShape
constexpr int kIslandTag = 228;     ///< m_islandTag1
constexpr int kCompanionId = 232;   ///< m_companionId (a body's solver body, in a solver group)
constexpr int kActivation = 240;    ///< m_activationState1
constexpr int kInternalType = 272;  ///< m_internalType
constexpr int kUserIndex = 292;     ///< m_userIndex
constexpr int kCollideWith = 312;   ///< m_checkCollideWith
constexpr int kIgnoreList = 336;    ///< m_objectsWithoutCollisionCheck's array (what checkCollideWith reads)
// btRigidBody.
constexpr int kVelocities = 420;      ///< m_linearVelocity, then m_angularVelocity
constexpr int kInverseMass = 452;     ///< m_inverseMass
constexpr int kConstraintRefs = 600;  ///< m_constraintRefs
// btPersistentManifold.
constexpr int kManifoldBodies = 840;  ///< m_body0, m_body1
constexpr int kManifoldCount = 856;   ///< m_cachedPoints

/// Empty when every place above holds what Bullet's public calls set or return (on bodies and a
/// manifold made for the check); else the first place that does not, and what it held.
std::string mismatch();

/// Fetches the cache line that holds byte `at` of `p`.
inline void fetch(const void* p, int at) {
  __builtin_prefetch(static_cast<const char*>(p) + at);
}

/// Fetches the lines that hold bytes [from, to) of `p`.
inline void fetchRange(const void* p, int from, int to) {
  for (int at = from; at < to; at += 64) fetch(p, at);
  fetch(p, to - 1);
}

/// Fetches the lines of a body's pose (64 bytes from kPose: one line or two).
inline void fetchPose(const void* body) {
  fetch(body, kPose);
  fetch(body, kPose + 63);
}

}  // namespace rm3d::bullet_layout
