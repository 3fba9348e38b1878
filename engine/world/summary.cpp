// The run summary (`--json`): the fields docs/command-line.md lists, module by module, in id order.
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

nlohmann::json World::summary(double wallSeconds) const {
  using nlohmann::json;
  json j;
  j["world"] = m_worldFile;
  j["sim_time"] = m_time;
  j["steps"] = m_steps;
  j["dt"] = m_settings.dt;
  j["solver"] = solverName(m_settings.solver);
  j["substeps"] = m_settings.substeps;
  j["solver_iterations"] = m_settings.solverIterations;
  j["wall_seconds"] = wallSeconds;
  j["seed"] = m_settings.seed;
  json mods = json::array();
  for (size_t i = 0; i < m_modules.size(); ++i) {
    const Module& m = m_modules[i];
    json mj;
    mj["id"] = m.id;
    mj["name"] = m.name;
    mj["type"] = m.type->name;
    if (m_physics) {
      const Pose p = modulePose(int(i));
      mj["position"] = {number(p.pos.x()), number(p.pos.y()), number(p.pos.z())};
      mj["orientation"] = {number(p.rot.w()), number(p.rot.x()), number(p.rot.y()), number(p.rot.z())};
    }
    json joints = json::object();
    for (size_t k = 0; k < m.type->joints.size(); ++k)
      joints[m.type->joints[k].name] = number(jointAngle(int(i), int(k)));
    mj["joints"] = joints;
    json docks = json::object();
    for (size_t k = 0; k < m.docks.size(); ++k) {
      const DockState& d = m.docks[k];
      json dj = {
          {"enabled", d.enabled}, {"engaged", d.engaged}, {"peer_module", nullptr}, {"peer_dock", nullptr}};
      if (d.engaged) {
        dj["peer_module"] = m_modules[size_t(d.peerModule)].id;
        dj["peer_dock"] = m_modules[size_t(d.peerModule)].type->docks[size_t(d.peerDock)].name;
      }
      docks[m.type->docks[k].name] = dj;
    }
    mj["docks"] = docks;
    mj["error"] = m.fault.empty() ? json(nullptr) : json(m.fault);
    mods.push_back(mj);
  }
  j["modules"] = mods;
  auto dockName = [&](int m, int d) { return m_modules[size_t(m)].type->docks[size_t(d)].name; };
  json conns = json::array();
  for (const Connection& c : connections())
    conns.push_back({m_modules[size_t(c.moduleA)].id, dockName(c.moduleA, c.dockA),
                     m_modules[size_t(c.moduleB)].id, dockName(c.moduleB, c.dockB)});
  j["connections"] = conns;
  json events = json::array();
  for (const DockEvent& e : World::events()) {
    json ej = {{"time", e.time},
               {"event", dockEventName(e.kind)},
               {"module_a", m_modules[size_t(e.moduleA)].id},
               {"dock_a", dockName(e.moduleA, e.dockA)},
               {"module_b", m_modules[size_t(e.moduleB)].id},
               {"dock_b", dockName(e.moduleB, e.dockB)}};
    if (e.force >= 0) ej["load"] = {{"force", number(e.force)}, {"torque", number(e.torque)}};
    events.push_back(ej);
  }
  const MessageStats ms = messageStats();
  j["messages"] = {{"sent", ms.sent}, {"received", ms.received}, {"dropped", ms.dropped}};
  j["events"] = events;
  json failures = json::array();
  for (const Failure& f : m_failures) failures.push_back({{"time", f.time}, {"message", f.message}});
  j["failures"] = failures;
  json metrics = json::object();
  for (const auto& [name, value] : m_metrics) metrics[name] = value;
  j["metrics"] = metrics;
  // Environment: kind, count, bounds and whether any node is not finite, per cloth.
  json env = json::array();
  for (size_t c = 0; c < m_cloths.size(); ++c) {
    const ClothStats st = clothStats(int(c));
    auto vec = [&](const Vec3& v) { return json{number(v.x()), number(v.y()), number(v.z())}; };
    env.push_back({{"kind", "cloth"},
                   {"count", st.nodes},
                   {"resolution", {m_cloths[c].nx, m_cloths[c].ny}},
                   {"bounds", {{"min", vec(st.lo)}, {"max", vec(st.hi)}}},
                   {"nan", st.nan}});
  }
  if (!env.empty()) j["environment"] = env;  // absent without any: older summaries stay as they were
  if (!m_particles.empty()) {                // only then, so summaries without particles keep their bytes
    json systems = json::array();
    for (const auto& ps : m_particles) {
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
  j["faults"] = faultCount();
  const std::string& error = m_scriptError.empty() ? m_divergence : m_scriptError;
  j["error"] = error.empty() ? json(nullptr) : json(error);
  return j;
}

}  // namespace rm3d
