// Joints handed to simulation islands in linear time (see solver_world.h).
#include "physics/solver_world.h"

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <BulletDynamics/ConstraintSolver/btConstraintSolver.h>
#include <BulletDynamics/ConstraintSolver/btTypedConstraint.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <LinearMath/btQuickprof.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <string>

#include "physics/bullet_layout.h"
#include "physics/exact_solver.h"
#include "physics/fused_passes_check.h"

namespace rm3d {

namespace {

/// A joint's island: its first body's, or its second's when the first is static (as Bullet).
int islandOf(const btTypedConstraint* c) {
  const int a = c->getRigidBodyA().getIslandTag();
  return a >= 0 ? a : c->getRigidBodyB().getIslandTag();
}

struct IslandOrder {
  bool operator()(const SolverWorld::IslandJoint& l, const SolverWorld::IslandJoint& r) const {
    return l.island < r.island;
  }
};

/// Bullet's InplaceSolverIslandCallback, with each island's joints looked up instead of searched.
class Batches : public btSimulationIslandManager::IslandCallback {
  SolverWorld* m_world;  // (with m_finisher: each batch finished after its solve)
  ExactSolver* m_finisher;
  // The batch being gathered: in `scratch` (SolverWorld::m_gathering), whose storage is kept
  // from one substep to the next (arrays of its own grew by doubling every substep: 26
  // allocations a step on a 100-module snake).
  btAlignedObjectArray<btCollisionObject*>& m_bodies;
  btAlignedObjectArray<btPersistentManifold*>& m_manifolds;
  btAlignedObjectArray<btTypedConstraint*>& m_constraints;

 public:
  /// `out`: batches are collected there (from `*outCount` on) instead of solved at once.
  Batches(btConstraintSolver& solver, btContactSolverInfo& info, btIDebugDraw* draw, btDispatcher* dispatcher,
          btTypedConstraint** sorted, int count, const std::vector<int>& start, const std::vector<int>& runs,
          SolverWorld::Batch& scratch, std::vector<SolverWorld::Batch>* out = nullptr,
          int* outCount = nullptr, SolverWorld* world = nullptr, ExactSolver* finisher = nullptr)
      : m_world(world),
        m_finisher(finisher),
        m_bodies(scratch.bodies),
        m_manifolds(scratch.manifolds),
        m_constraints(scratch.constraints),
        m_out(out),
        m_outCount(outCount),
        m_solver(solver),
        m_info(info),
        m_draw(draw),
        m_dispatcher(dispatcher),
        m_sorted(sorted),
        m_count(count),
        m_start(start),
        m_runs(runs) {}

  void processIsland(btCollisionObject** bodies, int numBodies, btPersistentManifold** manifolds,
                     int numManifolds, int island) override {
    if (island < 0) {  // islands not split: everything at once
      m_solver.solveGroup(bodies, numBodies, manifolds, numManifolds, m_sorted, m_count, m_info, m_draw,
                          m_dispatcher);
      return;
    }
    const bool known = island < int(m_start.size()) && m_start[size_t(island)] >= 0;
    btTypedConstraint** first = known ? m_sorted + m_start[size_t(island)] : nullptr;
    const int n = known ? m_runs[size_t(island)] : 0;
    for (int i = 0; i < numBodies; ++i) m_bodies.push_back(bodies[i]);
    // Only manifolds with contact points come here (ContactIslands::buildAndProcess): one without
    // makes no rows, and it may join bodies of two islands, so solving it would make the other
    // island's body a solver body of this batch, which writes its velocity back, gravity included,
    // a second time.
    for (int i = 0; i < numManifolds; ++i) m_manifolds.push_back(manifolds[i]);
    for (int i = 0; i < n; ++i) m_constraints.push_back(first[i]);
    if (m_constraints.size() + m_manifolds.size() > m_info.m_minimumSolverBatchSize) flush();
  }

  void flush() {
    if (m_out) {
      if (m_bodies.size() + m_manifolds.size() + m_constraints.size() == 0) return;
      if (int(m_out->size()) <= *m_outCount) m_out->emplace_back();
      SolverWorld::Batch& b = (*m_out)[size_t((*m_outCount)++)];
      b.bodies.copyFromArray(m_bodies);  // into the storage of the last substep's batch
      b.manifolds.copyFromArray(m_manifolds);
      b.constraints.copyFromArray(m_constraints);
      m_bodies.resize(0);
      m_manifolds.resize(0);
      m_constraints.resize(0);
      return;
    }
    m_solver.solveGroup(m_bodies.size() ? &m_bodies[0] : nullptr, m_bodies.size(),
                        m_manifolds.size() ? &m_manifolds[0] : nullptr, m_manifolds.size(),
                        m_constraints.size() ? &m_constraints[0] : nullptr, m_constraints.size(), m_info,
                        m_draw, m_dispatcher);
    if (m_finisher && m_bodies.size())
      m_world->finishBatch(*m_finisher, &m_bodies[0], m_bodies.size(), m_info.m_timeStep);
    m_bodies.resize(0);
    m_manifolds.resize(0);
    m_constraints.resize(0);
  }

