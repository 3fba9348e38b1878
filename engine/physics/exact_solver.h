// The exact joint solver: Bullet's sequential impulses for contacts and friction, and a direct,
// linear-time solve for the hinges of every connected cluster of bodies.
//
// Docked links are merged into one rigid body (physics_world.h), so a cluster of modules is a
// tree of bodies joined by hinges, plus a few hinges that close loops (below). For each tree the
// solver eliminates the sparse system
//
//     [ M  J^T ] [ dv ]   [ 0 ]
//     [ J  -eI ] [ mu ] = [ r ]      (mu = -lambda, r = target - J v)
//
// in Baraff's order ("Linear-Time Dynamics using Lagrange Multipliers", SIGGRAPH 1996): a body
// and a joint are both nodes of one tree, leaves first, with no fill-in, so a factor and a solve
// cost time linear in the cluster's size. A joint that closes a loop (a ring of modules) is not
// in the tree: its rows are solved through their Schur complement S = J_L A^-1 J_L^T (one tree
// solve per loop row to build it, a dense factor of size 6 x loops), and each impulse on them is
// passed on through the tree, so loops are as exact as the tree. Each hinge has five structural rows (three
// for the pivot, two keeping the axes parallel) and one axial row that carries the motor, or the limit stop
// near a limit. The axial row is a box-bounded unknown (the motor's rated torque); it is in the factor while
// its impulse is inside its bounds and leaves it, fixed at the bound, once it reaches one (a saturated
// servo). Within a substep a fixed row comes back at most once, when its joint moves the way the bound
// resists (complementarity), so the active set cannot cycle; the next substep starts by checking it again.
// Every iteration is one block Gauss-Seidel pass: Bullet's sweep over the contact rows, then the exact solve
// of all hinge rows, so the last iteration always leaves the hinges exact and the motors within their torque.
// An island whose sweep changed no contact impulse by more than 1e-8 N s has settled: its exact solve in
// that iteration is its last (bounds applied), and the iterations after it pass it by (planSettling).
//
// Contact normals stay Bullet's rows, swept by this solver; friction is the solver's own, per
// contact patch with anchors (contact_patches.cpp), and capture joints add rows of their own
// (capture_joint.cpp). A body joined to others by hinges whose motors hold them moves, within the
// sweep, with its rigid group (the group's mass and inertia take the impulse; in the first
// iteration of a substep split among the group's contacts), and after the sweep each impulse goes
// to the body it hit for the exact solve to pass on through the hinges.
//
// The structural rows aim at J v = -(h/2) dJ/dt v (dJ/dt v at the velocities of the last exact
// solve), not 0: with J v = 0 each substep's projection, at a pose turned by h w from the last,
// takes a share (h w)^2 of the joints' kinetic energy (a free pendulum let go at 90 deg swung 54
// deg after 10 s); with half the turn ahead it takes O((h w)^4). Only clusters touching nothing
// outside themselves, with no loop and at most one anchor, take it (updateCentripetal).
//
// After integration, the position error of the hinges (pivot gap, axis tilt) is projected out
// with the same factor (post-stabilisation): no Baumgarte velocity, so no energy is added. Where
// an error above 10 um or 10 urad is left (bodies turning fast, whose separate integration opens
// their hinges by h^2 x joint speed x tumbling rate), it is projected again: with the same factor
// where the first pass's rate says that is enough (a chord step; a crawling chain), else with rows
// and factor at the corrected poses (a Newton step; a tumbling one, a loop). Three passes at most.
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletDynamics/ConstraintSolver/btTypedConstraint.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <utility>
#include <vector>

#include "core/function_ref.h"
#include "core/pace.h"

namespace rm3d {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// One hinge as the exact solver sees it. PhysicsWorld writes the inputs before every substep
/// and reads the outputs after it.
struct ExactJoint {
  // Inputs.
  btRigidBody* a = nullptr;
  btRigidBody* b = nullptr;
  btTransform frameA, frameB;  ///< joint frames in each body's centre-of-mass frame; z is the axis
  bool motorOn = false;
  double targetVel = 0;   ///< rad/s, B relative to A about the axis
  double maxImpulse = 0;  ///< N m s per substep (rated torque x substep)
  double compliance = 0;  ///< rad/s per N m s on the motor row: the servo's finite stiffness
  bool limited = false;
  double lower = 0, upper = 0;  ///< rad
  double angle = 0;             ///< rad, unwrapped, B relative to A

  // Outputs of the last substep.
  double axialImpulse = 0;  ///< N m s on the axial row (motor and limit together)
  bool saturated = false;   ///< the motor gave its full rating
  Vec6 impulseA = Vec6::Zero(),
       impulseB = Vec6::Zero();  ///< on each body: force, torque about its centre of mass (N s, N m s)

  // Solver state carried between substeps.
  enum class Axial : uint8_t { Fixed, Motor, Lower, Upper };
  Axial state = Axial::Motor;
  double fixedImpulse = 0;  ///< when Fixed: the impulse the row is held at
  double bound = 0;         ///< Lower: least impulse; Upper: largest impulse
  double rowTarget = 0;     ///< axial target velocity this substep
  double lowVel = 0, highVel = 0;
  bool nearLower = false, nearUpper = false;
};

/// A zero-row constraint: puts both bodies in one island and solver group while the exact solver
/// does the work; `Tag` (its user constraint type) says whose, `index` which one.
template <int Tag>
class SolverLink : public btTypedConstraint {
 public:
  static constexpr int kType = Tag;
  SolverLink(btRigidBody& a, btRigidBody& b, int index)
      : btTypedConstraint(MAX_CONSTRAINT_TYPE, a, b), m_index(index) {
    setUserConstraintType(kType);
  }
  int index() const { return m_index; }
  void getInfo1(btConstraintInfo1* info) override {
    info->m_numConstraintRows = 0;
    info->nub = 0;
  }
  void getInfo2(btConstraintInfo2*) override {}
  void setParam(int, btScalar, int) override {}
  btScalar getParam(int, int) const override { return 0; }

