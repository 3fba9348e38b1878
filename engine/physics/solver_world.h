// The soft-rigid dynamics world with a linear-time hand-out of joints to simulation islands.
//
// Bullet's island callback finds each island's joints by scanning the sorted joint list from its
// start for every island, so a world of n separate modules spends O(n^2) a substep there: 19% of
// `superbots_1000`'s time. This world sorts the joints the same way, notes where each island's run
// starts once, and batches islands into solver groups of at least 128 rows as Bullet does. Its
// islands are joined by contact points, not by overlapping bounding boxes (ContactIslands in
// solver_world.cpp). With worker threads it solves the batches on several solvers at once
// (setBatchSolvers); the batches are the same at any thread count, and a batch is solved the same
// by any of the solvers, so the results are the same bits. It also skips the predictive-contact
// pass that only continuous collision detection needs.
#pragma once

#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include <functional>
#include <vector>

#include "core/function_ref.h"
#include "core/home_ranges.h"
#include "core/pace.h"

namespace rm3d {

class ExactSolver;

class SolverWorld : public btSoftRigidDynamicsWorld {
 public:
  SolverWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase, btConstraintSolver* solver,
              btCollisionConfiguration* config);
  /// Runs fn(t) for t in [0, n), each on its own thread where it can.
  using Tasks = std::function<void(int n, FunctionRef<void(int)> fn)>;
  /// With helpers, the batches of islands are collected and then solved on `primary` (the
  /// world's constraint solver) and the helpers (its batch solvers, ExactSolver::shareStateOf) at
  /// once, one per task; no helpers: each batch is solved as it is made, on this thread.
  void setBatchSolvers(ExactSolver* primary, std::vector<ExactSolver*> helpers, Tasks tasks);
  /// Every pass that can go to the threads goes there, not only where the clock says it pays
  /// (tests: core/pace.h).
  void setAlwaysThreads(bool always) { m_alwaysThreads = always; }
  /// Each batch finished right after its solve, where this substep's passes run fused: its bodies
  /// integrated and its clusters stabilised (ExactSolver::finishBatch) while the batch's data is
  /// in the caches, instead of in the passes over every body and cluster after all the batches.
  /// Each body, cluster and contact patch belongs to one batch and these steps read nothing of
  /// another's, so the order changes no bit. For the exact solver `primary` (the world's
  /// constraint solver; null: off).
  void setFinishBatches(ExactSolver* primary) { m_finisher = primary; }
  /// After solver s solved a batch of these bodies (setFinishBatches, in a fused substep): where
  /// s takes it, the batch finished and its bodies marked as integrated.
  void finishBatch(ExactSolver& s, btCollisionObject* const* bodies, int numBodies, btScalar timeStep);
  /// Takes every joint and rigid body out of the world (a teardown) in the order that keeps
  /// Bullet's searches short: its lists are searched from the front and a removal moves the last
  /// entry to the hole, so removing the first entry each time costs O(1). Removed in any other
  /// order, each removal searched the whole list: 0.3 s of a 10,000-module world's teardown.
  void removeAllJointsAndBodies() {
    while (getNumConstraints() > 0) removeConstraint(getConstraint(0));
    while (m_nonStaticRigidBodies.size() > 0) removeRigidBody(m_nonStaticRigidBodies[0]);
    for (int i = m_collisionObjects.size(); i-- > 0;)
      if (btRigidBody* rb = btRigidBody::upcast(m_collisionObjects[i])) removeRigidBody(rb);
  }
  /// Bullet runs seven passes over every body a substep, each reading its lines anew: with 10,000
  /// modules (30 MB of bodies) each pass waits on memory. Where a call is one substep with
  /// nothing between the passes that reads a body (no cloth, actions, tick callbacks, or motion
  /// states synchronised all at once), they run as two: the kinematic state, gravity and damping
  /// with the motion prediction; the activation state, motion state and force reset with the
  /// integration. Each of these passes reads and writes only its own body, so each body sees the
  /// same operations in the same order: the same bits.
  int stepSimulation(btScalar timeStep, int maxSubSteps, btScalar fixedTimeStep) override;
  /// Bodies the last integration ran on the worker threads (0: one loop on this thread).
  int threadedBodies() const { return m_threadedBodies; }
  struct Batch {
    btAlignedObjectArray<btCollisionObject*> bodies;
    btAlignedObjectArray<btPersistentManifold*> manifolds;
    btAlignedObjectArray<btTypedConstraint*> constraints;
  };
  /// fn(i) for i in [0, n), `chunk` at a time: on the batch solvers' threads (each index on the
  /// same thread from one call to the next, core/home_ranges.h) when there are threads, n is at
  /// least 4 chunks and `pace` says it pays (always with setAlwaysThreads), else here in order.
  /// fn(i) must touch only what index i owns. Returns how many went to the threads (0: none).
  template <class Fn>
  int forEachIndex(Pace& pace, int n, int chunk, const Fn& fn) {
    auto alone = [&] {
      for (int i = 0; i < n; ++i) fn(i);
    };
    if (m_helpers.empty() || !m_tasks || n < 4 * chunk) {
      alone();
      return 0;
    }
    auto threads = [&] { m_homes.forEach(m_tasks, 1 + int(m_helpers.size()), n, chunk, fn); };
    return runPaced(pace, m_alwaysThreads, threads, alone) ? n : 0;
  }
  struct IslandJoint {  ///< a joint and its island, to sort by
    int island;
    btTypedConstraint* joint;
  };

