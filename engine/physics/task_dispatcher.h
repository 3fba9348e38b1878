// The collision dispatcher, with the narrowphase on worker threads.
//
// Bullet's dispatcher runs every overlapping pair's algorithm in turn on one thread; with 1500
// ATRONs that is 6.9 ms of a 15 ms substep. Each pair's algorithm reads its two bodies and writes
// only its own contact manifolds, so pairs can run at once, save for what they share through the
// dispatcher: the pools of algorithms and manifolds, and the world's list of manifolds, whose order
// is the order of the solver's contact rows. Here the new pairs' algorithms are made on the calling
// thread, pair by pair, as Bullet would make them; then the pairs run on the threads, each thread
// noting the manifolds its pairs make and let go; then those changes are made to the list in pair
// order.
// The list comes out as Bullet's own loop leaves it, so the results are the same bits at any
// thread count.
//
// On one thread, the pairs run in the same order as in Bullet's loop, but each pair's broadphase
// proxies, bodies, shapes and algorithm are fetched a few pairs ahead: with 10,000 modules they lie
// outside the caches. Without the look-ahead, the pairs' loop, needsCollision and the compound
// shapes' algorithm took 18.6 ms of a `superbots_10000` step (CPU, one thread); with it, 8.3 ms.
#pragma once

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "core/function_ref.h"
#include "core/home_ranges.h"
#include "core/pace.h"
#include "physics/slot_pool.h"

namespace rm3d {

class TaskDispatcher : public btCollisionDispatcher {
 public:
  /// Runs fn(t) for t in [0, n), each on its own thread where it can.
  using Tasks = std::function<void(int n, FunctionRef<void(int)> fn)>;
  /// Manifolds and algorithms come from the dispatcher's own pools (physics/slot_pool.h), not
  /// from the configuration's (which may be made with room for one of each).
  explicit TaskDispatcher(btCollisionConfiguration* config);
  /// With `threads` > 1 and `tasks`, the pairs run on that many threads; otherwise on this one
  /// (as in a world with cloth: its pairs share the cloth's contact lists).
  void setTasks(int threads, Tasks tasks);
  /// The pairs on the threads wherever they may go, not only where the clock says it pays
  /// (tests: core/pace.h).
  void setAlwaysThreads(bool always) { m_always = always; }

  void dispatchAllCollisionPairs(btOverlappingPairCache* pairCache, const btDispatcherInfo& info,
                                 btDispatcher* dispatcher) override;
  btPersistentManifold* getNewManifold(const btCollisionObject* body0,
                                       const btCollisionObject* body1) override;
  void releaseManifold(btPersistentManifold* manifold) override;
  void* allocateCollisionAlgorithm(int size) override;
  void freeCollisionAlgorithm(void* ptr) override;
  /// As Bullet's, without searching a body's list of the bodies it ignores where the other body
  /// has no joint: every joint here is added with collisions between its bodies off
  /// (btDiscreteDynamicsWorld::addConstraint(c, true)), which lists it on both bodies and makes each
  /// ignore the other, so a rigid body that lists no joint (the ground, most obstacles) is in no
  /// body's list. The search read a list kept apart in memory for every pair with the ground: 3%
  /// of a superbots_1000 step.
  bool needsCollision(const btCollisionObject* body0, const btCollisionObject* body1) override;
  /// Pairs the last dispatch ran on the threads (0: Bullet's loop ran them).
  int threadedPairs() const { return m_threadedPairs; }

 private:
  /// A manifold made or let go while the pairs run: made to the list afterwards, in pair order.
  struct Change {
    int pair, phase, seq;  // phase 0: as the pair's algorithm was made; 1: as it ran
    btPersistentManifold* manifold;
    bool release;
    bool operator<(const Change& o) const {
      return pair != o.pair ? pair < o.pair : phase != o.phase ? phase < o.phase : seq < o.seq;
    }
  };
  /// One thread's state while the pairs run.
  struct alignas(64) Lane {  // (a cache line of its own: each thread writes its own per pair)
    std::atomic<std::thread::id> thread{};
    int pair = -1, phase = 0;
    std::vector<Change> changes;
  };
  Lane* lane();  ///< the calling thread's, or null
  /// Task t: takes kChunk pairs at a time, its own range's first (m_homes), and runs them (as the
  /// near callback would).
  void runPairs(int t, btBroadphasePairArray& pairs, const btDispatcherInfo& info);
  void note(btPersistentManifold* manifold, bool release);
  /// Bullet's getNewManifold and releaseManifold (3.24), from and to m_manifolds.
  btPersistentManifold* makeManifold(const btCollisionObject* body0, const btCollisionObject* body1);
  void freeManifold(btPersistentManifold* manifold);
  /// A pair as Bullet's near callback runs it; its algorithm made first (where it has none) only
  /// with `make`.
  void runPair(btBroadphasePair& pair, const btDispatcherInfo& info, bool make);
  /// The pairs on this thread, in order, as Bullet's loop runs them (the pairs' data fetched ahead).
  void dispatchHere(btOverlappingPairCache* pairCache, const btDispatcherInfo& info);
  /// The pairs on the threads (dispatchAllCollisionPairs, where they may go and it pays).
  void dispatchOnThreads(btOverlappingPairCache* pairCache, const btDispatcherInfo& info);

  int m_threads = 1;
  Tasks m_tasks;
  bool m_deferring = false;  // the pairs are running: manifolds are noted, not listed
  int m_threadedPairs = 0;
  bool m_always = false;
  Pace m_pace;         // whether the threads pay
  HomeRanges m_homes;  // the pairs' ranges, one per thread
  std::mutex m_mutex;  // the pools, while the pairs run on the threads
  SlotPool m_manifolds;
  SlotPool m_algorithms;
  std::vector<std::unique_ptr<Lane>> m_lanes;
  std::vector<Change> m_changes;
};

}  // namespace rm3d
