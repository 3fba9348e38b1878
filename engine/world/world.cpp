// World: building modules from their types, the seven-phase step, and the queries the
// bindings, the summary and the benchmarks use.
#include "world/world.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string_view>

#include "core/error.h"
#include "core/path_rule.h"
#include "core/source_files.h"
#include "core/text_file.h"
#include "docking/dock_frame.h"
#include "world/behaviour_pool.h"
#include "world/budget.h"
#include "world/module_handle.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

MotorMode motorMode(JointMode m) {
  switch (m) {
    case JointMode::Servo:
      return MotorMode::Servo;
    case JointMode::Velocity:
      return MotorMode::Velocity;
    default:
      return MotorMode::Off;
  }
}

/// Joint frame in the link frame: origin at the pivot, z along the axis.
Pose jointFrame(const JointDef& j) {
  return {j.pivot, Quat::FromTwoVectors(Vec3::UnitZ(), j.axis.normalized())};
}

/// Every link's pose for a module whose root link is at `root`, at the given joint angles (by
/// joint index; missing ones 0). Every link frame is the module frame at zero angles, so a joint
/// turns its child side about its axis through its pivot; the links form a tree from the root.
std::vector<Pose> postureOf(const ModuleTypeDef& type, const Pose& root, const std::vector<double>& angles) {
  std::vector<Pose> poses(type.links.size(), root);
  if (angles.empty()) return poses;
  std::vector<char> placed(type.links.size(), 0);
  placed[size_t(type.rootLink)] = 1;
  for (bool grew = true; grew;) {  // a few links: sweep until every reachable one is placed
    grew = false;
    for (size_t j = 0; j < type.joints.size(); ++j) {
      const JointDef& jd = type.joints[j];
      const size_t p = size_t(jd.parent), c = size_t(jd.child);
      if (placed[p] == placed[c]) continue;
      const double angle = j < angles.size() ? angles[j] : 0.0;
      // The child relative to the parent: a turn by `angle` about the axis through the pivot.
      const Quat q(Eigen::AngleAxisd(angle, jd.axis));
      const Pose turn{jd.pivot - q * jd.pivot, q};
      if (placed[p])
        poses[c] = poses[p] * turn;
      else
        poses[p] = poses[c] * turn.inverse();
      placed[p] = placed[c] = 1;
      grew = true;
    }
  }
  return poses;
}

/// FNV-1a of a module name, with the top bit set so it never equals a small id.
uint64_t streamOfName(const std::string& name) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : name) h = (h ^ c) * 0x100000001b3ull;
  return h | (1ull << 63);
}

/// Derived fields of a freshly loaded type: dock frames, and how far any dock face (plus its
/// capture radius) can be from the root link's origin in any pose: along the joint path from the
/// root, the distances between successive pivots and from the last pivot to the dock, which no
/// joint angle changes.
void prepareType(ModuleTypeDef& t) {
  for (DockDef& d : t.docks) d.frame = dockFrame(d);
  std::vector<double> path(t.links.size(), -1);
  std::vector<Vec3> lastPivot(t.links.size(), Vec3::Zero());
  path[size_t(t.rootLink)] = 0;
  for (bool grew = true; grew;) {
    grew = false;
    for (const JointDef& j : t.joints)
      for (auto [from, to] : {std::pair{j.parent, j.child}, std::pair{j.child, j.parent}})
        if (path[size_t(from)] >= 0 && path[size_t(to)] < 0) {
          path[size_t(to)] = path[size_t(from)] + (j.pivot - lastPivot[size_t(from)]).norm();
          lastPivot[size_t(to)] = j.pivot;
          grew = true;
        }
  }
  for (const SensorDef& s : t.sensors) {
    t.hasAccelerometer |= s.kind == SensorKind::Accelerometer;
    t.hasContact |= s.kind == SensorKind::Contact;
  }
  t.dockReach = 0;
  for (const DockDef& d : t.docks)
    t.dockReach = std::max(t.dockReach, std::max(0.0, path[size_t(d.link)]) +
                                            (d.pos - lastPivot[size_t(d.link)]).norm() + d.captureRadius);
}

}  // namespace

World::World(RunOptions options) : m_options(std::move(options)) {
  if (m_options.seed) m_settings.seed = *m_options.seed;
  m_pool = std::make_unique<BehaviourPool>(std::max(1, m_options.threads), std::max(1, m_options.chunkSize));
  if (m_pool->threads() > 1)
    m_tasks = [pool = m_pool.get()](int n, FunctionRef<void(int)> fn) {
      pool->run(n, fn, 1);  // n coarse tasks, each taken alone
    };
}

World::~World() {
  // The programs (VMs) hold pointers into the world: close them first, then their host.
  m_program.reset();
  m_behaviours.clear();
  m_host.reset();
}