 private:
  int m_index;
};
/// A hinge of ExactSolver::joints (it also keeps its bodies from colliding).
using ExactLink = SolverLink<0x5258>;

/// A capture joint (capture_joint.cpp): draws the dock frame on b towards the one on a (turned
/// by `mate`) at a bounded speed, with a bounded force and torque. PhysicsWorld writes the inputs
/// before every substep.
struct CaptureJoint {
  btRigidBody* a = nullptr;
  btRigidBody* b = nullptr;
  btTransform frameA = btTransform::getIdentity(),
              frameB = btTransform::getIdentity();  ///< the dock frames in each body's centre-of-mass frame
  Eigen::Quaterniond mate = Eigen::Quaterniond::Identity();  ///< b's dock frame wanted, relative to a's
  double speed = 0.05;                                       ///< m/s: the faces close at most this fast
  double angularSpeed = 1.0;                                 ///< rad/s: ... and turn at most this fast
  double gain = 5.0;    ///< 1/s: the closing speed per metre (radian) still to close
  double force = 20.0;  ///< N: the most force the joint exerts
  double torque = 1.0;  ///< N m: the most torque
  // Last substep's impulses on a (world frame; b takes the opposite), its warm start.
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();
  struct Error {
    Eigen::Vector3d gap, turn;       ///< b's face from a's (m), and the turn that would mate them (rad)
    Eigen::Vector3d pointA, pointB;  ///< the face centres, world
  };
  Error error() const;  ///< at the bodies' present poses
};

/// A capture joint of ExactSolver::captures.
using CaptureLink = SolverLink<0x5259>;

class ExactSolver : public btSequentialImpulseConstraintSolver {
 public:
  /// Indexed by joint id (the hinge index of PhysicsWorld); ExactLinks name them.
  std::vector<ExactJoint> joints;
  /// Indexed by capture id (PhysicsWorld's); CaptureLinks name them.
  std::vector<CaptureJoint> captures;
  /// Clusters made this substep (none: it solved no batch).
  bool hasClusters() const { return !m_clusters.empty(); }

  /// Friction per contact patch with anchors (contact_patches.cpp): on for the exact solver;
  /// "pgs" keeps Bullet's friction rows per point.
  bool patches = false;
  /// Every tree factored whole (PhysicsSettings::wholeFactors; batch solvers read the primary's).
  bool wholeFactors = false;
  /// Every substep's trees made afresh (PhysicsSettings::freshTrees; batch solvers read the
  /// primary's): never taken again from the last substep (reuseTrees).
  bool freshTrees = false;
  /// Every island swept in every iteration (PhysicsSettings::everyIteration; batch solvers read
  /// the primary's): none settles (planSettling), but for those solved on their own operator.
  bool everyIteration = false;
  /// Small islands' contacts solved on their own operator (dense_islands.cpp;
  /// PhysicsSettings::denseIslands; batch solvers read the primary's).
  bool denseIslands = true;
  /// The most coordinates of a tree the operator takes (PhysicsSettings::denseCoordinates, at
  /// most kDenseCoordinatesMax; batch solvers read the primary's).
  int denseCoordinates = 60;
  static constexpr int kDenseCoordinatesMax = 72;
  /// The tree solve's and the dense operator's AVX variants, where the CPU has AVX
  /// (PhysicsSettings::avx; batch solvers read the primary's); off: their SSE2 ones, the same bits.
  bool avx = __builtin_cpu_supports("avx");
  /// Islands so far whose contacts were solved on their own operator (dense_islands.cpp).
  long denseIslandCount() const { return m_denseIslands; }
  /// Factors so far that took only the nodes whose rows changed (factor).
  long partialFactorCount() const { return m_partialFactors; }
  /// Substeps whose trees were taken again from the last substep (reuseTrees).
  long reusedTreeCount() const { return m_reusedTrees; }
  /// Contact sweeps of islands so far (one island swept once: 1), and those an island settled
  /// before the substep's last iteration was spared (planSettling).
  long islandSweepCount() const { return m_islandSweeps; }
  long sparedSweepCount() const { return m_sparedSweeps; }
  /// Stabilisation passes after a cluster's first so far: with its last factor (chord steps), and
  /// with rows and factor made at the corrected poses (Newton steps; stabiliseCluster).
  long chordPassCount() const { return m_chordPasses; }
  long newtonPassCount() const { return m_newtonPasses; }

  /// Makes this a batch solver of `primary` (PhysicsWorld's, on a worker thread): it reads and
  /// writes the primary's joints, capture joints and contact-patch table instead of its own. Each
  /// joint, capture joint and contact manifold belongs to one island, so solvers working on
  /// different batches of islands never touch the same entry; the table must not grow while they
  /// work (claimPatchSlots first).
  void shareStateOf(ExactSolver& primary) {
    m_shared = &primary;
    patches = primary.patches;
  }
  /// Gives every manifold with contacts a slot in the patch table before batches are solved in
  /// parallel (a serial solve claims them as it goes; which slot a patch has changes nothing).
  void claimPatchSlots(btPersistentManifold* const* manifolds, int numManifolds);

