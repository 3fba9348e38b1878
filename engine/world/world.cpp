// World: building modules from their types, the seven-phase step, and the queries the
// bindings, the summary and the benchmarks use.
#include "world/world.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "docking/dock_frame.h"
#include "script/behaviour.h"
#include "script/lua_vm.h"

#include <lua.hpp>
#include "script/module_type_loader.h"
#include "script/watchdog.h"
#include "script/world_script.h"
#include "world/behaviour_pool.h"
#include "world/module_handle.h"

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
    t.dockReach = std::max(t.dockReach, std::max(0.0, path[size_t(d.link)]) + (d.pos - lastPivot[size_t(d.link)]).norm() + d.captureRadius);
}

}  // namespace

World::World(RunOptions options) : m_options(std::move(options)) {
  if (m_options.seed) m_settings.seed = *m_options.seed;
  m_pool = std::make_unique<BehaviourPool>(std::max(1, m_options.threads), std::max(1, m_options.chunkSize));
  if (m_options.watchdogSeconds > 0) m_watchdog = std::make_unique<Watchdog>(m_options.watchdogSeconds);
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
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".lua") == 0) {
    // A module-type file given by path (a variant kept next to a world, say).
    const std::string path = resolvePath(name);
    if (path.empty()) throw InputError("module type file '" + name + "' not found (looked in the world's folder and the project root)");
    auto def = std::make_unique<ModuleTypeDef>(loadModuleType(path, m_options.projectRoot));
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
  prepareType(*def);
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
  // A named module's stream follows its name, so adding or reordering other modules never
  // changes its numbers; an unnamed one's follows its id (its place in spawn order).
  m.rng.seed(m_settings.seed, def.name.empty() ? uint64_t(m.id) : streamOfName(def.name));
  m.fixed = def.fixed;
  for (size_t l = 0; l < type.links.size(); ++l) {
    const LinkDef& link = type.links[l];
    PartDesc d;
    d.shapes = link.shapes;
    d.mass = def.fixed && int(l) == type.rootLink ? 0.0 : link.mass;  // mass 0: static
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
    m_behaviours.back() = std::make_unique<Behaviour>(m_options, ModuleHandle(*this, index));
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
  const DockError e = dockError(dockPose(a, da), dockPose(b, db));
  const bool facing = e.gap <= 0.001 && e.angle <= 1.0 / kDegPerRad;
  if (std::find(comp.begin(), comp.end(), a) != comp.end() && !facing) {
    // Closing a loop: both docks are placed already; they must face each other.
    throw InputError(ma.name + " and " + mb.name +
                     " are already connected another way and these docks do not face each other (gap " +
                     std::to_string(e.gap * 1000) + " mm, angle " + std::to_string(e.angle * kDegPerRad) +
                     " deg; at most 1 mm and 1 deg)");
  }
  // Docks that already face each other are locked where they are (closing a loop, or modules
  // placed by hand); otherwise b's side is moved so the faces mate exactly.
  lock(a, da, b, db, orientation, !facing);
}

void World::lock(int a, int da, int b, int db, int orientation, bool snap) {
  Module& ma = m_modules[size_t(a)];
  Module& mb = m_modules[size_t(b)];
  const DockDef& defA = ma.type->docks[size_t(da)];
  const DockDef& defB = mb.type->docks[size_t(db)];
  if (snap) {
    // Move the side that is free to move (not holding a fixed module, not already joined to
    // the other) so the two faces mate exactly.
    std::vector<int> compB = componentOf(b), compA = componentOf(a);
    const bool loop = std::find(compB.begin(), compB.end(), a) != compB.end();
    auto holdsFixed = [&](const std::vector<int>& c) {
      return std::any_of(c.begin(), c.end(), [&](int m) { return m_modules[size_t(m)].fixed; });
    };
    if (!loop) {
      const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
      if (!holdsFixed(compB)) {
        const Pose delta = matingFrame(dockPose(a, da), orientation, sym) * dockPose(b, db).inverse();
        std::vector<int> parts;
        for (int m : compB)
          for (int p : m_modules[size_t(m)].parts) parts.push_back(p);
        m_physics->transformParts(parts, delta);
      } else if (!holdsFixed(compA)) {
        const Pose delta = matingFrame(dockPose(b, db), orientation, sym) * dockPose(a, da).inverse();
        std::vector<int> parts;
        for (int m : compA)
          for (int p : m_modules[size_t(m)].parts) parts.push_back(p);
        m_physics->transformParts(parts, delta);
      }
    }
  }
  m_physics->lockParts(ma.parts[size_t(defA.link)], mb.parts[size_t(defB.link)]);
  ++m_topology;
  for (auto [st, peer, peerDock] : {std::tuple{&ma.docks[size_t(da)], b, db}, std::tuple{&mb.docks[size_t(db)], a, da}}) {
    st->engaged = true;
    st->peerModule = peer;
    st->peerDock = peerDock;
    st->brokeFromModule = st->brokeFromDock = -1;
  }
  Connection c{a, da, b, db, m_time};
  m_connections.push_back(c);
  m_events.push_back({m_time, "engaged", a, da, b, db});
  if (m_started) {
    ma.dockEvents.emplace_back(da, "engaged");
    mb.dockEvents.emplace_back(db, "engaged");
  }
}

void World::release(size_t index, const char* kind, double force, double torque) {
  const Connection c = std::move(m_connections[index]);
  m_connections.erase(m_connections.begin() + std::ptrdiff_t(index));
  Module& ma = m_modules[size_t(c.moduleA)];
  Module& mb = m_modules[size_t(c.moduleB)];
  m_physics->unlockParts(ma.parts[size_t(ma.type->docks[size_t(c.dockA)].link)],
                         mb.parts[size_t(mb.type->docks[size_t(c.dockB)].link)]);
  ++m_topology;
  const bool broken = std::string_view(kind) == "broken";
  ma.docks[size_t(c.dockA)].brokeFromModule = broken ? c.moduleB : -1;
  ma.docks[size_t(c.dockA)].brokeFromDock = broken ? c.dockB : -1;
  mb.docks[size_t(c.dockB)].brokeFromModule = broken ? c.moduleA : -1;
  mb.docks[size_t(c.dockB)].brokeFromDock = broken ? c.dockA : -1;
  for (auto [m, d] : {std::pair<Module*, int>{&ma, c.dockA}, std::pair<Module*, int>{&mb, c.dockB}}) {
    DockState& st = m->docks[size_t(d)];
    st.engaged = false;
    st.peerModule = st.peerDock = -1;
    m->dockEvents.emplace_back(d, kind);
  }
  m_mailboxes[size_t(c.moduleA)].dropInFlight(c.dockA);  // counted as dropped by the receiver
  m_mailboxes[size_t(c.moduleB)].dropInFlight(c.dockB);
  m_events.push_back({m_time, kind, c.moduleA, c.dockA, c.moduleB, c.dockB, force, torque});
}

bool World::disconnect(int m, int dock) {
  for (size_t i = 0; i < m_connections.size(); ++i) {
    const Connection& c = m_connections[i];
    if ((c.moduleA == m && c.dockA == dock) || (c.moduleB == m && c.dockB == dock)) {
      release(i, "disengaged", -1, -1);
      return true;
    }
  }
  return false;
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
  m_channelRng.seed(m_settings.seed, 0xC4A77E1ull);
  for (const auto& [name, type] : m_types)
    for (const DockDef& d : type->docks) m_captureCell = std::max(m_captureCell, d.captureRadius);
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
  if (!b) {
    m_modules[size_t(i)].dockEvents.clear();
    return;
  }
  Module& m = m_modules[size_t(i)];
  if (!m.fault.empty()) {
    m.dockEvents.clear();
    return;
  }
  std::string err;
  for (const auto& [dock, kind] : m.dockEvents)
    if (!b->callOnDock(dock, kind, err)) {
      m.fault = err.empty() ? "fault" : err;
      m.dockEvents.clear();
      return;
    }
  m.dockEvents.clear();
  if (!b->callStep(m_settings.dt, err)) m.fault = err.empty() ? "fault" : err;
}

void World::runBehaviours() {
  // Everything a behaviour can read is fixed before the phase (module_handle.h states the rule).
  if (m_proximityWanted.load(std::memory_order_relaxed)) buildProximity();
  const int n = int(m_modules.size());
  m_pool->run(n, [this](int i) { runBehaviour(i); });
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
        for (const std::string& line : m.log) std::fprintf(stderr, "[%8.3f %s] %s\n", m_time, m.name.c_str(), line.c_str());
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
    if (m_channel.rate > 0) m_dockSent.assign(m.docks.size(), 0);
    size_t kept = 0;
    for (size_t k = 0; k < box.outbox.size(); ++k) {
      Message& msg = box.outbox[k];
      const DockState& d = m.docks[size_t(msg.dock)];
      if (!d.engaged) {
        ++box.dropped;
        continue;
      }
      if (m_channel.rate > 0 && m_dockSent[size_t(msg.dock)]++ >= m_channel.rate) {
        // Bandwidth: at most `rate` messages leave a dock per step; the rest wait, in order.
        if (kept != k) box.outbox[kept] = std::move(msg);
        ++kept;
        continue;
      }
      ++box.sent;
      if (m_channel.loss > 0 && m_channelRng.uniform() < m_channel.loss) {
        ++m_lostMessages;
        continue;
      }
      msg.dock = d.peerDock;
      msg.due = m_steps + 1 + m_channel.delay;
      if (m_mailboxes[size_t(d.peerModule)].accept(std::move(msg), m_options.mailboxLimit) == Mailbox::Accept::FirstDrop)
        m_modules[size_t(d.peerModule)].log.push_back("messages dropped: over " + std::to_string(m_options.mailboxLimit >> 20) +
                                                      " MiB of unread messages (read them with module.receive)");
    }
    box.outbox.resize(kept);
  }
}

