// The checks behind the unit tests "exact solver: its solver bodies are Bullet's" and "... its
// contact rows are Bullet's" (the tests do not see Bullet's headers): ExactSolver::convertBodies
// and convertContacts against Bullet 3.24's.
#include "physics/exact_solver_check.h"

#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
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
  // The solver bodies, then the contact rows of `manifolds`.
  void convertContacts(std::vector<btCollisionObject*>& bodies, std::vector<btPersistentManifold*>& manifolds,
                       const btContactSolverInfo& info) {
    for (btCollisionObject* o : bodies) o->setCompanionId(-1);
    convert(bodies, info);
    this->convertContacts(manifolds.data(), int(manifolds.size()), info);
  }
  using Solver::convertContacts;
  const btAlignedObjectArray<btSolverConstraint>& contacts() const {
    return this->m_tmpSolverContactConstraintPool;
  }
  const btAlignedObjectArray<btSolverConstraint>& friction() const {
    return this->m_tmpSolverContactFrictionConstraintPool;
  }
  int rollingRows() const { return this->m_tmpSolverContactRollingFrictionConstraintPool.size(); }
};

// Whether two vectors are the same bits (as numbers: 0 and -0 alike).
bool same(const btVector3& u, const btVector3& v) {
  return u.x() == v.x() && u.y() == v.y() && u.z() == v.z();
}

// The first field of the two contact rows that differs, or "".
std::string firstDifference(const btSolverConstraint& a, const btSolverConstraint& b) {
  const std::pair<const char*, std::pair<btVector3, btVector3>> vectors[] = {
      {"relpos1 x normal", {a.m_relpos1CrossNormal, b.m_relpos1CrossNormal}},
      {"normal 1", {a.m_contactNormal1, b.m_contactNormal1}},
      {"relpos2 x normal", {a.m_relpos2CrossNormal, b.m_relpos2CrossNormal}},
      {"normal 2", {a.m_contactNormal2, b.m_contactNormal2}},
      {"angular component A", {a.m_angularComponentA, b.m_angularComponentA}},
      {"angular component B", {a.m_angularComponentB, b.m_angularComponentB}},
  };
  for (const auto& [name, v] : vectors)
    if (!same(v.first, v.second)) return name;
  const std::pair<const char*, std::pair<btScalar, btScalar>> scalars[] = {
      {"applied push impulse", {a.m_appliedPushImpulse, b.m_appliedPushImpulse}},
      {"applied impulse", {a.m_appliedImpulse, b.m_appliedImpulse}},
      {"friction", {a.m_friction, b.m_friction}},
      {"jacobian diagonal", {a.m_jacDiagABInv, b.m_jacDiagABInv}},
      {"rhs", {a.m_rhs, b.m_rhs}},
      {"cfm", {a.m_cfm, b.m_cfm}},
      {"lower limit", {a.m_lowerLimit, b.m_lowerLimit}},
      {"upper limit", {a.m_upperLimit, b.m_upperLimit}},
      {"rhs penetration", {a.m_rhsPenetration, b.m_rhsPenetration}},
  };
  for (const auto& [name, v] : scalars)
    if (!(v.first == v.second)) return name;
  if (a.m_originalContactPoint != b.m_originalContactPoint) return "contact point";
  if (a.m_solverBodyIdA != b.m_solverBodyIdA || a.m_solverBodyIdB != b.m_solverBodyIdB)
    return "solver bodies";
  if (a.m_frictionIndex != b.m_frictionIndex) return "friction index";
  return "";
}