void World::setSettings(const WorldSettings& s) {
  m_settings = s;
  if (m_options.seed) m_settings.seed = *m_options.seed;
  if (m_physics) {
    PhysicsSettings ps = m_physics->settings();
    ps.solver = s.solver;
    ps.gravity = s.gravity;
    ps.solverIterations = s.solverIterations;
    ps.jointIterations = s.jointIterations;
    ps.erp = s.erp;
    m_physics->configure(ps);
  }
}

void World::ensurePhysics() {
  if (m_physics) return;
  PhysicsSettings ps;
  ps.solver = m_settings.solver;
  ps.gravity = m_settings.gravity;
  ps.solverIterations = m_settings.solverIterations;
  ps.jointIterations = m_settings.jointIterations;
  ps.erp = m_settings.erp;
  ps.wholeFactors = m_options.wholeFactors;
  ps.freshTrees = m_options.freshTrees;
  ps.everyIteration = m_options.everyIteration;
  ps.denseIslands = m_options.denseIslands;
  ps.denseCoordinates = m_options.denseCoordinates;
  ps.avx = m_options.avx;
  ps.alwaysThreads = m_options.alwaysThreads;
  ps.finishBatches = m_options.finishBatches;
  m_physics = std::make_unique<PhysicsWorld>(ps);
  if (m_tasks) m_physics->setParallel(m_pool->threads(), m_tasks, m_pool->watches());
}

void World::addGround(double friction, double restitution) {
  ensurePhysics();
  if (m_groundAdded) throw InputError("the ground is already there (call it once)");
  m_groundAdded = true;
  m_groundFriction = friction;
  m_groundRestitution = restitution;
  m_physics->addGroundPlane(friction, restitution);
}

int World::addObstacle(const ShapeDef& shape, const Pose& pose, double mass, double friction,
                       double rollingFriction) {
  if (mass > 0 && staticOnly(shape.kind))
    throw InputError("a concave mesh or a heightfield is static: mass must be 0 (the default)");
  if (shape.kind == ShapeKind::Heightfield &&
      (!shape.grid || shape.grid->nx < 2 || shape.grid->ny < 2 ||
       shape.grid->heights.size() != size_t(shape.grid->nx) * size_t(shape.grid->ny)))
    throw InputError("a heightfield needs a grid of at least 2 x 2 heights");
  double bytes = budget::kBody + double(shape.points.size()) * budget::kMeshPoint +
                 double(shape.triangles.size()) * budget::kMeshIndex;
  if (shape.grid) bytes += double(shape.grid->heights.size()) * budget::kHeightSample;
  chargeBudget(bytes, "a body");
  ensurePhysics();
  PartDesc d;
  d.shapes = {shape};
  d.mass = mass;
  d.pose = pose;
  d.friction = friction;
  d.rollingFriction = rollingFriction;
  const int part = m_physics->addPart(d);
  m_obstacles.push_back({part, shape, mass});
  return part;
}

namespace {

/// Bytes as a reader wants them: "12 MiB", or below a MiB "300 KiB" (never "0 MiB" for something;
/// --memory-budget 1 once refused a module that "would take 0 MiB" with "0 MiB left").
std::string byteSize(double bytes) {
  char buf[64];
  if (bytes >= 1048576.0)
    std::snprintf(buf, sizeof buf, "%.0f MiB", bytes / 1048576);
  else
    std::snprintf(buf, sizeof buf, "%.0f KiB", std::ceil(bytes / 1024));
  return buf;
}

}  // namespace

void World::chargeBudget(double bytes, const std::string& what) {
  const double budget = m_options.memoryBudget;
  if (!(m_budgetUsed + bytes <= budget)) {
    throw InputError("the world's memory budget: " + what + " would take " + byteSize(bytes) + ", " +
                     byteSize(std::max(0.0, budget - m_budgetUsed)) + " of the " + byteSize(budget) +
                     " budget are left (everything a world script adds shares it; see docs/limits.md)");
  }
  m_budgetUsed += bytes;
}

int World::addCloth(const ClothDesc& desc, const std::array<float, 4>& color) {
  chargeBudget(double(desc.nx) * double(desc.ny) * budget::kClothNode,
               "a cloth of " + std::to_string(desc.nx) + " x " + std::to_string(desc.ny) + " nodes");
  ensurePhysics();
  const int c = m_physics->addCloth(desc);
  m_cloths.push_back({desc.nx, desc.ny, color});
  // Before the first step world.set may still change the solver (and its default substeps): start()
  // applies it then.
  if (m_started) keepClothSubsteps();
  return c;
}

void World::keepClothSubsteps() {
  // Cloth keeps two substeps unless the world gives its own: its nodes meet bodies only where they
  // end a substep, so at one substep a sheet falling 1.8 m (5 cm a substep) went through a 2 cm plate.
  if (!m_settings.substepsGiven) m_settings.substeps = std::max(m_settings.substeps, kClothSubsteps);
}