void World::undockPhase() {
  for (size_t i = 0; i < m_connections.size();) {
    const Connection& c = m_connections[i];
    if (!m_modules[size_t(c.moduleA)].docks[size_t(c.dockA)].enabled ||
        !m_modules[size_t(c.moduleB)].docks[size_t(c.dockB)].enabled)
      release(i, "disengaged", -1, -1);
    else
      ++i;
  }
}

int World::bestOrientation(int a, int da, int b, int db) const {
  const DockDef& defA = m_modules[size_t(a)].type->docks[size_t(da)];
  const DockDef& defB = m_modules[size_t(b)].type->docks[size_t(db)];
  const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
  const Pose pa = dockPose(a, da), pb = dockPose(b, db);
  int best = 0;
  double bestAngle = 1e9;
  for (int k = 0; k < sym; ++k) {
    const Pose want = matingFrame(pa, k, sym);
    const double ang = angleBetween(want.rot * Vec3::UnitZ(), pb.rot * Vec3::UnitZ());
    if (ang < bestAngle) {
      bestAngle = ang;
      best = k;
    }
  }
  return best;
}

void World::dockPhase() {
  // Coarse pass: each module with a free dock is a box around its root link, as large as its
  // docks can reach (ModuleTypeDef::dockReach); a sweep along x finds the boxes that overlap.
  // Only those modules' docks are posed and searched below, so isolated modules cost one pose.
  m_dockBoxes.clear();
  for (size_t i = 0; i < m_modules.size(); ++i) {
    const Module& m = m_modules[i];
    bool anyFree = false;
    for (const DockState& st : m.docks) anyFree |= st.enabled && !st.engaged;
    if (!anyFree) continue;
    const Vec3 c = modulePose(int(i)).pos;
    const Vec3 r = Vec3::Constant(m.type->dockReach);
    m_dockBoxes.push_back({c - r, c + r, i, false});
  }
  std::sort(m_dockBoxes.begin(), m_dockBoxes.end(), [](const DockBox& a, const DockBox& b) {
    return a.lo.x() < b.lo.x() || (a.lo.x() == b.lo.x() && a.module < b.module);
  });
  for (size_t a = 0; a < m_dockBoxes.size(); ++a)
    for (size_t b = a + 1; b < m_dockBoxes.size() && m_dockBoxes[b].lo.x() <= m_dockBoxes[a].hi.x(); ++b) {
      DockBox& ba = m_dockBoxes[a];
      DockBox& bb = m_dockBoxes[b];
      if (ba.lo.y() <= bb.hi.y() && bb.lo.y() <= ba.hi.y() && ba.lo.z() <= bb.hi.z() && bb.lo.z() <= ba.hi.z())
        ba.near = bb.near = true;
    }
  std::sort(m_dockBoxes.begin(), m_dockBoxes.end(), [](const DockBox& a, const DockBox& b) { return a.module < b.module; });
  // Fine pass: the free docks of modules near another, hashed into cells.
  m_freeDocks.clear();
  for (const DockBox& box : m_dockBoxes) {
    const int i = int(box.module);
    Module& m = m_modules[box.module];
    if (!box.near) {  // nothing within reach: any broken partner is far away by now
      for (DockState& st : m.docks) st.brokeFromModule = st.brokeFromDock = -1;
      continue;
    }
    m_linkPoseValid.assign(m.type->links.size(), 0);
    if (m_linkPoses.size() < m.type->links.size()) m_linkPoses.resize(m.type->links.size());
    for (size_t d = 0; d < m.docks.size(); ++d) {
      DockState& st = m.docks[d];
      if (!st.enabled || st.engaged || !st.latchable) continue;
      const DockDef& def = m.type->docks[d];
      if (!m_linkPoseValid[size_t(def.link)]) {  // one pose per link, not per dock
        m_linkPoses[size_t(def.link)] = linkPose(i, def.link);
        m_linkPoseValid[size_t(def.link)] = 1;
      }
      const Pose pose = m_linkPoses[size_t(def.link)] * def.frame;
      if (st.brokeFromModule >= 0 &&
          (pose.pos - dockPose(st.brokeFromModule, st.brokeFromDock).pos).norm() > def.captureRadius)
        st.brokeFromModule = st.brokeFromDock = -1;
      m_freeDocks.push_back({i, int(d), pose});
    }
  }
  if (m_freeDocks.size() < 2) return;
  // Cells twice the largest capture radius: every dock within reach of a point lies in the 2x2x2
  // block of cells on the point's side of its own cell (8 look-ups, not 27).
  const double cell = 2.0 * m_captureCell;
  auto cellOf = [cell](const Vec3& p) {
    return Eigen::Vector3i(int(std::floor(p.x() / cell)), int(std::floor(p.y() / cell)), int(std::floor(p.z() / cell)));
  };
  auto key = [](const Eigen::Vector3i& c) {
    return (uint64_t(uint32_t(c.x())) * 73856093ull) ^ (uint64_t(uint32_t(c.y())) * 19349663ull) ^
           (uint64_t(uint32_t(c.z())) * 83492791ull);
  };
  // Open-addressing table of cells, each holding a chain of docks (head per slot, next per dock).
  size_t cap = 16;
  while (cap < 2 * m_freeDocks.size()) cap <<= 1;
  m_cellKeys.resize(cap);
  m_cellHead.assign(cap, -1);
  m_cellNext.resize(m_freeDocks.size());
  auto slotOf = [&](uint64_t k) {
    size_t h = size_t((k * 0x9E3779B97F4A7C15ull) >> 20) & (cap - 1);
    while (m_cellHead[h] >= 0 && m_cellKeys[h] != k) h = (h + 1) & (cap - 1);
    return h;
  };
  for (size_t i = 0; i < m_freeDocks.size(); ++i) {
    const uint64_t k = key(cellOf(m_freeDocks[i].pose.pos));
    const size_t h = slotOf(k);
    m_cellKeys[h] = k;
    m_cellNext[i] = m_cellHead[h];
    m_cellHead[h] = int(i);
  }
  m_latches.clear();
  for (size_t i = 0; i < m_freeDocks.size(); ++i) {
    const FreeDock& fa = m_freeDocks[i];
    const Eigen::Vector3i c = cellOf(fa.pose.pos);
    Eigen::Vector3i side;
    for (int a = 0; a < 3; ++a) side[a] = fa.pose.pos[a] / cell - double(c[a]) < 0.5 ? -1 : 1;
    for (int dx = 0; dx < 2; ++dx)
      for (int dy = 0; dy < 2; ++dy)
        for (int dz = 0; dz < 2; ++dz) {
          const uint64_t k = key(c + Eigen::Vector3i(dx * side.x(), dy * side.y(), dz * side.z()));
          for (int e = m_cellHead[slotOf(k)]; e >= 0; e = m_cellNext[size_t(e)]) {
            if (e <= int(i)) continue;  // each pair once
            const FreeDock& fb = m_freeDocks[size_t(e)];
            if (fb.module == fa.module) continue;
            const DockState& sa = m_modules[size_t(fa.module)].docks[size_t(fa.dock)];
            if (sa.brokeFromModule == fb.module && sa.brokeFromDock == fb.dock) continue;
            const DockDef& da = m_modules[size_t(fa.module)].type->docks[size_t(fa.dock)];
            const DockDef& db = m_modules[size_t(fb.module)].type->docks[size_t(fb.dock)];
            if (!gendersMate(da.gender, db.gender)) continue;
            const Vec3 gapVec = fb.pose.pos - fa.pose.pos;
            const double gap = gapVec.norm();
            if (gap > std::min(da.captureRadius, db.captureRadius)) continue;
            const Vec3 na = fa.pose.rot * Vec3::UnitX(), nb = fb.pose.rot * Vec3::UnitX();
            const double facing = angleBetween(na, -nb);
            if (facing > std::min(da.captureAngle, db.captureAngle)) continue;
            const double latchAngle = std::min(da.latchAngle, db.latchAngle);
            if (gap <= std::min(da.latchDistance, db.latchDistance) && facing <= latchAngle) {
              const int sym = std::max(1, std::min(da.symmetry, db.symmetry));
              const Pose want = matingFrame(fa.pose, bestOrientation(fa.module, fa.dock, fb.module, fb.dock), sym);
              if (angleBetween(want.rot * Vec3::UnitZ(), fb.pose.rot * Vec3::UnitZ()) <= latchAngle) {
                m_latches.push_back(fa.module < fb.module ? Latch{fa.module, fa.dock, fb.module, fb.dock}
                                                          : Latch{fb.module, fb.dock, fa.module, fa.dock});
                continue;
              }
            }
            // The magnet: equal and opposite pulls at the two faces, plus a torque turning the
            // faces towards each other.
            const double pull = std::min(da.pull, db.pull);
            if (pull <= 0) continue;
            const Vec3 dir = gap > 1e-9 ? Vec3(gapVec / gap) : Vec3(-na);
            const Module& ma = m_modules[size_t(fa.module)];
            const Module& mb = m_modules[size_t(fb.module)];
            const int pa = ma.parts[size_t(da.link)], pb = mb.parts[size_t(db.link)];
            m_physics->addForce(pa, pull * dir, fa.pose.pos);
            m_physics->addForce(pb, -pull * dir, fb.pose.pos);
            // Torques of the order pull x face size turn the faces square to each other and
            // twist them about the normal into the nearest of their mating orientations.
            const double arm = pull * std::min(da.size, db.size);
            const int sym = std::max(1, std::min(da.symmetry, db.symmetry));
            const Vec3 wantUp = matingFrame(fa.pose, bestOrientation(fa.module, fa.dock, fb.module, fb.dock), sym).rot * Vec3::UnitZ();
            const Vec3 turn = na.cross(-nb) * arm + (fb.pose.rot * Vec3::UnitZ()).cross(wantUp).dot(nb) * nb * arm;
            m_physics->addTorque(pa, -turn);
            m_physics->addTorque(pb, turn);
          }
        }
  }
  std::sort(m_latches.begin(), m_latches.end());
  for (const Latch& l : m_latches) {
    const Module& ma = m_modules[size_t(l.a)];
    const Module& mb = m_modules[size_t(l.b)];
    if (ma.docks[size_t(l.da)].engaged || mb.docks[size_t(l.db)].engaged) continue;  // took another this step
    // An earlier latch this step may have moved one side: check the faces again.
    const DockDef& da = ma.type->docks[size_t(l.da)];
    const DockDef& db = mb.type->docks[size_t(l.db)];
    const DockError e = dockError(dockPose(l.a, l.da), dockPose(l.b, l.db));
    if (e.gap > std::min(da.latchDistance, db.latchDistance) || e.angle > std::min(da.latchAngle, db.latchAngle)) continue;
    lock(l.a, l.da, l.b, l.db, bestOrientation(l.a, l.da, l.b, l.db), true);
  }
}

