// The exact joint solver (see exact_solver.h for the method).
#include "physics/exact_solver.h"

#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <LinearMath/btQuickprof.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "physics/bullet_layout.h"
#include "physics/node_eigen.h"
#include "physics/node_products.h"

namespace rm3d {

namespace {

using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

// Bodies in one rigid group at most: a long held chain is not rigid at its scale (its motors are
// bounded), and a group that spans it lets friction take self-cancelling impulses that its
// joints must then carry.
constexpr int kMaxGroupBodies = 8;
constexpr double kLimitMargin = 0.25;   // rad: a limit row may engage only this close to its stop
constexpr double kLimitRecovery = 0.2;  // share of a limit overshoot removed per substep
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kCentripetalTurn = 0.5;  // rad a substep: the centripetal target fades out beyond
constexpr int kClaimed = -2;              // a body whose joint node is placed, the body not yet
// Contact sweeps after motors saturate (finishJoints), until the largest squared impulse change of a
// row is under kResweepSettled, at most kResweeps. One sweep, as before, left the 10-module snake at
// one substep bouncing (modules thrown up at 2.4 m/s as a saturated joint let the impulse that
// stopped its rigid group land on one link) and breaking docks; with up to four it crawls as at two
// substeps, and at two substeps its converged comparison's RMS fell from 0.71 deg / 6.7 mm to
// 0.32 deg / 2.6 mm.
constexpr int kResweeps = 4;
constexpr double kResweepSettled = 1e-4;  // (N s)^2: the squared impulse change of a row
// Position stabilisation: a joint error (m of pivot gap, rad of axis tilt) left above this after a
// pass is projected again, up to kStabilisePasses in all. One pass with the substep's rows leaves
// about (motion per substep) x error: a free chain tumbling at dt 1/60 kept 0.04 rad tilt errors
// and its hinges opened by up to 5 deg, so its later passes take rows and factor at the corrected
// poses; a crawling snake's first pass leaves 1e-5 to 2e-5 m, and its second keeps the factor.
constexpr double kStabiliseTolerance = 1e-5;
constexpr int kStabilisePasses = 3;
// A pass with the last pass's rows and factor (a chord step) where the error left times the last
// pass's rate is under this share of the tolerance (stabiliseCluster).
constexpr double kChordShare = 0.5;
// A stabilisation pass that turns part of a structure about a distant point: a body moves (its
// centre, plus its turn at kLeverArm) over kLeverMove and over kLever times the largest joint
// error the pass closes. On a 300-SuperBot chain lying straight, closing errors of 3.8 um turned
// its halves and moved bodies by up to 130 um (34 times the error; at 1000 modules, 1.04 mm for
// 15 um, 68 times); a local correction moves a body by about the error it closes (2.4 times at the
// median, 6.8 at most, over 120 s of the snake-walker-snake sample). The contact anchors follow
// such a pass's moves (ExactSolver::followPatchPoses).
constexpr double kLeverMove = 5e-6;  // m
constexpr double kLeverArm = 0.1;    // m
constexpr double kLever = 10;
// A long tree's contact sweep goes to both halves' threads (planHalvedSweep) in runs of at least
// this many items between the items that touch both halves, and with at most kHalvedSweepBarriers
// such items.
constexpr int kHalvedSweepItems = 64;
constexpr size_t kHalvedSweepBarriers = 64;
/// A long tree's solve (a half helper at hand) makes its lists of solver bodies, contact rows and
/// sweep items, and writes them back, in two runs, one on each half's thread, from this many
/// entries: each entry is written by its own index alone, so the runs give the same bits as one
/// loop. Switched at random step by step within one run, at 2 threads: the physics 1.0-1.3% faster
/// on `snake_150`, 1.3-1.7% on `snake_1000` (where the helper idled through a third of the step).
constexpr int kSplitRows = 256;
/// Clusters of up to this many nodes have their bodies fetched ahead (postStabilise).
constexpr int kPrefetchNodes = 64;
/// The factor fetches a node's row, joint or body this many nodes ahead (fetchInit, fetchPass).
constexpr int kFetchAhead = 8;
/// convertBodies: bodies ahead of the one made whose lines (a btRigidBody's ten) are fetched.
constexpr int kBodiesAhead = 3;
// A tree of fewer nodes than this (about 30 modules: 250 kB of nodes and rows) stays in the second-
// level cache from one pass to the next: its passes fetch nothing ahead (m_fetch).
constexpr int kFetchNodes = 256;

Vec3d toEigen(const btVector3& v) {
  return Vec3d(v.x(), v.y(), v.z());
}

Mat3d toEigen(const btMatrix3x3& m) {
  Mat3d r;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) r(i, k) = m[i][k];
  return r;
}

Mat3d skew(const Vec3d& v) {
  Mat3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

/// node_eigen::invertSymmetric and passShare on AVX (node_products': the same bits).
[[gnu::target("avx")]] void invertSymmetricAvx(Mat6& a) {
  node_products::invertSymmetric(a.data());
}

[[gnu::target("avx")]] void passShareAvx(Mat6& pd, Mat6& g, const Mat6& d, const Mat6& jac, bool joint,
                                         bool axial, bool fresh) {
  node_products::passShare(pd.data(), g.data(), d.data(), jac.data(), joint, axial, fresh);
}

inline void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace

void ExactSolver::beginSubstep() {
  // Patches whose manifold had no rows in the last substep: the pair parted (or sleeps). The
  // table is the primary's; a batch solver only counts the substep with it.
  if (m_shared == this) {
    for (size_t i = 0; i < m_patches.size(); ++i) {
      Patch& p = m_patches[i];
      if (p.manifold && p.seen < m_substepCount) {
        p = Patch{};
        m_freePatches.push_back(int(i));
      }
    }
  }
  ++m_substepCount;
  m_groupsSolved = m_groupsFinished = 0;
  m_halvedSweeps = 0;
  m_halvedLists = 0;
  m_firstGroup = true;
  m_bodies.clear();
  m_nodes.clear();
  m_clusters.clear();
  m_loopJoints.clear();
  m_laneNodes.clear();
  m_nodeOfBody.clear();
  m_bodyCluster.clear();
  m_rows.clear();
  if (m_rowOf.size() < m_shared->joints.size()) m_rowOf.resize(m_shared->joints.size(), -1);
#ifndef NDEBUG
  std::fill(m_rowOf.begin(), m_rowOf.end(), -1);  // (rowIndex: no row is left from the substep before)
#endif
}

// (These two and rowSide are inlined: each exact iteration calls them for every node and row.)
[[gnu::always_inline]] inline Vec6 ExactSolver::bodyVelocity(int b) const {
  const btSolverBody& s = m_tmpSolverBodyPool[m_bodies[size_t(b)].sid];
  const btVector3 l = s.m_linearVelocity + s.m_externalForceImpulse + s.m_deltaLinearVelocity;
  const btVector3 w = s.m_angularVelocity + s.m_externalTorqueImpulse + s.m_deltaAngularVelocity;
  Vec6 v;
  v << l.x(), l.y(), l.z(), w.x(), w.y(), w.z();
  return v;
}

[[gnu::always_inline]] inline void ExactSolver::addBodyVelocity(int b, const Vec6& dv) {
  btSolverBody& s = m_tmpSolverBodyPool[m_bodies[size_t(b)].sid];
  s.m_deltaLinearVelocity += btVector3(btScalar(dv[0]), btScalar(dv[1]), btScalar(dv[2]));
  s.m_deltaAngularVelocity += btVector3(btScalar(dv[3]), btScalar(dv[4]), btScalar(dv[5]));
}

/// Moves the axial impulse of joint j by `impulse`, changing its bodies' velocities.
void ExactSolver::applyAxial(int j, double impulse) {
  if (impulse == 0) return;
  Row& r = row(j);
  r.lambda[5] += impulse;
  for (int side = 0; side < 2; ++side) {
    const int b = side == 0 ? r.na : r.nb;
    if (b < 0) continue;
    const Body& body = m_bodies[size_t(b)];
    const Eigen::Matrix<double, 1, 6> row = side == 0 ? r.ja.row(5) : r.jb.row(5);
    Vec6 dv;
    dv.head<3>() = body.invMass * row.head<3>().transpose() * impulse;
    dv.tail<3>() = body.invInertia * row.tail<3>().transpose() * impulse;
    addBodyVelocity(b, dv);
  }
}

ExactSolver::Cluster& ExactSolver::jointCluster(int j) {
  const Row& r = row(j);
  return m_clusters[size_t(m_bodyCluster[size_t(r.na >= 0 ? r.na : r.nb)])];
}

/// A joint's pivot arms and frame at its bodies' current poses.
ExactSolver::JointFrame ExactSolver::jointFrame(int j) const {
  const ExactJoint& e = m_shared->joints[size_t(j)];
  const btTransform ta = e.a->getCenterOfMassTransform() * e.frameA;
  const btTransform tb = e.b->getCenterOfMassTransform() * e.frameB;
  return {toEigen(ta.getOrigin()) - toEigen(e.a->getCenterOfMassPosition()),
          toEigen(tb.getOrigin()) - toEigen(e.b->getCenterOfMassPosition()), toEigen(ta.getBasis())};
}

/// A joint's rows on its two bodies at their current poses: J = [sI A; 0 B] on each (s = +-1),
/// the block form that structuralResidual and passToParent multiply by.
void ExactSolver::jointRows(int j) {
  Row& r = row(j);
  const auto [ra, rb, frame] = jointFrame(j);
  r.ra = ra;
  r.rb = rb;
  r.frame = frame;
  // (Each block written once, the zero block too: a whole matrix zeroed first cost as much as the
  // rest of the rows.)
  r.ja.bottomLeftCorner<3, 3>().setZero();
  r.jb.bottomLeftCorner<3, 3>().setZero();
  // Pivot: v_a + w_a x r_a - v_b - w_b x r_b = 0.
  r.ja.topLeftCorner<3, 3>().setIdentity();
  r.ja.topRightCorner<3, 3>() = -skew(ra);
  r.jb.topLeftCorner<3, 3>() = -Mat3d::Identity();
  r.jb.topRightCorner<3, 3>() = skew(rb);
  // Axes: (w_a - w_b) . x = (w_a - w_b) . y = 0; axial: (w_b - w_a) . z, the joint's speed.
  for (int k = 0; k < 2; ++k) {
    r.ja.block<1, 3>(3 + k, 3) = frame.col(k).transpose();
    r.jb.block<1, 3>(3 + k, 3) = -frame.col(k).transpose();
  }
  r.ja.block<1, 3>(5, 3) = -frame.col(2).transpose();
  r.jb.block<1, 3>(5, 3) = frame.col(2).transpose();
}

namespace {

/// A solver body's velocity as bodyVelocity makes it (each the float sum of three vectors, in
/// double), linear and angular in lanes 0-2 of two vectors: the same bits, for AVX code.
[[gnu::always_inline]] inline void velocityLanes(const btSolverBody& s, node_products::V4& lin,
                                                 node_products::V4& ang) {
  typedef float F4 __attribute__((vector_size(16), aligned(4), may_alias));
  auto f4 = [](const btVector3& v) { return *reinterpret_cast<const F4*>(v.m_floats); };
  lin = __builtin_convertvector(
      (f4(s.m_linearVelocity) + f4(s.m_externalForceImpulse)) + f4(s.m_deltaLinearVelocity),
      node_products::V4);
  ang = __builtin_convertvector(
      (f4(s.m_angularVelocity) + f4(s.m_externalTorqueImpulse)) + f4(s.m_deltaAngularVelocity),
      node_products::V4);
}

}  // namespace

/// What the rows still need of the bodies' present velocities: target - J v, the structural
/// rows' target being the centripetal one in r.bias; the axial row's entry is -J v alone (its
/// caller adds the motor's or the limit's target).
Vec6 ExactSolver::structuralResidual(int j) const {
  if (m_avx) return structuralResidualAvx(j);
  const Row& r = row(j);
  Vec6 va, vb;  // (read only for the bodies the row has)
  if (r.na >= 0) va = bodyVelocity(r.na);
  if (r.nb >= 0) vb = bodyVelocity(r.nb);
  return node_eigen::jointResidual(r.bias, r.na >= 0 ? &r.ja : nullptr, va, r.nb >= 0 ? &r.jb : nullptr, vb);
}

Vec6 ExactSolver::structuralResidualAvx(int j) const {
  const Row& r = row(j);
  node_products::V4 la, aa, lb, ab;
  if (r.na >= 0) velocityLanes(m_tmpSolverBodyPool[m_bodies[size_t(r.na)].sid], la, aa);
  if (r.nb >= 0) velocityLanes(m_tmpSolverBodyPool[m_bodies[size_t(r.nb)].sid], lb, ab);
  Vec6 y;
  node_products::jointResidual(y.data(), r.bias.data(), r.na >= 0 ? r.ja.data() : nullptr, la, aa,
                               r.nb >= 0 ? r.jb.data() : nullptr, lb, ab);
  return y;
}

/// The structural rows' target (h/2) dJ/dt v: their change as the bodies turn at velocities v.
///
/// With a target of 0 (J v = 0) the velocity is tangent to the pose at the substep's start, and
/// the next substep's rows, turned by h w, take off a share (h w)^2 of the joint's kinetic energy:
/// a free pendulum let go at 90 deg swung 54 deg after 10 s at the defaults, a free chain kept
/// turning more slowly the faster it turned. With J v = -(h/2) dJ/dt v, half the substep's turn
/// ahead, the next projection takes off O((h w)^4) (the pendulum keeps 89.9 deg) and a hinge opens
/// O(h^3) a substep instead of O(h^2) before post-stabilisation. The velocities are the substep's
/// starting ones, then those of each exact solve (joint-consistent: a contact sweep's or a
/// clamp's intermediate velocities gave targets of 0.5 m/s and opened a crawling snake's hinges
/// by millimetres).
void ExactSolver::updateCentripetal(int j) {
  Row& r = row(j);
  r.bias.setZero();
  if (!jointCluster(j).centripetal) return;
  const Vec3d wa = r.na >= 0 ? Vec3d(bodyVelocity(r.na).tail<3>()) : Vec3d::Zero();
  const Vec3d wb = r.nb >= 0 ? Vec3d(bodyVelocity(r.nb).tail<3>()) : Vec3d::Zero();
  const Vec3d dw = wa - wb;
  // Valid while a body turns well under a radian a substep; faded out beyond (a body spun faster
  // than its substep can follow would otherwise drive the target up as w^2).
  const double turn = m_h * std::max(wa.norm(), wb.norm()) / kCentripetalTurn;
  const double half = 0.5 * m_h / (1 + turn * turn * turn * turn);
  const Vec3d x = r.frame.col(0), y = r.frame.col(1), z = r.frame.col(2);
  r.bias.head<3>() = half * (wa.cross(wa.cross(r.ra)) - wb.cross(wb.cross(r.rb)));
  // Axis rows: dw . x is d/dt (y_a . z_b) and dw . y is -d/dt (x_a . z_b), at z_b = z_a.
  r.bias[3] = half * (wa.dot(z) * dw.dot(y) - y.dot(wb) * dw.dot(z));
  r.bias[4] = half * (x.dot(wb) * dw.dot(z) - wa.dot(z) * dw.dot(x));
}

/// Rows, targets and the axial row's state for one joint at the start of a substep.
void ExactSolver::setupJoint(int j, double h) {
  ExactJoint& e = m_shared->joints[size_t(j)];
  Row& r = row(j);
  jointRows(j);
  r.lambda.setZero();
  updateCentripetal(j);

  // The axial row: motor, limit stop, or fixed at a bound.
  using A = ExactJoint::Axial;
  const double tau = e.motorOn ? e.maxImpulse : 0;
  e.nearLower = e.limited && e.angle < e.lower + kLimitMargin;
  e.nearUpper = e.limited && e.angle > e.upper - kLimitMargin;
  e.lowVel = e.nearLower ? (e.lower - e.angle) / h * (e.angle < e.lower ? kLimitRecovery : 1.0) : -kInf;
  e.highVel = e.nearUpper ? (e.upper - e.angle) / h * (e.angle > e.upper ? kLimitRecovery : 1.0) : kInf;
  A s = e.state;
  if (s == A::Lower && !e.nearLower) s = A::Motor;
  if (s == A::Upper && !e.nearUpper) s = A::Motor;
  if (s == A::Fixed && (e.fixedImpulse == 0) == e.motorOn) s = A::Motor;  // the motor was switched
  if (s == A::Motor && !e.motorOn) s = A::Fixed, e.fixedImpulse = 0;
  if (s == A::Motor && e.targetVel < e.lowVel) s = A::Lower;
  if (s == A::Motor && e.targetVel > e.highVel) s = A::Upper;
  if (s == A::Fixed && e.fixedImpulse != 0) e.fixedImpulse = std::copysign(tau, e.fixedImpulse);
  if (s == A::Lower) e.rowTarget = e.lowVel, e.bound = !e.motorOn ? 0 : (e.targetVel > e.lowVel ? tau : -tau);
  if (s == A::Upper)
    e.rowTarget = e.highVel, e.bound = !e.motorOn ? 0 : (e.targetVel < e.highVel ? -tau : tau);
  if (s == A::Motor) e.rowTarget = e.targetVel;
  e.state = s;
  r.axialActive = s != A::Fixed;
}

void ExactSolver::buildClusters(btTypedConstraint** constraints, int numConstraints) {
  // The group's exact joints and their dynamic bodies.
  m_groupJoints.clear();
  const int pool = m_tmpSolverBodyPool.size();
  m_sidToBody.assign(size_t(pool), -1);
  auto bodyOf = [&](btRigidBody* rb) {
    if (rb->getInvMass() == 0) return -1;
    const int sid = rb->getCompanionId();
    if (sid < 0 || sid >= pool) return -1;
    if (m_sidToBody[size_t(sid)] < 0) {
      m_sidToBody[size_t(sid)] = int(m_bodies.size());
      m_bodies.push_back({rb, sid, 0, Mat3d(), Mat3d()});  // (its mass properties below)
    }
    return m_sidToBody[size_t(sid)];
  };
  const int firstBody = int(m_bodies.size());
  // The joints and their bodies lie all over memory (made module by module), and Bullet lists an
  // island's constraints in no particular order: each is fetched three steps ahead (the link
  // three times kFetchAhead constraints ahead, its joint and row twice, what bodyOf reads of
  // the joint's bodies once), each step reading only what the one before fetched.
  auto exact = [](const btTypedConstraint* c) {
    return c->getUserConstraintType() == ExactLink::kType && c->isEnabled();
  };
  for (int i = 0; i < numConstraints; ++i) {
    if (i + 3 * kFetchAhead < numConstraints) {
      const btTypedConstraint* ahead = constraints[i + 3 * kFetchAhead];
      __builtin_prefetch(ahead);
      __builtin_prefetch(reinterpret_cast<const char*>(ahead) + sizeof(ExactLink) - 1);
    }
    if (i + 2 * kFetchAhead < numConstraints && exact(constraints[i + 2 * kFetchAhead])) {
      const int ahead = static_cast<ExactLink*>(constraints[i + 2 * kFetchAhead])->index();
      __builtin_prefetch(&m_shared->joints[size_t(ahead)].a);
      __builtin_prefetch(&m_shared->joints[size_t(ahead)].b);
      __builtin_prefetch(&m_rowOf[size_t(ahead)], 1);
    }
    if (i + kFetchAhead < numConstraints && exact(constraints[i + kFetchAhead])) {
      const ExactJoint& e =
          m_shared->joints[size_t(static_cast<ExactLink*>(constraints[i + kFetchAhead])->index())];
      for (const btRigidBody* rb : {e.a, e.b}) {
        bullet_layout::fetch(rb, bullet_layout::kCompanionId);
        bullet_layout::fetch(rb, bullet_layout::kInverseMass);
      }
    }
    btTypedConstraint* c = constraints[i];
    if (!exact(c)) continue;
    const int j = static_cast<ExactLink*>(c)->index();
    const int na = bodyOf(m_shared->joints[size_t(j)].a);
    const int nb = bodyOf(m_shared->joints[size_t(j)].b);
    if (na < 0 && nb < 0) continue;
    // The joint's row for this substep: the group's rows one after the other, in its joints'
    // order (the batch's, reused by the next batch once this one is finished).
    m_rowOf[size_t(j)] = int(m_rows.size());
    Row& r = m_rows.emplace_back();
    r.na = na;
    r.nb = nb;
    m_groupJoints.push_back(j);
  }
  // The new bodies' mass properties (each body its own entry: on the halves' threads where a long
  // tree's solve has them; a 3 x 3 inverse each, 4000 of them in a 1000-module snake).
  forListHalves(int(m_bodies.size()) - firstBody, [&](int, int begin, int end) {
    for (int i = firstBody + begin; i < firstBody + end; ++i) {
      if (i + 4 < firstBody + end)
        bullet_layout::fetchRange(&m_bodies[size_t(i + 4)].rb->getInvInertiaTensorWorld(), 0,
                                  sizeof(btMatrix3x3));
      Body& b = m_bodies[size_t(i)];
      b.invMass = double(b.rb->getInvMass());
      b.invInertia = toEigen(b.rb->getInvInertiaTensorWorld());
      b.inertia = b.invInertia.inverse();
    }
  });
  // The substep's first group (the only one where a world is one structure) on the same joints
  // and bodies as the last substep's: its trees again (unless asked for fresh ones).
  const bool first = m_firstGroup && firstBody == 0 && m_nodes.empty() && m_clusters.empty() &&
                     m_loopJoints.empty() && m_laneNodes.empty() && !m_shared->freshTrees;
  m_firstGroup = false;
  if (first) {
    m_treeKey.clear();
    for (int j : m_groupJoints) m_treeKey.insert(m_treeKey.end(), {j, row(j).na, row(j).nb});
    if (reuseTrees()) return;
  }
  const int nb = int(m_bodies.size()) - firstBody;
  // Body -> joints adjacency (CSR).
  m_adjStart.assign(size_t(nb) + 1, 0);
  for (int j : m_groupJoints) {
    const Row& r = row(j);
    if (r.na >= 0) ++m_adjStart[size_t(r.na - firstBody) + 1];
    if (r.nb >= 0) ++m_adjStart[size_t(r.nb - firstBody) + 1];
  }
  for (int b = 0; b < nb; ++b) m_adjStart[size_t(b) + 1] += m_adjStart[size_t(b)];
  m_adj.resize(size_t(m_adjStart[size_t(nb)]));
  {
    std::vector<int>& fill = m_queue;
    fill.assign(m_adjStart.begin(), m_adjStart.end() - 1);
    for (int j : m_groupJoints) {
      const Row& r = row(j);
      if (r.na >= 0) m_adj[size_t(fill[size_t(r.na - firstBody)]++)] = j;
      if (r.nb >= 0) m_adj[size_t(fill[size_t(r.nb - firstBody)]++)] = j;
    }
  }
  m_bodyNode.assign(size_t(nb), -1);
  m_nodeOfBody.resize(m_bodies.size(), -1);
  m_bodyCluster.resize(m_bodies.size(), -1);
  if (m_seenJoint.size() < m_shared->joints.size()) m_seenJoint.resize(m_shared->joints.size());
  for (int j : m_groupJoints) {
    m_seenJoint[size_t(j)] = 0;
    row(j).node = -1;
  }

  // One cluster per connected component: first collect it, then root it at its anchor (a joint
  // to a static body) if it has one, else at its first body, and list nodes breadth first.
  for (int start : m_groupJoints) {
    if (m_seenJoint[size_t(start)]) continue;
    m_component.clear();
    m_component.push_back(start);
    m_seenJoint[size_t(start)] = 1;
    int root = -1;
    for (size_t k = 0; k < m_component.size(); ++k) {
      const int j = m_component[k];
      const Row& r = row(j);
      if (root < 0 && (r.na < 0 || r.nb < 0)) root = j;
      for (int b : {r.na, r.nb}) {
        if (b < 0) continue;
        for (int q = m_adjStart[size_t(b - firstBody)]; q < m_adjStart[size_t(b - firstBody) + 1]; ++q) {
          const int o = m_adj[size_t(q)];
          if (!m_seenJoint[size_t(o)]) {
            m_seenJoint[size_t(o)] = 1;
            m_component.push_back(o);
          }
        }
      }
    }
    Cluster c;
    c.begin = int(m_nodes.size());
    auto addNode = [&](int body, int joint, int parent, bool parentIsA) {
      if (body >= 0) {
        m_nodeOfBody[size_t(body)] = int(m_nodes.size());
        m_bodyCluster[size_t(body)] = int(m_clusters.size());
      }
      Node& n = m_nodes.emplace_back();
      n.body = body;
      n.joint = joint;
      n.parent = parent;
      n.parentIsA = parentIsA;
      return int(m_nodes.size()) - 1;
    };
    // Breadth first over the tree from a root joint (to the static world) or body; a joint whose
    // other body is placed already closes a loop and stays out of it.
    auto grow = [&](int rootJoint, int rootBody) {
      if (rootJoint >= 0)
        row(rootJoint).node = addNode(-1, rootJoint, -1, false);
      else
        m_bodyNode[size_t(rootBody - firstBody)] = addNode(rootBody, -1, -1, false);
      for (int k = c.begin; k < int(m_nodes.size()); ++k) {
        const int nodeJoint = m_nodes[size_t(k)].joint, nodeBody = m_nodes[size_t(k)].body;
        if (nodeJoint >= 0) {
          const Row& r = row(nodeJoint);
          for (int side = 0; side < 2; ++side) {
            const int b = side == 0 ? r.na : r.nb;
            if (b < 0 || m_bodyNode[size_t(b - firstBody)] >= 0) continue;
            m_bodyNode[size_t(b - firstBody)] = addNode(b, -1, k, side == 0);
          }
        } else {
          const int b = nodeBody;
          for (int q = m_adjStart[size_t(b - firstBody)]; q < m_adjStart[size_t(b - firstBody) + 1]; ++q) {
            const int j = m_adj[size_t(q)];
            Row& r = row(j);
            if (r.node >= 0) continue;  // already placed (the body's parent joint)
            const int other = r.na == b ? r.nb : r.na;
            // A body placed already, or claimed by another joint of this level: a loop.
            if (other >= 0 && m_bodyNode[size_t(other - firstBody)] != -1) continue;
            r.node = addNode(-1, j, k, r.na == b);
            if (other >= 0) m_bodyNode[size_t(other - firstBody)] = kClaimed;
          }
        }
      }
    };
    const int firstRootBody = row(start).na >= 0 ? row(start).na : row(start).nb;
    grow(root, firstRootBody);
    // A long tree without loops or anchors: rooted again at its centroid body, so that its two
    // halves can be factored and solved apart (splitTree).
    if (root < 0 && int(m_component.size()) >= kSplitJoints &&
        int(m_nodes.size()) - c.begin == 2 * int(m_component.size()) + 1) {
      const int centre = centroidBody(c.begin);
      for (int k = c.begin; k < int(m_nodes.size()); ++k) {
        const Node& n = m_nodes[size_t(k)];
        if (n.body >= 0) m_bodyNode[size_t(n.body - firstBody)] = -1;
        if (n.joint >= 0) row(n.joint).node = -1;
      }
      m_nodes.resize(size_t(c.begin));
      grow(-1, centre);
      splitTree(c);
    }
    c.end = int(m_nodes.size());
    for (int k = c.begin; k < c.end && c.island < 0; ++k)
      if (m_nodes[size_t(k)].body >= 0)
        c.island = m_bodies[size_t(m_nodes[size_t(k)].body)].rb->getIslandTag();
    // The component's joints the tree left out close loops: solved through their Schur
    // complement (factorLoops).
    c.loopBegin = int(m_loopJoints.size());
    for (int j : m_component)
      if (row(j).node < 0) m_loopJoints.push_back(j);
    c.loopEnd = int(m_loopJoints.size());
    // A loop, or a second joint to the static world (a loop through it), has poses where its
    // rows lose rank and a centripetal target cannot be met (updateCentripetal).
    int anchors = 0;
    for (int j : m_component) anchors += row(j).na < 0 || row(j).nb < 0;
    c.centripetal = c.loopEnd == c.loopBegin && anchors <= 1;
    m_clusters.push_back(std::move(c));
  }
  if (first) keepTrees();
}

/// The last first group's trees, if they were made from the same joints on the same bodies
/// (m_treeKey): buildClusters' walk is a function of those alone, so the same nodes, clusters,
/// lanes and loop joints, bit for bit. Only the clusters' islands are looked up again.
bool ExactSolver::reuseTrees() {
  if (!m_trees.valid || m_trees.key != m_treeKey) return false;
  m_nodeOfBody.resize(m_bodies.size(), -1);
  m_bodyCluster.resize(m_bodies.size(), -1);
  for (int j : m_groupJoints) row(j).node = -1;
  m_clusters = m_trees.clusters;
  m_nodes.resize(m_trees.nodes.size());
  // Each node writes its own entries, and its body's and joint's (on the halves' threads where a
  // long tree's solve has them).
  forListHalves(int(m_nodes.size()), [&](int, int begin, int end) {
    int ci = int(std::upper_bound(m_clusters.begin(), m_clusters.end(), begin,
                                  [](int k, const Cluster& c) { return k < c.begin; }) -
                 m_clusters.begin()) -
             1;
    for (int k = begin; k < end; ++k) {
      while (k >= m_clusters[size_t(ci)].end) ++ci;
      const NodeHead& head = m_trees.nodes[size_t(k)];
      Node& n = m_nodes[size_t(k)];
      n.body = head.body;
      n.joint = head.joint;
      n.parent = head.parent;
      n.parentIsA = head.parentIsA;
      if (n.body >= 0) {
        m_nodeOfBody[size_t(n.body)] = k;
        m_bodyCluster[size_t(n.body)] = ci;
      }
      if (n.joint >= 0) row(n.joint).node = k;
    }
  });
  for (Cluster& c : m_clusters)  // (its first body's island)
    for (int k = c.begin; k < c.end && c.island < 0; ++k)
      if (const int b = m_nodes[size_t(k)].body; b >= 0) c.island = m_bodies[size_t(b)].rb->getIslandTag();
  m_laneNodes = m_trees.laneNodes;
  m_loopJoints = m_trees.loopJoints;
  ++m_reusedTrees;
  return true;
}

void ExactSolver::keepTrees() {
  m_trees.valid = true;
  std::swap(m_trees.key, m_treeKey);
  m_trees.nodes.resize(m_nodes.size());
  for (size_t k = 0; k < m_nodes.size(); ++k) {
    const Node& n = m_nodes[k];
    m_trees.nodes[k] = {n.body, n.joint, n.parent, n.parentIsA};
  }
  m_trees.clusters = m_clusters;
  for (Cluster& c : m_trees.clusters) c.island = -1;
  m_trees.laneNodes = m_laneNodes;
  m_trees.loopJoints = m_loopJoints;
}

/// Rigid groups of this solver group's bodies (hinges whose motors hold them), their mass
/// properties, and each contact row's velocity error and effective mass as the sweep sees it.
void ExactSolver::buildGroups(int firstBody, bool planned) {
  using A = ExactJoint::Axial;
  const int nb = int(m_bodies.size()) - firstBody;
  m_groupParent.resize(size_t(nb));
  for (int i = 0; i < nb; ++i) m_groupParent[size_t(i)] = i;
  std::vector<int>& size = m_component;
  size.assign(size_t(nb), 1);
  auto find = [&](int i) {
    while (m_groupParent[size_t(i)] != i)
      i = m_groupParent[size_t(i)] = m_groupParent[size_t(m_groupParent[size_t(i)])];
    return i;
  };
  // (Each joint's row and state fetched a few joints ahead: a long chain's lie outside the caches.)
  const int joints = int(m_groupJoints.size());
  for (int q = 0; q < joints; ++q) {
    if (q + kFetchAhead < joints) {
      const int ahead = m_groupJoints[size_t(q + kFetchAhead)];
      __builtin_prefetch(&row(ahead).na);
      __builtin_prefetch(&m_shared->joints[size_t(ahead)].motorOn);
      __builtin_prefetch(&m_shared->joints[size_t(ahead)].state);
    }
    const int j = m_groupJoints[size_t(q)];
    const ExactJoint& e = m_shared->joints[size_t(j)];
    const Row& r = row(j);
    if (r.na < 0 || r.nb < 0 || !e.motorOn || e.state == A::Fixed) continue;
    if (planned && denseBody(r.na)) continue;  // (a tree the dense solve takes: no sweep moves it)
    const int a = find(r.na - firstBody), b = find(r.nb - firstBody);
    if (a == b || size[size_t(a)] + size[size_t(b)] > kMaxGroupBodies) continue;
    m_groupParent[size_t(std::max(a, b))] = std::min(a, b);
    size[size_t(std::min(a, b))] += size[size_t(std::max(a, b))];
  }
  m_groups.clear();
  // Only this solver group's range [firstBody, end): rows reach no body of an earlier group
  // (m_sidToBody is made per group), and resetting every body of the substep for each of a few
  // hundred groups made this O(n^2) at 10,000 modules.
  m_bodyGroup.resize(m_bodies.size());
  m_bodyOffset.resize(m_bodies.size());
  m_bodyImpulse.resize(m_bodies.size());
  // (Each body's group is written below; only a grouped body's impulse is read, so only those
  // are cleared: the dense islands' bodies are none.)
  // A group's root is its smallest body: groups are numbered in body order.
  std::vector<int>& rootGroup = m_queue;
  rootGroup.assign(size_t(nb), -1);
  for (int i = 0; i < nb; ++i) {
    const int root = find(i);
    if (root != i && rootGroup[size_t(root)] < 0) {
      rootGroup[size_t(root)] = int(m_groups.size());
      m_groups.push_back({0, Vec3d::Zero(), Mat3d::Zero(), Vec3d::Zero(), Vec3d::Zero(), 0});
    }
  }
  for (int i = 0; i < nb; ++i) {
    // (Each grouped body's pose fetched a few bodies ahead: with many modules the bodies are
    // outside the caches. An ungrouped one's is not read here.)
    if (i + kFetchAhead < nb && rootGroup[size_t(find(i + kFetchAhead))] >= 0)
      bullet_layout::fetchPose(m_bodies[size_t(firstBody + i + kFetchAhead)].rb);
    const int g = rootGroup[size_t(find(i))];
    m_bodyGroup[size_t(firstBody + i)] = g;
    if (g < 0) continue;
    m_bodyImpulse[size_t(firstBody + i)].setZero();
    const Body& b = m_bodies[size_t(firstBody + i)];
    const double m = 1.0 / b.invMass;
    m_groups[size_t(g)].invMass += m;  // the mass, until inverted below
    m_groups[size_t(g)].com += m * toEigen(b.rb->getCenterOfMassPosition());
  }
  for (Group& g : m_groups) g.com /= g.invMass;
  for (int i = 0; i < nb; ++i) {
    const int g = m_bodyGroup[size_t(firstBody + i)];
    if (g < 0) continue;
    const Body& b = m_bodies[size_t(firstBody + i)];
    const Vec3d d = toEigen(b.rb->getCenterOfMassPosition()) - m_groups[size_t(g)].com;
    m_bodyOffset[size_t(firstBody + i)] = d;
    m_groups[size_t(g)].invInertia +=
        b.inertia + (d.squaredNorm() * Mat3d::Identity() - d * d.transpose()) / b.invMass;
  }
  for (Group& g : m_groups) {
    g.invMass = 1.0 / g.invMass;
    g.invInertia = g.invInertia.inverse().eval();
  }

  // Rows: the velocity error and cfm behind Bullet's right-hand side, and 1 / (effective mass)
  // with a group's inertia in place of its body's.
  const int nc = m_tmpSolverContactConstraintPool.size(), nf = m_patchRows.size();
  m_rowExtra.resize(size_t(4 * (nc + nf)));
  m_rowPush.resize(size_t(12 * (nc + nf)));
  // Each group's contact points, counted in two runs of the rows (on the halves' threads) and added.
  forListHalves(nc, [&](int h, int begin, int end) {
    std::vector<int>& counts = m_groupContacts[h];
    counts.assign(m_groups.size(), 0);
    for (int i = begin; i < end; ++i)
      for (int side = 0; side < 2; ++side)
        if (const RowSide r = rowSide(m_tmpSolverContactConstraintPool[i], side); r.group >= 0)
          ++counts[size_t(r.group)];
  });
  for (size_t g = 0; g < m_groups.size(); ++g)
    m_groups[g].contacts = m_groupContacts[0][g] + m_groupContacts[1][g];
  forListHalves(nc + nf, [&](int, int begin, int end) {
    for (int i = begin; i < end; ++i) rowData(i, !planned || !m_rowDense[size_t(i)]);
  });
  planHalvedSweep();
}

void ExactSolver::rowData(int i, bool sweep) {
  const int nc = m_tmpSolverContactConstraintPool.size();
  btSolverConstraint& c = i < nc ? m_tmpSolverContactConstraintPool[i] : m_patchRows[i - nc];
  // What a unit impulse of the row does to a grouped side's group (every row: a row without
  // mass of its own may still take an impulse when its ball is clamped).
  for (int side = 0; sweep && side < 2; ++side) {
    const RowSide r = rowSide(c, side, i);
    if (!r.push || !r.body->m_originalBody) continue;
    const Group& gr = m_groups[size_t(r.group)];
    const Vec3d rg = toEigen(*r.rc) + m_bodyOffset[size_t(r.index)].cross(toEigen(*r.n));
    double* push = m_rowPush.data() + 12 * i + 6 * side;
    Eigen::Map<Vec3d> linear(push), angular(push + 3);
    linear = gr.invMass * toEigen(*r.n);
    angular = gr.invInertia * rg;
  }
  double* x = &m_rowExtra[size_t(4 * i)];
  const double jd = c.m_jacDiagABInv;
  if (jd == 0) {
    x[0] = x[1] = x[2] = x[3] = 0;
    return;
  }
  x[0] = double(c.m_rhs) / jd;
  x[1] = double(c.m_cfm) / jd;
  if (!sweep) {
    // (Its island's contacts solved on their own operator: of the sweep's entries only whether
    // the row has mass is read, x[2] != 0.)
    x[2] = x[3] = 1;
    return;
  }
  double w = 0, wu = 0;
  for (int side = 0; side < 2; ++side) {
    const RowSide r = rowSide(c, side);
    if (!r.body->m_originalBody) continue;
    if (r.group < 0) {
      w += double(r.body->m_originalBody->getInvMass()) * double(r.n->length2()) + double(r.ac->dot(*r.rc));
      wu += double(r.body->m_originalBody->getInvMass()) * double(r.n->length2()) + double(r.ac->dot(*r.rc));
    } else {
      const Group& gr = m_groups[size_t(r.group)];
      const Vec3d rg = toEigen(*r.rc) + m_bodyOffset[size_t(r.index)].cross(toEigen(*r.n));
      // Split among the group's contacts, so that they share its weight instead of the first
      // one swept carrying it all.
      w += (gr.invMass * double(r.n->length2()) + rg.dot(gr.invInertia * rg)) * std::max(1, gr.contacts);
      wu += (gr.invMass * double(r.n->length2()) + rg.dot(gr.invInertia * rg));
    }
  }
  x[2] = 1.0 / (w + x[1]);
  x[3] = 1.0 / (wu + x[1]);
}

void ExactSolver::planHalvedSweep() {
  m_halvedSweep = false;
  if (!m_halfHelper) return;
  bool split = false;
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) split |= m_clusters[size_t(ci)].split;
  if (!split) return;
  // Each body's half (2: a split tree's root, or no split tree's), then each group's.
  m_bodySide.assign(m_bodies.size(), 2);
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) {
    const Cluster& c = m_clusters[size_t(ci)];
    if (!c.split) continue;
    for (int h = 0; h < 2; ++h)
      for (int i = c.lane[h]; i < c.lane[h + 1]; ++i)
        if (const int b = m_nodes[size_t(m_laneNodes[size_t(i)])].body; b >= 0)
          m_bodySide[size_t(b)] = static_cast<signed char>(h);
  }
  auto join = [](int a, int b) { return a < 0 ? b : (a == b ? a : 2); };
  m_groupSide.assign(m_groups.size(), -1);
  for (size_t b = size_t(m_groupFirstBody); b < m_bodies.size(); ++b)
    if (const int g = m_bodyGroup[b]; g >= 0)
      m_groupSide[size_t(g)] = static_cast<signed char>(join(m_groupSide[size_t(g)], m_bodySide[b]));
  // An item's half: that of every body its rows move (a static body moves not).
  auto sideOf = [&](btSolverConstraint& c) {
    int s = -1;
    for (int side = 0; side < 2; ++side) {
      const RowSide r = rowSide(c, side);
      if (!r.body->m_originalBody) continue;
      s = join(s, r.index < 0    ? 2
                  : r.group >= 0 ? m_groupSide[size_t(r.group)]
                                 : m_bodySide[size_t(r.index)]);
    }
    return s < 0 ? 2 : s;
  };
  const int nc = m_tmpSolverContactConstraintPool.size();
  const int ncap = int(m_groupCaptures.size()), npatch = int(m_groupPatches.size());
  m_itemSide.resize(size_t(ncap + nc + npatch));
  m_itemBarriers.clear();
  // Each item's side written at its own place (forListHalves).
  forListHalves(ncap + nc + npatch, [&](int, int begin, int end) {
    for (int t = begin; t < end; ++t) {
      btSolverConstraint& c = t < ncap ? m_patchRows[m_groupCaptures[size_t(t)].row]
                              : t < ncap + nc
                                  ? m_tmpSolverContactConstraintPool[m_orderTmpConstraintPool[t - ncap]]
                                  : m_patchRows[m_groupPatches[size_t(t - ncap - nc)].row];
      m_itemSide[size_t(t)] = static_cast<signed char>(sideOf(c));
    }
  });
  for (size_t t = 0; t < m_itemSide.size(); ++t)
    if (m_itemSide[t] == 2) m_itemBarriers.push_back(int(t));
  m_halvedSweep =
      m_itemBarriers.size() <= kHalvedSweepBarriers && int(m_itemSide.size()) >= 2 * kHalvedSweepItems;
}

