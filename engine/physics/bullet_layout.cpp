// The check that physics/bullet_layout.h names the right fields (see there).
#include "physics/bullet_layout.h"

#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/ConstraintSolver/btPoint2PointConstraint.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include "core/read_at.h"

namespace rm3d::bullet_layout {

namespace {

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
  check(readAt<const btCollisionShape*>(&a, kShape) == &sphere, "kShape: the shape", 0);
  a.setIslandTag(12345);
  check(readAt<int>(&a, kIslandTag) == 12345, "kIslandTag: the island tag", readAt<int>(&a, kIslandTag));
  for (int state : {DISABLE_DEACTIVATION, ISLAND_SLEEPING}) {
    a.forceActivationState(state);
    check(readAt<int>(&a, kActivation) == state, "kActivation: the activation state",
          readAt<int>(&a, kActivation));
  }
  a.setUserIndex(2468);
  check(readAt<int>(&a, kUserIndex) == 2468, "kUserIndex: the user index", readAt<int>(&a, kUserIndex));
  a.setCompanionId(4321);
  check(readAt<int>(&a, kCompanionId) == 4321, "kCompanionId: the companion id",
        readAt<int>(&a, kCompanionId));
  a.setMassProps(4, btVector3(1, 1, 1));
  check(readAt<float>(&a, kInverseMass) == 0.25f, "kInverseMass: the inverse mass",
        (long long)(1000 * readAt<float>(&a, kInverseMass)));
  check(readAt<int>(&a, kInternalType) == btCollisionObject::CO_RIGID_BODY, "kInternalType: the type",
        readAt<int>(&a, kInternalType));
  check(offsetOf(&a, &a.getLinearVelocity()) == kVelocities, "kVelocities: the linear velocity",
        offsetOf(&a, &a.getLinearVelocity()));
  check(offsetOf(&a, &a.getAngularVelocity()) == kVelocities + 16, "kVelocities + 16: the angular velocity",
        offsetOf(&a, &a.getAngularVelocity()));
  // The joints: their count (btAlignedObjectArray's size, after its empty allocator) and the
  // collision check that a joint turns on.
  btPoint2PointConstraint joint(a, b, btVector3(0, 0, 0), btVector3(0, 0, 0.2f));
  for (int refs : {0, 1}) {
    if (refs == 1) a.addConstraintRef(&joint);
    check(readAt<int>(&a, kConstraintRefs + 4) == refs, "kConstraintRefs: the joint count",
          readAt<int>(&a, kConstraintRefs + 4));
    check(readAt<int>(&a, kCollideWith) == refs, "kCollideWith: the collision check",
          readAt<int>(&a, kCollideWith));
  }
  const auto* const* ignored = readAt<const btCollisionObject* const*>(&a, kIgnoreList);
  check(a.getNumObjectsWithoutCollision() == 1 && ignored && ignored[0] == a.getObjectWithoutCollision(0),
        "kIgnoreList: the bodies without a collision check", a.getNumObjectsWithoutCollision());
  a.removeConstraintRef(&joint);
  btPersistentManifold m(&a, &b, 0, 0.02f, 0.02f);
  check(readAt<const btCollisionObject*>(&m, kManifoldBodies) == &a, "kManifoldBodies: body 0", 0);
  check(readAt<const btCollisionObject*>(&m, kManifoldBodies + 8) == &b, "kManifoldBodies + 8: body 1", 0);
  for (int points : {0, 1}) {
    if (points == 1)
      m.addManifoldPoint(btManifoldPoint(btVector3(0, 0, 0), btVector3(0, 0, 0), btVector3(0, 0, 1), -0.01f));
    check(readAt<int>(&m, kManifoldCount) == points, "kManifoldCount: the point count",
          readAt<int>(&m, kManifoldCount));
  }
  return out;
}

}  // namespace rm3d::bullet_layout
