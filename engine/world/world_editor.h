// What a world script may do to its World: build it (ground, obstacles, modules, connections,
// cloth, particles), set it up, push and pin things, inject faults, report results. Main thread
// only, between steps. The world-script bindings (script/world_*.cpp) hold a WorldEditor for
// these and a `const World&` for everything they read, so the script layer never reaches the
// physics or a module's record directly (World::physics() and mutableModule() are private).
#pragma once

#include <array>
#include <string>

#include "world/world.h"

namespace rm3d {

class WorldEditor {
 public:
  explicit WorldEditor(World& world) : m_world(world) {}
  const World& view() const { return m_world; }

  // --- building ---
  void setSettings(const WorldSettings& s) { m_world.setSettings(s); }
  void addGround(double friction, double restitution) { m_world.addGround(friction, restitution); }
  int addObstacle(const ShapeDef& shape, const Pose& pose, double mass, double friction,
                  double rollingFriction = 0) {
    return m_world.addObstacle(shape, pose, mass, friction, rollingFriction);
  }
  int addCloth(const ClothDesc& desc, const std::array<float, 4>& color) {
    return m_world.addCloth(desc, color);
  }
  int addParticles(const ParticleDef& def) { return m_world.addParticles(def); }
  void chargeBudget(double bytes, const std::string& what) { m_world.chargeBudget(bytes, what); }
  const ModuleTypeDef& moduleType(const std::string& name) { return m_world.moduleType(name); }
  int spawn(const World::SpawnDef& def) { return m_world.spawn(def); }
  void connect(int a, int dockA, int b, int dockB, int orientation) {
    m_world.connect(a, dockA, b, dockB, orientation);
  }
  double placeOnGround(int m, double z) { return m_world.placeOnGround(m, z); }
  void placeFacing(int a, int dockA, int b, int dockB, double gap, int orientation) {
    m_world.placeFacing(a, dockA, b, dockB, gap, orientation);
  }
  void setDockSettings(const DockSettings& s) { m_world.setDockSettings(s); }
  void setCamera(const World::CameraDef& c) { m_world.setCamera(c); }
  void setChannel(const ChannelDef& c) { m_world.setChannel(c); }

  // --- while running ---
  /// Sets an obstacle's (or any part's) linear velocity.
  void setPartVelocity(int part, const Vec3& v) { m_world.m_physics->setPartVelocity(part, v); }
  /// A force (N) on a module's root link at its centre, for the next step.
  void pushModule(int m, const Vec3& force) {
    const Module& mod = m_world.module(m);
    const int part = mod.parts[size_t(mod.type->rootLink)];
    m_world.m_physics->addForce(part, force, m_world.m_physics->partPose(part).pos);
  }
  /// A torque (N m) on a module's root link, for the next step.
  void twistModule(int m, const Vec3& torque) {
    const Module& mod = m_world.module(m);
    m_world.m_physics->addTorque(mod.parts[size_t(mod.type->rootLink)], torque);
  }
  void setClothNodePinned(int cloth, int node, bool pinned) {
    m_world.m_physics->setClothNodePinned(cloth, node, pinned);
  }
  /// Enables or disables a dock (as the module's own dock:enable()/disable(), applied now).
  void setDockEnabled(int m, int dock, bool on) {
    m_world.m_modules[size_t(m)].docks[size_t(dock)].enabled = on;
  }
  /// A sensor reading for the world script (cached per step like a behaviour's).
  SensorReading readSensor(int m, int code, bool velocity = false) {
    return m_world.readSensor(m, code, velocity);
  }
  void stallJoint(int m, int joint) { m_world.stallJoint(m, joint); }
  void blockDock(int m, int dock) { m_world.blockDock(m, dock); }
  void killSensor(int m, int code) { m_world.killSensor(m, code); }

  // --- results ---
  void setMetric(const std::string& name, double value) { m_world.setMetric(name, value); }
  TraceSeries& worldTraces() { return m_world.worldTraces(); }
  void addFailure(const std::string& message) { m_world.addFailure(message); }
  void requestStop() { m_world.requestStop(); }

 private:
  World& m_world;
};

}  // namespace rm3d
