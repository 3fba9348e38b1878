// The World owns everything of one simulation: physics, module types, modules and their
// programs (behaviour VMs), mailboxes and routing, docking and the connection graph, the world
// script, RNG and clock. Several worlds can live in one process. World::step is the list of
// the step's phases (docs/architecture.md); each phase's work lives in its subsystem (messaging/, docking/,
// physics/), and the scripts are reached through world/programs.h, so nothing here includes Lua.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "core/pace.h"
#include "core/rng.h"
#include "core/trace_series.h"
#include "core/types.h"
#include "docking/docking.h"
#include "messaging/mailbox.h"
#include "messaging/router.h"
#include "messaging/value.h"
#include "modules/module.h"
#include "modules/module_type.h"
#include "particles/particle_system.h"
#include "physics/physics_world.h"
#include "world/divergence.h"
#include "world/programs.h"

namespace rm3d {

class WorldScript;
class BehaviourPool;
class ModuleHandle;
class SourceFiles;
class MeshCache;

/// How to run: what the command line or a test gives.
struct RunOptions {
  std::string projectRoot;                    ///< absolute; lua/, behaviors/, assets/ live here
  std::map<std::string, std::string> params;  ///< --param key=value, seen as `args`
  std::optional<uint64_t> seed;               ///< overrides world.set{seed=}
  bool strict = false;                        ///< a module fault stops the run
  int threads = 1;                            ///< behaviour worker threads
  int chunkSize = 16;                         ///< modules a worker takes at a time (tests use 1)
  bool wholeFactors = false;                  ///< tests: PhysicsSettings::wholeFactors
  bool freshTrees = false;                    ///< tests: PhysicsSettings::freshTrees
  bool everyIteration = false;                ///< tests: PhysicsSettings::everyIteration
  bool denseIslands = true;                   ///< tests: PhysicsSettings::denseIslands
  int denseCoordinates = 60;                  ///< tests: PhysicsSettings::denseCoordinates
  bool avx = true;                            ///< tests: PhysicsSettings::avx
  bool alwaysThreads = false;                 ///< tests: PhysicsSettings::alwaysThreads
  bool finishBatches = true;                  ///< tests: PhysicsSettings::finishBatches
  size_t vmMemoryLimit = 32u << 20;           ///< bytes per behaviour VM
  int64_t behaviourBudget = 10'000'000;       ///< Lua instructions per callback
  int64_t worldBudget = 500'000'000;          ///< for the world script and its hooks
  size_t worldMemoryLimit = 256u << 20;       ///< bytes for the world VM
  double memoryBudget = 2048.0 * (1 << 20);   ///< bytes for what the world script adds (--memory-budget)
  size_t mailboxLimit = 8u << 20;             ///< bytes of unread messages per module; more are dropped
  double watchdogSeconds = 5;                 ///< wall-clock limit on one call into a VM (0: none)
  bool echoLog = true;                        ///< print module log lines to stderr
  bool echoWorldLog = true;  ///< print the world script's log/print lines (run --quiet keeps them)
  bool keepHistory = false;  ///< keep recent log lines and messages per module (viewer)
  /// Where Lua sources are read (core/source_files.h): noted for --record, a recording's texts
  /// for --fork; null: straight from the disk.
  std::shared_ptr<SourceFiles> sources;
  /// Meshes already parsed (assets/mesh_loader.h), kept by whoever makes worlds again; null: none.
  std::shared_ptr<MeshCache> meshes;
};

/// The substeps and solver iterations each joint solver runs at unless world.set gives them:
/// "exact" 1 x 15, "pgs" 4 x 30 (its hinges need both; docs/physics.md, Joint solvers).
constexpr int defaultSubsteps(SolverKind k) {
  return k == SolverKind::Exact ? 1 : 4;
}
/// The substeps a world with cloth runs at unless world.set gives them (World::start).
constexpr int kClothSubsteps = 2;
constexpr int defaultIterations(SolverKind k) {
  return k == SolverKind::Exact ? 15 : 30;
}

/// world.set{...}: fixed before the first step.
struct WorldSettings {
  SolverKind solver = SolverKind::Exact;
  double dt = 1.0 / 60.0;
  int substeps = defaultSubsteps(SolverKind::Exact);
  int solverIterations = defaultIterations(SolverKind::Exact);
  bool substepsGiven = false, iterationsGiven = false;  ///< by world.set: a change of solver keeps them
  int jointIterations = 0;
  double erp = 0.8;
  Vec3 gravity = Vec3(0, 0, -9.81);
  uint64_t seed = 1;
  double duration = 10.0;
  DivergenceLimits limits;  ///< max_speed, max_angular_speed, bounds (world/divergence.h)
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
  /// Defined by the script layer (script/world_script.cpp), which sets the ScriptHost and the
  /// WorldProgram below.
  void loadFile(const std::string& path);
  /// Runs world-script source held in memory; `chunkName` is what messages call it.
  void loadString(const std::string& source, const std::string& chunkName = "world");
  void setScriptHost(std::unique_ptr<ScriptHost> host) { m_host = std::move(host); }
  ScriptHost* scriptHost() const { return m_host.get(); }
  void setWorldFile(const std::string& absolutePath) { m_worldFile = absolutePath; }
  void setProgram(std::unique_ptr<WorldProgram> program) { m_program = std::move(program); }
  /// Calls init() of every behaviour. Done by the first step() if not called.
  void start();
  /// One control step of settings().dt (the seven phases of docs/architecture.md, then world hooks).
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
  const std::vector<Module>& modules() const { return m_modules; }
  const Module& module(int i) const { return m_modules[size_t(i)]; }
  const std::vector<Failure>& failures() const { return m_failures; }
  const std::vector<DockEvent>& events() const { return m_docking.events(); }
  const std::vector<Connection>& connections() const { return m_docking.connections(); }
  const Docking& dockingConst() const { return m_docking; }
  /// A world-script error (bad input at run time), or empty.
  const std::string& scriptError() const { return m_scriptError; }
  bool fatalFault() const { return m_fatal; }
  /// Why the physics diverged (a fatal stop: world/divergence.h), or empty.
  const std::string& divergence() const { return m_divergence; }
  int faultCount() const;
  std::string worldFile() const { return m_worldFile; }
  /// The world script (null before a world is loaded); defined by the script layer.
  WorldScript* script() const;
  void setScriptError(const std::string& e) {
    if (m_scriptError.empty()) m_scriptError = e;
  }