double ExactSolver::rowVelocity(const RowSide (&sides)[2]) const {
  double vel = 0;
  for (const RowSide& r : sides) {
    if (!r.body->m_originalBody) continue;
    vel += double(r.n->dot(r.body->m_deltaLinearVelocity) + r.rc->dot(r.body->m_deltaAngularVelocity));
    if (r.group >= 0) {
      const Group& gr = m_groups[size_t(r.group)];
      vel +=
          toEigen(*r.n).dot(gr.dv + gr.dw.cross(m_bodyOffset[size_t(r.index)])) + toEigen(*r.rc).dot(gr.dw);
    }
  }
  return vel;
}

/// One row of the contact sweep, as Bullet's, except that a body in a rigid group moves with its
/// group: its velocity includes the group's pending twist and an impulse goes to that twist.
double ExactSolver::sweepRow(btSolverConstraint& c, double lo, double hi, int row) {
  const RowSide sides[2] = {rowSide(c, 0, row), rowSide(c, 1, row)};
  const double* x = &m_rowExtra[size_t(4 * row)];
  const double vel = rowVelocity(sides);
  const double lambda = c.m_appliedImpulse;
  const double inv = m_useSplit ? x[2] : x[3];
  const double next = std::clamp(lambda + inv * (x[0] - x[1] * lambda - vel), lo, hi);
  const double delta = next - lambda;
  c.m_appliedImpulse = btScalar(next);
  applyRowImpulse(sides, delta);
  return delta * delta;
}

