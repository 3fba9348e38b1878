// The World owns everything of one simulation: physics, module types, modules and their Lua
// VMs, mailboxes, the connection graph, the world script's VM, RNG and clock. Several worlds
// can live in one process. The step follows DESIGN.md's order (see World::step).
#pragma once

#include <cstdint>
#include <atomic>
#include <deque>
#include <map>
#include <mutex>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/rng.h"
#include "core/types.h"
#include "messaging/mailbox.h"
#include "modules/module_type.h"
#include "physics/physics_world.h"
#include "script/lua_value.h"
#include "world/divergence.h"

namespace rm3d {

class Behaviour;
class WorldScript;
class BehaviourPool;
class ModuleHandle;
class Watchdog;

/// How to run: what the command line or a test gives.
struct RunOptions {
  std::string projectRoot;                    ///< absolute; lua/, behaviors/, assets/ live here
  std::map<std::string, std::string> params;  ///< --param key=value, seen as `args`
  std::optional<uint64_t> seed;               ///< overrides world.set{seed=}
  bool strict = false;                        ///< a module fault stops the run
  int threads = 1;                            ///< behaviour worker threads
  int chunkSize = 16;                         ///< modules a worker takes at a time (tests use 1)
  size_t vmMemoryLimit = 32u << 20;           ///< bytes per behaviour VM
  int64_t behaviourBudget = 10'000'000;      ///< Lua instructions per callback
  int64_t worldBudget = 500'000'000;          ///< for the world script and its hooks
  size_t worldMemoryLimit = 256u << 20;       ///< bytes for the world VM
  size_t mailboxLimit = 8u << 20;             ///< bytes of unread messages per module; more are dropped
  double watchdogSeconds = 5;                 ///< wall-clock limit on one call into a VM (0: none)
  bool echoLog = true;                        ///< print module log lines to stderr
  bool keepHistory = false;                   ///< keep recent log lines and messages per module (viewer)
};

/// world.set{...}: fixed before the first step.
struct WorldSettings {
  double dt = 1.0 / 60.0;
  int substeps = 4;
  int solverIterations = 30;
  int jointIterations = 0;
  double erp = 0.8;
  Vec3 gravity = Vec3(0, 0, -9.81);
  uint64_t seed = 1;
  double duration = 10.0;
  DivergenceLimits limits;  ///< max_speed, max_angular_speed, bounds (world/divergence.h)
};

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
  bool flag = false;                     ///< Boolean; Dock: enabled
  bool engaged = false;                  ///< Dock
  double proximity = -1;                 ///< Dock: distance to the nearest free partner, < 0: none
};

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
  LuaValue params;
  Rng rng;
  std::string fault;  ///< empty: healthy
  bool faultReported = false;
  bool fixed = false;  ///< root link held in place (a base)
  /// on_dock events for the module's next step: (dock, "engaged" | "disengaged" | "broken").
  std::vector<std::pair<int, const char*>> dockEvents;
  /// Sensors by code (joints, then docks, then the type's sensors): per-step cache and faults.
  std::vector<std::pair<int64_t, SensorReading>> sensorCache;
  std::vector<char> deadSensors;
  std::vector<Vec3> accelPrevVel, accelWorld;  ///< per type sensor (accelerometers)
  bool accelInUse = false;                     ///< an accelerometer has been read
  int64_t accelSteps = 0;                      ///< steps tracked since
  std::vector<char> stalled;                   ///< per joint: an injected stall
  std::vector<double> stallAngle;
  std::vector<std::string> log;  ///< lines written this step, flushed in id order
  std::deque<std::string> recentLog;       ///< with keepHistory: the last 20 lines ("t: text")
  std::deque<std::string> recentMessages;  ///< with keepHistory: the last 20 messages read
};

struct Connection {
  int moduleA, dockA, moduleB, dockB;
  double time = 0;  ///< when it was made
  /// Cache for load measurement: the parts on B's side, valid for topology version `sideOf`.
  mutable std::vector<int> side;
  mutable uint64_t sideOf = 0;
};