 private:
  std::vector<SolverWorld::Batch>* m_out;
  int* m_outCount;
  btConstraintSolver& m_solver;
  btContactSolverInfo& m_info;
  btIDebugDraw* m_draw;
  btDispatcher* m_dispatcher;
  btTypedConstraint** m_sorted;
  int m_count;
  const std::vector<int>&m_start, &m_runs;
};

/// Islands joined by contacts, not by overlapping bounding boxes. Bullet unites two bodies
/// whose boxes overlap (each grown by 2 cm), so 1500 ATRONs 5 cm apart (a turned hull's box is
/// 41% wider than the hull) made one island: one solver batch, nothing to share between threads.
/// Here two bodies share an island when their manifold has contact points, which are what make
/// solver rows: the solve is the same, and a body now wakes when it comes within the contact
/// distance (2 cm) of a moving one instead of when their boxes first overlap.
class ContactIslands : public btSimulationIslandManager {
 public:
  void updateActivationState(btCollisionWorld* world, btDispatcher* dispatcher) override {
    // As Bullet's, each object, manifold and manifold's bodies fetched ahead (buildAndProcess);
    // without Bullet's reset of each object's hit fraction, which nothing reads: the integration
    // sets it to 1 before it reads it (SolverWorld::integrateBody, and Bullet's own integration
    // where it runs), nothing else sets it, and it lies on another line than the island tag (one
    // line less for each body: with many modules, each line is fetched from memory).
    using namespace bullet_layout;
    int index = 0;
    btCollisionObjectArray& objects = world->getCollisionObjectArray();
    for (int i = 0, n = objects.size(); i < n; ++i) {
      if (i + kAhead < n) fetch(objects[i + kAhead], kIslandTag);
      btCollisionObject* o = objects[i];
      if (!o->isStaticOrKinematicObject()) o->setIslandTag(index++);
      o->setCompanionId(-1);
    }
    initUnionFind(index);
    btPersistentManifold* const* list = dispatcher->getInternalManifoldPointer();
    for (int i = 0, n = dispatcher->getNumManifolds(); i < n; ++i) {
      if (i + 2 * kAhead < n) {
        fetch(list[i + 2 * kAhead], kManifoldBodies);
        fetch(list[i + 2 * kAhead], kManifoldCount);
      }
      if (i + kAhead < n) {
        fetch(list[i + kAhead]->getBody0(), kIslandTag);
        fetch(list[i + kAhead]->getBody1(), kIslandTag);
      }
      const btPersistentManifold* m = dispatcher->getManifoldByIndexInternal(i);
      const btCollisionObject* a = m->getBody0();
      const btCollisionObject* b = m->getBody1();
      if (m->getNumContacts() > 0 && a->mergesSimulationIslands() && b->mergesSimulationIslands())
        getUnionFind().unite(a->getIslandTag(), b->getIslandTag());
    }
  }

  void storeIslandActivationState(btCollisionWorld* world) override {
    // As Bullet's (3.24, with STATIC_SIMULATION_ISLAND_OPTIMIZATION), each object fetched ahead.
    using namespace bullet_layout;
    btCollisionObjectArray& objects = world->getCollisionObjectArray();
    btUnionFind& islands = getUnionFind();
    int index = 0;
    for (int i = 0, n = objects.size(); i < n; ++i) {
      if (i + kAhead < n) fetch(objects[i + kAhead], kIslandTag);
      btCollisionObject* o = objects[i];
      if (!o->isStaticOrKinematicObject()) {
        o->setIslandTag(islands.find(index));
        islands.getElement(index).m_sz = i;
        o->setCompanionId(-1);
        ++index;
      } else {
        o->setIslandTag(-1);
        o->setCompanionId(-2);
      }
    }
  }

