// The check that physics/bullet_layout.h names the right fields (see there).
#include "physics/bullet_layout.h"

#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/ConstraintSolver/btPoint2PointConstraint.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <cstring>

namespace rm3d::bullet_layout {

namespace {

template <class T>
T read(const void* p, int offset) {
  T v;
  std::memcpy(&v, static_cast<const char*>(p) + offset, sizeof v);
  return v;
}

int offsetOf(const void* base, const void* field) {
  return int(static_cast<const char*>(field) - static_cast<const char*>(base));
}

}  // namespace

std::string mismatch() {
  std::string out;
  auto check = [&](bool ok, const char* what, long long held) {
    if (!ok && out.empty()) out = std::string(what) + " (held " + std::to_string(held) + ")";
  };
  btSphereShape sphere(0.1f);
  btRigidBody a(1, nullptr, &sphere), b(1, nullptr, &sphere);
  check(offsetOf(&a, &a.getWorldTransform()) == kPose, "kPose: the world transform",
        offsetOf(&a, &a.getWorldTransform()));
  check(read<const btCollisionShape*>(&a, kShape) == &sphere, "kShape: the shape", 0);
  a.setIslandTag(12345);
  check(read<int>(&a, kIslandTag) == 12345, "kIslandTag: the island tag", read<int>(&a, kIslandTag));
  for (int state : {DISABLE_DEACTIVATION, ISLAND_SLEEPING}) {
    a.forceActivationState(state);
    check(read<int>(&a, kActivation) == state, "kActivation: the activation state",
          read<int>(&a, kActivation));
  }
  a.setCompanionId(4321);
  check(read<int>(&a, kCompanionId) == 4321, "kCompanionId: the companion id", read<int>(&a, kCompanionId));
  a.setMassProps(4, btVector3(1, 1, 1));
  check(read<float>(&a, kInverseMass) == 0.25f, "kInverseMass: the inverse mass",
        (long long)(1000 * read<float>(&a, kInverseMass)));
  check(read<int>(&a, kInternalType) == btCollisionObject::CO_RIGID_BODY, "kInternalType: the type",
        read<int>(&a, kInternalType));
  check(offsetOf(&a, &a.getLinearVelocity()) == kVelocities, "kVelocities: the linear velocity",
        offsetOf(&a, &a.getLinearVelocity()));
  check(offsetOf(&a, &a.getAngularVelocity()) == kVelocities + 16, "kVelocities + 16: the angular velocity",
        offsetOf(&a, &a.getAngularVelocity()));
  // The joints: their count (btAlignedObjectArray's size, after its empty allocator) and the
  // collision check that a joint turns on.
  btPoint2PointConstraint joint(a, b, btVector3(0, 0, 0), btVector3(0, 0, 0.2f));
  for (int refs : {0, 1}) {
    if (refs == 1) a.addConstraintRef(&joint);
    check(read<int>(&a, kConstraintRefs + 4) == refs, "kConstraintRefs: the joint count",
          read<int>(&a, kConstraintRefs + 4));
    check(read<int>(&a, kCollideWith) == refs, "kCollideWith: the collision check",
          read<int>(&a, kCollideWith));
  }
  a.removeConstraintRef(&joint);
  btPersistentManifold m(&a, &b, 0, 0.02f, 0.02f);
  check(read<const btCollisionObject*>(&m, kManifoldBodies) == &a, "kManifoldBodies: body 0", 0);
  check(read<const btCollisionObject*>(&m, kManifoldBodies + 8) == &b, "kManifoldBodies + 8: body 1", 0);
  for (int points : {0, 1}) {
    if (points == 1)
      m.addManifoldPoint(btManifoldPoint(btVector3(0, 0, 0), btVector3(0, 0, 0), btVector3(0, 0, 1), -0.01f));
    check(read<int>(&m, kManifoldCount) == points, "kManifoldCount: the point count",
          read<int>(&m, kManifoldCount));
  }
  return out;
}

}  // namespace rm3d::bullet_layout
