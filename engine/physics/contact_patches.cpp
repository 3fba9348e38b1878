// Friction per contact patch, with anchors (see ExactSolver::Patch in exact_solver.h).
//
// Bullet gives each contact point two friction rows, each clamped to +-mu N of its own point and
// started from zero every substep. Solved with the hinges in a few sweeps, that never converges
// at rest: each substep leaves a small tangential velocity, and integrated, that is creep (a
// servo-held SuperBot crept 21 mm in 10 s; one on a 10 deg slope turned 38 deg). Three changes:
//
// - One friction model per patch (a manifold: one pair of bodies, one child shape), as Jolt's:
//   two tangent rows at the patch's centre, clamped together to a circle of mu times the patch's
//   total normal impulse, and a twist row about the normal bounded by mu sum(r_i N_i) (r_i: each
//   point's distance from the centre) plus a spin lever arm times the normal impulse. Two rolling
//   rows, bounded by a rolling lever arm times the normal impulse, where a material resists
//   rolling. The bound is the patch's, whatever way its normal impulse is shared among its points.
// - Warm started from the last substep's impulses (Bullet starts friction at zero).
// - Anchors: a patch that sticks keeps its bodies' relative pose from when it stuck, and its rows
//   aim at the velocity that takes the slip since then (of its centre, about its normal, and in
//   rolling) back out at kAnchorRate a substep, so the error a sweep leaves is corrected by the next
//   substep instead of adding up (PhysX's "strong friction", Solver2D's sticky anchors, MuJoCo's
//   proposed per-body-pair stiction). The decision to let go is the patch's, never a point's:
//   when its friction reaches its bound it slides, and it anchors anew where it is. (Bullet's
//   anchors decide point by point: a saturated point re-anchors while its neighbours hold, which
//   ratcheted a resting SuperBot's yaw by 5-8 deg in 10 s at mu 0.3.)
// - The position stabilisation's moves are not slip: where it turned part of a structure about a
//   distant point, the anchors on that structure move with it (followPatchPoses).
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <cmath>

#include "physics/bullet_eigen.h"
#include "physics/exact_solver.h"
#include "physics/hypot.h"