  /// Forget the clusters of the previous substep (called before each one).
  void beginSubstep();
  /// A tree of at least this many joints (a long chain) is rooted at its middle and factored and
  /// solved as two halves, which may run on two threads (splitTree). (From 1024 to 256: a
  /// 150-module snake, 449 joints, ran 6% faster at 2 threads, where it had been no faster than 1.)
  static constexpr int kSplitJoints = 256;
  /// -e on the joint diagonal (m/(N s) and rad/(N m s)): the rows' regularisation.
  static constexpr double kRegularisation = 1e-9;
  /// An island whose contact sweep (after the first, with split masses) changed no row's impulse
  /// by more than 1e-8 N s has settled (planSettling): that is the resolution of the float
  /// impulses Bullet keeps for a row of 0.1 N s, and with its contacts unchanged the exact solve
  /// that follows finds what the last one did. An ATRON on the ground settles in the second
  /// iteration of 15. The dense sweeps (dense_islands.cpp) stop there too. (N s)^2.
  static constexpr double kSweepSettled = 1e-16;
  /// A second thread for the halves of long trees (splitTree), while this solver works alone
  /// (runWithHalfHelper): it runs helpHalves(h) until h.stop. Each second half is offered to it;
  /// whichever thread takes it first solves it (this one, once its own half is done, if the
  /// helper has not woken), and which one does changes nothing.
  struct HalfHelper {
    std::atomic<uint64_t> posted{0};  // halves offered so far
    std::atomic<uint64_t> taken{0};   // the last offered half that a thread has taken
    std::atomic<uint64_t> done{0};    // the last half the helper finished
    std::atomic<bool> stop{false};
    FunctionRef<void(int)> fn;
    bool watch = false;  // watches for halves until stopped, never sleeping (halfHelperWatches)
  };
  static void helpHalves(HalfHelper& h);
  /// Runs fn() here with a half helper from `tasks` (two tasks: this thread and one more), or
  /// just fn() without tasks, or alone where the clock says the helper does not pay (Pace; `site`
  /// names the caller: each times its own work).
  enum class HalfSite { Solve, Stabilise };
  void runWithHalfHelper(const std::function<void(int, FunctionRef<void(int)>)>& tasks,
                         FunctionRef<void()> fn, HalfSite site);
  /// The half helper watches for halves until the solve ends instead of sleeping after a while:
  /// where there are no more threads than cores (PhysicsWorld::setParallel's `watch`). Between
  /// halves a solve does serial work of up to a few milliseconds (its set-up; the motors'
  /// settling), and a helper that had gone to sleep took about 0.1 ms to wake: on `snake_1000` it
  /// slept 9 times a solve, and 1.5% of the halves went unhelped.
  bool halfHelperWatches = false;
  /// Every long tree's second half offered to a second thread, whatever the clock says (tests:
  /// the helper's way must give the same bits; PhysicsSettings::alwaysThreads).
  bool alwaysThreads = false;
  /// A cluster of this substep is a long tree solved in halves.
  bool hasSplitTrees() const { return !m_laneNodes.empty(); }
  /// Contact sweeps of this substep run in a split tree's halves (planHalvedSweep).
  int halvedSweepCount() const { return m_halvedSweeps; }
  /// Lists of this substep made in two runs on a split tree's halves' threads (kSplitRows).
  int halvedListCount() const { return m_halvedLists; }
  int splitTreeCount() const {
    return int(std::count_if(m_clusters.begin(), m_clusters.end(), [](const Cluster& c) { return c.split; }));
  }
  /// Projects the hinges' position error out after integration.
  void postStabilise();
  /// Before and after every solver's postStabilise, on the primary (the patch table is its): the
  /// contact anchors follow the moves the stabilisation makes (contact_patches.cpp).
  void notePatchPoses();
  void followPatchPoses();
  /// Right after this solver's solveGroup (SolverWorld::setFinishBatches, its bodies integrated):
  /// whether the batch may be finished now (no tree of it in halves), and then its patches'
  /// poses noted, its clusters stabilised and its patches' anchors followed, as notePatchPoses,
  /// postStabilise and followPatchPoses would do for them later (which then pass them over).
  bool batchFinishable() const;
  void finishBatch();
  /// Every batch this solver solved this substep was finished (finishBatch): nothing is left for
  /// notePatchPoses, postStabilise and followPatchPoses.
  bool batchesFinished() const { return m_groupsFinished == m_groupsSolved; }
  /// Batches so far solved, and finished right after their solve (finishBatch).
  long solvedBatchCount() const { return m_solvedBatches; }
  long finishedBatchCount() const { return m_finishedBatches; }
  /// The primary's pose table as large as its patch table (before batches are finished on
  /// several threads: the table does not grow then).
  void sizePatchPoses() { m_patchPoses.resize(m_patches.size()); }