  /// As btSimulationIslandManager::buildAndProcessIslands (Bullet 3.24, split islands), with the
  /// manifolds sorted by island on their island ids side by side, each read once: Bullet's sort
  /// read two bodies per comparison, scattered over memory, and grew faster than the world. The
  /// sort is Bullet's own (btAlignedObjectArray::quickSort), on the same keys in the same first
  /// order, so it makes the same order, and the batches are the same bits.
  ///
  /// With many modules the bodies and manifolds have left the caches, and these passes reach them
  /// out of memory's order: each is fetched kAhead items ahead (physics/bullet_layout.h).
  void buildAndProcess(btDispatcher* dispatcher, btCollisionWorld* world, IslandCallback* callback) {
    using namespace bullet_layout;
    btCollisionObjectArray& objects = world->getCollisionObjectArray();
    btUnionFind& islands = getUnionFind();
    const bool deterministic = world->getDispatchInfo().m_deterministicOverlappingPairs;
    const int count = islands.getNumElements();
    {
      BT_PROFILE("islandUnionFindAndQuickSort");
      islands.sortIslands();
      for (int start = 0, end = 1; start < count; start = end) {
        const int id = islands.getElement(start).m_id;
        for (end = start + 1; end < count && islands.getElement(end).m_id == id; ++end) {
        }
        bool allSleeping = true;
        for (int k = start; k < end && allSleeping; ++k) {
          const btCollisionObject* o = objects[islands.getElement(k).m_sz];
          if (o->getIslandTag() == id &&
              (o->getActivationState() == ACTIVE_TAG || o->getActivationState() == DISABLE_DEACTIVATION))
            allSleeping = false;
        }
        for (int k = start; k < end; ++k) {
          btCollisionObject* o = objects[islands.getElement(k).m_sz];
          if (o->getIslandTag() != id) continue;
          if (allSleeping) {
            o->setActivationState(ISLAND_SLEEPING);
          } else if (o->getActivationState() == ISLAND_SLEEPING) {
            o->setActivationState(WANTS_DEACTIVATION);
            o->setDeactivationTime(btScalar(0));
          }
        }
      }
      m_manifolds.resize(0);
      const int manifolds = dispatcher->getNumManifolds();
      btPersistentManifold* const* list = dispatcher->getInternalManifoldPointer();
      for (int i = 0; i < manifolds; ++i) {
        if (i + 2 * kAhead < manifolds) {
          fetch(list[i + 2 * kAhead], kManifoldBodies);
          fetch(list[i + 2 * kAhead], kManifoldCount);
        }
        if (i + kAhead < manifolds) {
          fetch(list[i + kAhead]->getBody0(), kActivation);
          fetch(list[i + kAhead]->getBody1(), kActivation);
        }
        btPersistentManifold* m = dispatcher->getManifoldByIndexInternal(i);
        if (deterministic && m->getNumContacts() == 0) continue;
        btCollisionObject* a = const_cast<btCollisionObject*>(m->getBody0());
        btCollisionObject* b = const_cast<btCollisionObject*>(m->getBody1());
        if (a->getActivationState() == ISLAND_SLEEPING && b->getActivationState() == ISLAND_SLEEPING)
          continue;
        if (a->isKinematicObject() && a->getActivationState() != ISLAND_SLEEPING && a->hasContactResponse())
          b->activate();
        if (b->isKinematicObject() && b->getActivationState() != ISLAND_SLEEPING && b->hasContactResponse())
          a->activate();
        if (getSplitIslands() && dispatcher->needsResponse(a, b))
          m_manifolds.push_back(
              {a->getIslandTag() >= 0 ? a->getIslandTag() : b->getIslandTag(), m->getNumContacts() > 0, m});
      }
    }
    BT_PROFILE("processIslands");
    if (!getSplitIslands()) {
      callback->processIsland(objects.size() ? &objects[0] : nullptr, objects.size(),
                              dispatcher->getInternalManifoldPointer(), dispatcher->getNumManifolds(), -1);
      return;
    }
    if (deterministic)
      m_manifolds.quickSort(DeterministicOrder());
    else
      m_manifolds.quickSort(KeyOrder());
    // Each island's manifolds with contact points, in their sorted order (one without points makes
    // no rows, and it may join bodies of two islands: see Batches::processIsland). Whether a
    // manifold has points was read above, beside its bodies: read here, each would wait on memory.
    const int manifolds = m_manifolds.size();
    m_sorted.resize(0);
    for (int i = 0; i < manifolds; ++i)
      if (m_manifolds[i].points) m_sorted.push_back(m_manifolds[i].manifold);
    int first = 0;   // the next island's manifolds start here (in m_manifolds)
    int listed = 0;  // and its manifolds with points here (in m_sorted)
    for (int start = 0, end = 1; start < count; start = end) {
      const int id = islands.getElement(start).m_id;
      bool sleeping = true;
      for (end = start; end < count && islands.getElement(end).m_id == id; ++end) {
        if (end + kAhead < count) fetch(objects[islands.getElement(end + kAhead).m_sz], kActivation);
        btCollisionObject* o = objects[islands.getElement(end).m_sz];
        m_bodies.push_back(o);
        if (o->isActive()) sleeping = false;
      }
      int last = first, points = 0;
      for (; last < manifolds && m_manifolds[last].island == id; ++last) points += m_manifolds[last].points;
      if (!sleeping)
        callback->processIsland(&m_bodies[0], m_bodies.size(), points > 0 ? &m_sorted[listed] : nullptr,
                                points, id);
      first = last;
      listed += points;
      m_bodies.resize(0);
    }
  }