Wrench World::connectionLoad(const Connection& c) const {
  const Module& ma = m_modules[size_t(c.moduleA)];
  const Module& mb = m_modules[size_t(c.moduleB)];
  const int pa = ma.parts[size_t(ma.type->docks[size_t(c.dockA)].link)];
  const int pb = mb.parts[size_t(mb.type->docks[size_t(c.dockB)].link)];
  // B's side: the parts locked to B's link without crossing this connection. In a closed loop
  // that reaches A's side too, so only B's own link is counted. Recomputed only when the lock
  // graph has changed.
  if (c.sideOf != m_topology) {
    c.side = m_physics->lockedGroup(pb, pa, pb);
    if (std::find(c.side.begin(), c.side.end(), pa) != c.side.end()) c.side = {pb};
    c.sideOf = m_topology;
  }
  return m_physics->internalLoad(c.side, dockPose(c.moduleB, c.dockB).pos);
}

void World::breakagePhase() {
  for (size_t i = 0; i < m_connections.size();) {
    const Connection& c = m_connections[i];
    const DockDef& da = m_modules[size_t(c.moduleA)].type->docks[size_t(c.dockA)];
    const DockDef& db = m_modules[size_t(c.moduleB)].type->docks[size_t(c.dockB)];
    const Wrench w = connectionLoad(c);
    const double f = w.force.norm(), t = w.torque.norm();
    if (f > std::min(da.strength, db.strength) || t > std::min(da.strengthTorque, db.strengthTorque))
      release(i, "broken", f, t);
    else
      ++i;
  }
}