  btScalar solveGroupCacheFriendlySetup(btCollisionObject** bodies, int numBodies,
                                        btPersistentManifold** manifolds, int numManifolds,
                                        btTypedConstraint** constraints, int numConstraints,
                                        const btContactSolverInfo& info, btIDebugDraw* debugDrawer) override;
  btScalar solveSingleIteration(int iteration, btCollisionObject** bodies, int numBodies,
                                btPersistentManifold** manifolds, int numManifolds,
                                btTypedConstraint** constraints, int numConstraints,
                                const btContactSolverInfo& info, btIDebugDraw* debugDrawer) override;
  btScalar solveGroupCacheFriendlyFinish(btCollisionObject** bodies, int numBodies,
                                         const btContactSolverInfo& info) override;
  /// As Bullet's (the same solver bodies, ids and order), each body's lines fetched a few bodies
  /// ahead: with thousands of modules the bodies lie all over memory and Bullet's loop waited on
  /// each in turn.
  void convertBodies(btCollisionObject** bodies, int numBodies, const btContactSolverInfo& info) override;
  /// As Bullet's with `patches` on (the same normal rows, friction directions and pools' sizes),
  /// but each point's friction rows left empty (their impulses 0) and no rolling or spinning rows
  /// made: the patches solve friction with rows of their own, and Bullet's per point only carry
  /// the patches' shares back to the points (finishPatches, writeBackContacts). Without
  /// `patches` ("pgs"), Bullet's.
  void convertContacts(btPersistentManifold** manifolds, int numManifolds,
                       const btContactSolverInfo& info) override;

 private:
  struct Body {
    btRigidBody* rb;
    int sid;  // solver body index (valid during its group)
    double invMass;
    Eigen::Matrix3d invInertia;
    Eigen::Matrix3d inertia;  // invInertia's inverse
  };
  struct Node {
    int body = -1, joint = -1;  // exactly one is set
    int parent = -1;            // node index, -1 for the root
    bool parentIsA = false;     // joint node: its parent is body a; body node: it is the joint's a
    // The pivot block D while the factor sums it (initNode, passToParent), then its inverse.
    Mat6 dinv;
    Mat6 g;  // D^-1 H(node, parent), kept from the factor for the solves
    Vec6 y, x;
    // Not zeroed (a value-initialised node was a 700-byte clear each, every substep): each field
    // is written before it is read (initNode, passToParent, the solves). Without NDEBUG (the
    // sanitizer build) a new node's numbers are NaN, so that a read before a write shows.
    Node() {
#ifndef NDEBUG
      dinv.setConstant(std::nan(""));
      g.setConstant(std::nan(""));
      y.setConstant(std::nan(""));
      x.setConstant(std::nan(""));
#endif
    }
  };
  struct Cluster {
    int begin = 0, end = 0;  // nodes, in order root first
    bool dirty = true;       // the active set changed since the last factor
    bool full = true;        // ... or more than rows of its nodes (m_rowChanged): factored whole
    bool clamped = false;    // a bounded row was fixed at its bound this substep (threads write their own)
    bool retry = false;      // a fixed row came back this round (finishJoints)
    bool resolve = false;    // factored for rows fixed at their bounds, not yet solved with them
    // Its rows take a centripetal target (updateCentripetal): no loop, one anchor at most, and no
    // contact row joining one of its bodies to anything else this substep.
    bool centripetal = false;
    int island = -1;  // Bullet's island of its bodies
    // Joints that close loops (not in the tree), in m_loopJoints, and the Schur complement of
    // their rows through the tree, S = J_L (tree-constrained mobility) J_L^T + compliance.
    int loopBegin = 0, loopEnd = 0;
    // A long tree rooted at its middle (splitTree): its nodes but the root in two halves, each in
    // m_laneNodes[lane[h], lane[h + 1]) in node order, and the root's children in
    // m_laneNodes[lane[2], lane[3]).
    bool split = false;
    bool stabilised = false;  // by finishBatch (postStabilise passes it over)
    int lane[4] = {0, 0, 0, 0};
    Eigen::MatrixXd schur;        // S, then its eigenvectors
    Eigen::VectorXd schurInv;     // damped inverse eigenvalues (0 for the redundant directions)
    Eigen::VectorXd schurPosInv;  // ... for the position projection, damped much less
  };
  struct Row {                        // per joint, this substep
    int node = -1, na = -1, nb = -1;  // body indices (into m_bodies) or -1 static
    Mat6 ja, jb;                      // rows x body dofs (linear, angular), world frame
    Eigen::Vector3d ra, rb;           // the joint's frame (jointFrame) the rows were made at
    Eigen::Matrix3d frame;
    Vec6 bias = Vec6::Zero();  // (h/2) dJ/dt v: the structural rows aim at J v = -bias
    Vec6 lambda;
    bool axialActive = false;
  };