void ExactSolver::applyRowImpulse(const RowSide (&sides)[2], double delta) {
  if (delta == 0) return;
  for (const RowSide& r : sides) {
    if (!r.body->m_originalBody) continue;
    if (r.group < 0) {
      r.body->internalApplyImpulse(*r.n * r.body->internalGetInvMass(), *r.ac, btScalar(delta));
      continue;
    }
    Group& gr = m_groups[size_t(r.group)];
    gr.dv += Eigen::Map<const Vec3d>(r.push) * delta;
    gr.dw += Eigen::Map<const Vec3d>(r.push + 3) * delta;
    Vec6& p = m_bodyImpulse[size_t(r.index)];
    p.head<3>() += toEigen(*r.n) * delta;
    p.tail<3>() += toEigen(*r.rc) * delta;
  }
}

/// The contact sweep, with rigid groups: Bullet's normal rows, then the patches' friction
/// (contact_patches.cpp).
btScalar ExactSolver::contactSweep() {
  double residual = 0;
  const int nc = m_tmpSolverContactConstraintPool.size();
  // Only the rows of the islands m_sweepIsland names, when it names any: a row's island (of its
  // first body that has one: a row joins bodies of one island, or one and the static world), -1
  // where it names none (every row is swept), -2 for a row of an island it does not name.
  auto islandOf = [&](const btSolverConstraint& c) {
    if (m_sweepIsland.empty()) return -1;
    for (const int sid : {c.m_solverBodyIdA, c.m_solverBodyIdB}) {
      const btRigidBody* o = m_tmpSolverBodyPool[sid].m_originalBody;
      const int island = o ? o->getIslandTag() : -1;
      if (island >= 0 && island < int(m_sweepIsland.size()) && m_sweepIsland[size_t(island)]) return island;
    }
    return -2;
  };
  // A re-sweep notes each island's largest change on its own (each island stops on its own).
  auto noted = [&](int island, int h, double change) {
    if (island >= 0) {
      double& largest = m_islandChange[h][size_t(island)];
      largest = std::max(largest, change);
    }
    return change;
  };
  // Item t: the capture joints, the normal rows in Bullet's order, then the patches' friction.
  const int captures = int(m_groupCaptures.size()), items = captures + nc + int(m_groupPatches.size());
  auto sweepRowsOf = [&](int t, int h) -> double {
    if (t < captures) {
      const GroupCapture& gc = m_groupCaptures[size_t(t)];
      const int island = islandOf(m_patchRows[gc.row]);
      return island != -2 ? noted(island, h, sweepCapture(gc)) : 0.0;
    }
    if (t < captures + nc) {
      const int i = m_orderTmpConstraintPool[t - captures];
      btSolverConstraint& c = m_tmpSolverContactConstraintPool[i];
      if (m_rowExtra[size_t(4 * i + 2)] == 0) return 0.0;
      const int island = islandOf(c);
      return island != -2 ? noted(island, h, sweepRow(c, c.m_lowerLimit, c.m_upperLimit, i)) : 0.0;
    }
    const PatchRows& pr = m_groupPatches[size_t(t - captures - nc)];
    const int island = islandOf(m_patchRows[pr.row]);
    return island != -2 ? noted(island, h, sweepPatch(pr)) : 0.0;
  };
  // Item t, swept on thread h of a halved sweep (0 otherwise), unless its island has settled.
  auto sweepItem = [&](int t, int h) -> double {
    const int slot = m_settling ? m_itemSlot[size_t(t)] : -1;
    if (slot < 0) return sweepRowsOf(t, h);
    if (m_slotSettle[size_t(slot)] == Settle::Settled) return 0.0;
    const double change = sweepRowsOf(t, h);
    double& largest = m_slotChange[h][size_t(slot)];
    largest = std::max(largest, change);
    return change;
  };
  if (!m_halvedSweep || !m_halfHelper) {
    for (int t = 0; t < items; ++t) residual = std::max(residual, sweepItem(t, 0));
  } else {
    // A long tree's: each half's items on its thread between the items of both (planHalvedSweep).
    ++m_halvedSweeps;
    double halves[2] = {0, 0};
    int from = 0, to = 0;
    for (size_t b = 0; b <= m_itemBarriers.size(); ++b) {
      to = b < m_itemBarriers.size() ? m_itemBarriers[b] : items;
      if (to - from >= kHalvedSweepItems) {
        forBothHalves([&](int h) {
          // (Kept here and stored once: both halves' slots share a cache line.)
          double largest = halves[h];
          for (int t = from; t < to; ++t)
            if (m_itemSide[size_t(t)] == h) largest = std::max(largest, sweepItem(t, h));
          halves[h] = largest;
        });
      } else {
        for (int t = from; t < to; ++t) residual = std::max(residual, sweepItem(t, 0));
      }
      if (to < items) residual = std::max(residual, sweepItem(to, 0));
      from = to + 1;
    }
    residual = std::max({residual, halves[0], halves[1]});
  }
  // The twists only predicted how the groups move within the sweep: each grouped body now takes
  // the impulses that reached it, and the exact solve passes them through its hinges (so joint
  // impulses, torques and loads carry them). Each body's own step: a halved sweep's bodies on
  // their half's thread, so that the solve that follows finds them in its own core's cache (taken
  // all here, they were the half helper's first misses in the solve).
  auto passOn = [this](int side) {
    for (size_t b = size_t(m_groupFirstBody); b < m_bodyGroup.size(); ++b) {
      if (m_bodyGroup[b] < 0 || (side >= 0 && m_bodySide[b] != side)) continue;
      Vec6& p = m_bodyImpulse[b];
      const Body& body = m_bodies[b];
      Vec6 dv;
      dv.head<3>() = body.invMass * p.head<3>();
      dv.tail<3>() = body.invInertia * p.tail<3>();
      addBodyVelocity(int(b), dv);
      p.setZero();
    }
    // The groups' twists cleared for the next sweep, each half's on its thread (the same reason).
    for (size_t g = 0; g < m_groups.size(); ++g)
      if (side < 0 || m_groupSide[g] == side || (side == 2 && m_groupSide[g] < 0))
        m_groups[g].dv.setZero(), m_groups[g].dw.setZero();
  };
  if (m_halvedSweep && m_halfHelper) {
    forBothHalves([&passOn](int h) { passOn(h); });
    passOn(2);
  } else {
    passOn(-1);
  }
  return btScalar(residual);
}