struct DockEvent {
  double time;
  std::string kind;  ///< "engaged", "disengaged", "broken"
  int moduleA, dockA, moduleB, dockB;
  double force = -1, torque = -1;  ///< measured load for "broken" (N, N m), else -1
};

/// world.channel{...}: how messages travel over a connection (seeded, deterministic).
struct ChannelDef {
  double loss = 0;           ///< probability that a message is lost
  int delay = 0;             ///< extra steps in flight (a message sent at t is read at t+1+delay)
  int rate = 0;              ///< messages per step per dock (0: unlimited); the rest wait their turn
  size_t maxBytes = 65536;   ///< payload size limit
};

struct Failure {
  double time;
  std::string message;
};

/// Joint and dock fidelity figures (bench and tests).
struct Quality {
  double hingeGapMm = 0, hingeAngleDeg = 0;
  double dockGapMm = 0, dockAngleDeg = 0;
  double trackingRmsDeg = 0;
};

class World {
 public:
  explicit World(RunOptions options);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Runs a world script (throws InputError for bad input: the message names file and line).
  void loadFile(const std::string& path);
  /// Runs world-script source held in memory; `chunkName` is what messages call it.
  void loadString(const std::string& source, const std::string& chunkName = "world");
  /// Calls init() of every behaviour. Done by the first step() if not called.
  void start();
  /// One control step of settings().dt (DESIGN.md's seven phases, then world hooks).
  void step();
  /// True after world.stop(), a world-script error, a fatal fault, or the duration.
  bool finished() const;
  /// True after world.stop(), a world-script error or a fatal fault (not the duration).
  bool stopped() const { return m_stopRequested || m_fatal || !m_scriptError.empty(); }

  // --- state ---
  double time() const { return m_time; }
  int64_t steps() const { return m_steps; }
  const WorldSettings& settings() const { return m_settings; }
  const RunOptions& options() const { return m_options; }
  /// Limits calls into this world's VMs to watchdogSeconds (nullptr when off).
  Watchdog* watchdog() const { return m_watchdog.get(); }
  const std::vector<Module>& modules() const { return m_modules; }
  const Module& module(int i) const { return m_modules[size_t(i)]; }
  const std::vector<Failure>& failures() const { return m_failures; }
  const std::vector<DockEvent>& events() const { return m_events; }
  const std::vector<Connection>& connections() const { return m_connections; }
  /// A world-script error (bad input at run time), or empty.
  const std::string& scriptError() const { return m_scriptError; }
  bool fatalFault() const { return m_fatal; }
  /// Why the physics diverged (a fatal stop: world/divergence.h), or empty.
  const std::string& divergence() const { return m_divergence; }
  int faultCount() const;
  std::string worldFile() const { return m_worldFile; }
  WorldScript* script() const { return m_script.get(); }  ///< null before a world is loaded
  void setScriptError(const std::string& e) { if (m_scriptError.empty()) m_scriptError = e; }

  Pose modulePose(int m) const;
  Pose linkPose(int m, int link) const;
  Pose dockPose(int m, int dock) const;  ///< dock frame in the world
  double jointAngle(int m, int joint) const;
  double jointVelocity(int m, int joint) const;
  Quality quality() const;
  /// Adds this step's servo tracking error to the running RMS that quality() reports.
  void sampleTracking();
  /// Connected components (module indices, each sorted), by the connection graph.
  std::vector<std::vector<int>> components() const;
  nlohmann::json summary(double wallSeconds) const;
  /// Phase timings of the last step, ms.
  struct StepTimes {
    double behaviours = 0, physics = 0, other = 0;
  };
  const StepTimes& lastStepTimes() const { return m_times; }
  PhysicsWorld& physics() { return *m_physics; }
  const PhysicsWorld& physicsConst() const { return *m_physics; }

