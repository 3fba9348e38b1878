// World: building modules from their types, the seven-phase step, and the queries the
// bindings, the summary and the benchmarks use.
#include "world/world.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numeric>

#include "core/error.h"
#include "docking/dock_frame.h"
#include "script/behaviour.h"
#include "script/module_type_loader.h"
#include "script/world_script.h"
#include "world/behaviour_pool.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

MotorMode motorMode(JointMode m) {
  switch (m) {
    case JointMode::Servo: return MotorMode::Servo;
    case JointMode::Velocity: return MotorMode::Velocity;
    default: return MotorMode::Off;
  }
}

/// Joint frame in the link frame: origin at the pivot, z along the axis.
Pose jointFrame(const JointDef& j) {
  return {j.pivot, Quat::FromTwoVectors(Vec3::UnitZ(), j.axis.normalized())};
}

}  // namespace

World::World(RunOptions options) : m_options(std::move(options)) {
  if (m_options.seed) m_settings.seed = *m_options.seed;
  m_pool = std::make_unique<BehaviourPool>(std::max(1, m_options.threads));
}

World::~World() {
  // Behaviour VMs and the world VM hold pointers into the world: close them first.
  m_script.reset();
  m_behaviours.clear();
}

void World::loadFile(const std::string& path) {
  std::error_code ec;
  m_worldFile = fs::absolute(path, ec).lexically_normal().string();
  m_script = std::make_unique<WorldScript>(*this);
  m_script->runFile(m_worldFile);
}

void World::loadString(const std::string& source, const std::string& chunkName) {
  if (m_worldFile.empty()) m_worldFile = (fs::path(m_options.projectRoot) / "worlds" / "inline.lua").string();
  m_script = std::make_unique<WorldScript>(*this);
  m_script->runString(source, chunkName);
}

void World::setSettings(const WorldSettings& s) {
  m_settings = s;
  if (m_options.seed) m_settings.seed = *m_options.seed;
  if (m_physics) {
    PhysicsSettings ps = m_physics->settings();
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
  ps.gravity = m_settings.gravity;
  ps.solverIterations = m_settings.solverIterations;
  ps.jointIterations = m_settings.jointIterations;
  ps.erp = m_settings.erp;
  m_physics = std::make_unique<PhysicsWorld>(ps);
}

void World::addGround(double friction, double restitution) {
  ensurePhysics();
  if (m_groundAdded) throw InputError("the ground is already there (call it once)");
  m_groundAdded = true;
  m_groundFriction = friction;
  m_groundRestitution = restitution;
  m_physics->addGroundPlane(friction, restitution);
}

int World::addObstacle(const ShapeDef& shape, const Pose& pose, double mass, double friction) {
  ensurePhysics();
  PartDesc d;
  d.shapes = {shape};
  d.mass = mass;
  d.pose = pose;
  d.friction = friction;
  const int part = m_physics->addPart(d);
  m_obstacles.push_back({part, shape, mass});
  return part;
}

Pose World::obstaclePose(int part) const { return m_physics->partPose(part); }
Vec3 World::obstacleVelocity(int part) const { return m_physics->partLinearVelocity(part); }

std::string World::resolvePath(const std::string& path) const {
  const fs::path p(path);
  if (p.is_absolute()) return p.string();
  const fs::path worldDir = fs::path(m_worldFile).parent_path();
  for (const fs::path& base : {worldDir, fs::path(m_options.projectRoot)}) {
    const fs::path c = (base / p).lexically_normal();
    if (fs::exists(c)) return c.string();
  }
  return {};
}

const ModuleTypeDef& World::moduleType(const std::string& name) {
  auto it = m_types.find(name);
  if (it != m_types.end()) return *it->second;
  const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
  const fs::path dir = fs::path(m_options.projectRoot) / "assets" / "modules";
  const fs::path file = dir / (name + ".lua");
  if (!plain || !fs::is_regular_file(file)) {
    std::string known;
    std::error_code ec;
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".lua") names.push_back(e.path().stem().string());
    std::sort(names.begin(), names.end());
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw InputError("unknown module type '" + name + "' (expected one of: " + known + ")");
  }
  auto def = std::make_unique<ModuleTypeDef>(loadModuleType(file.string(), m_options.projectRoot));
  const ModuleTypeDef& ref = *def;
  m_types.emplace(name, std::move(def));
  return ref;
}