void ExactSolver::initNode(int k) {
  Node& n = m_nodes[size_t(k)];
  if (n.joint >= 0) {
    const Row& r = row(n.joint);
    n.dinv = -kRegularisation * Mat6::Identity();
    if (!r.axialActive) n.dinv(5, 5) = -1;
    const ExactJoint& ej = m_shared->joints[size_t(n.joint)];
    if (r.axialActive && ej.state == ExactJoint::Axial::Motor) n.dinv(5, 5) -= ej.compliance;
  } else {
    const Body& b = m_bodies[size_t(n.body)];
    n.dinv.setZero();
    n.dinv.topLeftCorner<3, 3>() = Mat3d::Identity() / b.invMass;
    n.dinv.bottomRightCorner<3, 3>() = b.inertia;
  }
}

/// (node_eigen::passShare says what the share is.)
void ExactSolver::passToParent(int k, bool fresh) {
  Node& n = m_nodes[size_t(k)];
  // H(node, parent): the joint's rows on the body (J) for a joint node, their transpose for a
  // body node; without the axial row while it is fixed.
  const Row& r = row(n.joint >= 0 ? n.joint : m_nodes[size_t(n.parent)].joint);
  Mat6& pd = m_nodes[size_t(n.parent)].dinv;
  const Mat6& jac = n.parentIsA ? r.ja : r.jb;
  if (m_avx)
    passShareAvx(pd, n.g, n.dinv, jac, n.joint >= 0, r.axialActive, fresh);
  else
    node_eigen::passShare(pd, n.g, n.dinv, jac, n.joint >= 0, r.axialActive, fresh);
}

void ExactSolver::invertPivot(Mat6& d) const {
  if (m_avx)
    invertSymmetricAvx(d);
  else
    node_eigen::invertSymmetric(d);
}

template <class Fn>
void ExactSolver::forEachNode(const Cluster& c, const Fn& fn) {
  if (!c.split) {
    for (int k = c.begin; k < c.end; ++k) fn(k, 0);
    return;
  }
  fn(c.begin, 0);
  forBothHalves([&](int h) {
    for (int i = c.lane[h]; i < c.lane[h + 1]; ++i) fn(m_laneNodes[size_t(i)], h);
  });
}

void ExactSolver::runWithHalfHelper(const std::function<void(int, FunctionRef<void(int)>)>& tasks,
                                    FunctionRef<void()> fn, HalfSite site) {
  if (!tasks) return fn();
  runPaced(
      m_halfPace[int(site)], alwaysThreads, [&] { runHelped(tasks, fn); }, fn);
}

void ExactSolver::runHelped(const std::function<void(int, FunctionRef<void(int)>)>& tasks,
                            FunctionRef<void()> fn) {
  HalfHelper helper;
  helper.watch = halfHelperWatches;
  tasks(2, [&](int t) {
    if (t == 1) return helpHalves(helper);
    m_halfHelper = &helper;
    fn();
    m_halfHelper = nullptr;
    helper.stop.store(true, std::memory_order_release);
    helper.posted.fetch_add(1, std::memory_order_release);  // (wakes it to see the stop)
    helper.posted.notify_one();
  });
}

void ExactSolver::forBothHalves(FunctionRef<void(int)> fn) {
  HalfHelper* h = m_halfHelper;
  if (!h) {
    fn(0);
    fn(1);
    return;
  }
  h->fn = fn;
  const uint64_t g = h->posted.load(std::memory_order_relaxed) + 1;
  h->posted.store(g, std::memory_order_release);
  h->posted.notify_one();
  fn(0);
  uint64_t expected = g - 1;
  if (h->taken.compare_exchange_strong(expected, g, std::memory_order_acq_rel)) {
    fn(1);  // the helper did not take it in time
    return;
  }
  // The helper is on it: wait (yielding after a while, should it be waiting for this core).
  for (int spins = 0; h->done.load(std::memory_order_acquire) != g; ++spins) {
    if (spins < 4000)
      cpuRelax();
    else
      std::this_thread::yield();
  }
}

void ExactSolver::forListHalves(int n, FunctionRef<void(int, int, int)> fn) {
  auto half = [&](int h) { fn(h, h * n / 2, (h + 1) * n / 2); };
  if (m_halfHelper && n >= kSplitRows) {
    ++m_halvedLists;
    forBothHalves(half);
  } else {
    half(0);
    half(1);
  }
}

void ExactSolver::helpHalves(HalfHelper& h) {
  // Spins a while between halves (they come every few hundred microseconds while a long tree is
  // solved, and a sleeping thread took longer to wake than a half takes), then sleeps until the
  // next is offered; with h.watch it spins until the solve ends.
  constexpr int kSpins = 4000;
  uint64_t seen = 0;  // (a helper that starts late takes the half on offer, if still free, or sees the stop)
  int idle = 0;
  for (;;) {
    const uint64_t g = h.posted.load(std::memory_order_acquire);
    if (g == seen) {
      if (++idle < kSpins || h.watch) {
        cpuRelax();
      } else {
        h.posted.wait(seen, std::memory_order_acquire);
        idle = 0;
      }
      continue;
    }
    seen = g;
    idle = 0;
    if (h.stop.load(std::memory_order_acquire)) return;
    uint64_t expected = g - 1;
    if (!h.taken.compare_exchange_strong(expected, g, std::memory_order_acq_rel)) continue;
    h.fn(1);
    h.done.store(g, std::memory_order_release);
  }
}

void ExactSolver::factor(Cluster& c, bool solveToo) {
  m_fetch = c.end - c.begin >= kFetchNodes;
  // After rows left or rejoined the active set (and nothing else changed), only their nodes, their
  // children (whose coupling H holds the row) and the nodes on the way to the root are factored
  // again; every other node keeps its inverse and G and only passes its share to a parent that is
  // factored again, in the same order as a whole factor (so the same bits). Trees with loops are
  // factored whole.
  const bool partial = !c.full && c.loopEnd == c.loopBegin && !m_shared->wholeFactors;
  m_partialFactors += partial;
  if (m_need.size() < m_nodes.size()) m_need.resize(m_nodes.size(), 0);
  if (m_rowChanged.size() < m_nodes.size()) m_rowChanged.resize(m_nodes.size(), 0);
  auto needs = [&](int k) { return !partial || m_need[size_t(k)]; };
  // Node k (not the root) must be factored again: its row changed, or its parent's (a joint whose
  // row changed is the parent of the bodies it couples).
  auto own = [&](int k) {
    const Node& n = m_nodes[size_t(k)];
    m_need[size_t(k)] = m_rowChanged[size_t(k)] || m_rowChanged[size_t(n.parent)];
  };
  if (solveToo && m_residualMade.size() < m_nodes.size()) m_residualMade.resize(m_nodes.size(), 0);
  if (c.split) {
    // Each half leaves first, as below; the root's children pass their shares to it after both,
    // in the same order as a whole pass would (so the halves' threads change no bit).
    initNode(c.begin);
    if (solveToo) iterationResidual(c.begin);
    forBothHalves([&](int h) {
      if (partial) {
        for (int i = c.lane[h]; i < c.lane[h + 1]; ++i) own(m_laneNodes[size_t(i)]);
        for (int i = c.lane[h + 1] - 1; i >= c.lane[h]; --i) {
          const Node& n = m_nodes[size_t(m_laneNodes[size_t(i)])];
          if (m_need[size_t(m_laneNodes[size_t(i)])] && n.parent != c.begin) m_need[size_t(n.parent)] = 1;
        }
      }
      const int* lane = m_laneNodes.data();
      for (int i = c.lane[h]; i < c.lane[h + 1]; ++i) {
        if (m_fetch && i + kFetchAhead < c.lane[h + 1] && needs(lane[i + kFetchAhead]))
          fetchInit(lane[i + kFetchAhead]);
        if (needs(lane[i])) initNode(lane[i]);
      }
      for (int i = c.lane[h + 1] - 1; i >= c.lane[h]; --i) {
        if (m_fetch && i - kFetchAhead >= c.lane[h]) {
          fetchPass(lane[i - kFetchAhead]);
          if (solveToo) fetchResidual(lane[i - kFetchAhead]);
        }
        const int k = lane[i];
        Node& n = m_nodes[size_t(k)];
        if (needs(k)) {
          invertPivot(n.dinv);
          if (n.parent != c.begin) passToParent(k, true);
        } else if (n.parent != c.begin && m_need[size_t(n.parent)]) {
          passToParent(k, false);
        }
        if (solveToo) iterationDownStep(k, c.begin);
      }
      for (int i = c.lane[h]; i < c.lane[h + 1]; ++i) m_rowChanged[size_t(lane[i])] = 0;
    });
    for (int i = c.lane[3] - 1; i >= c.lane[2]; --i)
      passToParent(m_laneNodes[size_t(i)], needs(m_laneNodes[size_t(i)]));
    invertPivot(m_nodes[size_t(c.begin)].dinv);
  } else {
    if (partial) {
      m_need[size_t(c.begin)] = m_rowChanged[size_t(c.begin)];
      for (int k = c.begin + 1; k < c.end; ++k) own(k);
      for (int k = c.end - 1; k > c.begin; --k)
        if (m_need[size_t(k)]) m_need[size_t(m_nodes[size_t(k)].parent)] = 1;
    }
    for (int k = c.begin; k < c.end; ++k) {
      if (m_fetch && k + kFetchAhead < c.end && needs(k + kFetchAhead)) fetchInit(k + kFetchAhead);
      if (needs(k)) initNode(k);
    }
    for (int k = c.end - 1; k >= c.begin; --k) {  // leaves first
      if (m_fetch && k - kFetchAhead >= c.begin) {
        fetchPass(k - kFetchAhead);
        if (solveToo) fetchResidual(k - kFetchAhead);
      }
      Node& n = m_nodes[size_t(k)];
      if (needs(k)) {
        invertPivot(n.dinv);
        if (n.parent >= 0) passToParent(k, true);
      } else if (n.parent >= 0 && m_need[size_t(n.parent)]) {
        passToParent(k, false);
      }
      if (solveToo) iterationDownStep(k, -1);
    }
  }
  if (solveToo) solveFromRoot(c, true);
  if (c.split)  // (each half's nodes cleared by its thread)
    m_rowChanged[size_t(c.begin)] = 0;
  else
    std::fill(m_rowChanged.begin() + c.begin, m_rowChanged.begin() + c.end, char(0));
  c.dirty = c.full = false;
  if (c.loopEnd > c.loopBegin) factorLoops(c);
}

void ExactSolver::pushThroughTree(Cluster& c, const Eigen::VectorXd& p, bool positions) {
  for (int k = c.begin; k < c.end; ++k) m_nodes[size_t(k)].y.setZero();
  for (int l = c.loopBegin; l < c.loopEnd; ++l) {
    const Row& r = row(m_loopJoints[size_t(l)]);
    const auto pl = p.segment<6>(6 * (l - c.loopBegin));
    if (r.na >= 0) m_nodes[size_t(m_nodeOfBody[size_t(r.na)])].y.noalias() += r.ja.transpose() * pl;
    if (r.nb >= 0) m_nodes[size_t(m_nodeOfBody[size_t(r.nb)])].y.noalias() += r.jb.transpose() * pl;
  }
  solve(c);
  if (positions) return;
  for (int k = c.begin; k < c.end; ++k) {
    Node& n = m_nodes[size_t(k)];
    if (n.body >= 0)
      addBodyVelocity(n.body, n.x);
    else
      row(n.joint).lambda -= n.x;
  }
}

/// The loop rows' response to their own impulses through the tree (the tree's joints held
/// exact), one tree solve per row, plus their compliance; a fixed axial row is left out.
void ExactSolver::factorLoops(Cluster& c) {
  const int loops = c.loopEnd - c.loopBegin, k = 6 * loops;
  c.schur.setZero(k, k);
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(k);
  auto loopRow = [&](int l) -> const Row& { return row(m_loopJoints[size_t(c.loopBegin + l)]); };
  auto nodeX = [&](int body) -> const Vec6& { return m_nodes[size_t(m_nodeOfBody[size_t(body)])].x; };
  for (int col = 0; col < k; ++col) {
    if (col % 6 == 5 && !loopRow(col / 6).axialActive) continue;
    unit.setZero();
    unit[col] = 1;
    pushThroughTree(c, unit, true);
    for (int l = 0; l < loops; ++l) {
      const Row& r = loopRow(l);
      Vec6 jv = Vec6::Zero();
      if (r.na >= 0) jv.noalias() += r.ja * nodeX(r.na);
      if (r.nb >= 0) jv.noalias() += r.jb * nodeX(r.nb);
      c.schur.block<6, 1>(6 * l, col) = jv;
    }
  }
  for (int l = 0; l < loops; ++l) {
    const Row& r = loopRow(l);
    const ExactJoint& e = m_shared->joints[size_t(m_loopJoints[size_t(c.loopBegin + l)])];
    for (int i = 0; i < 6; ++i) c.schur(6 * l + i, 6 * l + i) += kRegularisation;
    const int a = 6 * l + 5;
    if (!r.axialActive) {  // held at its bound: not an unknown
      c.schur.row(a).setZero();
      c.schur.col(a).setZero();
      c.schur(a, a) = 1;
    } else if (e.state == ExactJoint::Axial::Motor) {
      c.schur(a, a) += e.compliance;
    }
  }
  // S is singular where a loop's rows repeat the tree's (a planar ring's out-of-plane rows): a
  // pseudo-inverse through its eigenvectors. Redundant directions measure 1e-9 to 5e-7 (the
  // regularisation and float rounding) against 1 to 100 for real ones: below 1e-5 of the
  // largest, a direction is dropped.
  //
  // S is also nearly singular where a loop's rows nearly repeat the tree's: in a packed grid of
  // SuperBots, side by side, two modules' pitch axes are nearly one line, and S has directions
  // at 1e-5 to 1e-3 of its largest. Inverted exactly, each small misfit in such a direction
  // became hundreds of newtons of self-stress through the hinges' motor rows, which a motor held
  // at its rating then let go of at once: zero-gravity packs of 100 and 196 SuperBots latching at
  // run time diverged. So the velocity solve damps them: 1 / s becomes s / (s^2 + m^2), m =
  // kLoopDamping of the largest (a direction at 10 m keeps 99% of its correction, and every
  // iteration sweeps again). The position projection keeps them nearly exact (kLoopPositionDamping):
  // damped as much, the free ring of tests/engine/physics, folding flat at speed, opened by
  // 0.08 mm; with 1e-4, by 0.0012 mm, as undamped.
  constexpr double kLoopDamping = 1e-2, kLoopPositionDamping = 1e-4;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (c.schur + c.schur.transpose()));
  c.schur = eig.eigenvectors();
  const Eigen::VectorXd& values = eig.eigenvalues();
  const double top = std::max(values.cwiseAbs().maxCoeff(), 1e-300), floor = 1e-5 * top;
  c.schurInv.resize(k);
  c.schurPosInv.resize(k);
  auto damped = [&](double v, double m) { return v > floor ? v / (v * v + m * m * top * top) : 0.0; };
  for (int i = 0; i < k; ++i) {
    c.schurInv[i] = damped(values[i], kLoopDamping);
    c.schurPosInv[i] = damped(values[i], kLoopPositionDamping);
  }
}