  // --- building (world scripts, tests) ---
  void setSettings(const WorldSettings& s);
  void addGround(double friction, double restitution);
  int addObstacle(const ShapeDef& shape, const Pose& pose, double mass, double friction);
  struct Obstacle {
    int part;
    ShapeDef shape;
    double mass;
  };
  const std::vector<Obstacle>& obstacles() const { return m_obstacles; }
  /// world.camera{...}: where pictures are taken from.
  struct CameraDef {
    std::optional<Vec3> eye, target;  ///< with `follow`, eye is an offset from the module
    int follow = -1;                  ///< module index, or -1
    double fovDeg = 45;
  };
  const CameraDef& camera() const { return m_camera; }
  bool hasGround() const { return m_groundAdded; }
  void setCamera(const CameraDef& c) { m_camera = c; }
  Pose obstaclePose(int body) const;
  Vec3 obstacleVelocity(int body) const;
  const ModuleTypeDef& moduleType(const std::string& name);
  struct SpawnDef {
    std::string type;
    Pose pose;
    std::string name;
    std::string behaviour;  ///< path as written; resolved against the world's folder, then root
    LuaValue params;
    bool fixed = false;     ///< the root link does not move
  };
  /// Throws InputError (without location: the caller adds it).
  int spawn(const SpawnDef& def);
  void connect(int a, int dockA, int b, int dockB, int orientation);
  /// Releases the connection at module m's dock (as if a dock were disabled). False if none.
  bool disconnect(int m, int dock);
  void setChannel(const ChannelDef& c) { m_channel = c; }
  const ChannelDef& channel() const { return m_channel; }
  /// The connection graph now, as JSON ({"modules": [...], "connections": [...]}) or Graphviz DOT.
  std::string graphJson() const;
  std::string graphDot() const;
  /// Load through a connection during the last step (force N, torque N m about the dock face).
  Wrench connectionLoad(const Connection& c) const;
  /// Messages counted over the run: sent, delivered (read), lost in flight.
  struct MessageStats {
    size_t sent = 0, received = 0, dropped = 0;
  };
  MessageStats messageStats() const;
  void addFailure(const std::string& message);
  void requestStop() { m_stopRequested = true; }
  /// Resolves a path from a world script: the world's folder first, then the project root.
  std::string resolvePath(const std::string& path) const;

  // --- hot reload ---
  /// Files whose edits should reach the run: behaviour files in use, lua/*.lua, the world file.
  std::vector<std::string> watchedFiles() const;
  /// Reloads a changed behaviour (or, for a lua/ file, every behaviour) into every module running
  /// it. Returns how many modules took the new code; errors (file:line) go to `errors`, and
  /// those modules keep their old code. A module that had faulted runs again once its
  /// behaviour reloads cleanly.
  int reloadFile(const std::string& path, std::vector<std::string>& errors);
  /// The module's declared percepts and their last values, one "name = value" per line (viewer).
  std::string describePercepts(int module);

  // --- sensors (module.sensor, percepts) ---
  /// Sensor code for a name ("joint:pitch", "dock:front", "accelerometer", ...), or -1.
  int sensorCode(int module, const std::string& name) const;
  std::string sensorNames(int module) const;
  /// The reading this step (computed on first use, cached for the step). `velocity` reads a
  /// joint's speed instead of its angle (not cached). Main thread; behaviours read through
  /// their ModuleHandle.
  SensorReading readSensor(int module, int code, bool velocity = false) {
    return readSensor(m_modules[size_t(module)], module, code, velocity);
  }
  /// World-script fault injection: a joint stalls where it is, a dock stops latching, a sensor
  /// reads nil from now on.
  void stallJoint(int module, int joint);
  void blockDock(int module, int dock);
  void killSensor(int module, int code);

  /// A module's record, writable: main thread only (world scripts, tests). Behaviours get a
  /// ModuleHandle instead (world/module_handle.h).
  Module& mutableModule(int i) { return m_modules[size_t(i)]; }
  void faultModule(int i, const std::string& message);