World::ClothStats World::clothStats(int c) const {
  ClothStats st;
  st.nodes = m_physics->clothNodeCount(c);
  int finite = 0;
  for (int i = 0; i < st.nodes; ++i) {
    const Vec3 p = m_physics->clothNode(c, i), v = m_physics->clothNodeVelocity(c, i);
    if (!p.allFinite() || !v.allFinite()) {
      st.nan = true;
      continue;
    }
    st.lo = finite ? st.lo.cwiseMin(p) : p;
    st.hi = finite ? st.hi.cwiseMax(p) : p;
    st.meanVelocity += v;
    ++finite;
  }
  if (finite) st.meanVelocity /= finite;
  return st;
}

Pose World::obstaclePose(int part) const {
  return m_physics->partPose(part);
}
Vec3 World::obstacleVelocity(int part) const {
  return m_physics->partLinearVelocity(part);
}
bool World::obstacleSleeping(int part) const {
  return m_physics->partSleeping(part);
}

namespace {

/// The world's own project folder: the nearest folder at or above the world file's that holds a
/// `behaviors/` folder (a checkout, or a folder made by `rm3d init`); empty if none.
std::string projectFolderOf(const fs::path& worldDir) {
  std::error_code ec;
  for (fs::path d = fs::absolute(worldDir, ec).lexically_normal(); !d.empty(); d = d.parent_path()) {
    if (fs::is_directory(d / "behaviors", ec)) return d.string();
    if (d == d.parent_path()) break;
  }
  return {};
}

}  // namespace

std::string World::resolvePath(const std::string& path) const {
  // The world's folder, its project folder (so worlds/w.lua may name behaviors/b.lua or
  // ../behaviors/b.lua in a project of its own), then the project root (docs/limits.md).
  const fs::path worldDir = fs::path(m_worldFile).parent_path();
  std::vector<std::string> folders = {worldDir.string()};
  if (std::string own = projectFolderOf(worldDir); !own.empty()) folders.push_back(std::move(own));
  folders.push_back(m_options.projectRoot);
  const ScriptFile f = findScriptFile(path, folders, folders, m_options.sources.get());
  if (f.status == ScriptFile::Status::Outside)
    throw InputError(outsideMessage(path, folders) +
                     (m_options.sources ? m_options.sources->diskNote() : ""));
  return f.path;
}

bool World::sourceExists(const std::string& path) const {
  std::error_code ec;
  return m_options.sources ? m_options.sources->isFile(path) : fs::is_regular_file(path, ec);
}

std::string World::resolveLookedIn() const {
  const fs::path worldDir = fs::path(m_worldFile).parent_path();
  return "(looked in " + (worldDir / "").lexically_normal().string() + " and " +
         (fs::path(m_options.projectRoot) / "").lexically_normal().string() +
         ", the project root: the only folders a world's files may come from, docs/limits.md)";
}

const ModuleTypeDef& World::moduleType(const std::string& name) {
  auto it = m_types.find(name);
  if (it != m_types.end()) return *it->second;
  if (!m_host)
    throw InputError("module type '" + name +
                     "': module types are read by the script layer (load a world first)");
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".lua") == 0) {
    // A module-type file given by path (a variant kept next to a world, say).
    const std::string path = resolvePath(name);
    if (path.empty()) throw InputError("module type file '" + name + "' not found " + resolveLookedIn());
    auto def = std::make_unique<ModuleTypeDef>(m_host->loadModuleType(path));
    prepareType(*def);
    const ModuleTypeDef& ref = *def;
    m_types.emplace(name, std::move(def));
    return ref;
  }
  const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
  const fs::path dir = fs::path(m_options.projectRoot) / "assets" / "modules";
  const fs::path file = dir / (name + ".lua");
  if (!plain || !sourceExists(file.string())) {
    std::string known;
    std::error_code ec;
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".lua") names.push_back(e.path().stem().string());
    std::sort(names.begin(), names.end());
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw InputError("unknown module type '" + name + "' (expected one of: " + known + "; looked in " +
                     (dir / "").lexically_normal().string() + ")");
  }
  auto def = std::make_unique<ModuleTypeDef>(m_host->loadModuleType(file.string()));
  prepareType(*def);
  const ModuleTypeDef& ref = *def;
  m_types.emplace(name, std::move(def));
  return ref;
}

const ModuleTypeDef* World::loadedModuleType(const std::string& name) const {
  auto it = m_types.find(name);
  if (it != m_types.end()) return it->second.get();
  for (const auto& [key, def] : m_types)
    if (def->name == name) return def.get();
  return nullptr;
}