namespace rm3d {

namespace {

using Vec3d = Eigen::Vector3d;
using bt::rotationVector;
using bt::toBt;
using bt::toEigen;

// Share of a patch's slip its rows aim to take out per substep.
constexpr double kAnchorRate = 0.5;
// A patch whose bodies have turned this far (rad) against each other since it stuck anchors
// anew: a rolling or rocking body's contact moves over its surface, and the material point now at
// the contact was elsewhere when the patch stuck.
constexpr double kAnchorTurn = 0.05;
// A slip beyond this (m) is not creep to take back but a contact that moved on: anchor anew.
constexpr double kAnchorSlip = 0.005;
// Saturated: the patch's friction carries at least this share of its bound.
constexpr double kSaturated = 0.999;

}  // namespace

/// A row of the solver's own (patch friction, capture joints), set up as Bullet sets up its
/// friction rows: its right-hand side from the velocities before any impulse of this substep,
/// aiming the relative velocity linear . (v_A(pointA) - v_B(pointB)) + angular . (w_A - w_B) at
/// `target`.
void ExactSolver::addOwnRow(int idA, int idB, const Vec3d& pointA, const Vec3d& pointB, const Vec3d& linear,
                            const Vec3d& angular, double target, double friction, int owner) {
  btSolverBody& sa = m_tmpSolverBodyPool[idA];
  btSolverBody& sb = m_tmpSolverBodyPool[idB];
  const btRigidBody* ba = sa.m_originalBody;
  const btRigidBody* bb = sb.m_originalBody;
  const btVector3 relA = ba ? toBt(pointA) - ba->getCenterOfMassPosition() : btVector3(0, 0, 0);
  const btVector3 relB = bb ? toBt(pointB) - bb->getCenterOfMassPosition() : btVector3(0, 0, 0);
  btSolverConstraint& s = m_patchRows.expandNonInitializing();
  s = btSolverConstraint();
  s.m_solverBodyIdA = idA;
  s.m_solverBodyIdB = idB;
  s.m_originalContactPoint = nullptr;
  s.m_frictionIndex = owner;
  s.m_friction = btScalar(friction);
  s.m_appliedImpulse = 0;
  s.m_appliedPushImpulse = 0;
  const btVector3 n = toBt(linear), a = toBt(angular);
  double denom = 0, vel = 0;
  s.m_contactNormal1 = ba ? n : btVector3(0, 0, 0);
  s.m_relpos1CrossNormal = ba ? relA.cross(n) + a : btVector3(0, 0, 0);
  s.m_angularComponentA = ba ? ba->getInvInertiaTensorWorld() * s.m_relpos1CrossNormal : btVector3(0, 0, 0);
  s.m_contactNormal2 = bb ? -n : btVector3(0, 0, 0);
  s.m_relpos2CrossNormal = bb ? -(relB.cross(n) + a) : btVector3(0, 0, 0);
  s.m_angularComponentB = bb ? bb->getInvInertiaTensorWorld() * s.m_relpos2CrossNormal : btVector3(0, 0, 0);
  if (ba) {
    denom += double(ba->getInvMass()) * double(n.length2()) +
             double(s.m_relpos1CrossNormal.dot(s.m_angularComponentA));
    vel += double(s.m_contactNormal1.dot(sa.m_linearVelocity + sa.m_externalForceImpulse) +
                  s.m_relpos1CrossNormal.dot(sa.m_angularVelocity + sa.m_externalTorqueImpulse));
  }
  if (bb) {
    denom += double(bb->getInvMass()) * double(n.length2()) +
             double(s.m_relpos2CrossNormal.dot(s.m_angularComponentB));
    vel += double(s.m_contactNormal2.dot(sb.m_linearVelocity + sb.m_externalForceImpulse) +
                  s.m_relpos2CrossNormal.dot(sb.m_angularVelocity + sb.m_externalTorqueImpulse));
  }
  s.m_jacDiagABInv = denom > 0 ? btScalar(1.0 / denom) : btScalar(0);
  s.m_rhs = btScalar((target - vel) * double(s.m_jacDiagABInv));
  s.m_rhsPenetration = 0;
  s.m_cfm = 0;
  s.m_lowerLimit = -s.m_friction;
  s.m_upperLimit = s.m_friction;
}

/// Applies a row's impulse `impulse` to its bodies outside the sweep (a warm start).
void ExactSolver::warmStartRow(btSolverConstraint& s, double impulse) {
  s.m_appliedImpulse = btScalar(impulse);
  if (impulse == 0) return;
  btSolverBody& sa = m_tmpSolverBodyPool[s.m_solverBodyIdA];
  btSolverBody& sb = m_tmpSolverBodyPool[s.m_solverBodyIdB];
  if (sa.m_originalBody)
    sa.internalApplyImpulse(s.m_contactNormal1 * sa.internalGetInvMass(), s.m_angularComponentA,
                            s.m_appliedImpulse);
  if (sb.m_originalBody)
    sb.internalApplyImpulse(s.m_contactNormal2 * sb.internalGetInvMass(), s.m_angularComponentB,
                            s.m_appliedImpulse);
}

/// A patch's normal impulse now, and the sum of its points' normal impulses times their distance
/// from its centre (the twist's lever).
std::pair<double, double> ExactSolver::patchLoad(const PatchRows& pr) const {
  double normalSum = 0, twistArm = 0;
  for (int r = pr.contactBegin; r < pr.contactEnd; ++r) {
    const double n = std::max(0.0, double(m_tmpSolverContactConstraintPool[r].m_appliedImpulse));
    normalSum += n;
    twistArm += m_contactArm[size_t(r)] * n;
  }
  return {normalSum, twistArm};
}

/// `count` (2 or 3) of the solver's own rows from `row` on, solved one after the other, then
/// clamped together to a circle or ball of radius `bound` (a patch's tangent or rolling pair, a
/// capture joint's force or torque); returns the squared change of their impulses.
double ExactSolver::sweepBall(int row, int count, double bound) {
  const int nc = m_tmpSolverContactConstraintPool.size();
  double before[3], after[3];
  RowSide sides[3][2];
  for (int k = 0; k < count; ++k) {
    btSolverConstraint& s = m_patchRows[row + k];
    const int i = nc + row + k;
    sides[k][0] = rowSide(s, 0, i);
    sides[k][1] = rowSide(s, 1, i);
    const double* x = &m_rowExtra[size_t(4 * i)];
    before[k] = s.m_appliedImpulse;
    after[k] = x[2] == 0 ? before[k]
                         : before[k] +
                               (m_useSplit ? x[2] : x[3]) * (x[0] - x[1] * before[k] - rowVelocity(sides[k]));
    applyRowImpulse(sides[k], after[k] - before[k]);
  }
  const double len = count == 2 ? hypotInline(after[0], after[1])
                                : std::sqrt(after[0] * after[0] + after[1] * after[1] + after[2] * after[2]);
  const double scale = len > bound ? bound / len : 1.0;
  double change = 0;
  for (int k = 0; k < count; ++k) {
    btSolverConstraint& s = m_patchRows[row + k];
    applyRowImpulse(sides[k], after[k] * scale - after[k]);
    s.m_appliedImpulse = btScalar(after[k] * scale);
    change += (after[k] * scale - before[k]) * (after[k] * scale - before[k]);
  }
  return change;
}

/// The manifold's slot in the patch table, or -1 (m_companionIdA is unused by Bullet: it is for
/// serialisation only).
int ExactSolver::patchSlot(const btPersistentManifold* man) const {
  const std::vector<Patch>& table = m_shared->m_patches;
  const int slot = man->m_companionIdA - 1;
  return slot >= 0 && slot < int(table.size()) && table[size_t(slot)].manifold == man ? slot : -1;
}

int ExactSolver::claimPatchSlot(btPersistentManifold* man) {
  std::vector<Patch>& table = m_shared->m_patches;
  std::vector<int>& free = m_shared->m_freePatches;
  int slot;
  if (!free.empty()) {
    slot = free.back();
    free.pop_back();
  } else {
    slot = int(table.size());
    table.emplace_back();
  }
  table[size_t(slot)] = Patch{man};
  man->m_companionIdA = slot + 1;
  return slot;
}

void ExactSolver::claimPatchSlots(btPersistentManifold* const* manifolds, int numManifolds) {
  if (!patches) return;
  for (int i = 0; i < numManifolds; ++i)
    if (manifolds[i]->getNumContacts() > 0 && patchSlot(manifolds[i]) < 0) claimPatchSlot(manifolds[i]);
}

void ExactSolver::setupPatches(btPersistentManifold** manifolds, int numManifolds) {
  m_groupPatches.clear();
  m_patchRows.resizeNoInitialize(0);
  const int nc = m_tmpSolverContactConstraintPool.size();
  m_contactArm.assign(size_t(nc), 0.0);
  if (!patches) return;
  const double h = m_h, rate = kAnchorRate;
  int row = 0;
  for (int i = 0; i < numManifolds && row < nc; ++i) {
    btPersistentManifold* man = manifolds[i];
    // Bullet makes the contact rows manifold by manifold, in order: this manifold's are the next
    // ones whose contact point lies in its cache.
    int end = row;
    if (man->getNumContacts() > 0) {
      const char* lo = reinterpret_cast<const char*>(&man->getContactPoint(0));
      const char* hi = lo + sizeof(btManifoldPoint) * MANIFOLD_CACHE_SIZE;
      while (end < nc) {
        const char* p =
            static_cast<const char*>(m_tmpSolverContactConstraintPool[end].m_originalContactPoint);
        if (p < lo || p >= hi) break;
        ++end;
      }
    }
    std::vector<Patch>& table = m_shared->m_patches;
    int slot = patchSlot(man);
    if (end == row) {  // no rows: the contact ended (or has not begun)
      if (slot >= 0) table[size_t(slot)] = Patch{man};
      continue;
    }
    // A batch solver finds every slot claimed (claimPatchSlots): the table never grows under it.
    if (slot < 0) slot = claimPatchSlot(man);
    Patch& p = table[size_t(slot)];
    p.seen = m_substepCount;
    const btSolverConstraint& first = m_tmpSolverContactConstraintPool[row];
    const auto* cp0 = static_cast<const btManifoldPoint*>(first.m_originalContactPoint);

    // The patch's centre and normal (from body 1 towards body 0), its tangent frame.
    Vec3d centre = Vec3d::Zero(), normal = Vec3d::Zero();
    for (int r = row; r < end; ++r) {
      const auto* cp =
          static_cast<const btManifoldPoint*>(m_tmpSolverContactConstraintPool[r].m_originalContactPoint);
      centre += 0.5 * (toEigen(cp->getPositionWorldOnA()) + toEigen(cp->getPositionWorldOnB()));
      normal += toEigen(cp->m_normalWorldOnB);
    }
    centre /= double(end - row);
    normal.normalize();
    for (int r = row; r < end; ++r) {
      const auto* cp =
          static_cast<const btManifoldPoint*>(m_tmpSolverContactConstraintPool[r].m_originalContactPoint);
      Vec3d d = 0.5 * (toEigen(cp->getPositionWorldOnA()) + toEigen(cp->getPositionWorldOnB())) - centre;
      d -= normal * normal.dot(d);
      m_contactArm[size_t(r)] = d.norm();
    }
    btVector3 t1b, t2b;
    btPlaneSpace1(toBt(normal), t1b, t2b);
    const Vec3d t1 = toEigen(t1b).normalized(), t2 = normal.cross(t1);

    PatchRows pr;
    pr.centre = centre;
    pr.t1 = toEigen(toBt(t1));  // as the rows hold them (floats)
    pr.t2 = toEigen(toBt(t2));
    pr.slot = slot;
    pr.contactBegin = row;
    pr.contactEnd = end;
    pr.row = m_patchRows.size();
    pr.mu = double(cp0->m_combinedFriction);
    pr.spin = double(cp0->m_combinedSpinningFriction);
    pr.rolling = double(cp0->m_combinedRollingFriction);
    pr.roll = pr.rolling > 0;

    // The anchor: the slip of the centre's material point on body 0 relative to body 1 since the
    // patch stuck, and the turn of body 0 relative to body 1.
    const btTransform& tr0 = man->getBody0()->getWorldTransform();
    const btTransform& tr1 = man->getBody1()->getWorldTransform();
    const Eigen::Quaterniond r0 = toEigen(tr0.getRotation()), r1 = toEigen(tr1.getRotation());
    const Vec3d o0 = toEigen(tr0.getOrigin()), o1 = toEigen(tr1.getOrigin());
    const Eigen::Quaterniond rot = r1.conjugate() * r0;
    const Vec3d pos = r1.conjugate() * (o0 - o1);
    Vec3d slip = Vec3d::Zero(), turn = Vec3d::Zero();
    if (p.anchored) {
      turn = r1 * rotationVector(rot * p.rot.conjugate());
      const Vec3d q = r0.conjugate() * (centre - o0);
      slip = r1 * ((rot * q + pos) - (p.rot * q + p.pos));
      slip -= normal * normal.dot(slip);
      if (turn.norm() > kAnchorTurn || slip.norm() > kAnchorSlip) p.anchored = false;
    }
    if (!p.anchored) {
      p.rot = rot;
      p.pos = pos;
      p.anchored = true;
      slip.setZero();
      turn.setZero();
    }

    // The rows, at the patch's centre.
    const int idA = first.m_solverBodyIdA, idB = first.m_solverBodyIdB;
    auto addRow = [&](const Vec3d& linear, const Vec3d& angular, double target) {
      addOwnRow(idA, idB, centre, centre, linear, angular, target, pr.mu, int(m_groupPatches.size()));
    };
    const Vec3d zero = Vec3d::Zero();
    addRow(t1, zero, -rate * t1.dot(slip) / h);
    addRow(t2, zero, -rate * t2.dot(slip) / h);
    addRow(zero, normal, -rate * normal.dot(turn) / h);
    if (pr.roll) {
      addRow(zero, t1, -rate * t1.dot(turn) / h);
      addRow(zero, t2, -rate * t2.dot(turn) / h);
    }

    // Warm start: last substep's impulses in this substep's frame, within this substep's bounds
    // at the normal impulses Bullet warm-started (the sweep clamps them again).
    const auto [normalSum, twistArm] = patchLoad(pr);
    double f1 = t1.dot(p.force), f2 = t2.dot(p.force);
    const double fb = pr.mu * normalSum, f = hypotInline(f1, f2);
    if (f > fb) f1 *= fb / f, f2 *= fb / f;
    const double tb = pr.mu * twistArm + pr.spin * normalSum;
    const double warm[5] = {f1, f2, std::clamp(p.twist, -tb, tb), t1.dot(p.roll), t2.dot(p.roll)};
    const int rows = pr.roll ? 5 : 3;
    for (int k = 0; k < rows; ++k) warmStartRow(m_patchRows[pr.row + k], warm[k]);
    m_groupPatches.push_back(pr);
    row = end;
  }
}

/// A patch's friction rows, after the normal rows of the same sweep: tangent rows together
/// (clamped to the circle), then twist, then rolling (clamped to a circle too).
double ExactSolver::sweepPatch(const PatchRows& pr) {
  const int nc = m_tmpSolverContactConstraintPool.size();
  const auto [normalSum, twistArm] = patchLoad(pr);
  double residual = sweepBall(pr.row, 2, pr.mu * normalSum);
  {
    btSolverConstraint& t = m_patchRows[pr.row + 2];
    const double bound = pr.mu * twistArm + pr.spin * normalSum;
    residual = std::max(residual, sweepRow(t, -bound, bound, nc + pr.row + 2));
  }
  if (pr.roll) residual = std::max(residual, sweepBall(pr.row + 3, 2, pr.rolling * normalSum));
  return residual;
}

/// After the solve: a patch whose friction reached its bound slides, and anchors anew next
/// substep where it is; the impulses are kept for the next substep's warm start, and written to
/// Bullet's rows of each point (which copy them to the manifold's points, for load tracking),
/// shared so that they make the same force and twist about the centre.
void ExactSolver::finishPatches() {
  for (const PatchRows& pr : m_groupPatches) {
    Patch& p = m_shared->m_patches[size_t(pr.slot)];
    const auto [normalSum, twistArm] = patchLoad(pr);
    const btSolverConstraint* rows = &m_patchRows[pr.row];
    const Vec3d &t1 = pr.t1, &t2 = pr.t2, normal = t1.cross(t2);
    const double f1 = rows[0].m_appliedImpulse, f2 = rows[1].m_appliedImpulse, tw = rows[2].m_appliedImpulse;
    p.force = f1 * t1 + f2 * t2;
    p.twist = tw;
    p.roll = pr.roll ? Vec3d(double(rows[3].m_appliedImpulse) * t1 + double(rows[4].m_appliedImpulse) * t2)
                     : Vec3d::Zero();
    const double linBound = pr.mu * normalSum, twistBound = pr.mu * twistArm + pr.spin * normalSum;
    const bool slides = linBound <= 0 || hypotInline(f1, f2) >= kSaturated * linBound ||
                        (twistBound > 0 && std::abs(tw) >= kSaturated * twistBound);
    if (slides) p.anchored = false;

    // Each point's share: the force equally (the centre is the points' mean), the twist in
    // proportion to the distance from the centre.
    const int n = pr.contactEnd - pr.contactBegin;
    double arm2 = 0;
    for (int r = pr.contactBegin; r < pr.contactEnd; ++r)
      arm2 += m_contactArm[size_t(r)] * m_contactArm[size_t(r)];
    for (int r = pr.contactBegin; r < pr.contactEnd; ++r) {
      const btSolverConstraint& c = m_tmpSolverContactConstraintPool[r];
      const auto* cp = static_cast<const btManifoldPoint*>(c.m_originalContactPoint);
      Vec3d d = 0.5 * (toEigen(cp->getPositionWorldOnA()) + toEigen(cp->getPositionWorldOnB())) - pr.centre;
      d -= normal * normal.dot(d);
      Vec3d f = p.force / double(n);
      if (arm2 > 0) f += tw * normal.cross(d) / arm2;
      btSolverConstraint& l1 = m_tmpSolverContactFrictionConstraintPool[c.m_frictionIndex];
      btSolverConstraint& l2 = m_tmpSolverContactFrictionConstraintPool[c.m_frictionIndex + 1];
      l1.m_appliedImpulse = btScalar(toEigen(cp->m_lateralFrictionDir1).dot(f));
      l2.m_appliedImpulse = btScalar(toEigen(cp->m_lateralFrictionDir2).dot(f));
    }
  }
}

/// The position stabilisation (ExactSolver::stabiliseCluster) moves bodies to close their joints'
/// errors, a correction of the integration and not a slip; but the anchors took it for one. On a
/// long chain an axis error of a few microradians is closed by turning part of the chain about its
/// root, which moves its far end by a hundred micrometres, and the anchors then pulled every module
/// back towards where it stuck, against the chain's joints: the friction that took added up along
/// the chain, and a straight 300-SuperBot chain lying still on the ground broke 71 docks in its
/// second step (loads up to 127 N; at 1000 modules 544 of 999, up to 618 N). So where a
/// stabilisation pass turned part of a structure (it moved a body many times the largest error it
/// closed: kLever in exact_solver.cpp), the anchors of every patch on that structure's bodies move
/// with them (the bodies are marked with the substep, in Bullet's third user index, which nothing
/// else uses); then the 300-module chain's largest dock load is 14 N and the 1000-module chain's
/// 13 N. A local correction, about as large as the errors it closes, is left to the anchors: the
/// contacts of small robots are solved as before, to the bit.
void ExactSolver::notePatchPoses() {
  if (!patches) return;
  m_patchPoses.resize(m_patches.size());
  for (size_t i = 0; i < m_patches.size(); ++i)
    if (m_patches[i].finished != m_substepCount) notePatchPose(m_patches[i], m_patchPoses[i]);
}

void ExactSolver::notePatchPose(const Patch& p, PatchPoses& poses) const {
  // (A manifold the solve of this substep did not see may be gone: only those it saw.)
  const int substep = m_shared->m_substepCount;
  if (!p.manifold || !p.anchored || p.seen != substep) return;
  poses = {p.manifold->getBody0()->getWorldTransform(), p.manifold->getBody1()->getWorldTransform()};
}

void ExactSolver::followPatchPoses() {
  if (!patches) return;
  for (size_t i = 0; i < m_patches.size() && i < m_patchPoses.size(); ++i)
    if (m_patches[i].finished != m_substepCount) followPatchPose(m_patches[i], m_patchPoses[i]);
}

void ExactSolver::followPatchPose(Patch& p, const PatchPoses& was) const {
  const int substep = m_shared->m_substepCount;
  if (!p.manifold || !p.anchored || p.seen != substep) return;
  const btCollisionObject *body0 = p.manifold->getBody0(), *body1 = p.manifold->getBody1();
  if (body0->getUserIndex3() != substep && body1->getUserIndex3() != substep) return;
  const btTransform& now0 = body0->getWorldTransform();
  const btTransform& now1 = body1->getWorldTransform();
  if (now0 == was.body0 && now1 == was.body1) return;
  // Body 0's pose in body 1's frame, as setupPatches measures the anchor.
  auto relative = [](const btTransform& t0, const btTransform& t1) {
    const Eigen::Quaterniond r0 = toEigen(t0.getRotation()), r1 = toEigen(t1.getRotation());
    return std::make_pair(Eigen::Quaterniond(r1.conjugate() * r0),
                          Vec3d(r1.conjugate() * (toEigen(t0.getOrigin()) - toEigen(t1.getOrigin()))));
  };
  const auto [rotWas, posWas] = relative(was.body0, was.body1);
  const auto [rotNow, posNow] = relative(now0, now1);
  const Eigen::Quaterniond turn = rotNow * rotWas.conjugate();
  // The anchor moves as body 0 moved in body 1's frame: where the stabilisation was the only
  // change since the patch stuck, the slip stays zero.
  p.pos = turn * (p.pos - posWas) + posNow;
  p.rot = (turn * p.rot).normalized();
}

}  // namespace rm3d