int World::spawn(const SpawnDef& def) {
  if (m_started) throw InputError("modules are spawned while the world script runs, before the first step");
  const ModuleTypeDef& type = moduleType(def.type);
  ensurePhysics();
  std::string behaviourPath;
  if (!def.behaviour.empty()) {
    behaviourPath = resolvePath(def.behaviour);
    if (behaviourPath.empty())
      throw InputError("behavior '" + def.behaviour + "' not found (looked in the world's folder and the project root)");
  }
  const int index = int(m_modules.size());
  m_modules.emplace_back();
  Module& m = m_modules.back();
  m.id = index + 1;
  m.name = def.name.empty() ? type.name + "_" + std::to_string(m.id) : def.name;
  m.type = &type;
  m.behaviourFile = behaviourPath;
  m.params = def.params;
  m.rng.seed(m_settings.seed, uint64_t(m.id));
  for (const LinkDef& link : type.links) {
    PartDesc d;
    d.shapes = link.shapes;
    d.mass = link.mass;
    d.pose = def.pose;  // every link frame is the module frame at zero joint angles
    d.friction = link.friction;
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
    m.hinges.push_back(m_physics->addHinge(h));
  }
  m.commands.assign(type.joints.size(), JointCommand{});
  m.docks.assign(type.docks.size(), DockState{});
  m_mailboxes.emplace_back();
  m_behaviours.emplace_back();
  if (!behaviourPath.empty()) {
    m_behaviours.back() = std::make_unique<Behaviour>(*this, index);
    std::string err;
    if (!m_behaviours.back()->load(behaviourPath, err)) faultModule(index, err);
  }
  return index;
}

std::vector<int> World::componentOf(int m) const {
  std::vector<int> out{m};
  std::vector<char> seen(m_modules.size(), 0);
  seen[size_t(m)] = 1;
  for (size_t k = 0; k < out.size(); ++k)
    for (const DockState& d : m_modules[size_t(out[k])].docks)
      if (d.engaged && !seen[size_t(d.peerModule)]) {
        seen[size_t(d.peerModule)] = 1;
        out.push_back(d.peerModule);
      }
  return out;
}

void World::connect(int a, int da, int b, int db, int orientation) {
  if (a == b) throw InputError("a module cannot dock to itself");
  Module& ma = m_modules[size_t(a)];
  Module& mb = m_modules[size_t(b)];
  const DockDef& defA = ma.type->docks[size_t(da)];
  const DockDef& defB = mb.type->docks[size_t(db)];
  for (auto [m, d] : {std::pair<Module*, int>{&ma, da}, std::pair<Module*, int>{&mb, db}})
    if (m->docks[size_t(d)].engaged)
      throw InputError("dock '" + m->type->docks[size_t(d)].name + "' of " + m->name + " is already engaged");
  if (!gendersMate(defA.gender, defB.gender))
    throw InputError(std::string("a ") + genderName(defA.gender) + " dock cannot mate with a " +
                     genderName(defB.gender) + " dock");
  const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
  if (orientation < 0 || orientation >= sym)
    throw InputError("orientation must be 0.." + std::to_string(sym - 1) + ", got " + std::to_string(orientation));
  const std::vector<int> comp = componentOf(b);
  if (std::find(comp.begin(), comp.end(), a) != comp.end()) {
    // Closing a loop: both docks are placed already; they must face each other.
    const DockError e = dockError(dockPose(a, da), dockPose(b, db));
    if (e.gap > 0.005 || e.angle > 3.0 / kDegPerRad)
      throw InputError("" + ma.name + " and " + mb.name +
                       " are already connected another way and these docks do not face each other (gap " +
                       std::to_string(e.gap * 1000) + " mm, angle " + std::to_string(e.angle * kDegPerRad) + " deg)");
  } else {
    const Pose want = matingFrame(dockPose(a, da), orientation, sym);
    const Pose delta = want * dockPose(b, db).inverse();
    std::vector<int> parts;
    for (int m : comp)
      for (int p : m_modules[size_t(m)].parts) parts.push_back(p);
    m_physics->transformParts(parts, delta);
  }
  m_physics->lockParts(ma.parts[size_t(defA.link)], mb.parts[size_t(defB.link)]);
  ma.docks[size_t(da)] = {ma.docks[size_t(da)].enabled, true, b, db};
  mb.docks[size_t(db)] = {mb.docks[size_t(db)].enabled, true, a, da};
  m_connections.push_back({a, da, b, db});
  m_events.push_back({m_time, "engaged", a, da, b, db});
}

void World::addFailure(const std::string& message) { m_failures.push_back({m_time, message}); }

void World::faultModule(int i, const std::string& message) {
  Module& m = m_modules[size_t(i)];
  if (m.fault.empty()) m.fault = message.empty() ? "fault" : message;
}

int World::faultCount() const {
  return int(std::count_if(m_modules.begin(), m_modules.end(), [](const Module& m) { return !m.fault.empty(); }));
}

void World::start() {
  if (m_started) return;
  ensurePhysics();
  m_started = true;
  for (size_t i = 0; i < m_modules.size(); ++i) {
    Behaviour* b = m_behaviours[i].get();
    if (!b || !m_modules[i].fault.empty()) continue;
    std::string err;
    if (!b->callInit(err)) faultModule(int(i), err);
  }
  reportModuleOutput();
}

