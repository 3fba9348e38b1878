// What a behaviour may touch while the behaviour phase runs (docs/architecture.md, the step: 2).
//
// Behaviours run in parallel on worker threads, so their bindings never see a writable World.
// Each behaviour VM holds a ModuleHandle, and the rule of the phase is what its type allows:
//   - writes go only to the module's own records: its Module (joint commands, queued dock
//     requests, log lines, random stream, sensor cache, published values) and its Mailbox (the
//     outbox it fills, the inbox it consumes);
//   - everything else is read through `const World&`, and all of it is frozen for the phase:
//     dock states change only after the phase, when World::applyDockRequests() applies the queued
//     requests in module order; the dock-proximity index is built before the phase; physics is
//     not stepped until every behaviour has returned;
//   - the one shared structure a read touches, Bullet's ray-test stack, is serialised inside
//     PhysicsWorld::rayCast.
// So a run is bit-identical whatever the thread count or the order the pool hands modules out.
#pragma once

#include "world/world.h"

namespace rm3d {

class ModuleHandle {
 public:
  ModuleHandle(World& world, int index) : m_world(&world), m_index(index) {}

  int index() const { return m_index; }
  /// The module's own record (written only by its own behaviour during the phase).
  Module& self() const { return m_world->m_modules[size_t(m_index)]; }
  /// The module's own mailbox.
  Mailbox& mailbox() const { return m_world->m_mailboxes[size_t(m_index)]; }
  /// Everything else, read-only.
  const World& world() const { return *m_world; }
  /// A sensor of this module, computed on first read this step and cached in its own record.
  SensorReading readSensor(int code, bool velocity = false) const {
    return m_world->readSensor(self(), m_index, code, velocity);
  }

 private:
  World* m_world;
  int m_index;
};

}  // namespace rm3d