Eigen::VectorXd ExactSolver::solveLoops(const Cluster& c, const Eigen::VectorXd& inv,
                                        const Eigen::VectorXd& v) const {
  return c.schur * inv.cwiseProduct(c.schur.transpose() * v);
}

/// Makes the loop rows exact after the tree's solve: their impulse change through S, then
/// passed on through the tree so its joints stay exact.
void ExactSolver::loopIteration(Cluster& c, bool clamp) {
  using A = ExactJoint::Axial;
  if (c.dirty) factor(c);
  const int loops = c.loopEnd - c.loopBegin;
  Eigen::VectorXd err(6 * loops);
  for (int l = 0; l < loops; ++l) {
    const int j = m_loopJoints[size_t(c.loopBegin + l)];
    const Row& r = row(j);
    const ExactJoint& e = m_shared->joints[size_t(j)];
    Vec6 y = structuralResidual(j);
    y[5] = r.axialActive ? e.rowTarget + y[5] - (e.state == A::Motor ? e.compliance * r.lambda[5] : 0) : 0;
    err.segment<6>(6 * l) = y;
  }
  const Eigen::VectorXd dl = solveLoops(c, c.schurInv, err);
  for (int l = 0; l < loops; ++l) row(m_loopJoints[size_t(c.loopBegin + l)]).lambda += dl.segment<6>(6 * l);
  pushThroughTree(c, dl, false);
  if (!clamp) return;
  for (int l = 0; l < loops; ++l) {  // as the tree's bounded rows (clusterIteration)
    const int j = m_loopJoints[size_t(c.loopBegin + l)];
    Row& r = row(j);
    if (!r.axialActive) continue;
    ExactJoint& e = m_shared->joints[size_t(j)];
    const double v = r.lambda[5], tau = e.motorOn ? e.maxImpulse : 0;
    double fixAt = v;
    if (e.state == A::Motor && std::abs(v) > tau) fixAt = std::copysign(tau, v);
    if (e.state == A::Lower && v < e.bound) fixAt = e.bound;
    if (e.state == A::Upper && v > e.bound) fixAt = e.bound;
    if (fixAt != v) {
      c.clamped = true;
      applyAxial(j, fixAt - v);
      e.state = A::Fixed;
      e.fixedImpulse = fixAt;
      r.axialActive = false;
      c.dirty = c.full = true;
    }
  }
}

/// Solves for the right-hand side already in each node's y (bodies: 0; joints: the rows'
/// residual); leaves x: a body's velocity (or position) change, a joint's -lambda.
void ExactSolver::solve(Cluster& c, bool iteration) {
  m_fetch = c.end - c.begin >= kFetchNodes;
  // Three products a node (G = D^-1 H from the factor): down, x = D^-1 y and the parent's
  // y -= H^T D^-1 y = G^T y; up, x -= G x_parent.
  if (iteration && m_residualMade.size() < m_nodes.size()) m_residualMade.resize(m_nodes.size(), 0);
  if (c.split) {  // each half apart, the root's children passing on to it after both
    if (iteration) iterationResidual(c.begin);
    forBothHalves(
        [&](int h) { solveDown(c.lane[h], c.lane[h + 1], m_laneNodes.data(), c.begin, iteration); });
  } else {
    solveDown(c.begin, c.end, nullptr, -1, iteration);
  }
  solveFromRoot(c, iteration);
}

/// The rest of a solve after its down pass (solve, or a factor's with `solveToo`): a split tree's
/// root takes its children's shares and is solved; then the up pass.
void ExactSolver::solveFromRoot(Cluster& c, bool iteration) {
  if (!c.split) return solveUp(c.begin, c.end, nullptr, iteration);
  Node& root = m_nodes[size_t(c.begin)];
  for (int i = c.lane[3] - 1; i >= c.lane[2]; --i) {
    const Node& n = m_nodes[size_t(m_laneNodes[size_t(i)])];
    root.y.noalias() -= n.g.transpose() * n.y;
  }
  root.x.noalias() = root.dinv * root.y;
  if (iteration) iterationApply(c.begin);
  forBothHalves([&](int h) { solveUp(c.lane[h], c.lane[h + 1], m_laneNodes.data(), iteration); });
}

/// Node k's right-hand side made, the first time the down pass reaches it.
[[gnu::always_inline]] inline void ExactSolver::prepareResidual(int k) {
  if (m_residualMade[size_t(k)]) return;
  m_residualMade[size_t(k)] = 1;
  iterationResidual(k);
}

template <bool Iteration>
[[gnu::always_inline]] inline void ExactSolver::downPass(int from, int to, const int* order, int skip) {
  node_products::downPass(
      m_nodes.data(), from, to, order, skip,
      [this](int k) {
        if (Iteration) prepareResidual(k);
      },
      [this](int k) {
        if (Iteration && m_fetch) fetchResidual(k);
      });
}

template <bool Iteration>
[[gnu::always_inline]] inline void ExactSolver::upPass(int from, int to, const int* order) {
  node_products::upPass(
      m_nodes.data(), from, to, order,
      [this](int k) {
        if (!Iteration) return;
        m_residualMade[size_t(k)] = 0;
        iterationApply(k);
      },
      [this](int k) {
        if (Iteration && m_fetch) fetchApply(k);
      });
}

// The rows and solver bodies lie in other orders than the tree's nodes, and with a long tree they
// have left the caches between two solves (a 1000-module snake's 6000 nodes take 4 MB): what
// node k's residual and its result's application will touch, fetched a few nodes ahead.
[[gnu::always_inline]] inline void ExactSolver::fetchSolverBody(int sid, bool all) const {
  const btSolverBody& s = m_tmpSolverBodyPool[sid];
  __builtin_prefetch(&s.m_deltaLinearVelocity);
  if (!all) return;
  __builtin_prefetch(&s.m_linearVelocity);
  __builtin_prefetch(&s.m_externalTorqueImpulse);
}

[[gnu::always_inline]] inline void ExactSolver::fetchResidual(int k) const {
  const NodeBodies& nb = m_nodeBodies[size_t(k)];
  const int j = m_nodes[size_t(k)].joint;
  if (j < 0) return;  // (a body node's residual is 0)
  const Row& r = row(j);
  __builtin_prefetch(&r.na);
  for (const Mat6* m : {&r.ja, &r.jb}) {  // (their right halves: 144 bytes)
    __builtin_prefetch(&m->coeffRef(0, 3));
    __builtin_prefetch(&m->coeffRef(2, 4));
    __builtin_prefetch(&m->coeffRef(5, 5));
  }
  __builtin_prefetch(&r.bias);
  __builtin_prefetch(&r.axialActive);
  const ExactJoint& e = m_shared->joints[size_t(j)];
  __builtin_prefetch(&e.compliance);
  __builtin_prefetch(&e.state);
  for (int side = 0; side < 2; ++side)
    if (nb.sid[side] >= 0) {
      __builtin_prefetch(&m_bodies[size_t(nb.body[side])].sid);
      fetchSolverBody(nb.sid[side], true);
    }
}

[[gnu::always_inline]] inline void ExactSolver::fetchApply(int k) const {
  const NodeBodies& nb = m_nodeBodies[size_t(k)];
  const int j = m_nodes[size_t(k)].joint;
  if (j >= 0) {
    const Row& r = row(j);
    __builtin_prefetch(&r.lambda[0]);
    __builtin_prefetch(&r.lambda[5]);
  } else if (nb.sid[0] >= 0) {
    __builtin_prefetch(&m_bodies[size_t(nb.body[0])].sid);
    fetchSolverBody(nb.sid[0], false);
  }
}

// The same for the factor: what initNode and passToParent read of a node's row, joint or body.
[[gnu::always_inline]] inline void ExactSolver::fetchInit(int k) const {
  const Node& n = m_nodes[size_t(k)];
  if (n.joint >= 0) {
    __builtin_prefetch(&row(n.joint).axialActive);
    const ExactJoint& e = m_shared->joints[size_t(n.joint)];
    __builtin_prefetch(&e.compliance);
    __builtin_prefetch(&e.state);
  } else {
    const Body& b = m_bodies[size_t(n.body)];
    __builtin_prefetch(&b.invMass);
    __builtin_prefetch(&b.inertia(2, 2));
  }
}

[[gnu::always_inline]] inline void ExactSolver::fetchPass(int k) const {
  const int j = m_nodeBodies[size_t(k)].coupling;
  if (j < 0) return;
  const Row& r = row(j);
  const Mat6& m = m_nodes[size_t(k)].parentIsA ? r.ja : r.jb;
  __builtin_prefetch(&m.coeffRef(0, 0));
  __builtin_prefetch(&m.coeffRef(0, 3));
  __builtin_prefetch(&m.coeffRef(2, 4));
  __builtin_prefetch(&m.coeffRef(5, 5));
  __builtin_prefetch(&r.axialActive);
}

/// m_nodeBodies for the nodes from `begin` (this solver group's).
void ExactSolver::noteNodeBodies(int begin) {
  m_nodeBodies.resize(m_nodes.size());
  auto note = [&](NodeBodies& nb, int side, int b) {
    nb.body[side] = b;
    nb.sid[side] = b >= 0 ? m_bodies[size_t(b)].sid : -1;
  };
  for (size_t k = size_t(begin); k < m_nodes.size(); ++k) {
    const Node& n = m_nodes[k];
    NodeBodies& nb = m_nodeBodies[k];
    if (n.joint >= 0) {
      note(nb, 0, row(n.joint).na);
      note(nb, 1, row(n.joint).nb);
      nb.coupling = n.joint;
    } else {
      note(nb, 0, n.body);
      note(nb, 1, -1);
      nb.coupling = n.parent >= 0 ? m_nodes[size_t(n.parent)].joint : -1;
    }
  }
}

void ExactSolver::iterationDownStep(int k, int skip) {
  if (m_avx)
    iterationDownStepAvx(k, skip);
  else
    iterationDownStepPlain(k, skip);
}

void ExactSolver::iterationDownStepPlain(int k, int skip) {
  node_products::downStep(m_nodes.data(), k, skip, [this](int i) { prepareResidual(i); });
}

void ExactSolver::iterationDownStepAvx(int k, int skip) {
  node_products::downStep(m_nodes.data(), k, skip, [this](int i) { prepareResidual(i); });
}

void ExactSolver::solveDownPlain(int from, int to, const int* order, int skip, bool iteration) {
  iteration ? downPass<true>(from, to, order, skip) : downPass<false>(from, to, order, skip);
}

void ExactSolver::solveUpPlain(int from, int to, const int* order, bool iteration) {
  iteration ? upPass<true>(from, to, order) : upPass<false>(from, to, order);
}

void ExactSolver::solveDownAvx(int from, int to, const int* order, int skip, bool iteration) {
  iteration ? downPass<true>(from, to, order, skip) : downPass<false>(from, to, order, skip);
}

void ExactSolver::solveUpAvx(int from, int to, const int* order, bool iteration) {
  iteration ? upPass<true>(from, to, order) : upPass<false>(from, to, order);
}

void ExactSolver::solveDown(int from, int to, const int* order, int skip, bool iteration) {
  if (m_avx)
    solveDownAvx(from, to, order, skip, iteration);
  else
    solveDownPlain(from, to, order, skip, iteration);
}

void ExactSolver::solveUp(int from, int to, const int* order, bool iteration) {
  if (m_avx)
    solveUpAvx(from, to, order, iteration);
  else
    solveUpPlain(from, to, order, iteration);
}

/// A node's right-hand side for an iteration: a body's 0, a joint's rows' residual.
void ExactSolver::iterationResidual(int k) {
  Node& n = m_nodes[size_t(k)];
  if (n.joint < 0) {
    n.y.setZero();
    return;
  }
  const Row& r = row(n.joint);
  n.y = structuralResidual(n.joint);
  const ExactJoint& e = m_shared->joints[size_t(n.joint)];
  n.y[5] = r.axialActive
               ? e.rowTarget + n.y[5] - (e.state == ExactJoint::Axial::Motor ? e.compliance * r.lambda[5] : 0)
               : 0;
}

/// A node's solved change applied: a body's velocity, a joint's impulses.
void ExactSolver::iterationApply(int k) {
  const Node& n = m_nodes[size_t(k)];
  if (n.body >= 0)
    addBodyVelocity(n.body, n.x);
  else
    row(n.joint).lambda -= n.x;
}

/// m_subtree: the nodes in each node's subtree, for the tree from `begin` to the end of m_nodes
/// (children come after their parent).
void ExactSolver::subtreeSizes(int begin) {
  const int end = int(m_nodes.size());
  m_subtree.assign(size_t(end - begin), 1);
  for (int k = end - 1; k > begin; --k)
    m_subtree[size_t(m_nodes[size_t(k)].parent - begin)] += m_subtree[size_t(k - begin)];
}

/// The body whose removal leaves no part of the tree from `begin` (its nodes to the end of
/// m_nodes) with more than half its nodes: from the root, down the largest subtree while it holds
/// more than half.
int ExactSolver::centroidBody(int begin) {
  subtreeSizes(begin);
  const int end = int(m_nodes.size()), total = end - begin;
  std::vector<int>& largest = m_half;  // each node's largest child
  largest.assign(size_t(total), -1);
  for (int k = begin + 1; k < end; ++k) {
    int& l = largest[size_t(m_nodes[size_t(k)].parent - begin)];
    if (l < 0 || m_subtree[size_t(k - begin)] > m_subtree[size_t(l - begin)]) l = k;
  }
  int v = begin;
  while (largest[size_t(v - begin)] >= 0 && 2 * m_subtree[size_t(largest[size_t(v - begin)] - begin)] > total)
    v = largest[size_t(v - begin)];
  const Node& n = m_nodes[size_t(v)];
  return n.body >= 0 ? n.body : m_nodes[size_t(n.parent)].body;
}