  // Friction per contact patch (contact_patches.cpp). A patch is one manifold's contacts (one
  // pair of bodies, one child shape). Its friction is three rows at the patch's centre (two
  // tangent directions, bounded together by a circle of mu times the patch's normal impulse, and
  // a twist about the normal), plus two rolling rows where the materials resist rolling. While
  // it sticks it keeps the pair's relative pose from when it stuck (its anchor), and its rows
  // aim to take the slip since then back out; it lets go when its friction saturates.
  struct Patch {
    const btPersistentManifold* manifold = nullptr;           // owner (slots are reused); null: free
    Eigen::Quaterniond rot = Eigen::Quaterniond::Identity();  // body 0 in body 1's frame when it stuck
    Eigen::Vector3d pos = Eigen::Vector3d::Zero();
    bool anchored = false;
    int seen = -1;      // substep count when it last had rows
    int finished = -1;  // substep count when finishBatch noted and followed it
    // Last substep's impulses (warm start): tangential (world), twist and rolling (about the
    // normal and the tangent axes, world).
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), roll = Eigen::Vector3d::Zero();
    double twist = 0;
  };
  struct PatchRows {                       // one patch's rows in this solver group
    int slot = -1;                         // into m_patches
    int contactBegin = 0, contactEnd = 0;  // its contact rows
    int row = 0;  // its first row in m_patchRows: tangent 1, tangent 2, twist, [roll 1, roll 2]
    bool roll = false;
    double mu = 0, spin = 0, rolling = 0;  // friction, and the lever arms (m) of spin and rolling
    Eigen::Vector3d centre, t1, t2;        // where its rows act, and their tangent directions
  };
  std::pair<double, double> patchLoad(const PatchRows& pr) const;
  double sweepBall(int row, int count, double bound);
  void setupPatches(btPersistentManifold** manifolds, int numManifolds);
  void addOwnRow(int idA, int idB, const Eigen::Vector3d& pointA, const Eigen::Vector3d& pointB,
                 const Eigen::Vector3d& linear, const Eigen::Vector3d& angular, double target,
                 double friction, int owner);
  void warmStartRow(btSolverConstraint& s, double impulse);
  double sweepPatch(const PatchRows& pr);
  void finishPatches();
  int patchSlot(const btPersistentManifold* man) const;  ///< its slot in the table, or -1
  int claimPatchSlot(btPersistentManifold* man);
  ExactSolver* m_shared = this;  ///< whose joints, capture joints and patch table (shareStateOf)
  std::vector<Patch> m_patches;  ///< the primary's table, by slot
  std::vector<int> m_freePatches;
  struct PatchPoses {  // a patch's two bodies before the stabilisation (notePatchPoses)
    btTransform body0, body1;
  };
  std::vector<PatchPoses> m_patchPoses;  ///< by slot
  /// notePatchPoses' and followPatchPoses' step for one patch (at the primary's substep count).
  void notePatchPose(const Patch& p, PatchPoses& poses) const;
  void followPatchPose(Patch& p, const PatchPoses& was) const;
  std::vector<PatchRows> m_groupPatches;  // this solver group's
  btAlignedObjectArray<btSolverConstraint> m_patchRows;
  std::vector<double> m_contactArm;  // by contact row: its distance from its patch's centre (m)
  // Capture joints (capture_joint.cpp): six rows each in m_patchRows (force x, y, z; torque x, y, z).
  struct GroupCapture {
    int id, row;
  };
  std::vector<GroupCapture> m_groupCaptures;
  void setupCaptures(btTypedConstraint** constraints, int numConstraints);
  double sweepCapture(const GroupCapture& gc);
  void finishCaptures();
  int m_substepCount = 0;
  int m_groupsSolved = 0, m_groupsFinished = 0;  // this substep's (batchesFinished)
  long m_solvedBatches = 0, m_finishedBatches = 0;