int World::spawn(const SpawnDef& def) {
  if (m_started) throw InputError("modules are spawned while the world script runs, before the first step");
  const ModuleTypeDef* typePtr = &moduleType(def.type);
  DockSettings docks = m_dockSettings;
  docks.overlay(def.docks);
  if (!docks.empty()) {
    // A copy of the type with these dock settings, shared by every module spawned with them.
    const std::string key = typePtr->name + "|" + typePtr->file + "|" + docks.key();
    std::unique_ptr<ModuleTypeDef>& variant = m_dockVariants[key];
    if (!variant) {
      auto t = std::make_unique<ModuleTypeDef>(*typePtr);
      for (DockDef& d : t->docks) {
        docks.applyTo(d);
        if (d.latchDistance > d.captureRadius)
          throw InputError("dock settings: latch_distance (" + std::to_string(d.latchDistance) +
                           " m) must not exceed capture_radius (" + std::to_string(d.captureRadius) +
                           " m) on dock '" + d.name + "'");
      }
      prepareType(*t);
      variant = std::move(t);
    }
    typePtr = variant.get();
  }
  const ModuleTypeDef& type = *typePtr;
  if (def.params.type != Value::Type::Nil) {
    const ValueCounts c = valueCounts(def.params);
    chargeBudget(c.values * budget::kParamsValue + c.stringBytes * budget::kParamsByte, "a module's params");
  }
  chargeBudget(budget::kBody * double(type.links.size()), "a module");
  ensurePhysics();
  std::string behaviourPath;
  if (!def.behaviour.empty()) {
    behaviourPath = resolvePath(def.behaviour);
    if (behaviourPath.empty())
      throw InputError("behavior '" + def.behaviour + "' not found " + resolveLookedIn());
    if (!sourceExists(behaviourPath))
      throw InputError("behavior '" + def.behaviour + "' is not a file (" + behaviourPath +
                       "; expected a .lua file)");
  }
  const int index = int(m_modules.size());
  m_modules.emplace_back();
  Module& m = m_modules.back();
  m.id = index + 1;
  m.name = def.name.empty() ? type.name + "_" + std::to_string(m.id) : def.name;
  m.type = &type;
  m.behaviourFile = behaviourPath;
  m.params = def.params;
  // A named module's stream follows its name, so adding or reordering other modules never
  // changes its numbers; an unnamed one's follows its id (its place in spawn order).
  m.rngStream = def.name.empty() ? uint64_t(m.id) : streamOfName(def.name);
  m.rng.seed(m_settings.seed, m.rngStream);
  m.fixed = def.fixed;
  const std::vector<Pose> linkPoses = postureOf(type, def.pose, def.joints);
  for (size_t l = 0; l < type.links.size(); ++l) {
    const LinkDef& link = type.links[l];
    PartDesc d;
    d.shapes = link.collisionShapes();
    d.mass = def.fixed && int(l) == type.rootLink ? 0.0 : link.mass;  // mass 0: static
    d.pose = linkPoses[l];
    d.friction = link.friction;
    d.rollingFriction = link.rollingFriction;
    d.owner = index;
    m.parts.push_back(m_physics->addPart(d));
  }
  for (const JointDef& j : type.joints) {
    HingeDesc h;
    h.partA = m.parts[size_t(j.parent)];
    h.partB = m.parts[size_t(j.child)];
    h.frameA = h.frameB = jointFrame(j);
    h.limited = j.limited;
    h.lower = j.lower;
    h.upper = j.upper;
    h.maxTorque = j.maxTorque;
    h.maxSpeed = j.maxSpeed;
    h.servoGain = j.servoGain;
    h.servoStiffness = j.servoStiffness;
    m.hinges.push_back(m_physics->addHinge(h));
  }
  m.commands.assign(type.joints.size(), JointCommand{});
  for (size_t j = 0; j < def.joints.size() && j < m.commands.size(); ++j) m.commands[j].value = def.joints[j];
  m.docks.assign(type.docks.size(), DockState{});
  m.dockRequests.assign(type.docks.size(), -1);
  const size_t codes = type.joints.size() + type.docks.size() + type.sensors.size();
  m.sensorCache.assign(codes, {-1, SensorReading{}});
  m.deadSensors.assign(codes, 0);
  m.accelPrevVel.assign(type.sensors.size(), Vec3::Zero());
  m.accelWorld.assign(type.sensors.size(), Vec3::Zero());
  m.stalled.assign(type.joints.size(), 0);
  m.stallAngle.assign(type.joints.size(), 0.0);
  m_contactSensors |= type.hasContact;
  m_mailboxes.emplace_back();
  m_behaviours.emplace_back();
  if (!behaviourPath.empty()) {
    if (!m_host) throw InputError("behaviours are run by the script layer (load a world first)");
    std::string err;
    m_behaviours.back() = m_host->loadBehaviour(ModuleHandle(*this, index), behaviourPath, err);
    if (!err.empty()) faultModule(index, err);
  }
  return index;
}

void World::addFailure(const std::string& message) {
  m_failures.push_back({m_time, message});
}

void World::faultModule(int i, const std::string& message) {
  Module& m = m_modules[size_t(i)];
  if (m.fault.empty()) m.fault = message.empty() ? "fault" : message;
}