/// The halves of a tree rooted at its centroid: the root's subtrees, largest first, each to the
/// half with fewer nodes so far. (Breadth first, the root's children are the nodes right after it.)
void ExactSolver::splitTree(Cluster& c) {
  subtreeSizes(c.begin);
  const int begin = c.begin, end = int(m_nodes.size());
  int children = 0;
  while (begin + 1 + children < end && m_nodes[size_t(begin + 1 + children)].parent == begin) ++children;
  std::vector<int>& half = m_half;  // each node's half (0 or 1; the root -1): its subtree's
  half.assign(size_t(end - begin), -1);
  int sizes[2] = {0, 0};
  for (int placed = 0; placed < children; ++placed) {
    int best = -1;
    for (int k = begin + 1; k <= begin + children; ++k)
      if (half[size_t(k - begin)] < 0 &&
          (best < 0 || m_subtree[size_t(k - begin)] > m_subtree[size_t(best - begin)]))
        best = k;
    const int h = sizes[0] <= sizes[1] ? 0 : 1;
    half[size_t(best - begin)] = h;
    sizes[h] += m_subtree[size_t(best - begin)];
  }
  for (int k = begin + children + 1; k < end; ++k)
    half[size_t(k - begin)] = half[size_t(m_nodes[size_t(k)].parent - begin)];
  // Each half's nodes together in memory: the root, its children as they were, then the rest of
  // half 0, then of half 1, each in its order. Breadth first from the middle of a chain, the
  // halves' nodes alternated, and each thread's walk over its own half took every node's
  // neighbours' cache lines too. Every node keeps its parent, each half its order, and the root's
  // children theirs, so each pass does the same operations in the same order.
  {
    std::vector<int>& order = m_subtree;  // old node (less begin) by new place; sizes are done with
    order.clear();
    for (int k = begin; k <= begin + children; ++k) order.push_back(k - begin);
    for (int h = 0; h < 2; ++h)
      for (int k = begin + children + 1; k < end; ++k)
        if (half[size_t(k - begin)] == h) order.push_back(k - begin);
    std::vector<int>& place = m_queue;  // new place (less begin) by old node
    place.resize(order.size());
    for (size_t i = 0; i < order.size(); ++i) place[size_t(order[i])] = int(i);
    m_nodeHeads.resize(order.size());
    for (size_t i = 0; i < order.size(); ++i) {
      const Node& n = m_nodes[size_t(begin + order[i])];
      m_nodeHeads[i] = {n.body, n.joint, n.parent < 0 ? -1 : begin + place[size_t(n.parent - begin)],
                        n.parentIsA};
    }
    for (size_t i = 0; i < order.size(); ++i) {
      const NodeHead& head = m_nodeHeads[i];
      Node& n = m_nodes[size_t(begin) + i];
      n.body = head.body;
      n.joint = head.joint;
      n.parent = head.parent;
      n.parentIsA = head.parentIsA;
      if (n.body >= 0) m_nodeOfBody[size_t(n.body)] = begin + int(i);
      if (n.joint >= 0) row(n.joint).node = begin + int(i);
    }
  }
  // Each half's lane, in node order (a node's half is its old place's).
  const std::vector<int>& order = m_subtree;
  c.lane[0] = int(m_laneNodes.size());
  for (int h = 0; h < 2; ++h) {
    for (int k = begin + 1; k < end; ++k)
      if (half[size_t(order[size_t(k - begin)])] == h) m_laneNodes.push_back(k);
    c.lane[h + 1] = int(m_laneNodes.size());
  }
  for (int k = begin + 1; k <= begin + children; ++k) m_laneNodes.push_back(k);
  c.lane[3] = int(m_laneNodes.size());
  c.split = true;
}

void ExactSolver::forEachCluster(int begin, FunctionRef<void(int)> fn) {
  for (int i = begin; i < int(m_clusters.size()); ++i) fn(i);
}

void ExactSolver::exactIterationWhere(bool clamp, FunctionRef<bool(const Cluster&)> want) {
  forEachCluster(m_groupBegin, [&](int ci) {
    Cluster& c = m_clusters[size_t(ci)];
    if (want(c)) clusterIteration(c, clamp);
  });
}

/// Node k's axial row fixed at its bound if the last solve took it past its motor's rating or a
/// limit (true if it was); the row's node marked changed for the next factor. Touches node k's
/// row, joint and bodies only.
bool ExactSolver::clampAxial(int k) {
  using A = ExactJoint::Axial;
  Node& n = m_nodes[size_t(k)];
  if (n.body >= 0) return false;
  Row& r = row(n.joint);
  if (!r.axialActive) return false;
  ExactJoint& e = m_shared->joints[size_t(n.joint)];
  const double l = r.lambda[5];
  const double tau = e.motorOn ? e.maxImpulse : 0;
  double fixAt = l;
  if (e.state == A::Motor && std::abs(l) > tau) fixAt = std::copysign(tau, l);
  if (e.state == A::Lower && l < e.bound) fixAt = e.bound;
  if (e.state == A::Upper && l > e.bound) fixAt = e.bound;
  if (fixAt == l) return false;
  r.lambda[5] = l;
  applyAxial(n.joint, fixAt - l);
  e.state = A::Fixed;
  e.fixedImpulse = fixAt;
  r.axialActive = false;
  m_rowChanged[size_t(k)] = 1;
  return true;
}

/// One exact solve of a cluster's rows. It reads and writes only the cluster's own bodies,
/// joints and nodes, so clusters may run in parallel.
void ExactSolver::clusterIteration(Cluster& c, bool clamp) {
  // The rows' residuals, the solve, and its result applied, in one pass each way (each node reads
  // and writes its own row or body), a long tree's halves apart; after a factor, its down pass
  // with the factor's.
  if (c.dirty && c.loopEnd == c.loopBegin) {
    factor(c, true);
  } else {
    if (c.dirty) factor(c);
    solve(c, true);
  }
  // The centripetal targets at these joint-consistent velocities, before any row is clamped; then
  // a bounded axial row that left its bounds is fixed at the bound from now on. A long tree's
  // halves each on their own thread (the rows and bodies each thread's solve has just written
  // stay in its core's cache; from the other core, each read and the next write of a line was a
  // transfer between the cores): the root and its children first, so that every body takes its
  // joints' impulses in node order, as in one pass (the same bits).
  if (c.centripetal)
    forEachNode(c, [&](int k, int) {
      if (const int j = m_nodes[size_t(k)].joint; j >= 0) updateCentripetal(j);
    });
  bool clamped = false;
  if (clamp && !c.split) {
    for (int k = c.begin; k < c.end; ++k) clamped |= clampAxial(k);
  } else if (clamp) {
    clamped |= clampAxial(c.begin);
    for (int i = c.lane[2]; i < c.lane[3]; ++i) clamped |= clampAxial(m_laneNodes[size_t(i)]);
    bool halves[2] = {false, false};
    forBothHalves([&](int h) {
      bool any = false;
      for (int i = c.lane[h]; i < c.lane[h + 1]; ++i)
        if (const int k = m_laneNodes[size_t(i)]; m_nodes[size_t(k)].parent != c.begin) any |= clampAxial(k);
      halves[h] = any;
    });
    clamped |= halves[0] || halves[1];
  }
  c.resolve = false;
  if (clamped) c.clamped = c.dirty = true;
  if (c.loopEnd > c.loopBegin) {
    // The loops' solve factors the tree again for the rows just fixed (their impulses were set
    // at their bounds on their joints' bodies alone), and so clears `dirty`; the tree's other
    // rows still want the solve that carries that change through them (finishJoints' settle).
    // Without it a lattice kept those joints apart at up to 406 m/s and rad/s of row velocity until the
    // next substep (worlds/breakage_grid.lua).
    loopIteration(c, clamp);
    c.resolve = clamped && !c.dirty;
  }
}

void ExactSolver::convertBodies(btCollisionObject** bodies, int numBodies, const btContactSolverInfo& info) {
  BT_PROFILE("convertBodies");
  // Bullet 3.24 without thread support: every listed body's companion id cleared; then, in list
  // order, a body met first that moves (or is kinematic) takes the next solver body, made from it
  // (initSolverBody), and anything else the one fixed body; each listed body with mass then takes
  // its gyroscopic impulse. Here the ids are handed out first, in that order, and then the solver
  // bodies made in the same order, each body's lines fetched a few bodies ahead: the same solver
  // bodies, bit for bit.
  for (int i = 0; i < numBodies; ++i) {
    if (i + kFetchAhead < numBodies) {
      bullet_layout::fetch(bodies[i + kFetchAhead], bullet_layout::kCompanionId);
      bullet_layout::fetch(bodies[i + kFetchAhead], bullet_layout::kInverseMass);
    }
    bodies[i]->setCompanionId(-1);
  }
  m_tmpSolverBodyPool.reserve(numBodies + 1);
  m_tmpSolverBodyPool.resizeNoInitialize(0);
  m_freshBodies.clear();
  for (int i = 0; i < numBodies; ++i) {
    btCollisionObject& o = *bodies[i];
    const btRigidBody* rb = btRigidBody::upcast(&o);
    if (o.getCompanionId() >= 0) {
      // A body listed twice (Bullet's islands never list one so) takes a second gyroscopic
      // impulse in Bullet's order: Bullet's loop it is, from the start.
      m_fixedBodyId = -1;
      return btSequentialImpulseConstraintSolver::convertBodies(bodies, numBodies, info);
    }
    if (rb && (rb->getInvMass() != 0 || rb->isKinematicObject())) {
      o.setCompanionId(m_tmpSolverBodyPool.size());
      m_tmpSolverBodyPool.expandNonInitializing();  // (initSolverBody sets every field, below)
      m_freshBodies.push_back(i);
    } else {
      getOrInitSolverBody(o, info.m_timeStep);  // the fixed body
    }
  }
  const int n = int(m_freshBodies.size());
  forListHalves(n, [&](int, int begin, int end) {
    for (int k = begin; k < end; ++k) {
      if (k + kBodiesAhead < end)
        bullet_layout::fetchRange(bodies[m_freshBodies[size_t(k + kBodiesAhead)]], 0,
                                  int(sizeof(btRigidBody)));
      btCollisionObject* o = bodies[m_freshBodies[size_t(k)]];
      btSolverBody& solverBody = m_tmpSolverBodyPool[o->getCompanionId()];
      initSolverBody(&solverBody, o, info.m_timeStep);
      btRigidBody* body = btRigidBody::upcast(o);
      if (body->getInvMass() == 0) continue;  // (kinematic)
      if (body->getFlags() & BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT) {
        const btVector3 gyroForce = body->computeGyroscopicForceExplicit(info.m_maxGyroscopicForce);
        solverBody.m_externalTorqueImpulse -= gyroForce * body->getInvInertiaTensorWorld() * info.m_timeStep;
      }
      if (body->getFlags() & BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD)
        solverBody.m_externalTorqueImpulse += body->computeGyroscopicImpulseImplicit_World(info.m_timeStep);
      if (body->getFlags() & BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY)
        solverBody.m_externalTorqueImpulse += body->computeGyroscopicImpulseImplicit_Body(info.m_timeStep);
    }
  });
}

void ExactSolver::convertContacts(btPersistentManifold** manifolds, int numManifolds,
                                  const btContactSolverInfo& info) {
  if (!patches) {
    btSequentialImpulseConstraintSolver::convertContacts(manifolds, numManifolds, info);
    return;
  }
  // Bullet 3.24's convertContact, point by point, but for the friction rows' set-up
  // (setupFrictionConstraint: Jacobians, diagonals, targets nobody reads here) and the rolling and
  // spinning rows (addTorsionalFrictionConstraint: never swept here).
  const bool twoDirections = info.m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS;
  for (int i = 0; i < numManifolds; ++i) {
    // With many modules the manifolds have left the caches since the narrowphase: the bodies and
    // count of the one 4 ahead, the points and bodies of the one 2 ahead, fetched now.
    if (i + 4 < numManifolds) bullet_layout::fetch(manifolds[i + 4], bullet_layout::kManifoldBodies);
    if (i + 2 < numManifolds) {
      const btPersistentManifold* ahead = manifolds[i + 2];
      bullet_layout::fetch(ahead->getBody0(), bullet_layout::kCompanionId);
      bullet_layout::fetch(ahead->getBody1(), bullet_layout::kCompanionId);
      for (int k = 0; k < ahead->getNumContacts(); ++k)
        bullet_layout::fetchRange(&ahead->getContactPoint(k), 0, int(sizeof(btManifoldPoint)));
    }
    btPersistentManifold* manifold = manifolds[i];
    auto* colObj0 = const_cast<btCollisionObject*>(manifold->getBody0());
    auto* colObj1 = const_cast<btCollisionObject*>(manifold->getBody1());
    const int idA = getOrInitSolverBody(*colObj0, info.m_timeStep);
    const int idB = getOrInitSolverBody(*colObj1, info.m_timeStep);
    btSolverBody* bodyA = &m_tmpSolverBodyPool[idA];
    btSolverBody* bodyB = &m_tmpSolverBodyPool[idB];
    // (No response between two static objects.)
    if (!bodyA || (bodyA->m_invMass.fuzzyZero() && (!bodyB || bodyB->m_invMass.fuzzyZero()))) continue;
    for (int j = 0; j < manifold->getNumContacts(); ++j) {
      btManifoldPoint& cp = manifold->getContactPoint(j);
      if (!(cp.getDistance() <= manifold->getContactProcessingThreshold())) continue;
      btSolverConstraint& row = m_tmpSolverContactConstraintPool.expandNonInitializing();
      row.m_solverBodyIdA = idA;
      row.m_solverBodyIdB = idB;
      row.m_originalContactPoint = &cp;
      const btVector3 relPos1 = cp.getPositionWorldOnA() - colObj0->getWorldTransform().getOrigin();
      const btVector3 relPos2 = cp.getPositionWorldOnB() - colObj1->getWorldTransform().getOrigin();
      btVector3 vel1, vel2;
      bodyA->getVelocityInLocalPointNoDelta(relPos1, vel1);
      bodyB->getVelocityInLocalPointNoDelta(relPos2, vel2);
      const btVector3 vel = vel1 - vel2;
      const btScalar relVel = cp.m_normalWorldOnB.dot(vel);
      btScalar relaxation;
      setupContactConstraint(row, idA, idB, cp, info, relaxation, relPos1, relPos2);
      row.m_frictionIndex = m_tmpSolverContactFrictionConstraintPool.size();
      // The friction directions, as Bullet's (no direction caching here): along the sliding
      // velocity, or any two across the normal.
      cp.m_lateralFrictionDir1 = vel - cp.m_normalWorldOnB * relVel;
      const btScalar latRelVel = cp.m_lateralFrictionDir1.length2();
      if (!(info.m_solverMode & SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION) &&
          latRelVel > SIMD_EPSILON) {
        cp.m_lateralFrictionDir1 *= 1.f / btSqrt(latRelVel);
        applyAnisotropicFriction(colObj0, cp.m_lateralFrictionDir1,
                                 btCollisionObject::CF_ANISOTROPIC_FRICTION);
        applyAnisotropicFriction(colObj1, cp.m_lateralFrictionDir1,
                                 btCollisionObject::CF_ANISOTROPIC_FRICTION);
        if (twoDirections) {
          cp.m_lateralFrictionDir2 = cp.m_lateralFrictionDir1.cross(cp.m_normalWorldOnB);
          cp.m_lateralFrictionDir2.normalize();
          applyAnisotropicFriction(colObj0, cp.m_lateralFrictionDir2,
                                   btCollisionObject::CF_ANISOTROPIC_FRICTION);
          applyAnisotropicFriction(colObj1, cp.m_lateralFrictionDir2,
                                   btCollisionObject::CF_ANISOTROPIC_FRICTION);
        }
      } else {
        btPlaneSpace1(cp.m_normalWorldOnB, cp.m_lateralFrictionDir1, cp.m_lateralFrictionDir2);
        applyAnisotropicFriction(colObj0, cp.m_lateralFrictionDir1,
                                 btCollisionObject::CF_ANISOTROPIC_FRICTION);
        applyAnisotropicFriction(colObj1, cp.m_lateralFrictionDir1,
                                 btCollisionObject::CF_ANISOTROPIC_FRICTION);
        if (twoDirections) {
          applyAnisotropicFriction(colObj0, cp.m_lateralFrictionDir2,
                                   btCollisionObject::CF_ANISOTROPIC_FRICTION);
          applyAnisotropicFriction(colObj1, cp.m_lateralFrictionDir2,
                                   btCollisionObject::CF_ANISOTROPIC_FRICTION);
          if (info.m_solverMode & SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION)
            cp.m_contactPointFlags |= BT_CONTACT_FLAG_LATERAL_FRICTION_INITIALIZED;
        }
      }
      for (int k = 0; k < (twoDirections ? 2 : 1); ++k) {
        btSolverConstraint& f = m_tmpSolverContactFrictionConstraintPool.expandNonInitializing();
        f.m_frictionIndex = m_tmpSolverContactConstraintPool.size() - 1;
        f.m_originalContactPoint = nullptr;
        f.m_appliedImpulse = 0;
      }
    }
  }
}