  std::vector<int> m_freshBodies;  // convertBodies: the listed bodies that take a solver body of their own
  void buildClusters(btTypedConstraint** constraints, int numConstraints);
  void setupJoint(int j, double h);
  struct JointFrame {
    Eigen::Vector3d ra, rb;  // pivot from each body's centre of mass, world frame
    Eigen::Matrix3d frame;   // the joint's frame on body a: x, y, z (the axis) in the columns
  };
  JointFrame jointFrame(int j) const;
  void jointRows(int j);
  Vec6 structuralResidual(int j) const;
  [[gnu::target("avx")]] Vec6 structuralResidualAvx(int j) const;  ///< the same on AVX (the same bits)
  void updateCentripetal(int j);
  Cluster& jointCluster(int j);  ///< the cluster of a joint of this substep
  /// With `solveToo`, then an iteration's solve (solve(c, true)), its down pass node by node as
  /// each is factored (its pivot and G still in the caches): the same operations in the same
  /// order. Not for a tree with loops (factorLoops solves the tree in between).
  void factor(Cluster& c, bool solveToo = false);
  bool m_fetch = true;  ///< this factor's or solve's passes fetch ahead (a large tree: kFetchNodes)
  void iterationDownStep(int k, int skip);
  void iterationDownStepPlain(int k, int skip);
  [[gnu::target("avx")]] void iterationDownStepAvx(int k, int skip);
  /// With `iteration`, each node's right-hand side is made (iterationResidual) as the down pass
  /// first needs it, and its result applied (iterationApply) as the up pass leaves it: two passes
  /// over the nodes instead of four, the same operations in the same order.
  void solve(Cluster& c, bool iteration = false);
  void solveFromRoot(Cluster& c, bool iteration);
  void iterationResidual(int k);
  void prepareResidual(int k);
  void iterationApply(int k);
  std::vector<char> m_residualMade;  // by node, during a down pass with `iteration`
  /// By node: its bodies (a joint's two, a body node's own; -1 none) and their solver bodies, and
  /// the joint whose rows couple it to its parent (-1: the root), to fetch them ahead of the
  /// passes that read them (fetchResidual, fetchApply, fetchInit, fetchPass).
  struct NodeBodies {
    int body[2], sid[2];
    int coupling;
  };
  std::vector<NodeBodies> m_nodeBodies;
  void noteNodeBodies(int begin);
  void fetchSolverBody(int sid, bool all) const;
  void fetchResidual(int k) const;
  void fetchApply(int k) const;
  void fetchInit(int k) const;
  void fetchPass(int k) const;
  /// The tree solve's passes over m_nodes[order[i]] for i in [from, to) (m_nodes[i] where order
  /// is null): down (last first), x = D^-1 y and, but for a parent `skip`, the parent's
  /// y -= G^T y; up, x -= G x_parent. Four rows at a time where the CPU has AVX
  /// (node_products.h: the same bits).
  void solveDown(int from, int to, const int* order, int skip, bool iteration);
  void solveUp(int from, int to, const int* order, bool iteration);
  template <bool Iteration>
  void downPass(int from, int to, const int* order, int skip);
  template <bool Iteration>
  void upPass(int from, int to, const int* order);
  void solveDownPlain(int from, int to, const int* order, int skip, bool iteration);
  void solveUpPlain(int from, int to, const int* order, bool iteration);
  [[gnu::target("avx")]] void solveDownAvx(int from, int to, const int* order, int skip, bool iteration);
  [[gnu::target("avx")]] void solveUpAvx(int from, int to, const int* order, bool iteration);
  bool m_avx = __builtin_cpu_supports("avx");  // the primary's avx, taken at each group's setup
  /// Long trees: the body that splits the tree from `begin` (this substep's newest cluster's
  /// first node) most evenly, and the two halves of a tree rooted there.
  int centroidBody(int begin);
  void splitTree(Cluster& c);
  void subtreeSizes(int begin);
  void initNode(int k);             ///< a node's pivot block before its children's shares
  void invertPivot(Mat6& d) const;  ///< a node's summed pivot block inverted, in place (AVX where m_avx)
  /// Its share of its parent's pivot block (its own inverted); `fresh`: its G worked out again
  /// (else the last factor's, its subtree unchanged since).
  void passToParent(int k, bool fresh);
  /// By node: its row left or rejoined the active set since the cluster's last factor; and, in
  /// factor, whether the node is factored again.
  std::vector<char> m_rowChanged, m_need;
  long m_partialFactors = 0;
  /// fn(k, h) for every node of c: a long tree's root (h 0), then its halves (forBothHalves; h the half).
  template <class Fn>
  void forEachNode(const Cluster& c, const Fn& fn);
  /// fn(0) and fn(1): fn(1) on the half helper's thread while there is one (runWithHalfHelper).
  void forBothHalves(FunctionRef<void(int)> fn);
  /// fn(h, begin, end) for the two halves of [0, n), h 0 and 1: on the half helper's thread for h 1
  /// where a long tree's solve has one and n is at least kSplitRows (counted in m_halvedLists),
  /// else both here in turn. For lists whose entries are each written by their own index alone,
  /// so that either way gives the bits of one loop.
  void forListHalves(int n, FunctionRef<void(int, int, int)> fn);
  /// Loop joints: S from one tree solve per loop row (after factor), and the step that makes
  /// the loop rows exact: their impulse change through S, passed on through the tree.
  void factorLoops(Cluster& c);
  void loopIteration(Cluster& c, bool clamp);
  /// S's pseudo-inverse times v, through inverse eigenvalues `inv` (c.schurInv for velocities,
  /// c.schurPosInv for positions): loop rows that repeat the tree's (a planar ring's
  /// out-of-plane rows) are redundant, and take no impulse; nearly redundant directions are
  /// damped (factorLoops).
  Eigen::VectorXd solveLoops(const Cluster& c, const Eigen::VectorXd& inv, const Eigen::VectorXd& v) const;
  /// Applies impulses `p` (6 per loop joint row) on the loop joints' bodies through the tree:
  /// the tree's joints take their share (lambda) and the bodies' velocities change (or, with
  /// `positions`, returns the bodies' position changes in the nodes' x without applying them).
  void pushThroughTree(Cluster& c, const Eigen::VectorXd& p, bool positions);
  /// An exact solve of the current group's clusters for which want(cluster) holds, and only
  /// those: which clusters share a solver group (Bullet's batches of islands) changes nothing.
  void exactIterationWhere(bool clamp, FunctionRef<bool(const Cluster&)> want);
  struct RowSide {
    btSolverBody* body;
    const btVector3 *n, *rc, *ac;
    int index, group;  // into m_bodies and m_groups, -1: not ours / not grouped
    /// Grouped, and the row given (`row` of rowSide): its group's velocity change per unit
    /// impulse, linear then angular (m_rowPush); else null.
    const double* push;
  };
  /// `row`: the row's index in m_rowExtra (a contact row's own, a solver row's after the
  /// contacts), for the sweep's m_rowPush; -1 where the sweep's figures are not wanted.
  RowSide rowSide(btSolverConstraint& c, int side, int row = -1);
  /// `planned`: at the group's setup, after planDenseIslands: the islands the dense solve takes
  /// get no rigid groups and their rows no sweep data (made for them later, where it declines).
  void buildGroups(int firstBody, bool planned = false);
  /// Row i's share of buildGroups: its velocity error and cfm, and for the sweeps (`sweep`) what
  /// a unit impulse does to its grouped sides and its effective masses.
  void rowData(int i, bool sweep);
  double sweepRow(btSolverConstraint& c, double lo, double hi, int row);
  double rowVelocity(const RowSide (&sides)[2]) const;
  void applyRowImpulse(const RowSide (&sides)[2], double delta);
  btScalar contactSweep();
  void clusterIteration(Cluster& c, bool clamp);
  bool clampAxial(int k);
  void forGroupJoints(FunctionRef<bool(int)> fn, FunctionRef<void(Cluster&, bool)> marked);
  double axialSpeed(int j) const;
  static bool outgrown(const ExactJoint& e, double w);
  bool reenter(int j);
  void settleState(int j);
  void stabiliseCluster(Cluster& c);
  Vec6 positionError(int j) const;
  double stabiliseExcess(int j, const Vec6& err) const;  ///< err: positionError(j)
  void applyPositionChanges(Cluster& c);
  void applyPositionChange(int k);  ///< node k's body, by its x
  void forEachCluster(int begin, FunctionRef<void(int)> fn);
  void runHelped(const std::function<void(int, FunctionRef<void(int)>)>& tasks, FunctionRef<void()> fn);
  HalfHelper* m_halfHelper = nullptr;
  Pace m_halfPace[2];  ///< by HalfSite
  std::vector<int> m_laneNodes, m_subtree, m_half;
  struct NodeHead {  // a node's place in its tree (splitTree's reordering)
    int body, joint, parent;
    bool parentIsA;
  };
  std::vector<NodeHead> m_nodeHeads;
  /// The trees buildClusters made for the substep's first solver group, and what they were made
  /// from (each joint's index and body indices): a structure that does not change from one
  /// substep to the next gets the same trees again without walking it (reuseTrees).
  struct Trees {
    bool valid = false;
    std::vector<int> key;  // j, na, nb per joint of the group, in order
    std::vector<NodeHead> nodes;
    std::vector<Cluster> clusters;  // as buildClusters leaves them
    std::vector<int> laneNodes, loopJoints;
  };
  Trees m_trees;
  long m_reusedTrees = 0;
  std::vector<int> m_treeKey;
  bool reuseTrees();
  void keepTrees();
  void finishJoints();
  Vec6 bodyVelocity(int b) const;
  void addBodyVelocity(int b, const Vec6& dv);
  void applyAxial(int j, double impulse);