 private:
  static constexpr int kAhead = 8;
  struct Keyed {
    int island;
    bool points;  ///< the manifold has contact points (read here, in memory's order: see below)
    btPersistentManifold* manifold;
  };
  struct KeyOrder {
    bool operator()(const Keyed& l, const Keyed& r) const { return l.island < r.island; }
  };
  /// Bullet's deterministic order (btPersistentManifoldSortPredicateDeterministic).
  struct DeterministicOrder {
    bool operator()(const Keyed& l, const Keyed& r) const {
      if (l.island != r.island) return l.island < r.island;
      const int l0 = l.manifold->getBody0()->getBroadphaseHandle()->m_uniqueId;
      const int r0 = r.manifold->getBody0()->getBroadphaseHandle()->m_uniqueId;
      if (l0 != r0) return l0 < r0;
      return l.manifold->getBody1()->getBroadphaseHandle()->m_uniqueId <
             r.manifold->getBody1()->getBroadphaseHandle()->m_uniqueId;
    }
  };
  btAlignedObjectArray<Keyed> m_manifolds;
  btAlignedObjectArray<btPersistentManifold*> m_sorted;
  btAlignedObjectArray<btCollisionObject*> m_bodies;
};

}  // namespace

SolverWorld::SolverWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                         btConstraintSolver* solver, btCollisionConfiguration* config)
    : btSoftRigidDynamicsWorld(dispatcher, broadphase, solver, config) {
  m_islandManager->~btSimulationIslandManager();
  btAlignedFree(m_islandManager);
  void* mem = btAlignedAlloc(sizeof(ContactIslands), 16);
  m_islandManager = new (mem) ContactIslands();
}

void SolverWorld::solveConstraints(btContactSolverInfo& info) {
  // As btDiscreteDynamicsWorld::solveConstraints, with the islands' runs found in one pass.
  // Each joint's island read once, then Bullet's sort (the same algorithm, so the same order) on
  // the ids side by side: sorting the joints themselves read two bodies per comparison, scattered
  // over memory (1.3 ms a substep at 10,000 modules).
  const int n = m_constraints.size();
  m_islandJoints.resize(n);
  for (int i = 0; i < n; ++i) {
    // (The joints and their bodies lie anywhere: each fetched some joints ahead.)
    if (i + 16 < n) bullet_layout::fetch(m_constraints[i + 16], 0);
    if (i + 8 < n) bullet_layout::fetch(&m_constraints[i + 8]->getRigidBodyA(), bullet_layout::kIslandTag);
    m_islandJoints[i] = {islandOf(m_constraints[i]), m_constraints[i]};
  }
  m_islandJoints.quickSort(IslandOrder());
  m_sortedConstraints.resize(n);
  for (int i = 0; i < n; ++i) m_sortedConstraints[i] = m_islandJoints[i].joint;
  m_islandStart.assign(size_t(getNumCollisionObjects()) + 1, -1);
  m_islandCount.assign(m_islandStart.size(), 0);
  for (int i = 0; i < n; ++i) {
    const int island = m_islandJoints[i].island;
    if (island < 0) continue;
    if (size_t(island) >= m_islandStart.size()) {
      m_islandStart.resize(size_t(island) + 1, -1);
      m_islandCount.resize(size_t(island) + 1, 0);
    }
    if (m_islandStart[size_t(island)] < 0) m_islandStart[size_t(island)] = i;
    ++m_islandCount[size_t(island)];
  }
  btTypedConstraint** sorted = n ? &m_sortedConstraints[0] : nullptr;
  const bool parallel = !m_helpers.empty() && m_tasks;
  int count = 0;
  // (Finished batch by batch only where this substep's passes run fused: otherwise Bullet's
  // separate passes come after the integration.)
  const bool finish = m_finisher && m_fused;
  if (finish) m_integrated.assign(size_t(getNumCollisionObjects()), 0);
  Batches batches(*m_constraintSolver, info, getDebugDrawer(), getDispatcher(), sorted, n, m_islandStart,
                  m_islandCount, m_gathering, parallel ? &m_batches : nullptr, &count, this,
                  finish && !parallel ? m_finisher : nullptr);
  m_constraintSolver->prepareSolve(getNumCollisionObjects(), getDispatcher()->getNumManifolds());
  static_cast<ContactIslands*>(m_islandManager)->buildAndProcess(getDispatcher(), this, &batches);
  batches.flush();
  if (parallel && count > 0) solveBatches(info, count);
  m_constraintSolver->allSolved(info, m_debugDrawer);
}

