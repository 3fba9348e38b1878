// Capture joints: two dock faces drawn together by a joint of bounded speed and force (see
// CaptureJoint in exact_solver.h; docs/physics.md, "Docking").
//
// A force at a dock face (a magnet) acts above the contact patch: below mu m g it cannot slide a
// resting module at all, and above it the module tips before it slides. A capture joint is an
// internal constraint between the two dock links instead, solved with the contacts in every sweep:
// its rows aim the faces' relative velocity at the one that closes the gap and the twist at a
// bounded speed, with impulses bounded by the capture force and torque. Both sides take equal and
// opposite impulses, so two equal modules close symmetrically (the pair's centre stays put), and
// friction and normal forces shift with it in the same solve, so nothing tips.
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <cmath>

#include "physics/bullet_eigen.h"
#include "physics/exact_solver.h"

namespace rm3d {

namespace {

using Vec3d = Eigen::Vector3d;
using bt::rotationVector;
using bt::toEigen;

}  // namespace

CaptureJoint::Error CaptureJoint::error() const {
  const btTransform ta = a->getCenterOfMassTransform() * frameA;
  const btTransform tb = b->getCenterOfMassTransform() * frameB;
  Error e;
  e.gap = toEigen(tb.getOrigin()) - toEigen(ta.getOrigin());
  e.turn = rotationVector(toEigen(ta.getRotation()) * mate * toEigen(tb.getRotation()).conjugate());
  e.pointA = toEigen(ta.getOrigin());
  e.pointB = toEigen(tb.getOrigin());
  return e;
}

void ExactSolver::setupCaptures(btTypedConstraint** constraints, int numConstraints) {
  m_groupCaptures.clear();
  for (int i = 0; i < numConstraints; ++i) {
    btTypedConstraint* c = constraints[i];
    if (c->getUserConstraintType() != CaptureLink::kType || !c->isEnabled()) continue;
    const int id = static_cast<CaptureLink*>(c)->index();
    CaptureJoint& cj = m_shared->captures[size_t(id)];
    const int idA = getOrInitSolverBody(*cj.a, btScalar(m_h)),
              idB = getOrInitSolverBody(*cj.b, btScalar(m_h));
    const CaptureJoint::Error e = cj.error();
    // The relative velocity that closes the gap and the turn within time 1/gain, at most the
    // closing speeds: the rows aim v_B - v_A at -gain x gap (at the faces' midpoint) and
    // w_B - w_A at gain x turn.
    Vec3d close = cj.gain * e.gap, turn = cj.gain * e.turn;
    if (close.norm() > cj.speed) close *= cj.speed / close.norm();
    if (turn.norm() > cj.angularSpeed) turn *= cj.angularSpeed / turn.norm();
    const Vec3d mid = 0.5 * (e.pointA + e.pointB), zero = Vec3d::Zero();
    const int row = m_patchRows.size();
    for (int k = 0; k < 3; ++k)
      addOwnRow(idA, idB, mid, mid, Vec3d::Unit(k), zero, close[k], cj.force * m_h, id);
    for (int k = 0; k < 3; ++k)
      addOwnRow(idA, idB, mid, mid, zero, Vec3d::Unit(k), -turn[k], cj.torque * m_h, id);
    // Warm start from the last substep's impulses, within this substep's bounds.
    Vec3d lin = cj.linear, ang = cj.angular;
    if (lin.norm() > cj.force * m_h) lin *= cj.force * m_h / lin.norm();
    if (ang.norm() > cj.torque * m_h) ang *= cj.torque * m_h / ang.norm();
    for (int k = 0; k < 3; ++k) warmStartRow(m_patchRows[row + k], lin[k]);
    for (int k = 0; k < 3; ++k) warmStartRow(m_patchRows[row + 3 + k], ang[k]);
    m_groupCaptures.push_back({id, row});
  }
}

double ExactSolver::sweepCapture(const GroupCapture& gc) {
  const CaptureJoint& cj = m_shared->captures[size_t(gc.id)];
  const double force = sweepBall(gc.row, 3, cj.force * m_h);  // (force first, then torque)
  return std::max(force, sweepBall(gc.row + 3, 3, cj.torque * m_h));
}

void ExactSolver::finishCaptures() {
  for (const GroupCapture& gc : m_groupCaptures) {
    CaptureJoint& cj = m_shared->captures[size_t(gc.id)];
    for (int k = 0; k < 3; ++k) {
      cj.linear[k] = double(m_patchRows[gc.row + k].m_appliedImpulse);
      cj.angular[k] = double(m_patchRows[gc.row + 3 + k].m_appliedImpulse);
    }
  }
}

}  // namespace rm3d