  Pose modulePose(int m) const;
  Pose linkPose(int m, int link) const;
  Pose dockPose(int m, int dock) const;  ///< dock frame in the world
  double jointAngle(int m, int joint) const;
  double jointVelocity(int m, int joint) const;
  /// Torque (N m) the joint's motor applied over the last step, and whether it was saturated.
  double jointTorque(int m, int joint) const;
  bool jointSaturated(int m, int joint) const;
  Quality quality() const;
  /// Adds this step's servo tracking error to the running RMS that quality() reports.
  void sampleTracking();
  /// Connected components (module indices, each sorted), by the connection graph.
  std::vector<std::vector<int>> components() const;
  /// Phase timings of the last step, ms.
  struct StepTimes {
    double behaviours = 0, physics = 0, other = 0;
    double particles = 0;  ///< part of `other`: fluids and debris (world/particles.cpp)
  };
  const StepTimes& lastStepTimes() const { return m_times; }
  const PhysicsWorld& physicsConst() const { return *m_physics; }
  /// False before the world is built (a world that failed to load has no physics).
  bool hasPhysics() const { return m_physics != nullptr; }

  // --- building (world scripts, tests) ---
  void setSettings(const WorldSettings& s);
  void addGround(double friction, double restitution);
  /// An obstacle: any shape, static (mass 0) or dynamic; a TriMesh or Heightfield only static.
  /// Returns its physics part. Throws InputError.
  int addObstacle(const ShapeDef& shape, const Pose& pose, double mass, double friction,
                  double rollingFriction = 0);
  struct Obstacle {
    int part;
    ShapeDef shape;
    double mass;
  };
  const std::vector<Obstacle>& obstacles() const { return m_obstacles; }
  /// world.cloth{...}: a cloth (physics/cloth.h; checked by the caller) and its colour.
  struct Cloth {
    int nx = 2, ny = 2;
    std::array<float, 4> color{0.8f, 0.3f, 0.25f, 1};
  };
  int addCloth(const ClothDesc& desc, const std::array<float, 4>& color);
  const std::vector<Cloth>& cloths() const { return m_cloths; }
  struct ClothStats {
    int nodes = 0;
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  ///< bounds of the finite nodes
    Vec3 meanVelocity = Vec3::Zero();
    bool nan = false;  ///< some node's position or velocity is NaN or infinite
  };
  ClothStats clothStats(int cloth) const;
  /// world.camera{...}: where pictures are taken from.
  struct CameraDef {
    std::optional<Vec3> eye, target;  ///< with `follow`, eye is an offset from the module
    int follow = -1;                  ///< module index, or -1
    double fovDeg = 45;
  };
  const CameraDef& camera() const { return m_camera; }
  /// world.fluid / world.debris: a box filled with particles; returns the system's index.
  /// Throws InputError (too many particles in the world, or none in the box).
  int addParticles(const ParticleDef& def);
  static constexpr double kMaxParticles = 2'000'000;  ///< in one world, all systems together
  /// One budget for everything a world allocates on behalf of its script (bodies, meshes and
  /// heightfields, modules, cloth nodes, particles), in estimated bytes (world/budget.h):
  /// RunOptions::memoryBudget. Each addition is charged before it is built; one past the budget
  /// throws InputError ("the world's memory budget: WHAT would take N MiB, M MiB of the 2048 MiB
  /// budget are left"; docs/limits.md).
  void chargeBudget(double bytes, const std::string& what);
  double budgetUsed() const { return m_budgetUsed; }
  const std::vector<std::unique_ptr<ParticleSystem>>& particleSystems() const { return m_particles; }
  bool hasGround() const { return m_groundAdded; }
  void setCamera(const CameraDef& c) { m_camera = c; }
  Pose obstaclePose(int body) const;
  Vec3 obstacleVelocity(int body) const;
  /// True when the obstacle is static or asleep (still for 2 s; it wakes when touched).
  bool obstacleSleeping(int body) const;
  const ModuleTypeDef& moduleType(const std::string& name);
  /// A type this world has already loaded, by the name it was spawned with or its own name;
  /// nullptr otherwise (never loads: safe from behaviours).
  const ModuleTypeDef* loadedModuleType(const std::string& name) const;
  struct SpawnDef {
    std::string type;
    Pose pose;
    std::string name;
    std::string behaviour;  ///< path as written; resolved against the world's folder, then root
    Value params;
    bool fixed = false;  ///< the root link does not move
    /// Initial joint angles by joint index (rad; empty: all zero). The root link is at `pose`
    /// and the other links follow, so the module starts in that posture and its servos hold it.
    std::vector<double> joints;
    DockSettings docks;  ///< over the type's docks (and the world's, setDockSettings)
  };
  /// Dock settings over the module types' for every module spawned after this (world.docks).
  void setDockSettings(const DockSettings& s) { m_dockSettings = s; }
  const DockSettings& dockSettings() const { return m_dockSettings; }
  /// Throws InputError (without location: the caller adds it).
  int spawn(const SpawnDef& def);
  void connect(int a, int dockA, int b, int dockB, int orientation);
  /// Moves module m's connected component straight up or down so that its lowest point is at
  /// height z (before the first step). Returns how far it moved (m, + up).
  double placeOnGround(int m, double z);
  /// Moves b's connected component so its dock `dockB` faces a's `dockA` squarely, `gap` metres
  /// out along a's normal (world.place_facing). Throws InputError.
  void placeFacing(int a, int dockA, int b, int dockB, double gap, int orientation);
  /// Releases the connection at module m's dock (as if a dock were disabled). False if none.
  bool disconnect(int m, int dock);
  void setChannel(const ChannelDef& c) { m_router.setChannel(c); }
  const ChannelDef& channel() const { return m_router.channel(); }
  /// Load through a connection during the last step (force N, torque N m about the dock face).
  Wrench connectionLoad(const Connection& c) const;
  /// Messages counted over the run: sent, delivered (read), lost in flight.
  using MessageStats = rm3d::MessageStats;
  MessageStats messageStats() const { return m_router.stats(m_mailboxes); }
  void addFailure(const std::string& message);
  /// world.trace(name, value) series (a module's are Module::traces).
  TraceSeries& worldTraces() { return m_traces; }
  const TraceSeries& worldTraces() const { return m_traces; }
  /// world.metric(name, value): named results, under "metrics" in the summary.
  static constexpr size_t kMaxMetrics = 10000;
  void setMetric(const std::string& name, double value) { m_metrics[name] = value; }
  const std::map<std::string, double>& metrics() const { return m_metrics; }
  void requestStop() { m_stopRequested = true; }
  /// Resolves a path from a world script: the world's folder first, then the project root (the
  /// path rule, core/path_rule.h). Empty when not found; InputError when it lies outside both.
  std::string resolvePath(const std::string& path) const;
  /// A source file exists (through options().sources when set, else on disk).
  bool sourceExists(const std::string& path) const;
  /// Where resolvePath looks, for not-found errors: "(looked in /w/worlds/ and /w/)".
  std::string resolveLookedIn() const;