btScalar ExactSolver::solveGroupCacheFriendlySetup(btCollisionObject** bodies, int numBodies,
                                                   btPersistentManifold** manifolds, int numManifolds,
                                                   btTypedConstraint** constraints, int numConstraints,
                                                   const btContactSolverInfo& info,
                                                   btIDebugDraw* debugDrawer) {
  const btScalar r = btSequentialImpulseConstraintSolver::solveGroupCacheFriendlySetup(
      bodies, numBodies, manifolds, numManifolds, constraints, numConstraints, info, debugDrawer);
  m_avx = m_shared->avx;
  m_h = double(info.m_timeStep);
  setupPatches(manifolds, numManifolds);
  if (patches)
    setupCaptures(constraints, numConstraints);
  else
    m_groupCaptures.clear();
  m_groupBegin = int(m_clusters.size());
  if (m_rowOf.size() < m_shared->joints.size()) m_rowOf.resize(m_shared->joints.size(), -1);
  m_groupFirstRow = int(m_rows.size());
  m_groupFirstBody = int(m_bodies.size());
  const int firstNode = int(m_nodes.size());
  m_groupFirstNode = firstNode;
  m_groupFirstLoop = int(m_loopJoints.size());
  buildClusters(constraints, numConstraints);
  noteNodeBodies(firstNode);
  m_groupHasJoints = !m_groupJoints.empty();
  // Clusters that touch anything else take no centripetal target (updateCentripetal).
  auto clusterOf = [&](int sid) {
    const int b = sid < int(m_sidToBody.size()) ? m_sidToBody[size_t(sid)] : -1;
    return b >= 0 ? m_bodyCluster[size_t(b)] : -1;
  };
  const auto& contacts = m_tmpSolverContactConstraintPool;
  for (int i = 0; i < contacts.size(); ++i) {
    const int ca = clusterOf(contacts[i].m_solverBodyIdA), cb = clusterOf(contacts[i].m_solverBodyIdB);
    if (ca == cb) continue;
    if (ca >= 0) m_clusters[size_t(ca)].centripetal = false;
    if (cb >= 0) m_clusters[size_t(cb)].centripetal = false;
  }
  // All at the velocities before any impulse. Each joint's setup reads its bodies and writes its
  // own row and state only: a long tree's joints go to the thread whose half holds them (its
  // solves then find their rows in their own core's cache); another long list, half of it each.
  bool split = false;
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) split |= m_clusters[size_t(ci)].split;
  if (m_halfHelper && split) {
    forGroupJoints([&](int j) { return setupJoint(j, m_h), false; }, [](Cluster&, bool) {});
  } else if (m_halfHelper && int(m_groupJoints.size()) >= kSplitJoints) {
    const int n = int(m_groupJoints.size());
    forBothHalves([&](int h) {
      for (int i = h * n / 2; i < (h + 1) * n / 2; ++i) setupJoint(m_groupJoints[size_t(i)], m_h);
    });
  } else {
    // (Each joint's row, about 13 lines that have left the caches since the last substep with
    // many modules, fetched a few joints ahead: setupJoint writes every one. Its joint (6 lines)
    // twice as far ahead, and the poses of the joint's bodies as far as the row.)
    const int n = int(m_groupJoints.size());
    for (int i = 0; i < n; ++i) {
      if (i + 2 * kFetchAhead < n)
        bullet_layout::fetchRange(&m_shared->joints[size_t(m_groupJoints[size_t(i + 2 * kFetchAhead)])], 0,
                                  int(sizeof(ExactJoint)));
      if (i + kFetchAhead < n) {
        const int j = m_groupJoints[size_t(i + kFetchAhead)];
        bullet_layout::fetchRange(&row(j), 0, int(sizeof(Row)));
        bullet_layout::fetchPose(m_shared->joints[size_t(j)].a);
        bullet_layout::fetchPose(m_shared->joints[size_t(j)].b);
      }
      setupJoint(m_groupJoints[size_t(i)], m_h);
    }
  }
  for (int j : m_groupJoints) {
    const ExactJoint& e = m_shared->joints[size_t(j)];
    if (e.state == ExactJoint::Axial::Fixed) applyAxial(j, e.fixedImpulse);
  }
  planSettling();
  planDenseIslands();
  if (m_groupHasJoints || patches) buildGroups(m_groupFirstBody, true);
  return r;
}

/// Gives each island of this solver group with sweep items a slot, and each item its island's
/// slot, so that an island can settle (settleIslands). An island's result depends only on its
/// own rows: it settles the same in any batch, at any thread count. Not where Bullet's own rows
/// are swept (loop-closing hinges of the Bullet solver: no island of their own here), nor for a
/// cluster that takes a centripetal target, whose exact solve moves it with each solve's
/// velocities; clusters with no sweep item keep every iteration as before.
void ExactSolver::planSettling() {
  for (const int tag : m_slotIsland) m_islandSlot[size_t(tag)] = -1;
  m_slotIsland.clear();
  m_itemSlot.clear();
  m_settling = patches && m_tmpSolverNonContactConstraintPool.size() == 0;
  if (!m_settling) return;
  auto slotOf = [&](const btSolverConstraint& c) {
    for (const int sid : {c.m_solverBodyIdA, c.m_solverBodyIdB}) {
      const btRigidBody* o = m_tmpSolverBodyPool[sid].m_originalBody;
      const int tag = o ? o->getIslandTag() : -1;
      if (tag < 0) continue;
      if (size_t(tag) >= m_islandSlot.size()) m_islandSlot.resize(size_t(tag) + 1, -1);
      int& slot = m_islandSlot[size_t(tag)];
      if (slot < 0) {
        slot = int(m_slotIsland.size());
        m_slotIsland.push_back(tag);
      }
      return slot;
    }
    return -1;
  };
  for (const GroupCapture& gc : m_groupCaptures) m_itemSlot.push_back(slotOf(m_patchRows[gc.row]));
  const int nc = m_tmpSolverContactConstraintPool.size();
  for (int j = 0; j < nc; ++j)
    m_itemSlot.push_back(slotOf(m_tmpSolverContactConstraintPool[m_orderTmpConstraintPool[j]]));
  for (const PatchRows& pr : m_groupPatches) m_itemSlot.push_back(slotOf(m_patchRows[pr.row]));
  const size_t slots = m_slotIsland.size();
  m_slotSettle.assign(slots, Settle::Open);
  for (std::vector<double>& change : m_slotChange) change.assign(slots, 0.0);
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci)
    if (const Cluster& c = m_clusters[size_t(ci)]; c.centripetal)
      if (const int slot = clusterSlot(c); slot >= 0) m_slotSettle[size_t(slot)] = Settle::Never;
}

/// Cluster c's island's slot (planSettling), or -1.
int ExactSolver::clusterSlot(const Cluster& c) const {
  return c.island >= 0 && size_t(c.island) < m_islandSlot.size() ? m_islandSlot[size_t(c.island)] : -1;
}

/// After iteration `iteration`'s sweep: an open island whose items all changed by less than
/// kSweepSettled settles, from the second iteration (the first splits masses) to the one before
/// the last. Its clusters take this iteration's exact solve as their last (bounds applied), and
/// then neither they nor its items are solved again this substep. True when every island and
/// cluster of the group has settled: the iterations end.
bool ExactSolver::settleIslands(int iteration, int last) {
  if (!m_settling) return false;
  bool all = !m_slotSettle.empty();
  const bool may = !m_shared->everyIteration && iteration >= 1 && iteration < last;
  for (size_t s = 0; s < m_slotSettle.size(); ++s) {
    Settle& state = m_slotSettle[s];
    double& change0 = m_slotChange[0][s];
    double& change1 = m_slotChange[1][s];
    if (state == Settle::Open || state == Settle::Never) ++m_islandSweeps;
    if (state == Settle::Open && may && std::max(change0, change1) < kSweepSettled) {
      state = Settle::Settling;
      m_sparedSweeps += last - iteration;
    }
    all &= state == Settle::Settling || state == Settle::Settled;
    change0 = change1 = 0;
  }
  for (int ci = m_groupBegin; ci < int(m_clusters.size()) && all; ++ci)
    all = clusterSlot(m_clusters[size_t(ci)]) >= 0;
  return all;
}

btScalar ExactSolver::solveSingleIteration(int iteration, btCollisionObject** bodies, int numBodies,
                                           btPersistentManifold** manifolds, int numManifolds,
                                           btTypedConstraint** constraints, int numConstraints,
                                           const btContactSolverInfo& info, btIDebugDraw* debugDrawer) {
  if (!m_groupHasJoints && !patches)
    return btSequentialImpulseConstraintSolver::solveSingleIteration(iteration, bodies, numBodies, manifolds,
                                                                     numManifolds, constraints,
                                                                     numConstraints, info, debugDrawer);
  // Bullet's own constraint rows (loop-closing hinges), as its sweep does them, then the contacts
  // with rigid groups.
  btScalar r = 0;
  for (int j = 0; j < m_tmpSolverNonContactConstraintPool.size(); ++j) {
    btSolverConstraint& c = m_tmpSolverNonContactConstraintPool[m_orderNonContactConstraintPool[j]];
    if (iteration >= c.m_overrideNumSolverIterations) continue;
    const btScalar res = resolveSingleConstraintRowGeneric(m_tmpSolverBodyPool[c.m_solverBodyIdA],
                                                           m_tmpSolverBodyPool[c.m_solverBodyIdB], c);
    r = std::max(r, res * res);
  }
  // Mass splitting in the first iteration only (see m_useSplit).
  m_useSplit = iteration == 0;
  if (iteration == 0 && m_shared->denseIslands && m_settling && m_groupHasJoints)
    solveDenseIslands(std::max(m_maxOverrideNumSolverIterations, info.m_numIterations));
  r = std::max(r, contactSweep());
  const int last = std::max(m_maxOverrideNumSolverIterations, info.m_numIterations) - 1;
  const bool settled = settleIslands(iteration, last);
  // An exact solve after every sweep (swept twice in a row, grouped bodies take the first sweep's
  // impulses as if free and the second overreacts: a snake diverged). Bounds apply at the last
  // iteration only (or an island's, where it settled): before it the contacts have not settled,
  // and a motor fixed at its rating on their account would be wrong for the whole substep.
  if (m_groupHasJoints)
    forEachCluster(m_groupBegin, [&](int ci) {
      Cluster& c = m_clusters[size_t(ci)];
      const int slot = m_settling ? clusterSlot(c) : -1;
      const Settle state = slot >= 0 ? m_slotSettle[size_t(slot)] : Settle::Open;
      if (state != Settle::Settled) clusterIteration(c, iteration >= last || state == Settle::Settling);
    });
  for (Settle& state : m_slotSettle)
    if (state == Settle::Settling) state = Settle::Settled;
  if (settled) return 0;  // (Bullet's loop ends at a residual of 0)
  // Never stop early on a small contact residual: the joints may still need their solve.
  return m_groupHasJoints && iteration < last ? std::max(r, info.m_leastSquaresResidualThreshold * 2 + 1) : r;
}

void ExactSolver::finishJoints() {
  // A row fixed at its bound in the last solve left the structure unsolved: solve again
  // (a row can only leave the active set, so this ends).
  // Each step below touches only the clusters (or, for contacts, the islands) it concerns, so that
  // a cluster's result does not depend on which others Bullet batched with it.
  // (True when there was a dirty cluster to solve.)
  auto settle = [&] {
    for (int pass = 0; pass < 4; ++pass) {
      bool dirty = false;
      for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci)
        dirty |= m_clusters[size_t(ci)].dirty || m_clusters[size_t(ci)].resolve;
      if (!dirty) return pass > 0;
      exactIterationWhere(true, [](const Cluster& c) { return c.dirty || c.resolve; });
    }
    return true;
  };
  // The contacts were swept with the structure held; where a motor then reached its rating, the
  // impulse they took to stop it now lands on a link its joint no longer holds. Sweep them again
  // with the saturated hinges splitting their groups. Without this, the raised head of a
  // 10-module snake landing at 2 substeps took 0.6 N s on its own link and its pitch joint spun
  // at 105 rad/s, 50 deg in one step (14.8 deg with it, 14.7 at 20 substeps x 100 iterations).
  bool clamped = false;
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) {
    const Cluster& c = m_clusters[size_t(ci)];
    if (!c.clamped || c.island < 0) continue;
    if (c.island >= int(m_sweepIsland.size())) m_sweepIsland.resize(size_t(c.island) + 1, 0);
    if (!m_sweepIsland[size_t(c.island)]) m_resweptIslands.push_back(c.island);
    m_sweepIsland[size_t(c.island)] = 1;
    clamped = true;
  }
  if (clamped) {
    settle();
    buildGroups(m_groupFirstBody);
    auto swept = [&](const Cluster& c) {
      return c.island >= 0 && c.island < int(m_sweepIsland.size()) && m_sweepIsland[size_t(c.island)];
    };
    // Swept again until the contacts settle (the largest impulse change of a sweep under
    // kResweepSettled) or kResweeps sweeps: mass splitting in the first only, as in the
    // substep's own iterations. A sweep whose solve fixes more motors at their rating splits the
    // groups again before the next: swept with the groups of before, the impulse that stops a
    // group lands on a link whose hinge no longer holds it, and the sweeps grew (changes of 0.001,
    // 0.015, 0.07, 0.9 N s squared; a walker's leg spun at 74 rad/s, 74 deg in a step, and loaded
    // its dock 93 N; with 12 sweeps the walker diverged).
    // Each island is swept again until its own contacts settle: ending all of them at once, when
    // the largest change of any settled, made an island's substep depend on which others Bullet
    // batched with it (a 13-module snake ended 0.4 mm elsewhere in one step as a 5-module one in its
    // batch was solved one way or the other).
    // (By the list of the islands swept, not a pass over every island's place.)
    for (std::vector<double>& change : m_islandChange)
      if (change.size() < m_sweepIsland.size()) change.resize(m_sweepIsland.size());
    for (int k = 0; k < kResweeps; ++k) {
      m_useSplit = k == 0;
      for (const int i : m_resweptIslands) m_islandChange[0][size_t(i)] = m_islandChange[1][size_t(i)] = 0;
      contactSweep();
      exactIterationWhere(true, swept);
      bool open = false;
      for (const int i : m_resweptIslands) {
        if (!m_sweepIsland[size_t(i)]) continue;
        if (std::max(m_islandChange[0][size_t(i)], m_islandChange[1][size_t(i)]) < kResweepSettled)
          m_sweepIsland[size_t(i)] = 0;
        else
          open = true;
      }
      if (!open) break;
      if (k + 1 < kResweeps && settle()) buildGroups(m_groupFirstBody);  // (after the last, settle() below)
    }
    m_sweepIsland.clear();
    m_resweptIslands.clear();
  }
  // A row fixed at its rating whose joint now moves beyond the command (the load it met went
  // away as the contacts settled, or the rating overshot it) takes its motor back, once: the
  // solve that follows may fix rows again, and settles. A row that would come back after that
  // holds its rating until the next substep, which starts by checking it again; so no motor
  // ever gives more than its rating. (Up to three such rounds, each refactoring the whole chain
  // once or twice, cost 9-18% of a crawling 150-module snake's time and 6-16% of a 1000-module
  // one's; the converged comparison at the defaults moved from 5.66 to 5.81 deg with one.)
  settle();
  bool reentered = false;
  forGroupJoints([&](int j) { return reenter(j); },
                 [&](Cluster& c, bool loop) {
                   c.dirty = c.retry = reentered = true;
                   c.full |= loop;
                 });
  if (reentered) {
    exactIterationWhere(true, [](const Cluster& c) { return c.retry; });
    for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) m_clusters[size_t(ci)].retry = false;
    settle();
  }
  forGroupJoints([&](int j) { return settleState(j), false; }, [](Cluster&, bool) {});
}