int World::faultCount() const {
  return int(
      std::count_if(m_modules.begin(), m_modules.end(), [](const Module& m) { return !m.fault.empty(); }));
}

void World::start() {
  if (m_started) return;
  ensurePhysics();
  m_started = true;
  if (!m_cloths.empty()) keepClothSubsteps();
  m_router.seed(m_settings.seed);
  double capture = 0.03;
  for (const auto* types : {&m_types, &m_dockVariants})
    for (const auto& [name, type] : *types)
      for (const DockDef& d : type->docks) capture = std::max(capture, d.captureRadius);
  m_docking.setCaptureCell(capture);
  for (size_t i = 0; i < m_modules.size(); ++i) {
    ModuleProgram* b = m_behaviours[i].get();
    if (!b || !m_modules[i].fault.empty()) continue;
    std::string err;
    if (!b->init(err)) faultModule(int(i), err);
  }
  reportModuleOutput();
}

bool World::finished() const {
  return stopped() || double(m_steps) * m_settings.dt >= m_settings.duration - 0.5 * m_settings.dt;
}

void World::runBehaviour(int i) {
  // With thousands of modules, each one's record and program have left the caches since its
  // last step: the program of the module 4 ahead, the record of the one 3 ahead, then in stages
  // what their programs read (ModuleProgram::fetchState), fetched now.
  const size_t n = m_behaviours.size();
  if (size_t(i + 4) < n)
    if (const ModuleProgram* ahead = m_behaviours[size_t(i + 4)].get()) __builtin_prefetch(ahead);
  if (size_t(i + 3) < n) {
    const char* record = reinterpret_cast<const char*>(&m_modules[size_t(i + 3)]);
    for (size_t at = 0; at < sizeof(Module); at += 64) __builtin_prefetch(record + at);
  }
  // (And the joint commands of the next module, which its joints' set calls write; read through its
  // record, fetched two modules ago.)
  if (size_t(i + 1) < n) __builtin_prefetch(m_modules[size_t(i + 1)].commands.data(), 1);
  for (int stage = 2; stage >= 0; --stage)
    if (size_t(i + 1 + stage) < n && m_behaviours[size_t(i + 1 + stage)])
      m_behaviours[size_t(i + 1 + stage)]->fetchState(stage);
  ModuleProgram* b = m_behaviours[size_t(i)].get();
  if (!b) {
    m_modules[size_t(i)].dockEvents.clear();
    if (m_actions && i < m_actionRows) applyAction(i, nullptr);
    return;
  }
  Module& m = m_modules[size_t(i)];
  if (!m.fault.empty()) {
    m.dockEvents.clear();
    return;
  }
  std::string err;
  for (const auto& [dock, kind] : m.dockEvents)
    if (!b->onDock(dock, kind, err)) {
      m.fault = err.empty() ? "fault" : err;
      m.dockEvents.clear();
      return;
    }
  m.dockEvents.clear();
  if (m_actions && i < m_actionRows) {
    applyAction(i, b);
    if (!m.fault.empty()) return;
  }
  if (!b->step(m_settings.dt, err)) m.fault = err.empty() ? "fault" : err;
}

void World::applyAction(int i, ModuleProgram* b) {
  Module& m = m_modules[size_t(i)];
  if (!m.fault.empty()) return;
  const double* row = m_actions + size_t(i) * size_t(m_actionStride);
  const int joints = int(m.commands.size());
  if (b && b->actSize(joints) >= 0) {
    std::string err;
    if (!b->act(row, std::min(b->actSize(joints), m_actionStride), err))
      m.fault = err.empty() ? "fault" : err;
    return;
  }
  for (int j = 0; j < joints && j < m_actionStride; ++j) m.commands[size_t(j)] = {JointMode::Servo, row[j]};
}

int World::actSize(int m) const {
  const ModuleProgram* b = m_behaviours[size_t(m)].get();
  const int joints = int(m_modules[size_t(m)].commands.size());
  return b && b->actSize(joints) >= 0 ? b->actSize(joints) : joints;
}

bool World::observe(int mi, std::vector<double>& out) {
  Module& m = m_modules[size_t(mi)];
  ModuleProgram* b = m_behaviours[size_t(mi)].get();
  if (!m.fault.empty()) return false;
  if (b && b->hasObserve()) {
    out.clear();  // keeps its capacity: no allocation once a row has been seen
    std::string err;
    if (!b->observe(out, err)) {
      m.fault = err.empty() ? "fault" : err;
      out.clear();
      return false;
    }
    return true;
  }
  const int joints = int(m.type->joints.size());
  out.resize(size_t(2 * joints) + m.docks.size());
  for (int j = 0; j < joints; ++j) {
    out[size_t(j)] = jointAngle(mi, j);
    out[size_t(joints + j)] = jointVelocity(mi, j);
  }
  for (size_t d = 0; d < m.docks.size(); ++d) out[size_t(2 * joints) + d] = m.docks[d].engaged ? 1.0 : 0.0;
  return true;
}