  // --- agents (the Python API's arrays: engine/api, docs/python.md) ---
  /// Actions for the next step() only: row m (`stride` numbers apart, the first actSize(m) used)
  /// goes to module m in the behaviour phase, before its step(): to act(a) when its behaviour
  /// defines one, else as its joints' servo targets. Rows past `rows` get nothing. The caller
  /// keeps the buffer unchanged until step() returns.
  void setActions(const double* data, int stride, int rows) {
    m_actions = data;
    m_actionStride = stride;
    m_actionRows = rows;
  }
  /// How many numbers module m's action row holds: its behaviour's act size (act_size, else its
  /// joint count) when it defines act(a), else its joint count.
  int actSize(int m) const;
  /// Module m's observation, written over `out`: observe() when its behaviour defines one, else
  /// its joint angles (rad), joint velocities (rad/s) and per dock 1 (engaged) or 0. A failing
  /// observe() faults the module (false; `out` empty). A faulted module is not observed (false;
  /// `out` unchanged). Modules may be observed in parallel (each VM is its own).
  bool observe(int m, std::vector<double>& out);
  /// Runs fn(m) for every module on the behaviour pool (in parallel with --threads > 1).
  void forEachModule(FunctionRef<void(int)> fn);

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

  /// Sets a joint's command (main thread, between steps: tests, the API). Behaviours set theirs
  /// through their ModuleHandle, world scripts through a WorldEditor (world/world_editor.h).
  void setJointCommand(int m, int joint, JointMode mode, double value) {
    m_modules[size_t(m)].commands[size_t(joint)] = {mode, value};
  }
  /// Module m's trace series, writable for the trace writer (which clears their `fresh` flags).
  TraceSeries& moduleTraces(int m) { return m_modules[size_t(m)].traces; }
  void faultModule(int i, const std::string& message);