 private:
  friend class BehaviourPool;
  friend class ModuleHandle;
  /// Reads a sensor of module `mi` whose record is `self`; writes only `self` (its cache), so
  /// behaviours may call it in parallel during their phase.
  SensorReading readSensor(Module& self, int mi, int code, bool velocity) const;
  /// Applies the dock:enable()/disable() calls queued during the behaviour phase, in module order.
  void applyDockRequests();
  void ensurePhysics();
  void runBehaviours();
  void reportModuleOutput();
  void runBehaviour(int i);
  void routeMessages();
  void undockPhase();
  void dockPhase();
  void breakagePhase();
  void applyActuators();
  /// Locks two docks: optionally moves b's component so the faces mate exactly first.
  void lock(int a, int da, int b, int db, int orientation, bool snap);
  void release(size_t connection, const char* kind, double force, double torque);
  int bestOrientation(int a, int da, int b, int db) const;
  std::vector<int> componentOf(int m) const;

  RunOptions m_options;
  std::unique_ptr<Watchdog> m_watchdog;  ///< outlives the VMs (declared before them)
  WorldSettings m_settings;
  std::string m_worldFile;
  std::unique_ptr<PhysicsWorld> m_physics;
  std::map<std::string, std::unique_ptr<ModuleTypeDef>> m_types;
  std::vector<Module> m_modules;
  std::vector<std::unique_ptr<Behaviour>> m_behaviours;  ///< one VM per module (null: none)
  std::vector<Mailbox> m_mailboxes;
  std::vector<Connection> m_connections;
  std::vector<DockEvent> m_events;
  std::vector<Failure> m_failures;
  std::vector<Obstacle> m_obstacles;
  CameraDef m_camera;
  ChannelDef m_channel;
  Rng m_channelRng;
  size_t m_lostMessages = 0;
  std::vector<int> m_dockSent;  ///< per dock, this step (channel rate)
  /// Reused every step by the dock phase (no allocation once warm).
  struct FreeDock {
    int module, dock;
    Pose pose;
  };
  std::vector<FreeDock> m_freeDocks;
  struct DockBox {
    Vec3 lo, hi;  ///< where a module's docks can reach
    size_t module;
    bool near;
  };
  std::vector<DockBox> m_dockBoxes;
  std::vector<uint64_t> m_cellKeys;  ///< dock hash: slot -> cell key
  std::vector<int> m_cellHead;       ///< slot -> first dock in the cell, or -1
  std::vector<int> m_cellNext;       ///< dock -> next dock in its cell, or -1
  std::vector<Pose> m_linkPoses;     ///< one module's link poses, computed once per step
  std::vector<char> m_linkPoseValid;
  struct Latch {
    int a, da, b, db;
    bool operator<(const Latch& o) const {
      return std::tie(a, da, b, db) < std::tie(o.a, o.da, o.b, o.db);
    }
  };
  std::vector<Latch> m_latches;
  double m_captureCell = 0.03;
  uint64_t m_topology = 1;  ///< bumped whenever a lock is made or released
  // Dock proximity (dock sensors): free docks sorted by x. Built before the behaviour phase once
  // any dock sensor has been read (the first read builds it under the mutex: dock states are
  // frozen during the phase, so either way every reader sees the same index).
  mutable std::mutex m_proximityMutex;
  mutable std::atomic<int64_t> m_proximityStep{-1};
  mutable std::atomic<bool> m_proximityWanted{false};
  mutable std::vector<FreeDock> m_proximityDocks;
  void buildProximity() const;
  void updateAccelerometers();
  bool m_contactSensors = false;
  std::unique_ptr<WorldScript> m_script;
  std::unique_ptr<BehaviourPool> m_pool;
  bool m_groundAdded = false;
  double m_groundFriction = 0.8, m_groundRestitution = 0;
  bool m_started = false;
  bool m_stopRequested = false;
  bool m_fatal = false;
  std::string m_scriptError;
  std::string m_divergence;
  double m_time = 0;
  int64_t m_steps = 0;
  double m_trackingSum = 0;
  int64_t m_trackingCount = 0;
  StepTimes m_times;
};

}  // namespace rm3d
