// The narrowphase on worker threads, with Bullet's results (see task_dispatcher.h).
#include "physics/task_dispatcher.h"

#include <BulletCollision/BroadphaseCollision/btCollisionAlgorithm.h>
#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <BulletCollision/CollisionDispatch/btCollisionConfiguration.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionShapes/btCollisionShape.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <LinearMath/btPoolAllocator.h>

#include <algorithm>

#include "core/read_at.h"
#include "physics/bullet_layout.h"

namespace rm3d {

namespace {

/// Below this many pairs to run, handing them to the threads costs more than it saves.
constexpr int kMinParallelPairs = 256;
/// Pairs a thread takes at a time.
constexpr int kChunk = 32;
/// How far ahead of the pair it runs a loop over pairs fetches what the pair will read: its
/// broadphase proxies, then its bodies (read through the proxies), then the bodies' shapes (read
/// through the bodies) and its algorithm.
constexpr int kProxiesAhead = 12, kBodiesAhead = 8, kShapesAhead = 4;

/// What a pair's run reads of a body: btCollisionObject's pose, shape, activation, type and
/// collision check, and btRigidBody's joints (needsCollision).
void prefetchBody(const btCollisionObject* o) {
  using namespace bullet_layout;
  fetchPose(o);
  for (int at : {kShape, kActivation, kInternalType, kCollideWith, kIgnoreList, kConstraintRefs})
    fetch(o, at);
}

/// What a pair's run reads through a body: its shape, and the bodies it skips the collision check
/// with (a body with joints: checkCollideWith walks that list, which lies anywhere on the heap;
/// with 10,000 modules, 78% of a pair's run waited on it).
void prefetchShape(const btCollisionObject* o) {
  using namespace bullet_layout;
  fetch(o->getCollisionShape(), 0);
  fetch(o->getCollisionShape(), 64);
  if (readAt<int>(o, kCollideWith))
    if (const void* list = readAt<const void*>(o, kIgnoreList)) fetch(list, 0);
}

/// Before pair i runs (the pairs lie in order in their array; what they point to, anywhere).
[[gnu::always_inline]] inline void prefetchPairs(const btBroadphasePairArray& pairs, int i, int n) {
  if (i + kProxiesAhead < n) {
    const btBroadphasePair& p = pairs[i + kProxiesAhead];
    __builtin_prefetch(p.m_pProxy0);
    __builtin_prefetch(p.m_pProxy1);
  }
  if (i + kBodiesAhead < n) {
    const btBroadphasePair& p = pairs[i + kBodiesAhead];
    prefetchBody(static_cast<const btCollisionObject*>(p.m_pProxy0->m_clientObject));
    prefetchBody(static_cast<const btCollisionObject*>(p.m_pProxy1->m_clientObject));
  }
  if (i + kShapesAhead < n) {
    const btBroadphasePair& p = pairs[i + kShapesAhead];
    prefetchShape(static_cast<const btCollisionObject*>(p.m_pProxy0->m_clientObject));
    prefetchShape(static_cast<const btCollisionObject*>(p.m_pProxy1->m_clientObject));
    if (p.m_algorithm) {
      bullet_layout::fetch(p.m_algorithm, 0);
      bullet_layout::fetch(p.m_algorithm, 64);
    }
  }
}

}  // namespace

TaskDispatcher::TaskDispatcher(btCollisionConfiguration* config)
    : btCollisionDispatcher(config),
      m_manifolds(sizeof(btPersistentManifold), 256),
      m_algorithms(size_t(config->getCollisionAlgorithmPool()->getElementSize()), 256) {}

btPersistentManifold* TaskDispatcher::makeManifold(const btCollisionObject* body0,
                                                   const btCollisionObject* body1) {
  const btScalar breaking =
      (m_dispatcherFlags & CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD)
          ? btMin(body0->getCollisionShape()->getContactBreakingThreshold(gContactBreakingThreshold),
                  body1->getCollisionShape()->getContactBreakingThreshold(gContactBreakingThreshold))
          : gContactBreakingThreshold;
  const btScalar processing =
      btMin(body0->getContactProcessingThreshold(), body1->getContactProcessingThreshold());
  auto* m = new (m_manifolds.take(sizeof(btPersistentManifold)))
      btPersistentManifold(body0, body1, 0, breaking, processing);
  m->m_index1a = m_manifoldsPtr.size();
  m_manifoldsPtr.push_back(m);
  return m;
}

void TaskDispatcher::freeManifold(btPersistentManifold* manifold) {
  clearManifold(manifold);
  const int i = manifold->m_index1a;
  m_manifoldsPtr.swap(i, m_manifoldsPtr.size() - 1);
  m_manifoldsPtr[i]->m_index1a = i;
  m_manifoldsPtr.pop_back();
  manifold->~btPersistentManifold();
  m_manifolds.give(manifold);
}

void TaskDispatcher::setTasks(int threads, Tasks tasks) {
  m_threads = tasks ? std::max(1, threads) : 1;
  m_tasks = m_threads > 1 ? std::move(tasks) : nullptr;
  m_lanes.clear();
  for (int t = 0; t < m_threads; ++t) m_lanes.push_back(std::make_unique<Lane>());
}

TaskDispatcher::Lane* TaskDispatcher::lane() {
  const std::thread::id me = std::this_thread::get_id();
  for (const auto& l : m_lanes)
    if (l->thread.load(std::memory_order_relaxed) == me) return l.get();
  return nullptr;
}

void TaskDispatcher::note(btPersistentManifold* manifold, bool release) {
  Lane* l = lane();
  l->changes.push_back({l->pair, l->phase, int(l->changes.size()), manifold, release});
}

btPersistentManifold* TaskDispatcher::getNewManifold(const btCollisionObject* body0,
                                                     const btCollisionObject* body1) {
  if (!m_deferring || !lane()) return makeManifold(body0, body1);
  btPersistentManifold* m;
  {
    std::lock_guard<std::mutex> hold(m_mutex);
    m = makeManifold(body0, body1);
    m_manifoldsPtr.pop_back();  // listed later, in pair order
  }
  note(m, false);
  return m;
}

void TaskDispatcher::releaseManifold(btPersistentManifold* manifold) {
  if (!m_deferring || !lane()) return freeManifold(manifold);
  note(manifold, true);  // cleared, unlisted and freed later, in pair order
}

void* TaskDispatcher::allocateCollisionAlgorithm(int size) {
  if (!m_deferring) return m_algorithms.take(size_t(size));
  std::lock_guard<std::mutex> hold(m_mutex);
  return m_algorithms.take(size_t(size));
}

void TaskDispatcher::freeCollisionAlgorithm(void* ptr) {
  if (!m_deferring) return m_algorithms.give(ptr);
  std::lock_guard<std::mutex> hold(m_mutex);
  m_algorithms.give(ptr);
}

bool TaskDispatcher::needsCollision(const btCollisionObject* body0, const btCollisionObject* body1) {
  if (!body0->isActive() && !body1->isActive()) return false;
  auto jointless = [](const btCollisionObject* o) {
    const btRigidBody* rb = btRigidBody::upcast(o);
    return rb && rb->getNumConstraintRefs() == 0;
  };
  if (jointless(body0) || jointless(body1)) return true;
  return body0->checkCollideWith(body1) && body1->checkCollideWith(body0);
}

void TaskDispatcher::runPair(btBroadphasePair& pair, const btDispatcherInfo& info, bool make) {
  auto* o0 = static_cast<btCollisionObject*>(pair.m_pProxy0->m_clientObject);
  auto* o1 = static_cast<btCollisionObject*>(pair.m_pProxy1->m_clientObject);
  if (!needsCollision(o0, o1)) return;
  const btCollisionObjectWrapper w0(nullptr, o0->getCollisionShape(), o0, o0->getWorldTransform(), -1, -1);
  const btCollisionObjectWrapper w1(nullptr, o1->getCollisionShape(), o1, o1->getWorldTransform(), -1, -1);
  if (!pair.m_algorithm && make)
    pair.m_algorithm = findAlgorithm(&w0, &w1, nullptr, BT_CONTACT_POINT_ALGORITHMS);
  if (!pair.m_algorithm) return;
  btManifoldResult result(&w0, &w1);
  pair.m_algorithm->processCollision(&w0, &w1, info, &result);
}

void TaskDispatcher::runPairs(int t, btBroadphasePairArray& pairs, const btDispatcherInfo& info) {
  Lane& l = *m_lanes[size_t(t)];
  l.thread.store(std::this_thread::get_id(), std::memory_order_relaxed);
  l.phase = 1;
  const int n = pairs.size();
  m_homes.run(t, [&](int k, int end) {
    for (int i = k; i < end; ++i) {
      prefetchPairs(pairs, i, n);
      if (!pairs[i].m_algorithm) continue;  // (made on the calling thread first: none needed)
      l.pair = i;
      runPair(pairs[i], info, false);
    }
  });
  l.thread.store(std::thread::id(), std::memory_order_relaxed);  // this thread may take another lane
}

void TaskDispatcher::dispatchAllCollisionPairs(btOverlappingPairCache* pairCache,
                                               const btDispatcherInfo& info, btDispatcher* dispatcher) {
  // Bullet's loop where it does not run the pairs in array order with its own near callback.
  m_threadedPairs = 0;
  if (info.m_dispatchFunc != btDispatcherInfo::DISPATCH_DISCRETE || info.m_deterministicOverlappingPairs ||
      getNearCallback() != &btCollisionDispatcher::defaultNearCallback)
    return btCollisionDispatcher::dispatchAllCollisionPairs(pairCache, info, dispatcher);
  if (!m_tasks || pairCache->getNumOverlappingPairs() < kMinParallelPairs)
    return dispatchHere(pairCache, info);
  runPaced(
      m_pace, m_always, [&] { dispatchOnThreads(pairCache, info); },
      [&] {
        m_threadedPairs = 0;
        dispatchHere(pairCache, info);
      });
}

void TaskDispatcher::dispatchHere(btOverlappingPairCache* pairCache, const btDispatcherInfo& info) {
  // As Bullet's loop (btHashedOverlappingPairCache::processAllOverlappingPairs with the near
  // callback, which never removes a pair), fetching each pair's data ahead.
  btBroadphasePairArray& pairs = pairCache->getOverlappingPairArray();
  const int n = pairs.size();
  for (int i = 0; i < n; ++i) {
    prefetchPairs(pairs, i, n);
    runPair(pairs[i], info, true);
  }
}

void TaskDispatcher::dispatchOnThreads(btOverlappingPairCache* pairCache, const btDispatcherInfo& info) {
  btBroadphasePairArray& pairs = pairCache->getOverlappingPairArray();
  const int n = pairs.size();
  m_threadedPairs = n;
  for (const auto& l : m_lanes) {
    l->thread.store(std::thread::id(), std::memory_order_relaxed);
    l->changes.clear();
  }
  m_deferring = true;
  // On this thread, in pair order: the algorithm of each new pair that collides, made as Bullet's
  // near callback makes it (an algorithm may make its manifold then).
  Lane& first = *m_lanes[0];
  first.thread.store(std::this_thread::get_id(), std::memory_order_relaxed);
  first.phase = 0;
  for (int i = 0; i < n; ++i) {
    btBroadphasePair& pair = pairs[i];
    if (pair.m_algorithm) continue;
    auto* o0 = static_cast<btCollisionObject*>(pair.m_pProxy0->m_clientObject);
    auto* o1 = static_cast<btCollisionObject*>(pair.m_pProxy1->m_clientObject);
    if (!needsCollision(o0, o1)) continue;
    first.pair = i;
    const btCollisionObjectWrapper w0(nullptr, o0->getCollisionShape(), o0, o0->getWorldTransform(), -1, -1);
    const btCollisionObjectWrapper w1(nullptr, o1->getCollisionShape(), o1, o1->getWorldTransform(), -1, -1);
    pair.m_algorithm = findAlgorithm(&w0, &w1, nullptr, BT_CONTACT_POINT_ALGORITHMS);
  }
  first.thread.store(std::thread::id(), std::memory_order_relaxed);
  // The pairs, on the threads, as the near callback runs them: each thread its own range of them
  // first, the same from one substep to the next (core/home_ranges.h).
  m_homes.begin(n, m_threads, kChunk);
  m_tasks(m_threads, [&](int t) { runPairs(t, pairs, info); });
  m_deferring = false;
  // The manifolds made and let go, listed and unlisted as Bullet's loop would have, pair by pair.
  m_changes.clear();
  for (const auto& l : m_lanes) m_changes.insert(m_changes.end(), l->changes.begin(), l->changes.end());
  if (m_changes.empty()) return;
  std::sort(m_changes.begin(), m_changes.end());
  for (const Change& c : m_changes) {
    if (c.release) {
      freeManifold(c.manifold);
    } else {
      c.manifold->m_index1a = m_manifoldsPtr.size();
      m_manifoldsPtr.push_back(c.manifold);
    }
  }
}

}  // namespace rm3d