void SolverWorld::calculateSimulationIslands() {
  BT_PROFILE("calculateSimulationIslands");
  // As btDiscreteDynamicsWorld::calculateSimulationIslands (3.24), each joint and its bodies'
  // island tags fetched ahead.
  using namespace bullet_layout;
  btSimulationIslandManager* islands = getSimulationIslandManager();
  islands->updateActivationState(this, getDispatcher());
  btUnionFind& find = islands->getUnionFind();
  auto unite = [&](const btCollisionObject* a, const btCollisionObject* b) {
    if (a && !a->isStaticOrKinematicObject() && b && !b->isStaticOrKinematicObject())
      find.unite(a->getIslandTag(), b->getIslandTag());
  };
  for (int i = 0; i < m_predictiveManifolds.size(); ++i)
    unite(m_predictiveManifolds[i]->getBody0(), m_predictiveManifolds[i]->getBody1());
  const int n = m_constraints.size();
  for (int i = 0; i < n; ++i) {
    if (i + 16 < n) fetchRange(m_constraints[i + 16], 0, 128);
    if (i + 8 < n) {
      fetch(&m_constraints[i + 8]->getRigidBodyA(), kIslandTag);
      fetch(&m_constraints[i + 8]->getRigidBodyB(), kIslandTag);
    }
    const btTypedConstraint* c = m_constraints[i];
    if (c->isEnabled()) unite(&c->getRigidBodyA(), &c->getRigidBodyB());
  }
  islands->storeIslandActivationState(this);
}

void SolverWorld::updateAabbs() {
  const int n = m_collisionObjects.size();
  if (getSoftBodyArray().size() > 0 || n < 4 * kChunk) return btSoftRigidDynamicsWorld::updateAabbs();
  BT_PROFILE("updateAabbs");
  // As btCollisionWorld::updateAabbs and updateSingleAabb: each object's box (on the threads,
  // where there are threads: it reads that object alone), then the boxes to the broadphase in
  // order, on this thread.
  if (m_boxes.size() < n) m_boxes.resize(n);
  const bool continuous = getDispatchInfo().m_useContinuous;
  const bool dbvt = dynamic_cast<btDbvtBroadphase*>(getBroadphase()) != nullptr;
  forEachIndex(m_boxPace, n, kChunk, [&](int i) {
    // The objects lie in order, their proxies and shapes anywhere: the object 16 ahead's poses
    // (its world and interpolated transforms), shape and activation, then the proxy and shape of
    // the one 8 ahead (with 10,000 modules, outside the caches).
    using namespace bullet_layout;
    if (i + 16 < n) fetchRange(m_collisionObjects[i + 16], 0, kActivation + 4);
    if (i + 8 < n) {
      const btCollisionObject* ahead = m_collisionObjects[i + 8];
      // (A tree's proxy: its box, then its leaf and stage links on the next line.)
      fetchRange(ahead->getBroadphaseHandle(), 0, dbvt ? int(sizeof(btDbvtProxy)) : 1);
      fetch(ahead->getCollisionShape(), 0);
      fetch(ahead->getCollisionShape(), 64);
    }
    const btCollisionObject* o = m_collisionObjects[i];
    Box& b = m_boxes[i];
    b.update = m_forceUpdateAllAabbs || o->isActive();
    if (!b.update) return;
    // What the broadphase's update will touch, to be fetched ahead (only ever prefetched: a
    // neighbour in its stage list may have changed by then).
    const auto* proxy = dbvt ? static_cast<const btDbvtProxy*>(o->getBroadphaseHandle()) : nullptr;
    b.touch[0] = o->getBroadphaseHandle();
    b.touch[1] = proxy ? proxy->leaf : nullptr;
    b.touch[2] = proxy ? proxy->links[0] : nullptr;
    b.touch[3] = proxy ? proxy->links[1] : nullptr;
    o->getCollisionShape()->getAabb(o->getWorldTransform(), b.min, b.max);
    const btVector3 threshold(gContactBreakingThreshold, gContactBreakingThreshold,
                              gContactBreakingThreshold);
    b.min -= threshold;
    b.max += threshold;
    if (continuous && o->getInternalType() == btCollisionObject::CO_RIGID_BODY &&
        !o->isStaticOrKinematicObject()) {
      btVector3 min2, max2;
      o->getCollisionShape()->getAabb(o->getInterpolationWorldTransform(), min2, max2);
      min2 -= threshold;
      max2 += threshold;
      b.min.setMin(min2);
      b.max.setMax(max2);
    }
  });
  btBroadphaseInterface* broadphase = getBroadphase();
  // The broadphase's proxies, tree leaves and stage lists lie all over memory, and each update
  // waits on them in turn (most of the 10 ms this pass took a substep at 10,000 modules): each
  // box's are fetched 8 boxes ahead.
  constexpr int kAhead = 8;
  for (int i = 0; i < n; ++i) {
    if (i + kAhead < n && m_boxes[i + kAhead].update)
      for (const void* p : m_boxes[i + kAhead].touch)
        if (p) __builtin_prefetch(p);
    const Box& b = m_boxes[i];
    if (!b.update) continue;
    btCollisionObject* o = m_collisionObjects[i];
    if (o->isStaticObject() || (b.max - b.min).length2() < btScalar(1e12))
      broadphase->setAabb(o->getBroadphaseHandle(), b.min, b.max, m_dispatcher1);
    else
      updateSingleAabb(o);  // Bullet's own handling of a box that overflowed
  }
}