 protected:
  void solveConstraints(btContactSolverInfo& info) override;
  /// No body here has a CCD motion threshold, so Bullet's predictive-contact pass, which predicts
  /// every body's next transform only to compare its motion with a threshold of 0, finds nothing:
  /// only the release is kept (results are bit-identical).
  void createPredictiveContacts(btScalar) override { releasePredictiveContacts(); }
  /// Bullet's passes over every body before and after the solve (damping and the predicted
  /// transform; integration), on the worker threads in chunks of bodies where there are threads
  /// and many bodies: each body's step reads and writes that body alone, so the results are the
  /// same bits. Worlds with cloth keep Bullet's loops.
  void predictUnconstraintMotion(btScalar timeStep) override;
  void integrateTransforms(btScalar timeStep) override;
  /// Bullet's other passes over every body, each fused into one of the two above when
  /// stepSimulation allows it (m_fused).
  void saveKinematicState(btScalar timeStep) override;
  void applyGravity() override;
  void updateActivationState(btScalar timeStep) override;
  void synchronizeMotionStates() override;
  void clearForces() override;
  /// Bullet's bounding boxes of every active object, for many objects: worked out first (on the
  /// worker threads where there are threads), then handed to the broadphase in order on this
  /// thread, each box's broadphase entries fetched a few boxes ahead (the same bits).
  void updateAabbs() override;
  /// As Bullet's, each joint's bodies fetched ahead.
  void calculateSimulationIslands() override;

 private:
  void solveBatches(btContactSolverInfo& info, int count);
  /// One body's part of integrateTransforms (fused: with its activation, motion state and forces).
  void integrateBody(btRigidBody* body, btScalar timeStep, bool fused);
  static constexpr int kChunk = 256;  ///< bodies (objects) a thread takes at a time
  /// fn(body) for every non-static rigid body, as forEachIndex. (The bodies lie in this order,
  /// and the processor's own prefetching keeps up: fetching them ahead gained nothing.)
  template <class Fn>
  int forEachBody(Pace& pace, const Fn& fn);
  /// updateActivationState's step for one body.
  static void activation(btRigidBody* body, btScalar timeStep);

  btAlignedObjectArray<IslandJoint> m_islandJoints;  ///< the joints by island, sorted
  std::vector<int> m_islandStart, m_islandCount;     ///< by island id: its run in m_sortedConstraints
  ExactSolver* m_primary = nullptr;
  std::vector<ExactSolver*> m_helpers;
  Tasks m_tasks;
  std::vector<Batch> m_batches;  ///< this substep's, reused
  Batch m_gathering;             ///< the batch being gathered, its storage reused (solveConstraints)
  int m_threadedBodies = 0;
  bool m_alwaysThreads = false;
  bool m_fused = false;               ///< this stepSimulation's passes run fused (stepSimulation)
  btScalar m_kinematicStep = 0;       ///< saveKinematicState's step, for the fused pass
  bool m_gravityDue = false;          ///< applyGravity was called: the fused pass applies it
  ExactSolver* m_finisher = nullptr;  ///< setFinishBatches
  std::vector<char> m_integrated;     ///< by world array index: integrated with its batch this substep
  /// Whether the threads pay (core/pace.h): the bounding boxes, the motion prediction, the
  /// integration, the solver batches.
  Pace m_boxPace, m_predictPace, m_integratePace, m_batchPace;
  HomeRanges m_homes;  // the bodies' (or batches') ranges of the run under way, one per thread
  struct Box {
    btVector3 min, max;
    bool update;
    const void* touch[4];  // the broadphase's proxy, tree leaf and stage-list neighbours
  };
  btAlignedObjectArray<Box> m_boxes;  ///< updateAabbs', by object
};

}  // namespace rm3d
