// A module in a running world: its bodies and hinges in the physics, joint commands, dock
// states, sensor caches, log and random stream. The World owns these records; the step's
// subsystems (behaviours, messaging, docking) read and write them in their phases.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "core/trace_series.h"
#include "core/types.h"
#include "docking/dock_event.h"
#include "messaging/value.h"
#include "modules/module_type.h"
#include "physics/physics_world.h"

namespace rm3d {

enum class JointMode : uint8_t { Off, Servo, Velocity };

struct JointCommand {
  JointMode mode = JointMode::Servo;  ///< a powered module holds its pose
  double value = 0;
};

struct DockState {
  bool latchable = true;  ///< false after an injected fault: the dock no longer latches
  bool enabled = true;
  bool engaged = false;
  int peerModule = -1;
  int peerDock = -1;
  /// After a break, the dock ignores that peer until the two faces are farther apart than the
  /// capture radius (else the magnet would latch the broken pair again at once).
  int brokeFromModule = -1;
  int brokeFromDock = -1;
};

/// One sensor reading, as the behaviour sees it before percepts.
struct SensorReading {
  enum class Kind : uint8_t { Nil, Number, Vector, Quaternion, Boolean, Dock } kind = Kind::Nil;
  double v[4] = {0, 0, 0, 0};
  bool flag = false;        ///< Boolean; Dock: enabled
  bool engaged = false;     ///< Dock
  double proximity = -1;    ///< Dock: distance to the nearest free partner, < 0: none
  bool hasBearing = false;  ///< Dock: v[0..2] is the unit direction to it, in the dock's frame
};

/// module.publish limits: distinct keys per module, and bytes per value (as a message payload).
constexpr size_t kMaxPublishedKeys = 256;
constexpr size_t kMaxPublishedBytes = 64 * 1024;

struct Module {
  int id = 0;
  std::string name;
  const ModuleTypeDef* type = nullptr;
  std::vector<int> parts;   ///< physics part per link
  std::vector<int> hinges;  ///< physics hinge per joint
  std::vector<JointCommand> commands;
  std::vector<DockState> docks;
  /// dock:enable()/disable() during the behaviour phase, applied after it in module order:
  /// per dock -1 (none), 0 (disable) or 1 (enable).
  std::vector<int8_t> dockRequests;
  bool hasDockRequests = false;
  std::string behaviourFile;  ///< absolute, empty: none
  Value params;
  Rng rng;
  uint64_t rngStream = 0;  ///< the stream `rng` was seeded with; sim.stream(key) derives from it
  std::string fault;       ///< empty: healthy
  bool faultReported = false;
  bool fixed = false;  ///< root link held in place (a base)
  /// on_dock events for the module's next step: (dock, what happened).
  std::vector<std::pair<int, DockEventKind>> dockEvents;
  /// Sensors by code (joints, then docks, then the type's sensors): per-step cache and faults.
  std::vector<std::pair<int64_t, SensorReading>> sensorCache;
  std::vector<char> deadSensors;
  std::vector<Vec3> accelPrevVel, accelWorld;  ///< per type sensor (accelerometers)
  bool accelInUse = false;                     ///< an accelerometer has been read
  int64_t accelSteps = 0;                      ///< steps tracked since
  std::vector<char> stalled;                   ///< per joint: an injected stall
  std::vector<double> stallAngle;
  std::vector<std::string> log;            ///< lines written this step, flushed in id order
  std::deque<std::string> recentLog;       ///< with keepHistory: the last 20 lines ("t: text")
  std::deque<std::string> recentMessages;  ///< with keepHistory: the last 20 messages read
  TraceSeries traces;                      ///< module.trace(name, value) series
  /// module.publish(key, value): the latest value per key, in order of first use, for the world
  /// script (m:published); written only by the module's own behaviour during the phase.
  std::vector<std::pair<std::string, Value>> published;
};
/// A link's pose in the world.
inline Pose linkPose(const PhysicsWorld& physics, const Module& m, int link) {
  return physics.partPose(m.parts[size_t(link)]);
}
/// A dock's frame in the world (x out of the face, z its "up").
inline Pose dockPose(const PhysicsWorld& physics, const Module& m, int dock) {
  const DockDef& d = m.type->docks[size_t(dock)];
  return linkPose(physics, m, d.link) * d.frame;
}

}  // namespace rm3d