int SolverWorld::stepSimulation(btScalar timeStep, int maxSubSteps, btScalar fixedTimeStep) {
  // One substep (a variable step: maxSubSteps 0) whose forces are cleared at its end, with
  // nothing that could read a body between the passes folded together.
  m_fused = maxSubSteps == 0 && !btFuzzyZero(timeStep) && getSoftBodyArray().size() == 0 &&
            m_actions.size() == 0 && !m_internalTickCallback && !m_internalPreTickCallback &&
            !m_synchronizeAllMotionStates && !m_applySpeculativeContactRestitution;
  m_gravityDue = false;
  const int substeps = btSoftRigidDynamicsWorld::stepSimulation(timeStep, maxSubSteps, fixedTimeStep);
  m_fused = false;
  return substeps;
}

void SolverWorld::saveKinematicState(btScalar timeStep) {
  // Fused: done body by body in predictUnconstraintMotion. Bullet walks every collision object
  // here, for a body flagged kinematic after it was added as a static one; RM3D makes no
  // kinematic bodies, and any other kinematic body is among the non-static ones.
  if (!m_fused) return btSoftRigidDynamicsWorld::saveKinematicState(timeStep);
  m_kinematicStep = timeStep;
}

void SolverWorld::applyGravity() {
  if (!m_fused) return btSoftRigidDynamicsWorld::applyGravity();
  m_gravityDue = true;  // body by body in predictUnconstraintMotion
}

void SolverWorld::updateActivationState(btScalar timeStep) {
  if (!m_fused) btSoftRigidDynamicsWorld::updateActivationState(timeStep);  // else in integrateTransforms
}

void SolverWorld::synchronizeMotionStates() {
  if (!m_fused) btSoftRigidDynamicsWorld::synchronizeMotionStates();  // else in integrateTransforms
}

void SolverWorld::clearForces() {
  if (!m_fused) btSoftRigidDynamicsWorld::clearForces();  // else in integrateTransforms
}

template <class Fn>
int SolverWorld::forEachBody(Pace& pace, const Fn& fn) {
  btRigidBody** bodies = m_nonStaticRigidBodies.size() ? &m_nonStaticRigidBodies[0] : nullptr;
  return forEachIndex(pace, m_nonStaticRigidBodies.size(), kChunk, [&](int i) { fn(bodies[i]); });
}

void SolverWorld::predictUnconstraintMotion(btScalar timeStep) {
  if (getSoftBodyArray().size() > 0) return btSoftRigidDynamicsWorld::predictUnconstraintMotion(timeStep);
  BT_PROFILE("predictUnconstraintMotion");
  // As btDiscreteDynamicsWorld::predictUnconstraintMotion, body by body; fused, after each
  // body's part of saveKinematicState and applyGravity.
  const bool fused = m_fused, gravity = m_gravityDue;
  const btScalar kinematicStep = m_kinematicStep;
  m_gravityDue = false;
  btRigidBody* const* bodies = m_nonStaticRigidBodies.size() ? &m_nonStaticRigidBodies[0] : nullptr;
  const int n = m_nonStaticRigidBodies.size();
  forEachIndex(m_predictPace, n, kChunk, [=](int i) {
    // The body 4 ahead, whole: this pass is the substep's first to reach each body, and with many
    // modules the bodies have left the caches since the last substep.
    if (i + 4 < n) bullet_layout::fetchRange(bodies[i + 4], 0, int(sizeof(btRigidBody)));
    btRigidBody* body = bodies[i];
    if (fused) {
      if (body->getActivationState() != ISLAND_SLEEPING && body->isKinematicObject())
        body->saveKinematicState(kinematicStep);
      if (gravity && body->isActive()) body->applyGravity();
    }
    if (body->isStaticOrKinematicObject()) return;
    body->applyDamping(timeStep);
    body->predictIntegratedTransform(timeStep, body->getInterpolationWorldTransform());
  });
}