/// fn(j) for each of this solver group's joints, cluster by cluster, and marked(cluster, loop) for
/// each cluster where it returned true (loop: for one of its loop joints). A long tree's joints go
/// by its halves (forEachNode), each on the thread that solves that half (the rows and bodies its
/// solves wrote); fn must touch only joint j's row, joint and bodies' velocities (read).
void ExactSolver::forGroupJoints(FunctionRef<bool(int)> fn, FunctionRef<void(Cluster&, bool)> marked) {
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) {
    Cluster& c = m_clusters[size_t(ci)];
    bool tree[2] = {false, false};  // (written only where fn returns true)
    forEachNode(c, [&](int k, int h) {
      if (const int j = m_nodes[size_t(k)].joint; j >= 0 && fn(j)) tree[h] = true;
    });
    bool loop = false;
    for (int l = c.loopBegin; l < c.loopEnd; ++l) loop |= fn(m_loopJoints[size_t(l)]);
    if (tree[0] || tree[1] || loop) marked(c, loop);
  }
}

/// Joint j's speed about its axis (its axial row's velocity).
double ExactSolver::axialSpeed(int j) const {
  const Row& r = row(j);
  double w = 0;
  if (r.na >= 0) w += r.ja.row(5).dot(bodyVelocity(r.na));
  if (r.nb >= 0) w += r.jb.row(5).dot(bodyVelocity(r.nb));
  return w;
}

/// Whether a motor fixed at its rating (fixedImpulse, nonzero) has outgrown it at axial speed w:
/// a servo's row with a compliance c meets its command as w + c lambda, so at its rating it wants
/// less once w + c x rating runs past the command (w alone, as before, held a servo at full torque
/// while its joint lagged the command by up to c x rating).
bool ExactSolver::outgrown(const ExactJoint& e, double w) {
  const double atRating = w + e.compliance * e.fixedImpulse;
  return (e.fixedImpulse > 0 && atRating > e.targetVel) || (e.fixedImpulse < 0 && atRating < e.targetVel);
}

/// A row fixed at its rating that its motor has outgrown takes its motor back (true if it did;
/// see finishJoints).
bool ExactSolver::reenter(int j) {
  using A = ExactJoint::Axial;
  ExactJoint& e = m_shared->joints[size_t(j)];
  Row& r = row(j);
  if (e.state != A::Fixed || e.fixedImpulse == 0 || !outgrown(e, axialSpeed(j))) return false;
  e.state = A::Motor;
  e.rowTarget = e.targetVel;
  r.axialActive = true;
  if (r.node >= 0) m_rowChanged[size_t(r.node)] = 1;
  return true;
}

/// Joint j's impulses as the substep leaves them, and the state its axial row starts the next
/// substep from (complementarity of the fixed rows).
void ExactSolver::settleState(int j) {
  using A = ExactJoint::Axial;
  ExactJoint& e = m_shared->joints[size_t(j)];
  Row& r = row(j);
  e.axialImpulse = r.lambda[5];
  e.saturated = e.motorOn && e.state == A::Fixed && e.fixedImpulse != 0;
  e.impulseA = r.ja.transpose() * r.lambda;
  e.impulseB = r.jb.transpose() * r.lambda;
  const double w = axialSpeed(j);
  if (e.state == A::Fixed) {
    if (outgrown(e, w)) e.state = A::Motor;
    if (e.state == A::Fixed && w < e.lowVel) e.state = A::Lower;
    if (e.state == A::Fixed && w > e.highVel) e.state = A::Upper;
  }
}

btScalar ExactSolver::solveGroupCacheFriendlyFinish(btCollisionObject** bodies, int numBodies,
                                                    const btContactSolverInfo& info) {
  m_settling = false;  // the sweeps after the iterations take every island they name
  ++m_groupsSolved, ++m_solvedBatches;
  if (m_groupHasJoints) finishJoints();
  if (patches) finishPatches(), finishCaptures();
  // As Bullet 3.24's: the joints' impulses written back (Bullet's rows; the solver's own write
  // theirs in finishJoints), then the contacts' (the warm start) and the bodies' velocities, each
  // row and each body its own, in two runs (forListHalves, by the bodies' count); then the pools
  // emptied.
  BT_PROFILE("solveGroupCacheFriendlyFinish");
  writeBackJoints(0, m_tmpSolverNonContactConstraintPool.size(), info);
  const int contacts = m_tmpSolverContactConstraintPool.size();
  forListHalves(m_tmpSolverBodyPool.size(), [&](int h, int begin, int end) {
    if (info.m_solverMode & SOLVER_USE_WARMSTARTING)
      writeBackContacts(h * contacts / 2, (h + 1) * contacts / 2, info);
    writeBackBodies(begin, end, info);
  });
  m_tmpSolverContactConstraintPool.resizeNoInitialize(0);
  m_tmpSolverNonContactConstraintPool.resizeNoInitialize(0);
  m_tmpSolverContactFrictionConstraintPool.resizeNoInitialize(0);
  m_tmpSolverContactRollingFrictionConstraintPool.resizeNoInitialize(0);
  m_tmpSolverBodyPool.resizeNoInitialize(0);
  return 0;
}

void ExactSolver::postStabilise() {
  if (m_clusters.empty()) return;
  // The next cluster's bodies are fetched while this one is stabilised: with many modules they
  // have left the caches since the integration (a `superbots_10000` substep reads 40,000 bodies
  // here): the pose (read by positionError) and the velocities (setCenterOfMassTransform).
  const int count = int(m_clusters.size());
  forEachCluster(0, [&](int ci) {
    if (ci + 1 < count) {
      const Cluster& next = m_clusters[size_t(ci + 1)];
      if (next.end - next.begin <= kPrefetchNodes)
        for (int k = next.begin; k < next.end; ++k)
          if (const int b = m_nodes[size_t(k)].body; b >= 0) {
            bullet_layout::fetchPose(m_bodies[size_t(b)].rb);
            bullet_layout::fetch(m_bodies[size_t(b)].rb, bullet_layout::kVelocities + 16);
          }
    }
    if (!m_clusters[size_t(ci)].stabilised) stabiliseCluster(m_clusters[size_t(ci)]);
  });
}

bool ExactSolver::batchFinishable() const {
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci)
    if (m_clusters[size_t(ci)].split) return false;
  return true;
}

void ExactSolver::finishBatch() {
  // (Each patch of the batch is this group's; the table is the primary's.)
  if (patches) {
    std::vector<PatchPoses>& poses = m_shared->m_patchPoses;
    if (poses.size() < m_shared->m_patches.size()) poses.resize(m_shared->m_patches.size());
    for (const PatchRows& pr : m_groupPatches) {
      Patch& p = m_shared->m_patches[size_t(pr.slot)];
      p.finished = m_shared->m_substepCount;
      notePatchPose(p, poses[size_t(pr.slot)]);
    }
  }
  for (int ci = m_groupBegin; ci < int(m_clusters.size()); ++ci) {
    Cluster& c = m_clusters[size_t(ci)];
    stabiliseCluster(c);
    c.stabilised = true;
  }
  if (patches)
    for (const PatchRows& pr : m_groupPatches)
      followPatchPose(m_shared->m_patches[size_t(pr.slot)], m_shared->m_patchPoses[size_t(pr.slot)]);
  ++m_groupsFinished, ++m_finishedBatches;
  // Nothing reads the batch's clusters, rows, nodes and bodies again this substep: the next
  // batch's take their places. With many small islands they had run to megabytes a substep (7000
  // nodes of 688 bytes and 3000 rows of 704 for 1000 SuperBots), each line written once from
  // memory; the same few hundred kilobytes now stay in the caches from one batch to the next.
  m_clusters.resize(size_t(m_groupBegin));
  m_rows.resize(size_t(m_groupFirstRow));
#ifndef NDEBUG
  for (int j : m_groupJoints) m_rowOf[size_t(j)] = -1;  // (rowIndex: read no more this substep)
#endif
  m_nodes.resize(size_t(m_groupFirstNode));
  m_loopJoints.resize(size_t(m_groupFirstLoop));
  m_bodies.resize(size_t(m_groupFirstBody));
  m_nodeOfBody.resize(std::min(m_nodeOfBody.size(), size_t(m_groupFirstBody)));
  m_bodyCluster.resize(std::min(m_bodyCluster.size(), size_t(m_groupFirstBody)));
}

/// Position errors at the integrated poses, projected out: first with the cluster's last factor
/// (its rows from the substep's start), then, while an error is left above kStabiliseTolerance,
/// again: with the same factor where the pass before predicts that this is enough (a chord step),
/// else with rows and factor at the corrected poses (a Newton step). A few passes at most.
void ExactSolver::stabiliseCluster(Cluster& c) {
  const bool loops = c.loopEnd > c.loopBegin;
  double before = 0;  // the largest error before the pass
  double rate = 1;    // what the pass before left of its error (left / before)
  for (int pass = 0; pass < kStabilisePasses; ++pass) {
    // A pass with the same rows takes the error down about as much as the pass before did (both
    // stale by the substep's motion): taken where that would leave under half the tolerance. A
    // crawling snake's first pass leaves 1e-5 to 2e-5 m of 1e-4 (rate 0.1 to 0.2); a chain
    // tumbling at speed, or a loop (its Schur complement from the substep's start, too), is
    // projected at the corrected poses.
    const bool chord = pass > 0 && !loops && before * rate <= kChordShare * kStabiliseTolerance;
    m_chordPasses += chord;
    m_newtonPasses += pass > 0 && !chord;
    // Node by node, each reading its own joint's bodies or writing its own row or body: a long
    // tree's halves apart (the largest error by half).
    if (pass > 0 && !chord) {
      forEachNode(c, [&](int k, int) {
        const Node& n = m_nodes[size_t(k)];
        if (n.joint >= 0) {
          jointRows(n.joint);
        } else {
          Body& b = m_bodies[size_t(n.body)];
          b.invInertia = toEigen(b.rb->getInvInertiaTensorWorld());
          b.inertia = b.invInertia.inverse();
        }
      });
      for (int l = c.loopBegin; l < c.loopEnd; ++l) jointRows(m_loopJoints[size_t(l)]);
      c.dirty = c.full = true;
    }
    if (c.dirty) factor(c);
    // (Each half's largest on a cache line of its own: written node by node, a shared line went
    // back and forth between the halves' cores.)
    // (Set field by field: a zero-initialised pair was a 128-byte clear for each.)
    struct alignas(64) Largest {
      double v;
    };
    // (A tree without loops has each node's y made by the pass before, at the present poses.)
    if (pass == 0 || loops) {
      Largest largest[2];
      largest[0].v = largest[1].v = 0;
      forEachNode(c, [&](int k, int h) {
        Node& n = m_nodes[size_t(k)];
        n.y.setZero();
        if (n.joint >= 0) n.y = positionError(n.joint);
        largest[h].v = std::max(largest[h].v, n.y.cwiseAbs().maxCoeff());
      });
      if (pass == 0) before = std::max(largest[0].v, largest[1].v);
    }
    solve(c);
    // Each body moved by its x; then each joint's error at the new poses (what is left, and the
    // next pass's right-hand side), in the same pass where no loop moves the bodies again: a
    // joint's, once its child body has moved (its parent body, earlier in node order, has).
    Largest moves[2], lefts[2];  // the largest move and error left, by half
    moves[0].v = moves[1].v = lefts[0].v = lefts[1].v = 0;
    auto errorLeft = [&](int k, int h) {  // joint node k's error, into its y
      Node& n = m_nodes[size_t(k)];
      n.y = positionError(n.joint);
      lefts[h].v = std::max(lefts[h].v, stabiliseExcess(n.joint, n.y));
    };
    forEachNode(c, [&](int k, int h) {
      Node& n = m_nodes[size_t(k)];
      if (n.body < 0) {
        // (A joint to the static world below a body has no child body: its error now.)
        if (loops || n.parent < 0) return;
        const Row& r = row(n.joint);
        if ((n.parentIsA ? r.nb : r.na) < 0) errorLeft(k, h);
        return;
      }
      moves[h].v = std::max(moves[h].v, n.x.head<3>().norm() + kLeverArm * n.x.tail<3>().norm());
      applyPositionChange(k);
      if (loops) return;
      n.y.setZero();
      if (n.parent >= 0) errorLeft(n.parent, h);
    });
    // A first pass that turned part of the structure: every body's move is followed by its
    // contact anchors (followPatchPoses; the mark is the substep, in Bullet's third user index).
    if (pass == 0 && std::max(moves[0].v, moves[1].v) > std::max(kLeverMove, kLever * before))
      for (int k = c.begin; k < c.end; ++k)
        if (const int b = m_nodes[size_t(k)].body; b >= 0)
          m_bodies[size_t(b)].rb->setUserIndex3(m_substepCount);
    if (loops) {
      // Then the loops' errors at the corrected poses, through S and the tree, and what is left.
      const int count = c.loopEnd - c.loopBegin;
      Eigen::VectorXd err(6 * count);
      for (int l = 0; l < count; ++l)
        err.segment<6>(6 * l) = positionError(m_loopJoints[size_t(c.loopBegin + l)]);
      pushThroughTree(c, solveLoops(c, c.schurPosInv, err), true);
      applyPositionChanges(c);
      forEachNode(c, [&](int k, int h) {
        if (const int j = m_nodes[size_t(k)].joint; j >= 0)
          lefts[h].v = std::max(lefts[h].v, stabiliseExcess(j, positionError(j)));
      });
    }
    double left = std::max(lefts[0].v, lefts[1].v);
    for (int l = c.loopBegin; l < c.loopEnd; ++l) {
      const int j = m_loopJoints[size_t(l)];
      left = std::max(left, stabiliseExcess(j, positionError(j)));
    }
    // Done when within the tolerance, or when a pass at the new poses no longer halves the error.
    if (left <= kStabiliseTolerance || (pass > 0 && left > 0.5 * before)) break;
    rate = before > 0 ? left / before : 1;
    before = left;
  }
}

/// A joint's position error beyond what float poses can resolve: Bullet keeps poses in float, so
/// a pivot 20 m from the origin is known to 2e-6 m, and one 400 m away to 3e-5 m.
double ExactSolver::stabiliseExcess(int j, const Vec6& err) const {
  const ExactJoint& e = m_shared->joints[size_t(j)];
  const double reach = double((e.a->getCenterOfMassTransform() * e.frameA.getOrigin()).length());
  const double resolution = 8 * double(std::numeric_limits<float>::epsilon()) * std::max(1.0, reach);
  return std::max({err.head<3>().cwiseAbs().maxCoeff() - resolution, err.tail<3>().cwiseAbs().maxCoeff()});
}

/// A joint's position error as its rows measure it: pivot gap, axis tilt (and 0 about the axis).
Vec6 ExactSolver::positionError(int j) const {
  const ExactJoint& e = m_shared->joints[size_t(j)];
  const btTransform ta = e.a->getCenterOfMassTransform() * e.frameA;
  const btTransform tb = e.b->getCenterOfMassTransform() * e.frameB;
  const Mat3d fa = toEigen(ta.getBasis());
  const Vec3d tilt = fa.col(2).cross(toEigen(tb.getBasis().getColumn(2)));
  Vec6 y;
  y.head<3>() = -(toEigen(ta.getOrigin()) - toEigen(tb.getOrigin()));
  y[3] = fa.col(0).dot(tilt);
  y[4] = fa.col(1).dot(tilt);
  y[5] = 0;
  return y;
}

/// Moves every body of the cluster by the position change in its node's x.
void ExactSolver::applyPositionChanges(Cluster& c) {
  for (int k = c.begin; k < c.end; ++k) applyPositionChange(k);
}

/// Moves node k's body (if it is one) by the position change in its x.
void ExactSolver::applyPositionChange(int k) {
  const Node& n = m_nodes[size_t(k)];
  if (n.body < 0) return;
  btRigidBody* rb = m_bodies[size_t(n.body)].rb;
  btTransform t = rb->getCenterOfMassTransform();
  t.setOrigin(t.getOrigin() + btVector3(btScalar(n.x[0]), btScalar(n.x[1]), btScalar(n.x[2])));
  const Vec3d dr = n.x.tail<3>();
  const double angle = dr.norm();
  if (angle > 0) {
    const Vec3d axis = dr / angle;
    btQuaternion q(btVector3(btScalar(axis.x()), btScalar(axis.y()), btScalar(axis.z())), btScalar(angle));
    t.setRotation((q * t.getRotation()).normalized());
  }
  rb->setCenterOfMassTransform(t);
  rb->setInterpolationWorldTransform(t);
}

}  // namespace rm3d