void World::forEachModule(FunctionRef<void(int)> fn) {
  if (m_pool)
    m_pool->run(int(m_modules.size()), fn);
  else
    for (int i = 0; i < int(m_modules.size()); ++i) fn(i);
}

void World::runBehaviours() {
  // Everything a behaviour can read is fixed before the phase (module_handle.h states the rule).
  if (m_proximityWanted.load(std::memory_order_relaxed)) buildProximity();
  const int n = int(m_modules.size());
  if (m_pool->threads() > 1) {
    runPaced(
        m_behaviourPace, m_options.alwaysThreads, [&] { m_pool->run(n, [this](int i) { runBehaviour(i); }); },
        [&] {
          for (int i = 0; i < n; ++i) runBehaviour(i);
        });
  } else {
    for (int i = 0; i < n; ++i) runBehaviour(i);
  }
  // What each behaviour's step reads (ModuleProgram::noteHotLines, 11 to 22 us a module), noted on
  // this thread between the runs: every module's after this world's first step, then a
  // kHotLinesEvery-th of them each step in turn (no step pays for them all).
  const bool all = !m_hotLinesNoted;
  m_hotLinesNoted = true;
  for (size_t i = all ? 0 : size_t(m_steps % kHotLinesEvery); i < m_behaviours.size();
       i += all ? 1 : size_t(kHotLinesEvery))
    if (m_behaviours[i] && m_modules[i].fault.empty()) m_behaviours[i]->noteHotLines();
  applyDockRequests();
  reportModuleOutput();
}

void World::applyDockRequests() {
  for (Module& m : m_modules) {
    if (!m.hasDockRequests) continue;
    for (size_t d = 0; d < m.docks.size(); ++d)
      if (m.dockRequests[d] >= 0) {
        m.docks[d].enabled = m.dockRequests[d] != 0;
        m.dockRequests[d] = -1;
      }
    m.hasDockRequests = false;
  }
}

void World::reportModuleOutput() {
  // Logs and new faults are reported in module order, whatever thread ran them.
  for (Module& m : m_modules) {
    if (!m.log.empty()) {
      if (m_options.echoLog)
        for (const std::string& line : m.log)
          std::fprintf(stderr, "[%8.3f %s] %s\n", m_time, m.name.c_str(), line.c_str());
      if (m_options.keepHistory)
        for (const std::string& line : m.log) {
          char t[32];
          std::snprintf(t, sizeof t, "%.2f: ", m_time);
          m.recentLog.push_back(t + line);
          if (m.recentLog.size() > 20) m.recentLog.pop_front();
        }
      m.log.clear();
    }
    if (!m.fault.empty() && !m.faultReported) {
      m.faultReported = true;
      if (m_options.echoLog)
        std::fprintf(stderr, "fault in %s at t=%.3f: %s\n", m.name.c_str(), m_time, m.fault.c_str());
      if (m_options.strict) m_fatal = true;
    }
  }
}

void World::dropReleased() {
  for (const auto& [module, dock] : m_docking.released()) m_mailboxes[size_t(module)].dropInFlight(dock);
  m_docking.released().clear();
}

void World::connect(int a, int dockA, int b, int dockB, int orientation) {
  ensurePhysics();
  m_docking.connect(dockingScene(), a, dockA, b, dockB, orientation);
}

double World::placeOnGround(int m, double z) {
  if (m_started) throw InputError("modules are placed while the world script runs, before the first step");
  ensurePhysics();
  std::vector<int> parts;
  for (int c : componentOf(m_modules, m))
    for (int p : m_modules[size_t(c)].parts) parts.push_back(p);
  const double lift = z - m_physics->lowestPoint(parts);
  if (!std::isfinite(lift)) return 0;
  m_physics->transformParts(parts, Pose{Vec3(0, 0, lift), Quat::Identity()});
  return lift;
}

void World::placeFacing(int a, int dockA, int b, int dockB, double gap, int orientation) {
  if (m_started) throw InputError("modules are placed while the world script runs, before the first step");
  ensurePhysics();
  if (a == b) throw InputError("a module cannot face itself");
  const std::vector<int> comp = componentOf(m_modules, b);
  if (std::find(comp.begin(), comp.end(), a) != comp.end())
    throw InputError(m_modules[size_t(a)].name + " and " + m_modules[size_t(b)].name +
                     " are connected: place_facing moves b's side, which holds a");
  const DockDef& defA = m_modules[size_t(a)].type->docks[size_t(dockA)];
  const DockDef& defB = m_modules[size_t(b)].type->docks[size_t(dockB)];
  const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
  if (orientation < 0 || orientation >= sym)
    throw InputError("orientation must be 0.." + std::to_string(sym - 1) + ", got " +
                     std::to_string(orientation));
  const Pose pa = dockPose(a, dockA);
  Pose want = matingFrame(pa, orientation, sym);
  want.pos += gap * (pa.rot * Vec3::UnitX());
  const Pose delta = want * dockPose(b, dockB).inverse();
  std::vector<int> parts;
  for (int m : comp)
    for (int p : m_modules[size_t(m)].parts) parts.push_back(p);
  m_physics->transformParts(parts, delta);
}

