// The run summary (`--json`): the fields docs/command-line.md lists, module by module, in id order.
#include "io/summary.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "world/world.h"

namespace rm3d {

namespace {
/// JSON has no NaN or infinity (nlohmann writes null): after a divergence such values are
/// written as the strings "nan", "inf" and "-inf".
nlohmann::json number(double v) {
  if (std::isfinite(v)) return v;
  return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
}
}  // namespace

nlohmann::json runSummary(const World& w, double wallSeconds) {
  using nlohmann::json;
  json j;
  j["world"] = w.worldFile();
  j["sim_time"] = w.time();
  j["steps"] = w.steps();
  j["dt"] = w.settings().dt;
  j["solver"] = solverName(w.settings().solver);
  j["substeps"] = w.settings().substeps;
  j["solver_iterations"] = w.settings().solverIterations;
  j["wall_seconds"] = wallSeconds;
  j["seed"] = w.settings().seed;
  json mods = json::array();
  for (size_t i = 0; i < w.modules().size(); ++i) {
    const Module& m = w.modules()[i];
    json mj;
    mj["id"] = m.id;
    mj["name"] = m.name;
    mj["type"] = m.type->name;
    if (w.hasPhysics()) {
      const Pose p = w.modulePose(int(i));
      mj["position"] = {number(p.pos.x()), number(p.pos.y()), number(p.pos.z())};
      mj["orientation"] = {number(p.rot.w()), number(p.rot.x()), number(p.rot.y()), number(p.rot.z())};
    }
    json joints = json::object();
    for (size_t k = 0; k < m.type->joints.size(); ++k)
      joints[m.type->joints[k].name] = number(w.jointAngle(int(i), int(k)));
    mj["joints"] = joints;
    json docks = json::object();
    for (size_t k = 0; k < m.docks.size(); ++k) {
      const DockState& d = m.docks[k];
      json dj = {
          {"enabled", d.enabled}, {"engaged", d.engaged}, {"peer_module", nullptr}, {"peer_dock", nullptr}};
      if (d.engaged) {
        dj["peer_module"] = w.modules()[size_t(d.peerModule)].id;
        dj["peer_dock"] = w.modules()[size_t(d.peerModule)].type->docks[size_t(d.peerDock)].name;
      }
      docks[m.type->docks[k].name] = dj;
    }
    mj["docks"] = docks;
    mj["error"] = m.fault.empty() ? json(nullptr) : json(m.fault);
    mods.push_back(mj);
  }
  j["modules"] = mods;
  auto dockName = [&](int m, int d) { return w.modules()[size_t(m)].type->docks[size_t(d)].name; };
  json conns = json::array();
  for (const Connection& c : w.connections())
    conns.push_back({w.modules()[size_t(c.moduleA)].id, dockName(c.moduleA, c.dockA),
                     w.modules()[size_t(c.moduleB)].id, dockName(c.moduleB, c.dockB)});
  j["connections"] = conns;
  json events = json::array();
  for (const DockEvent& e : w.events()) {
    json ej = {{"time", e.time},
               {"event", dockEventName(e.kind)},
               {"module_a", w.modules()[size_t(e.moduleA)].id},
               {"dock_a", dockName(e.moduleA, e.dockA)},
               {"module_b", w.modules()[size_t(e.moduleB)].id},
               {"dock_b", dockName(e.moduleB, e.dockB)}};
    if (e.force >= 0) ej["load"] = {{"force", number(e.force)}, {"torque", number(e.torque)}};
    if (e.gap >= 0) ej["left"] = {{"distance", number(e.gap)}, {"angle", number(e.angle * kDegPerRad)}};
    events.push_back(ej);
  }
  const MessageStats ms = w.messageStats();
  j["messages"] = {{"sent", ms.sent}, {"received", ms.received}, {"dropped", ms.dropped}};
  j["events"] = events;
  json failures = json::array();
  for (const Failure& f : w.failures()) failures.push_back({{"time", f.time}, {"message", f.message}});
  j["failures"] = failures;
  json metrics = json::object();
  for (const auto& [name, value] : w.metrics()) metrics[name] = value;
  j["metrics"] = metrics;
  // Environment: kind, count, bounds and whether any node is not finite, per cloth.
  json env = json::array();
  for (size_t c = 0; c < w.cloths().size(); ++c) {
    const World::ClothStats st = w.clothStats(int(c));
    auto vec = [&](const Vec3& v) { return json{number(v.x()), number(v.y()), number(v.z())}; };
    env.push_back({{"kind", "cloth"},
                   {"count", st.nodes},
                   {"resolution", {w.cloths()[c].nx, w.cloths()[c].ny}},
                   {"bounds", {{"min", vec(st.lo)}, {"max", vec(st.hi)}}},
                   {"nan", st.nan}});
  }
  if (!env.empty()) j["environment"] = env;  // absent without any: older summaries stay as they were
  if (!w.particleSystems().empty()) {        // only then, so summaries without particles keep their bytes
    json systems = json::array();
    for (const auto& ps : w.particleSystems()) {
      Vec3 lo, hi;
      ps->bounds(lo, hi);
      const Vec3 v = ps->meanVelocity();
      systems.push_back({{"kind", ps->kindName()},
                         {"count", ps->count()},
                         {"bounds",
                          {{"min", {number(lo.x()), number(lo.y()), number(lo.z())}},
                           {"max", {number(hi.x()), number(hi.y()), number(hi.z())}}}},
                         {"mean_velocity", {number(v.x()), number(v.y()), number(v.z())}},
                         {"nan", ps->nanCount()}});
    }
    j["particles"] = systems;
  }
  j["faults"] = w.faultCount();
  const std::string& error = w.scriptError().empty() ? w.divergence() : w.scriptError();
  j["error"] = error.empty() ? json(nullptr) : json(error);
  return j;
}

namespace {

struct Fnv {
  uint64_t h = 0xcbf29ce484222325ull;
  void bytes(const void* p, size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 0x100000001b3ull;
  }
  void f(double v) { bytes(&v, sizeof v); }
  void i(int64_t v) { bytes(&v, sizeof v); }
  void s(const std::string& v) { bytes(v.data(), v.size()); }
};

}  // namespace

uint64_t stateDigest(const World& w) {
  Fnv h;
  h.i(w.steps());
  for (size_t m = 0; m < w.modules().size(); ++m) {
    const Module& mod = w.module(int(m));
    for (size_t l = 0; l < mod.type->links.size(); ++l) {
      const Pose p = w.linkPose(int(m), int(l));
      for (int k = 0; k < 3; ++k) h.f(p.pos[k]);
      h.f(p.rot.w()), h.f(p.rot.x()), h.f(p.rot.y()), h.f(p.rot.z());
    }
    for (size_t j = 0; j < mod.type->joints.size(); ++j) h.f(w.jointVelocity(int(m), int(j)));
    for (const DockState& d : mod.docks) h.i(d.enabled), h.i(d.engaged), h.i(d.peerModule), h.i(d.peerDock);
    h.s(mod.fault);
  }
  for (const Connection& c : w.connections()) h.i(c.moduleA), h.i(c.dockA), h.i(c.moduleB), h.i(c.dockB);
  for (const DockEvent& e : w.events())
    h.f(e.time), h.s(dockEventName(e.kind)), h.i(e.moduleA), h.i(e.moduleB);
  const World::MessageStats ms = w.messageStats();
  h.i(int64_t(ms.sent)), h.i(int64_t(ms.received)), h.i(int64_t(ms.dropped));
  nlohmann::json j = runSummary(w, 0);
  j.erase("wall_seconds");
  j.erase("world");  // the world file's absolute path: differs between checkouts
  h.s(j.dump());
  return h.h;
}

}  // namespace rm3d