// The first field of the two solver bodies that differs, or "".
std::string firstDifference(const btSolverBody& a, const btSolverBody& b) {
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

std::string contactRowsMismatch() {
  btBoxShape box(btVector3(0.05, 0.03, 0.02));
  std::vector<std::unique_ptr<btRigidBody>> owned;
  auto make = [&](double mass, const btVector3& at, const btVector3& v, const btVector3& w) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) box.calculateLocalInertia(btScalar(mass), inertia);
    btRigidBody::btRigidBodyConstructionInfo ci(btScalar(mass), nullptr, &box, inertia);
    ci.m_startWorldTransform.setOrigin(at);
    ci.m_startWorldTransform.setRotation(btQuaternion(btVector3(1, 2, 3).normalized(), btScalar(0.3)));
    owned.push_back(std::make_unique<btRigidBody>(ci));
    btRigidBody* rb = owned.back().get();
    if (mass > 0) rb->setLinearVelocity(v), rb->setAngularVelocity(w);
    return rb;
  };
  btRigidBody* ground = make(0, {0, 0, -1}, {}, {});
  btRigidBody* wall = make(0, {1, 0, 0}, {}, {});
  btRigidBody* a = make(0.3, {0, 0, 0.02}, {0.2, -0.1, 0}, {0.5, 1, -2});  // sliding
  btRigidBody* b = make(0.2, {0.3, 0, 0.02}, {0, 0, 0}, {0, 0, 0});        // at rest: any directions
  // Points: on the ground (one warm-started, one beyond the processing threshold), between the
  // bodies (rolling friction: Bullet makes its rolling rows, which the patches never read), and
  // between two static bodies (no rows).
  auto point = [](btPersistentManifold& m, const btVector3& onA, const btVector3& onB,
                  const btVector3& normal, btScalar distance, btScalar warm, btScalar rolling) {
    btManifoldPoint p(btVector3(0, 0, 0), btVector3(0, 0, 0), normal, distance);
    p.m_positionWorldOnA = onA;
    p.m_positionWorldOnB = onB;
    p.m_combinedFriction = btScalar(0.8);
    p.m_combinedRestitution = btScalar(0.1);
    p.m_combinedRollingFriction = rolling;
    p.m_combinedSpinningFriction = rolling;
    p.m_appliedImpulse = warm;
    p.m_appliedImpulseLateral1 = btScalar(0.3);  // (not a warm start: Bullet's friction rows start at 0)
    m.addManifoldPoint(p);
  };
  btPersistentManifold onGround(a, ground, 0, btScalar(0.02), btScalar(0.01));
  point(onGround, {0.04, 0.02, -0.001}, {0.04, 0.02, -0.0005}, {0, 0, 1}, btScalar(-0.0005), btScalar(0.05),
        0);
  point(onGround, {-0.04, 0.02, -0.001}, {-0.04, 0.02, -0.0008}, {0, 0, 1}, btScalar(-0.0002), 0, 0);
  point(onGround, {-0.04, -0.02, 0.02}, {-0.04, -0.02, 0}, {0, 0, 1}, btScalar(0.02), 0, 0);
  btPersistentManifold between(a, b, 0, btScalar(0.02), btScalar(0.01));
  point(between, {0.15, 0, 0.02}, {0.151, 0, 0.02}, {-1, 0, 0}, btScalar(-0.001), btScalar(0.01),
        btScalar(0.05));
  btPersistentManifold bodyOnGround(b, ground, 0, btScalar(0.02), btScalar(0.01));
  point(bodyOnGround, {0.3, 0, -0.001}, {0.3, 0, 0}, {0, 0, 1}, btScalar(-0.001), 0, 0);
  btPersistentManifold statics(ground, wall, 0, btScalar(0.02), btScalar(0.01));
  point(statics, {1, 0, 0}, {1, 0, 0}, {0, 0, 1}, btScalar(-0.001), 0, 0);
  std::vector<btPersistentManifold*> manifolds = {&onGround, &between, &bodyOnGround, &statics};
  std::vector<btCollisionObject*> bodies = {a, ground, b, wall};
  btContactSolverInfo info;
  info.m_timeStep = btScalar(1.0 / 60);
  info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;

  // Each manifold's points' friction directions after Bullet's conversion, then after ours (the
  // points are the same objects: unset before each).
  auto directions = [&] {
    std::vector<btVector3> d;
    for (btPersistentManifold* m : manifolds)
      for (int j = 0; j < m->getNumContacts(); ++j)
        d.push_back(m->getContactPoint(j).m_lateralFrictionDir1),
            d.push_back(m->getContactPoint(j).m_lateralFrictionDir2);
    return d;
  };
  auto unset = [&] {
    for (btPersistentManifold* m : manifolds)
      for (int j = 0; j < m->getNumContacts(); ++j)
        m->getContactPoint(j).m_lateralFrictionDir1 = m->getContactPoint(j).m_lateralFrictionDir2 =
            btVector3(9, 9, 9);
  };
  unset();
  Probe<btSequentialImpulseConstraintSolver> bullet;
  bullet.convertContacts(bodies, manifolds, info);
  const std::vector<btVector3> bulletDirections = directions();
  unset();
  Probe<ExactSolver> ours;
  ours.patches = true;
  ours.convertContacts(bodies, manifolds, info);
  if (ours.contacts().size() != bullet.contacts().size())
    return std::to_string(ours.contacts().size()) + " contact rows, Bullet " +
           std::to_string(bullet.contacts().size());
  if (bullet.contacts().size() != 4)
    return "Bullet made " + std::to_string(bullet.contacts().size()) + " rows, not 4";
  if (bullet.rollingRows() != 3 || ours.rollingRows() != 0)
    return "rolling rows: Bullet " + std::to_string(bullet.rollingRows()) + " (3 expected), ours " +
           std::to_string(ours.rollingRows());
  for (int k = 0; k < bullet.contacts().size(); ++k)
    if (const std::string d = firstDifference(ours.contacts()[k], bullet.contacts()[k]); !d.empty())
      return "contact row " + std::to_string(k) + ": " + d;
  if (ours.friction().size() != bullet.friction().size())
    return std::to_string(ours.friction().size()) + " friction rows, Bullet " +
           std::to_string(bullet.friction().size());
  for (int k = 0; k < bullet.friction().size(); ++k)
    if (ours.friction()[k].m_appliedImpulse != 0 || bullet.friction()[k].m_appliedImpulse != 0)
      return "friction row " + std::to_string(k) + " starts with an impulse";
  const std::vector<btVector3> ourDirections = directions();
  for (size_t k = 0; k < bulletDirections.size(); ++k)
    if (!same(ourDirections[k], bulletDirections[k]))
      return "point " + std::to_string(k / 2) + ": friction direction " + std::to_string(k % 2 + 1);
  for (int k = 0; k < bullet.pool().size(); ++k)
    if (const std::string d = firstDifference(ours.pool()[k], bullet.pool()[k]); !d.empty())
      return "solver body " + std::to_string(k) + " after the rows' warm start: " + d;
  return "";
}

}  // namespace rm3d