bool World::finished() const {
  return stopped() || double(m_steps) * m_settings.dt >= m_settings.duration - 0.5 * m_settings.dt;
}

void World::runBehaviour(int i) {
  Behaviour* b = m_behaviours[size_t(i)].get();
  if (!b) return;
  Module& m = m_modules[size_t(i)];
  if (!m.fault.empty()) return;
  std::string err;
  if (!b->callStep(m_settings.dt, err)) m.fault = err.empty() ? "fault" : err;
}

void World::runBehaviours() {
  const int n = int(m_modules.size());
  m_pool->run(n, [this](int i) { runBehaviour(i); });
  reportModuleOutput();
}

void World::reportModuleOutput() {
  // Logs and new faults are reported in module order, whatever thread ran them.
  for (Module& m : m_modules) {
    if (!m.log.empty()) {
      if (m_options.echoLog)
        for (const std::string& line : m.log) std::fprintf(stderr, "[%8.3f %s] %s\n", m_time, m.name.c_str(), line.c_str());
      m.log.clear();
    }
    if (!m.fault.empty() && !m.faultReported) {
      m.faultReported = true;
      if (m_options.echoLog) std::fprintf(stderr, "fault in %s at t=%.3f: %s\n", m.name.c_str(), m_time, m.fault.c_str());
      if (m_options.strict) m_fatal = true;
    }
  }
}

void World::routeMessages() {
  for (size_t i = 0; i < m_mailboxes.size(); ++i) {
    Mailbox& box = m_mailboxes[i];
    if (box.outbox.empty()) continue;
    const Module& m = m_modules[i];
    for (Message& msg : box.outbox) {
      const DockState& d = m.docks[size_t(msg.dock)];
      if (!d.engaged) {
        ++box.dropped;
        continue;
      }
      msg.dock = d.peerDock;
      m_mailboxes[size_t(d.peerModule)].pending.push_back(std::move(msg));
      ++box.sent;
    }
    box.outbox.clear();
  }
}

void World::applyActuators() {
  for (const Module& m : m_modules)
    for (size_t j = 0; j < m.hinges.size(); ++j)
      m_physics->setMotor(m.hinges[j], motorMode(m.commands[j].mode), m.commands[j].value);
}

void World::step() {
  if (!m_started) start();
  if (m_fatal || !m_scriptError.empty()) return;
  const auto t0 = Clock::now();
  // 1. Deliver what was routed last step.
  for (Mailbox& box : m_mailboxes) box.deliver();
  // 2. Behaviours (in parallel when --threads > 1).
  const auto t1 = Clock::now();
  runBehaviours();
  const auto t2 = Clock::now();
  // 3. Route messages over engaged docks (readable next step).
  routeMessages();
  // 4. Undock and 5. dock: connections change only through world.connect in this version.
  // 6. Actuators, then physics.
  applyActuators();
  const auto t3 = Clock::now();
  m_physics->step(m_settings.dt, m_settings.substeps);
  const auto t4 = Clock::now();
  // 7. Breakage detection comes with run-time docking.
  ++m_steps;
  m_time = double(m_steps) * m_settings.dt;
  std::string err;
  if (m_script && !m_script->afterStep(m_time, err)) m_scriptError = err;
  const auto t5 = Clock::now();
  m_times.behaviours = msSince(t1, t2);
  m_times.physics = msSince(t3, t4);
  m_times.other = msSince(t0, t5) - m_times.behaviours - m_times.physics;
}

Pose World::linkPose(int m, int link) const { return m_physics->partPose(m_modules[size_t(m)].parts[size_t(link)]); }
Pose World::modulePose(int m) const { return linkPose(m, m_modules[size_t(m)].type->rootLink); }

Pose World::dockPose(int m, int dock) const {
  const DockDef& d = m_modules[size_t(m)].type->docks[size_t(dock)];
  return linkPose(m, d.link) * dockFrame(d);
}

double World::jointAngle(int m, int joint) const {
  return m_physics->hingeAngle(m_modules[size_t(m)].hinges[size_t(joint)]);
}

double World::jointVelocity(int m, int joint) const {
  return m_physics->hingeVelocity(m_modules[size_t(m)].hinges[size_t(joint)]);
}

void World::sampleTracking() {
  for (size_t i = 0; i < m_modules.size(); ++i) {
    const Module& m = m_modules[i];
    for (size_t j = 0; j < m.commands.size(); ++j) {
      if (m.commands[j].mode != JointMode::Servo) continue;
      const JointDef& jd = m.type->joints[j];
      const double target = jd.limited ? std::clamp(m.commands[j].value, jd.lower, jd.upper) : m.commands[j].value;
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
  for (const Connection& c : m_connections) {
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
    std::vector<int> c = componentOf(int(i));
    for (int m : c) seen[size_t(m)] = 1;
    std::sort(c.begin(), c.end());
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace rm3d