void SolverWorld::integrateTransforms(btScalar timeStep) {
  m_threadedBodies = 0;
  if (getSoftBodyArray().size() > 0 || m_applySpeculativeContactRestitution)
    return btSoftRigidDynamicsWorld::integrateTransforms(timeStep);
  BT_PROFILE("integrateTransforms");
  // As btDiscreteDynamicsWorld::integrateTransformsInternal without its motion clamping, which
  // only bodies with a CCD motion threshold take (none here); fused, then each body's part of
  // updateActivationState, synchronizeMotionStates and clearForces.
  const bool fused = m_fused;
  const char* done = m_integrated.empty() ? nullptr : m_integrated.data();  // (finishBatch's)
  m_threadedBodies = forEachBody(m_integratePace, [=, this](btRigidBody* body) {
    if (!done || !done[body->getWorldArrayIndex()]) integrateBody(body, timeStep, fused);
  });
  m_integrated.clear();
}

void SolverWorld::integrateBody(btRigidBody* body, btScalar timeStep, bool fused) {
  body->setHitFraction(1.f);
  if (body->isActive() && !body->isStaticOrKinematicObject()) {
    btTransform predicted;
    body->predictIntegratedTransform(timeStep, predicted);
    body->proceedToTransform(predicted);
  }
  if (!fused) return;
  activation(body, timeStep);
  if (body->isActive()) synchronizeSingleMotionState(body);
  body->clearForces();
}

void SolverWorld::finishBatch(ExactSolver& s, btCollisionObject* const* bodies, int numBodies,
                              btScalar timeStep) {
  // The batch's contact anchors and poses are the solver's to note before its clusters move them;
  // a batch it does not take (a tree in halves) is left to the passes after the integration.
  if (!s.batchFinishable()) return;
  for (int i = 0; i < numBodies; ++i) {
    btRigidBody* body = btRigidBody::upcast(bodies[i]);
    if (!body || body->isStaticObject()) continue;
    integrateBody(body, timeStep, true);
    m_integrated[size_t(body->getWorldArrayIndex())] = 1;
  }
  s.finishBatch();
}

void SolverWorld::activation(btRigidBody* body, btScalar timeStep) {
  // As btDiscreteDynamicsWorld::updateActivationState, for one body.
  body->updateDeactivation(timeStep);
  if (body->wantsSleeping()) {
    if (body->isStaticOrKinematicObject()) {
      body->setActivationState(ISLAND_SLEEPING);
    } else {
      if (body->getActivationState() == ACTIVE_TAG) body->setActivationState(WANTS_DEACTIVATION);
      if (body->getActivationState() == ISLAND_SLEEPING) {
        body->setAngularVelocity(btVector3(0, 0, 0));
        body->setLinearVelocity(btVector3(0, 0, 0));
      }
    }
  } else if (body->getActivationState() != DISABLE_DEACTIVATION) {
    body->setActivationState(ACTIVE_TAG);
  }
}

void SolverWorld::setBatchSolvers(ExactSolver* primary, std::vector<ExactSolver*> helpers, Tasks tasks) {
  m_primary = primary;
  m_helpers = std::move(helpers);
  m_tasks = std::move(tasks);
}

void SolverWorld::solveBatches(btContactSolverInfo& info, int count) {
  // The patch table must not grow while solvers on other threads hold its entries.
  for (int i = 0; i < count; ++i) {
    const Batch& b = m_batches[size_t(i)];
    if (b.manifolds.size()) m_primary->claimPatchSlots(&b.manifolds[0], b.manifolds.size());
  }
  // Each thread's solver takes the batches of its own range first, then any left in the others'
  // (core/home_ranges.h: a batch goes to the same thread from one substep to the next while the
  // islands stay as they are). Which solver solves a batch changes nothing: each keeps only its own batches'
  // scratch, and shares the primary's state.
  btIDebugDraw* draw = getDebugDrawer();
  btDispatcher* dispatcher = getDispatcher();
  const bool finish = m_finisher && m_fused;
  if (finish) m_primary->sizePatchPoses();
  auto solve = [&](ExactSolver* s, int i) {
    Batch& b = m_batches[size_t(i)];
    s->solveGroup(b.bodies.size() ? &b.bodies[0] : nullptr, b.bodies.size(),
                  b.manifolds.size() ? &b.manifolds[0] : nullptr, b.manifolds.size(),
                  b.constraints.size() ? &b.constraints[0] : nullptr, b.constraints.size(), info, draw,
                  dispatcher);
    if (finish && b.bodies.size()) finishBatch(*s, &b.bodies[0], b.bodies.size(), info.m_timeStep);
  };
  if (count == 1) {
    // One batch (one island holds most of the world): a second thread takes the second half of
    // each long tree in it (ExactSolver::splitTree).
    if (m_batches[0].constraints.size() >= ExactSolver::kSplitJoints)
      m_primary->runWithHalfHelper(
          m_tasks, [&] { solve(m_primary, 0); }, ExactSolver::HalfSite::Solve);
    else
      solve(m_primary, 0);
    return;
  }
  // (Alone, the primary solves them all, in order: the same bits.)
  const int tasks = std::min(count, 1 + int(m_helpers.size()));
  runPaced(
      m_batchPace, m_alwaysThreads,
      [&] {
        m_homes.begin(count, tasks, 1);
        m_tasks(tasks, [&](int t) {
          ExactSolver* s = t == 0 ? m_primary : m_helpers[size_t(t - 1)];
          m_homes.run(t, [&](int b, int) { solve(s, b); });
        });
      },
      [&] {
        for (int i = 0; i < count; ++i) solve(m_primary, i);
      });
}