bool World::disconnect(int m, int dock) {
  const bool released = m_docking.disconnect(dockingScene(), m, dock);
  dropReleased();
  return released;
}

Wrench World::connectionLoad(const Connection& c) const {
  return m_docking.connectionLoad(m_modules, *m_physics, c);
}

void World::applyActuators() {
  // With thousands of modules their records, joint lists and motors lie outside the caches: the
  // record of the module 12 ahead, the lists of the one 8 ahead and the motors of the one 4 ahead
  // are fetched now (each list, then each motor's write, waited on memory in turn: 0.5% of a
  // 10,000-module step).
  const size_t n = m_modules.size();
  for (size_t i = 0; i < n; ++i) {
    if (i + 12 < n) {
      __builtin_prefetch(&m_modules[i + 12].hinges);
      __builtin_prefetch(&m_modules[i + 12].commands);
      __builtin_prefetch(&m_modules[i + 12].stalled);
    }
    if (i + 8 < n) {
      const Module& ahead = m_modules[i + 8];
      __builtin_prefetch(ahead.hinges.data());
      __builtin_prefetch(ahead.commands.data());
      __builtin_prefetch(ahead.stalled.data());
    }
    if (i + 4 < n)
      for (int hinge : m_modules[i + 4].hinges) m_physics->fetchMotor(hinge);
    const Module& m = m_modules[i];
    for (size_t j = 0; j < m.hinges.size(); ++j) {
      if (m.stalled[j])
        m_physics->setMotor(m.hinges[j], MotorMode::Servo, m.stallAngle[j]);  // stuck where it failed
      else
        m_physics->setMotor(m.hinges[j], motorMode(m.commands[j].mode), m.commands[j].value);
    }
  }
}

void World::step() {
  if (!m_started) start();
  if (m_fatal || !m_scriptError.empty()) return;
  const auto t0 = Clock::now();
  // The worker threads watch for the step's runs instead of sleeping between them (until it ends).
  m_pool->hold(true);
  struct Release {
    BehaviourPool& pool;
    ~Release() { pool.hold(false); }
  } release{*m_pool};
  // 1. Deliver what was routed earlier and is due now.
  for (Mailbox& box : m_mailboxes) box.deliver(m_steps);
  // 2. Behaviours (in parallel when --threads > 1).
  const auto t1 = Clock::now();
  runBehaviours();
  m_actions = nullptr;  // applied in the behaviour phase; the next step gets its own
  const auto t2 = Clock::now();
  // 3. Route messages over engaged docks (readable next step).
  m_router.route(m_mailboxes, m_modules, m_steps, m_options.mailboxLimit);
  // 4. Undock: connections where either dock is now disabled are released.
  m_docking.undock(dockingScene());
  // 5. Dock: free compatible docks are drawn together (capture joints, or magnets); aligned ones
  // latch.
  const size_t eventsBefore = m_docking.events().size();
  m_docking.dock(dockingScene());
  for (size_t i = eventsBefore; i < m_docking.events().size() && m_options.echoLog; ++i) {
    const DockEvent& e = m_docking.events()[i];
    if (e.kind != DockEventKind::Stalled) continue;
    const Module& a = m_modules[size_t(e.moduleA)];
    const Module& b = m_modules[size_t(e.moduleB)];
    std::fprintf(
        stderr,
        "warning: t=%.3f: the capture of %s.%s and %s.%s has not latched: %.1f mm and %.1f deg left\n",
        m_time, a.name.c_str(), a.type->docks[size_t(e.dockA)].name.c_str(), b.name.c_str(),
        b.type->docks[size_t(e.dockB)].name.c_str(), e.gap * 1000, e.angle * kDegPerRad);
  }
  dropReleased();
  // 6. Actuators, then physics.
  applyActuators();
  m_physics->setLoadTracking(!m_docking.connections().empty());
  m_physics->setContactTracking(m_contactSensors);
  const auto t3 = Clock::now();
  m_physics->step(m_settings.dt, m_settings.substeps);
  const auto t4 = Clock::now();
  stepParticles();
  const auto t4p = Clock::now();
  updateAccelerometers();
  // 7. Connections whose transmitted load exceeds the docks' strength break.
  m_docking.breakage(dockingScene());
  dropReleased();
  ++m_steps;
  m_time = double(m_steps) * m_settings.dt;
  if (checkDivergence(*this, m_divergence)) {
    m_fatal = true;
    return;
  }  // world/divergence.h
  std::string err;
  if (m_program && !m_program->afterStep(m_time, err)) m_scriptError = err;
  const auto t5 = Clock::now();
  m_times.behaviours = msSince(t1, t2);
  m_times.physics = msSince(t3, t4);
  m_times.particles = msSince(t4, t4p);
  m_times.other = msSince(t0, t5) - m_times.behaviours - m_times.physics;
}

