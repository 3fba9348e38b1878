// The soft-rigid dynamics world with a linear-time hand-out of joints to simulation islands.
//
// Bullet's island callback finds each island's joints by scanning the sorted joint list from its
// start for every island, so a world of n separate modules spends O(n^2) a substep there: 19% of
// `superbots_1000`'s time. This world sorts the joints the same way, notes where each island's run
// starts once, and batches islands into solver groups exactly as Bullet does (the same groups in
// the same order, so results are bit-identical). It also skips the predictive-contact pass that
// only continuous collision detection needs.
#pragma once

#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include <vector>

namespace rm3d {

class SolverWorld : public btSoftRigidDynamicsWorld {
 public:
  using btSoftRigidDynamicsWorld::btSoftRigidDynamicsWorld;

 protected:
  void solveConstraints(btContactSolverInfo& info) override;
  /// No body here has a CCD motion threshold, so Bullet's predictive-contact pass, which predicts
  /// every body's next transform only to compare its motion with a threshold of 0, finds nothing:
  /// only the release is kept (results are bit-identical).
  void createPredictiveContacts(btScalar) override { releasePredictiveContacts(); }

 private:
  std::vector<int> m_islandStart, m_islandCount;  ///< by island id: its run in m_sortedConstraints
};

}  // namespace rm3d