 private:
  friend class BehaviourPool;
  friend class ModuleHandle;
  friend class WorldEditor;  // the world script's narrow access (world/world_editor.h)
  PhysicsWorld& physics() { return *m_physics; }
  /// Reads a sensor of module `mi` whose record is `self`; writes only `self` (its cache), so
  /// behaviours may call it in parallel during their phase.
  SensorReading readSensor(Module& self, int mi, int code, bool velocity) const;
  /// Applies the dock:enable()/disable() calls queued during the behaviour phase, in module order.
  void applyDockRequests();
  void ensurePhysics();
  /// Steps every particle system against the bodies as they are now and queues their push on
  /// the bodies for the next physics step (world/particles.cpp).
  void stepParticles();
  void runBehaviours();
  void reportModuleOutput();
  void runBehaviour(int i);
  void applyActuators();
  DockingScene dockingScene() {
    return {m_modules, *m_physics, m_time, m_started, m_tasks ? &m_tasks : nullptr, m_options.alwaysThreads};
  }
  /// Drops the messages in flight at docks that docking released.
  void dropReleased();
  /// A world with cloth runs at least kClothSubsteps unless world.set gave its substeps.
  void keepClothSubsteps();
  struct FreeDock {
    int module, dock;
    Pose pose;
  };

  RunOptions m_options;
  WorldSettings m_settings;
  std::string m_worldFile;
  std::unique_ptr<PhysicsWorld> m_physics;
  std::map<std::string, std::unique_ptr<ModuleTypeDef>> m_types;
  /// Types with dock settings over them (world.docks, world.spawn's docks), by type name and settings.
  std::map<std::string, std::unique_ptr<ModuleTypeDef>> m_dockVariants;
  DockSettings m_dockSettings;
  std::vector<Module> m_modules;
  std::unique_ptr<ScriptHost> m_host;                        ///< outlives the programs (declared before them)
  std::vector<std::unique_ptr<ModuleProgram>> m_behaviours;  ///< one per module (null: none)
  std::vector<Mailbox> m_mailboxes;
  Router m_router;
  Docking m_docking;
  std::vector<Failure> m_failures;
  TraceSeries m_traces;
  std::map<std::string, double> m_metrics;
  std::vector<Obstacle> m_obstacles;
  std::vector<Cloth> m_cloths;
  double m_budgetUsed = 0;  ///< bytes charged by chargeBudget
  std::vector<std::unique_ptr<ParticleSystem>> m_particles;
  ColliderSet m_colliders;  ///< reused every step
  CameraDef m_camera;
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
  std::unique_ptr<WorldProgram> m_program;
  std::unique_ptr<BehaviourPool> m_pool;
  Pace m_behaviourPace;  ///< whether the behaviours pay on the threads (core/pace.h)
  /// Each behaviour's note of what its step reads is renewed every kHotLinesEvery steps
  /// (runBehaviours); all were noted once.
  static constexpr int kHotLinesEvery = 512;
  bool m_hotLinesNoted = false;
  /// n coarse tasks on the pool, one per thread first (with --threads > 1): physics and docking.
  PhysicsWorld::ForEach m_tasks;
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
  const double* m_actions = nullptr;  ///< setActions: this step's action rows, or null
  int m_actionStride = 0, m_actionRows = 0;
  /// Applies module i's action row (behaviour phase).
  void applyAction(int i, ModuleProgram* b);
};

}  // namespace rm3d