Pose World::linkPose(int m, int link) const {
  return m_physics->partPose(m_modules[size_t(m)].parts[size_t(link)]);
}
Pose World::modulePose(int m) const {
  return linkPose(m, m_modules[size_t(m)].type->rootLink);
}

Pose World::dockPose(int m, int dock) const {
  const DockDef& d = m_modules[size_t(m)].type->docks[size_t(dock)];
  return linkPose(m, d.link) * d.frame;
}

double World::jointAngle(int m, int joint) const {
  return m_physics->hingeAngle(m_modules[size_t(m)].hinges[size_t(joint)]);
}

double World::jointVelocity(int m, int joint) const {
  return m_physics->hingeVelocity(m_modules[size_t(m)].hinges[size_t(joint)]);
}

double World::jointTorque(int m, int joint) const {
  return m_physics->hingeTorque(m_modules[size_t(m)].hinges[size_t(joint)]);
}

bool World::jointSaturated(int m, int joint) const {
  return m_physics->hingeSaturated(m_modules[size_t(m)].hinges[size_t(joint)]);
}

void World::sampleTracking() {
  for (size_t i = 0; i < m_modules.size(); ++i) {
    const Module& m = m_modules[i];
    for (size_t j = 0; j < m.commands.size(); ++j) {
      if (m.commands[j].mode != JointMode::Servo) continue;
      const JointDef& jd = m.type->joints[j];
      const double target =
          jd.limited ? std::clamp(m.commands[j].value, jd.lower, jd.upper) : m.commands[j].value;
      const double e = target - m_physics->hingeAngle(m.hinges[j]);
      m_trackingSum += e * e;
      ++m_trackingCount;
    }
  }
}

Quality World::quality() const {
  Quality q;
  if (!m_physics) return q;
  const HingeQuality h = m_physics->hingeQuality();
  q.hingeGapMm = h.maxGap * 1000;
  q.hingeAngleDeg = h.maxAngle * kDegPerRad;
  for (const Connection& c : m_docking.connections()) {
    const DockError e = dockError(dockPose(c.moduleA, c.dockA), dockPose(c.moduleB, c.dockB));
    q.dockGapMm = std::max(q.dockGapMm, e.gap * 1000);
    q.dockAngleDeg = std::max(q.dockAngleDeg, e.angle * kDegPerRad);
  }
  q.trackingRmsDeg = m_trackingCount ? std::sqrt(m_trackingSum / double(m_trackingCount)) * kDegPerRad : 0;
  return q;
}

std::vector<std::vector<int>> World::components() const {
  std::vector<std::vector<int>> out;
  std::vector<char> seen(m_modules.size(), 0);
  for (size_t i = 0; i < m_modules.size(); ++i) {
    if (seen[i]) continue;
    std::vector<int> c = componentOf(m_modules, int(i));
    for (int m : c) seen[size_t(m)] = 1;
    std::sort(c.begin(), c.end());
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<std::string> World::watchedFiles() const {
  std::vector<std::string> out;
  if (!m_worldFile.empty()) out.push_back(m_worldFile);
  for (const Module& m : m_modules)
    if (!m.behaviourFile.empty()) out.push_back(m.behaviourFile);
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(m_options.projectRoot) / "lua", ec))
    if (e.path().extension() == ".lua") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string World::describePercepts(int module) {
  ModuleProgram* b = m_behaviours[size_t(module)].get();
  if (!b) return {};
  return b->describePercepts();
}

int World::reloadFile(const std::string& path, std::vector<std::string>& errors) {
  const bool library = fs::path(path).parent_path() == fs::path(m_options.projectRoot) / "lua";
  int reloaded = 0;
  std::map<std::string, std::string> sources;  // each file read once
  for (size_t i = 0; i < m_modules.size(); ++i) {
    Module& m = m_modules[i];
    ModuleProgram* b = m_behaviours[i].get();
    if (!b || (!library && m.behaviourFile != path)) continue;
    auto it = sources.find(m.behaviourFile);
    if (it == sources.end()) {
      std::string t, why;
      if (m_options.sources ? !m_options.sources->read(m.behaviourFile, t, &why)
                            : !readTextFile(m.behaviourFile, t, &why)) {
        errors.push_back(m.behaviourFile + ": cannot read file (" + why + ")");
        continue;
      }
      it = sources.emplace(m.behaviourFile, std::move(t)).first;
    }
    const std::string& text = it->second;
    std::string err;
    if (b->reload(m.behaviourFile, text, err)) {
      ++reloaded;
      m.fault.clear();
      m.faultReported = false;
    } else if (std::find(errors.begin(), errors.end(), err) == errors.end()) {
      errors.push_back(err);
    }
  }
  return reloaded;
}

}  // namespace rm3d
