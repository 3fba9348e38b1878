// Docking (docs/architecture.md, the step: 4, 5 and 7): the connection graph, run-time latching by magnet,
// undocking, initial connections from world scripts, and breakage from measured loads.
//
// Docked links are locked into one rigid body in the physics (PhysicsWorld::lockParts), so a
// dock has no gap or twist; releasing splits the body again by the remaining locks.
#pragma once

#include <cstdint>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/pace.h"
#include "core/types.h"
#include "docking/dock_event.h"
#include "modules/module.h"
#include "physics/physics_world.h"

namespace rm3d {

struct Connection {
  int moduleA, dockA, moduleB, dockB;
  double time = 0;  ///< when it was made
  /// Cache for load measurement: the parts on B's side, valid for topology version `sideOf`.
  mutable std::vector<int> side;
  mutable uint64_t sideOf = 0;
};

struct DockEvent {
  double time;
  DockEventKind kind = DockEventKind::Engaged;
  int moduleA, dockA, moduleB, dockB;
  double force = -1, torque = -1;  ///< measured load for Broken (N, N m), else -1
  double gap = -1, angle = -1;     ///< what a Stalled capture has left to close (m, rad), else -1
};

/// A pair of docks a capture joint is drawing together (Docking::dock).
struct Capture {
  int a, da, b, db;      ///< a < b
  int id = -1;           ///< the physics' capture joint
  double start = 0;      ///< when it began
  bool stalled = false;  ///< reported as stalled
};

/// What docking works on: the World's modules and physics, and the clock.
struct DockingScene {
  std::vector<Module>& modules;
  PhysicsWorld& physics;
  double time;
  bool started;  ///< behaviours hear on_dock events only once the run has started
  /// The world's worker threads (null: none). Docking hands them only work whose result does not
  /// depend on which thread does which piece: the free docks' poses, the search for pairs within
  /// reach, and the connections' loads.
  const PhysicsWorld::ForEach* tasks = nullptr;
  bool alwaysThreads = false;  ///< on the threads wherever they may go (tests: core/pace.h)
};

/// The modules connected to module m through engaged docks (m first).
std::vector<int> componentOf(const std::vector<Module>& modules, int m);

class Docking {
 public:
  const std::vector<Connection>& connections() const { return m_connections; }
  const std::vector<DockEvent>& events() const { return m_events; }
  /// The largest capture radius of the types in use (the dock hash's cell size).
  void setCaptureCell(double radius) { m_captureCell = radius; }

  /// world.connect: places b's side so the docks mate (unless they face each other already, as
  /// when closing a loop) and locks them. Throws InputError (without location).
  void connect(const DockingScene& s, int a, int dockA, int b, int dockB, int orientation);
  /// Releases the connection at module m's dock. False if none.
  bool disconnect(const DockingScene& s, int m, int dock);

  /// Step 4: connections where either dock is now disabled are released.
  void undock(const DockingScene& s);
  /// Step 5: free compatible docks within reach attract (the magnet); aligned ones latch.
  void dock(const DockingScene& s);
  /// Step 7: connections whose transmitted load exceeds the docks' strength break.
  void breakage(const DockingScene& s);
  /// Load through a connection during the last step (force N, torque N m about the dock face).
  Wrench connectionLoad(const std::vector<Module>& modules, const PhysicsWorld& physics,
                        const Connection& c) const;

  /// Blocks of docking's work that ran on the threads, since the start (tests).
  long threadedBlocks() const { return m_threadedBlocks; }

  /// The captures in progress (joint mode), by (a, da, b, db).
  const std::vector<Capture>& captures() const { return m_captures; }
  /// Drops every capture (the physics world is going away or being rebuilt).
  void dropCaptures(const DockingScene& s);

  /// Docks released since the last call, (module, dock): the messages in flight there are lost.
  std::vector<std::pair<int, int>>& released() { return m_released; }