  double m_h = 0;
  int m_groupBegin = 0;  // first cluster of the current group
  bool m_groupHasJoints = false;
  std::vector<Body> m_bodies;
  std::vector<Node> m_nodes;
  std::vector<Cluster> m_clusters;
  std::vector<Row> m_rows;   // this substep's, group by group (a finished batch's reused)
  std::vector<int> m_rowOf;  // by joint id: its row in m_rows (set for the joints of a group)
  // (Without NDEBUG, as in the sanitizer build, a joint's index is -1 once its batch or substep
  // let its row go, and reading it then stops the program.)
  Row& row(int j) {
    return m_rows[rowIndex(j)];
  }
  const Row& row(int j) const {
    return m_rows[rowIndex(j)];
  }
  size_t rowIndex(int j) const {
    const int r = m_rowOf[size_t(j)];
#ifndef NDEBUG
    if (r < 0 || size_t(r) >= m_rows.size()) std::abort();
#endif
    return size_t(r);
  }
  std::vector<int> m_groupJoints;
  std::vector<int> m_loopJoints;  // by cluster (Cluster::loopBegin..loopEnd)
  /// Rigid groups: bodies joined by hinges whose motors hold them (the structure moves as one
  /// under a contact impulse). The contact sweep applies impulses to a group's twist.
  struct Group {
    double invMass;
    Eigen::Vector3d com;
    Eigen::Matrix3d invInertia;
    Eigen::Vector3d dv, dw;  // twist change not yet passed to the bodies
    int contacts;            // contact points on the group's bodies (mass splitting)
  };
  std::vector<Group> m_groups;          // this solver group's
  std::vector<int> m_groupContacts[2];  // buildGroups: each group's contact points, by half of the rows
  // A long tree's contact sweep in halves (planHalvedSweep): the sweep's items in order (capture
  // joints, the normal rows in Bullet's order, the patches), each with its half: 0 or 1 where
  // every body it moves (or that body's group) lies in that half of a split tree, 2 otherwise.
  // Items of one half touch nothing the other's do, so each half's run in order on its own thread
  // gives the serial sweep's bits; a 2 is swept alone, between.
  std::vector<signed char> m_bodySide, m_groupSide, m_itemSide;
  std::vector<int> m_itemBarriers;  // the items of side 2, in order
  bool m_halvedSweep = false;
  int m_halvedSweeps = 0;
  int m_halvedLists = 0;
  void planHalvedSweep();
  std::vector<int> m_bodyGroup;               // by body (index into m_groups, -1: alone)
  std::vector<Eigen::Vector3d> m_bodyOffset;  // body centre of mass minus its group's
  std::vector<Vec6> m_bodyImpulse;            // contact impulse on a grouped body this sweep
  std::vector<int> m_groupParent;             // union-find
  // Per contact row, then per row of the solver's own (m_patchRows): velocity error, cfm, 1 / mass
  // with the group's weight split among its contacts (first iteration), and without.
  std::vector<double> m_rowExtra;
  // Per row of m_rowExtra and side, where that side's body is grouped: the group's linear and
  // angular velocity change per unit impulse of the row (buildGroups), as the sweep adds them.
  std::vector<double> m_rowPush;
  int m_groupFirstBody = 0;
  int m_groupFirstNode = 0, m_groupFirstLoop = 0, m_groupFirstRow = 0;  // the group's first ones
  bool m_firstGroup = true;  // no group set up yet this substep (buildClusters: its trees kept)
  bool m_useSplit = true;
  std::vector<int> m_sidToBody;
  std::vector<int> m_bodyNode;
  std::vector<int> m_nodeOfBody;    // node of each body this substep (any group)
  std::vector<int> m_bodyCluster;   // cluster of each body this substep (any group)
  std::vector<char> m_sweepIsland;  // by island: the contact re-sweep takes its rows (empty: all)
  // By island, for each half's thread: the largest change of a re-sweep's rows (finishJoints),
  // and the islands it sweeps.
  std::vector<double> m_islandChange[2];
  std::vector<int> m_resweptIslands;
  // Islands that settle within the substep's iterations (planSettling): each of this solver
  // group's islands has a slot; each sweep item its island's slot (-1: none); by slot, the largest
  // squared impulse change of its items in this sweep (by thread of a halved sweep) and its state.
  enum class Settle : char { Open, Settling, Settled, Never };
  std::vector<int> m_islandSlot;  // by island tag (-1: none this group); grows, reset by tag
  std::vector<int> m_slotIsland;  // by slot: its island tag
  std::vector<int> m_itemSlot;
  std::vector<double> m_slotChange[2];
  std::vector<Settle> m_slotSettle;
  bool m_settling = false;  // within the substep's iterations: settled islands are not swept
  long m_islandSweeps = 0, m_sparedSweeps = 0;
  long m_chordPasses = 0, m_newtonPasses = 0;
  void planSettling();
  int clusterSlot(const Cluster& c) const;
  bool settleIslands(int iteration, int last);
  std::vector<int> m_adjStart, m_adj, m_queue, m_component;
  std::vector<char> m_seenJoint;

