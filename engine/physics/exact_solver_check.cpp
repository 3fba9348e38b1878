// The check behind the unit test "exact solver: its solver bodies are Bullet's" (the tests do
// not see Bullet's headers): ExactSolver::convertBodies against Bullet 3.24's convertBodies.
#include "physics/exact_solver_check.h"

#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "physics/exact_solver.h"

namespace rm3d {

namespace {

// Each solver's pool, as each solver's set-up leaves it before convertBodies (no fixed body yet).
template <class Solver>
struct Probe : Solver {
  void convert(std::vector<btCollisionObject*>& bodies, const btContactSolverInfo& info) {
    this->m_fixedBodyId = -1;
    this->convertBodies(bodies.data(), int(bodies.size()), info);
  }
  const btAlignedObjectArray<btSolverBody>& pool() const { return this->m_tmpSolverBodyPool; }
};

// The first field of the two solver bodies that differs, or "".
std::string firstDifference(const btSolverBody& a, const btSolverBody& b) {
  auto same = [](const btVector3& u, const btVector3& v) {
    return u.x() == v.x() && u.y() == v.y() && u.z() == v.z();
  };
  const btTransform ta = a.getWorldTransform(), tb = b.getWorldTransform();
  for (int r = 0; r < 3; ++r)
    if (!same(ta.getBasis()[r], tb.getBasis()[r])) return "basis row " + std::to_string(r);
  if (!same(ta.getOrigin(), tb.getOrigin())) return "origin";
  const std::pair<const char*, std::pair<btVector3, btVector3>> fields[] = {
      {"delta linear velocity", {a.m_deltaLinearVelocity, b.m_deltaLinearVelocity}},
      {"delta angular velocity", {a.m_deltaAngularVelocity, b.m_deltaAngularVelocity}},
      {"angular factor", {a.m_angularFactor, b.m_angularFactor}},
      {"linear factor", {a.m_linearFactor, b.m_linearFactor}},
      {"inverse mass", {a.m_invMass, b.m_invMass}},
      {"push velocity", {a.m_pushVelocity, b.m_pushVelocity}},
      {"turn velocity", {a.m_turnVelocity, b.m_turnVelocity}},
      {"linear velocity", {a.m_linearVelocity, b.m_linearVelocity}},
      {"angular velocity", {a.m_angularVelocity, b.m_angularVelocity}},
      {"external force impulse", {a.m_externalForceImpulse, b.m_externalForceImpulse}},
      {"external torque impulse", {a.m_externalTorqueImpulse, b.m_externalTorqueImpulse}},
  };
  for (const auto& [name, v] : fields)
    if (!same(v.first, v.second)) return name;
  if (a.m_originalBody != b.m_originalBody) return "original body";
  return "";
}

}  // namespace

std::string solverBodiesMismatch() {
  btBoxShape box(btVector3(0.05, 0.03, 0.02));
  std::vector<std::unique_ptr<btRigidBody>> owned;
  auto make = [&](double mass, const btVector3& at, const btVector3& spin) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) box.calculateLocalInertia(btScalar(mass), inertia);
    btRigidBody::btRigidBodyConstructionInfo ci(btScalar(mass), nullptr, &box, inertia);
    ci.m_startWorldTransform.setOrigin(at);
    ci.m_startWorldTransform.setRotation(btQuaternion(btVector3(1, 2, 3).normalized(), btScalar(0.7)));
    owned.push_back(std::make_unique<btRigidBody>(ci));
    btRigidBody* rb = owned.back().get();
    if (mass > 0) {
      rb->setLinearVelocity(btVector3(0.3, -0.2, 0.1));
      rb->setAngularVelocity(spin);  // (the gyroscopic impulse: its inertia is not a sphere's)
      rb->applyCentralForce(btVector3(0, 0, -9.81 * mass));
      rb->applyTorque(btVector3(0.01, 0.02, -0.03));
    }
    return rb;
  };
  btRigidBody* a = make(0.3, {0, 0, 0.1}, {2, -5, 7});
  btRigidBody* ground = make(0, {0, 0, -1}, {0, 0, 0});
  btRigidBody* b = make(0.2, {0.2, 0, 0.1}, {-4, 1, 3});
  btRigidBody* kinematic = make(0, {0.4, 0, 0.1}, {0, 0, 0});
  kinematic->setCollisionFlags(kinematic->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  kinematic->setLinearVelocity(btVector3(0.5, 0, 0));
  btRigidBody* c = make(0.25, {0.6, 0, 0.1}, {1, 1, -9});
  c->setFlags(c->getFlags() | BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD);
  btContactSolverInfo info;
  info.m_timeStep = btScalar(1.0 / 60);

  const std::vector<std::vector<btCollisionObject*>> lists = {
      {a, ground, b, kinematic, c},
      {ground, c, a},
      {a, b, c, b},  // b twice: a second gyroscopic impulse, after the first
  };
  for (size_t l = 0; l < lists.size(); ++l) {
    std::vector<btCollisionObject*> bodies = lists[l];
    const std::string where = "list " + std::to_string(l) + ": ";
    Probe<btSequentialImpulseConstraintSolver> bullet;
    bullet.convert(bodies, info);
    std::vector<int> ids;
    for (btCollisionObject* o : bodies) ids.push_back(o->getCompanionId());
    Probe<ExactSolver> ours;
    ours.convert(bodies, info);
    if (ours.pool().size() != bullet.pool().size())
      return where + std::to_string(ours.pool().size()) + " solver bodies, Bullet " +
             std::to_string(bullet.pool().size());
    for (size_t i = 0; i < bodies.size(); ++i)
      if (bodies[i]->getCompanionId() != ids[i])
        return where + "body " + std::to_string(i) + " took solver body " +
               std::to_string(bodies[i]->getCompanionId()) + ", Bullet " + std::to_string(ids[i]);
    for (int k = 0; k < bullet.pool().size(); ++k)
      if (const std::string d = firstDifference(ours.pool()[k], bullet.pool()[k]); !d.empty())
        return where + "solver body " + std::to_string(k) + ": " + d;
  }
  // The gyroscopic impulse was there to compare: a spinning body's torque impulse is not only
  // its applied torque times the step.
  Probe<btSequentialImpulseConstraintSolver> bullet;
  std::vector<btCollisionObject*> one = {a};
  bullet.convert(one, info);
  if (bullet.pool()[0].m_externalTorqueImpulse ==
      a->getInvInertiaTensorWorld() * a->getTotalTorque() * info.m_timeStep)
    return "no gyroscopic impulse to compare";
  return "";
}

}  // namespace rm3d