void World::applyActuators() {
  for (const Module& m : m_modules)
    for (size_t j = 0; j < m.hinges.size(); ++j) {
      if (m.stalled[j]) m_physics->setMotor(m.hinges[j], MotorMode::Servo, m.stallAngle[j]);  // stuck where it failed
      else m_physics->setMotor(m.hinges[j], motorMode(m.commands[j].mode), m.commands[j].value);
    }
}

void World::step() {
  if (!m_started) start();
  if (m_fatal || !m_scriptError.empty()) return;
  const auto t0 = Clock::now();
  // 1. Deliver what was routed earlier and is due now.
  for (Mailbox& box : m_mailboxes) box.deliver(m_steps);
  // 2. Behaviours (in parallel when --threads > 1).
  const auto t1 = Clock::now();
  runBehaviours();
  const auto t2 = Clock::now();
  // 3. Route messages over engaged docks (readable next step).
  routeMessages();
  // 4. Undock: connections where either dock is now disabled are released.
  undockPhase();
  // 5. Dock: free compatible docks attract; aligned ones latch.
  dockPhase();
  // 6. Actuators, then physics.
  applyActuators();
  m_physics->setLoadTracking(!m_connections.empty());
  m_physics->setContactTracking(m_contactSensors);
  const auto t3 = Clock::now();
  m_physics->step(m_settings.dt, m_settings.substeps);
  const auto t4 = Clock::now();
  updateAccelerometers();
  // 7. Connections whose transmitted load exceeds the docks' strength break.
  breakagePhase();
  ++m_steps;
  m_time = double(m_steps) * m_settings.dt;
  if (checkDivergence(*this, m_divergence)) { m_fatal = true; return; }  // world/divergence.h
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
  return linkPose(m, d.link) * d.frame;
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

std::string World::graphJson() const {
  nlohmann::json j;
  j["time"] = m_time;
  j["modules"] = nlohmann::json::array();
  for (const Module& m : m_modules) j["modules"].push_back({{"id", m.id}, {"name", m.name}, {"type", m.type->name}});
  j["connections"] = nlohmann::json::array();
  for (const Connection& c : m_connections)
    j["connections"].push_back({m_modules[size_t(c.moduleA)].id, m_modules[size_t(c.moduleA)].type->docks[size_t(c.dockA)].name,
                                m_modules[size_t(c.moduleB)].id, m_modules[size_t(c.moduleB)].type->docks[size_t(c.dockB)].name});
  j["components"] = nlohmann::json::array();
  for (const auto& comp : components()) {
    nlohmann::json ids = nlohmann::json::array();
    for (int m : comp) ids.push_back(m_modules[size_t(m)].id);
    j["components"].push_back(ids);
  }
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string World::graphDot() const {
  std::string out = "graph rm3d {\n  node [shape=box];\n";
  char line[256];
  for (const Module& m : m_modules) {
    std::snprintf(line, sizeof line, "  m%d [label=\"%s\\n%s\"];\n", m.id, m.name.c_str(), m.type->name.c_str());
    out += line;
  }
  for (const Connection& c : m_connections) {
    const Module& a = m_modules[size_t(c.moduleA)];
    const Module& b = m_modules[size_t(c.moduleB)];
    std::snprintf(line, sizeof line, "  m%d -- m%d [taillabel=\"%s\", headlabel=\"%s\"];\n", a.id, b.id,
                  a.type->docks[size_t(c.dockA)].name.c_str(), b.type->docks[size_t(c.dockB)].name.c_str());
    out += line;
  }
  return out + "}\n";
}

World::MessageStats World::messageStats() const {
  MessageStats st;
  for (const Mailbox& b : m_mailboxes) {
    st.sent += b.sent;
    st.received += b.received;
    st.dropped += b.dropped;
  }
  st.dropped += m_lostMessages;
  return st;
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

namespace rm3d {

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
  Behaviour* b = m_behaviours[size_t(module)].get();
  if (!b) return {};
  return b->describePercepts();
}

int World::reloadFile(const std::string& path, std::vector<std::string>& errors) {
  const bool library = fs::path(path).parent_path() == fs::path(m_options.projectRoot) / "lua";
  int reloaded = 0;
  std::map<std::string, std::string> sources;  // each file read once
  for (size_t i = 0; i < m_modules.size(); ++i) {
    Module& m = m_modules[i];
    Behaviour* b = m_behaviours[i].get();
    if (!b || (!library && m.behaviourFile != path)) continue;
    auto it = sources.find(m.behaviourFile);
    if (it == sources.end()) {
      std::string t;
      if (!readTextFile(m.behaviourFile, t)) {
        errors.push_back(m.behaviourFile + ": cannot read file");
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