  // Small islands' contacts on their own operator (dense_islands.cpp): an island of one tree (no
  // loop, no split, a body at its root, few hinges), its contact rows' matrix A = J H^-1 J^T in
  // the tree's own coordinates (the root's twist and each hinge's speed; H the tree's mass
  // matrix and each motor's stiffness), swept to convergence, then one exact solve.
  struct DenseRow {
    btSolverConstraint* c;
    int extra;  // into m_rowExtra
    RowSide sides[2];
  };
  struct DenseUnit {
    // Normal: a contact row; Tangent: a patch's tangent pair, then its twist; Rolling: its pair.
    enum Kind : char { Normal, Tangent, Rolling } kind;
    int row;    // its first row in m_denseRows
    int patch;  // into m_groupPatches (not Normal)
  };
  std::vector<DenseRow> m_denseRows;
  std::vector<DenseUnit> m_denseUnits;
  std::vector<double> m_denseA, m_denseU0, m_denseVel, m_denseLam, m_denseStart;
  std::vector<double> m_denseRowX;  // per row: target velocity, compliance, 1 / (diagonal + compliance)
  std::vector<double> m_denseH, m_denseY;  // nu rows of H, then U; nu rows of Y, a row's entry per row
  std::vector<int> m_denseNodeIndex;       // per node of the cluster: body row or hinge column
  std::vector<int> m_denseCols;            // per body: its count of non-zero columns, then them
  std::vector<double> m_denseS;            // per coordinate: its twist at the root's centre (linear, angular)
  std::vector<double> m_denseBody;  // per body: its centre from the root's, its subtree's m, h, I there
  std::vector<int> m_denseSlotStart, m_denseSlotItems, m_denseSlotClusters;
  long m_denseIslands = 0;
  std::vector<char> m_slotDense;  // per settling slot: its island is one the dense solve takes
  std::vector<char> m_rowDense;   // per contact and patch row: on such an island
  void planDenseIslands();
  int denseBound() const;
  template <class Fn>
  void forSlotRows(int s, const Fn& fn);
  bool denseBody(int b) const;
  void solveDenseIslands(int sweeps);
  bool denseIsland(Cluster& c, const int* items, int count, int sweeps);
  int denseShape(const Cluster& c);
  bool denseOperator(const Cluster& c, int n, int nu);
  [[gnu::target("avx")]] bool denseOperatorAvx(const Cluster& c, int n, int nu);
  template <class F>
  [[gnu::always_inline]] inline bool denseOperatorOf(const Cluster& c, int n, int nu);
  void denseSweeps(int n, int sweeps);
  [[gnu::target("avx")]] void denseSweepsAvx(int n, int sweeps);
  [[gnu::always_inline]] inline void denseSweepsOf(int n, int sweeps);
};

/// One side of a contact row: its solver body, Jacobian, and (if it is one of ours) body and group.
/// (Inlined: returned through memory, the sides cost the sweep a store-to-load round trip per
/// row, and 20% more of `superbots_1000`'s step in some builds, by where the code happened to lie.)
[[gnu::always_inline]] inline ExactSolver::RowSide ExactSolver::rowSide(btSolverConstraint& c, int side,
                                                                        int row) {
  RowSide r;
  const int sid = side == 0 ? c.m_solverBodyIdA : c.m_solverBodyIdB;
  r.body = &m_tmpSolverBodyPool[sid];
  r.n = side == 0 ? &c.m_contactNormal1 : &c.m_contactNormal2;
  r.rc = side == 0 ? &c.m_relpos1CrossNormal : &c.m_relpos2CrossNormal;
  r.ac = side == 0 ? &c.m_angularComponentA : &c.m_angularComponentB;
  r.index = sid < int(m_sidToBody.size()) ? m_sidToBody[size_t(sid)] : -1;
  r.group = r.index >= 0 ? m_bodyGroup[size_t(r.index)] : -1;
  r.push = r.group >= 0 && row >= 0 ? m_rowPush.data() + 12 * row + 6 * side : nullptr;
  return r;
}

}  // namespace rm3d