std::string fusedPassesMismatch() {
  struct Scene {
    btSoftBodyRigidBodyCollisionConfiguration config;
    btCollisionDispatcher dispatcher{&config};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    SolverWorld world{&dispatcher, &broadphase, &solver, &config};
    btStaticPlaneShape ground{btVector3(0, 0, 1), 0};
    btBoxShape box{btVector3(0.05f, 0.05f, 0.05f)};
    std::unique_ptr<btRigidBody> floor, resting, pushed, floating;
    Scene() {
      world.setGravity(btVector3(0, 0, -9.81f));
      floor = std::make_unique<btRigidBody>(0, nullptr, &ground);
      btVector3 inertia;
      box.calculateLocalInertia(1, inertia);
      auto make = [&](const btVector3& at) {
        btRigidBody::btRigidBodyConstructionInfo ci(1, nullptr, &box, inertia);
        ci.m_startWorldTransform.setOrigin(at);
        ci.m_linearDamping = 0.1f;
        ci.m_angularDamping = 0.2f;
        return std::make_unique<btRigidBody>(ci);
      };
      resting = make(btVector3(0, 0, 0.06f));
      pushed = make(btVector3(1, 0, 0.05f));
      pushed->setActivationState(DISABLE_DEACTIVATION);
      floating = make(btVector3(-1, 0, 1));
      floating->setFlags(BT_DISABLE_WORLD_GRAVITY);  // still: it falls asleep after 2 s
      for (btRigidBody* b : {floor.get(), resting.get(), pushed.get(), floating.get()}) world.addRigidBody(b);
    }
    ~Scene() {
      for (btRigidBody* b : {floating.get(), pushed.get(), resting.get(), floor.get()})
        world.removeRigidBody(b);
    }
  };
  Scene fused, apart;
  const btScalar h = btScalar(1) / 60;
  for (int step = 0; step < 240; ++step) {
    for (Scene* s : {&fused, &apart}) s->pushed->applyCentralForce(btVector3(8, 3, 0));
    fused.world.stepSimulation(h, 0, h);  // one substep a call: the passes fused
    apart.world.stepSimulation(h, 1, h);  // Bullet's fixed-step path: one substep, passes apart
  }
  // (Compared by value, x, y and z: a vector's fourth float is padding.)
  auto same3 = [](const btVector3& p, const btVector3& q) {
    return p.x() == q.x() && p.y() == q.y() && p.z() == q.z();
  };
  auto same = [&](const btTransform& p, const btTransform& q) {
    return same3(p.getOrigin(), q.getOrigin()) && same3(p.getBasis()[0], q.getBasis()[0]) &&
           same3(p.getBasis()[1], q.getBasis()[1]) && same3(p.getBasis()[2], q.getBasis()[2]);
  };
  const char* names[] = {"the resting box", "the pushed box", "the floating box"};
  const btRigidBody* f[] = {fused.resting.get(), fused.pushed.get(), fused.floating.get()};
  const btRigidBody* a[] = {apart.resting.get(), apart.pushed.get(), apart.floating.get()};
  for (int i = 0; i < 3; ++i) {
    if (!same(f[i]->getWorldTransform(), a[i]->getWorldTransform()))
      return std::string(names[i]) + ": its pose";
    if (!same3(f[i]->getLinearVelocity(), a[i]->getLinearVelocity()) ||
        !same3(f[i]->getAngularVelocity(), a[i]->getAngularVelocity()))
      return std::string(names[i]) + ": its velocity";
    if (f[i]->getActivationState() != a[i]->getActivationState())
      return std::string(names[i]) + ": its activation state";
  }
  // The check reaches every fused step only if a box fell asleep and the pushed one moved.
  if (fused.floating->getActivationState() != ISLAND_SLEEPING) return "the floating box never slept";
  if (fused.pushed->getWorldTransform().getOrigin().x() < 2) return "the pushed box did not move";
  return "";
}

}  // namespace rm3d