 private:
  /// Locks two docks: optionally moves b's component so the faces mate exactly first (or, with
  /// `split`, both components, each by its share: the pair's centre of mass stays put).
  void lock(const DockingScene& s, int a, int da, int b, int db, int orientation, bool snap,
            bool split = false);
  /// The capture joints: starts, ends, latches and stall reports for this step's candidates.
  void updateCaptures(const DockingScene& s);
  void release(const DockingScene& s, size_t connection, DockEventKind kind, double force, double torque);
  int bestOrientation(const DockingScene& s, int a, int da, int b, int db) const;
  /// fn(block, begin, end) for each block of `size` of the indices [0, n): on the scene's threads
  /// where the clock says they pay (`pace`), else here in order. Each block must write only its
  /// own results.
  template <class Fn>
  void inBlocks(const DockingScene& s, Pace& pace, int n, int size, const Fn& fn);
  /// The free docks of m_dockBoxes[k]'s module, posed into their places from m_boxFirst[k].
  void poseFreeDocks(const DockingScene& s, size_t k);
  /// m_freeDocks[i]'s pairs within the capture limits with the free docks after it, into `out`.
  struct Hit;
  void findPairs(const DockingScene& s, int i, double cell, std::vector<Hit>& out) const;

  std::vector<Connection> m_connections;
  std::vector<DockEvent> m_events;
  std::vector<std::pair<int, int>> m_released;
  uint64_t m_topology = 1;  ///< bumped whenever a lock is made or released
  double m_captureCell = 0.03;
  // Reused every step by the dock phase (no allocation once warm).
  struct FreeDock {
    int module, dock;
    Pose pose;
    const DockDef* def;  ///< its type's dock (findPairs reads it for every dock it meets)
  };
  std::vector<FreeDock> m_freeDocks;
  struct DockBox {
    Vec3 lo, hi;  ///< where a module's docks can reach
    size_t module;
    bool near;
  };
  std::vector<DockBox> m_dockBoxes;  ///< in module order
  /// By module: whether it has a free dock and, if so, where its root link is (the coarse pass's
  /// first part, made in blocks).
  struct ModuleRoot {
    Vec3 at;
    bool free;
  };
  std::vector<ModuleRoot> m_roots;
  struct SweepEnd {
    double x;      ///< a box's lower x end
    int32_t row;   ///< its band along y (the coarse pass)
    uint32_t box;  ///< its index in m_dockBoxes
  };
  std::vector<SweepEnd> m_sweep;     ///< the boxes by band, then lower x end
  std::vector<uint64_t> m_cellKeys;  ///< dock hash: slot -> cell key
  std::vector<int> m_cellHead;       ///< slot -> first dock in the cell, or -1
  std::vector<int> m_cellNext;       ///< dock -> next dock in its cell, or -1
  std::vector<uint64_t> m_cellBits;  ///< a bit per hash of an occupied cell's key (cellBit)
  std::vector<size_t> m_boxFirst;    ///< box -> its module's first free dock in m_freeDocks
  /// Two free docks within each other's capture limits (findPairs): m_freeDocks[i] and [e], e > i.
  struct Hit {
    int i, e;
    Vec3 gapVec;  ///< e's face from i's
    double gap, facing;
    Vec3 na, nb;  ///< the faces' normals
  };
  std::vector<std::vector<Hit>> m_hits;  ///< by block of free docks, in dock order
  std::vector<Wrench> m_loads;           ///< by connection (breakage)
  Pace m_rootPace, m_posePace, m_pairPace, m_loadPace;
  long m_threadedBlocks = 0;
  struct Latch {
    int a, da, b, db;
    bool split = false;  ///< a capture joint's latch: the last correction is shared
    bool operator<(const Latch& o) const { return std::tie(a, da, b, db) < std::tie(o.a, o.da, o.b, o.db); }
  };
  std::vector<Latch> m_latches;
  /// Pairs inside the capture limits this step whose docks both capture by joint.
  struct Candidate {
    int a, da, b, db;  ///< a < b
    double gap, facing, twist;
    bool operator<(const Candidate& o) const {
      return std::tie(a, da, b, db) < std::tie(o.a, o.da, o.b, o.db);
    }
  };
  std::vector<Candidate> m_candidates;
  std::vector<Capture> m_captures;  ///< sorted by (a, da, b, db)
  std::vector<Capture> m_nextCaptures;
};

}  // namespace rm3d
