// `rm3d bench`: named scale scenes, each stepped for a fixed number of steps; reports speed,
// the split between behaviours, physics and the rest, and joint/dock fidelity.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "app/app.h"
#include "app/run_world.h"
#include "core/error.h"
#include "world/world.h"

namespace rm3d {

namespace {

struct Scene {
  const char* name;
  const char* what;
  const char* script;  ///< world script; N, DT, SUBSTEPS and ITERATIONS come in as `args`
};

// The paper's scalability scenes (section IV.G), with one VM per module running a behaviour.
const Scene kScenes[] = {
    {"snake_1000", "N SuperBots docked in one chain, each VM running the travelling-wave gait",
     R"(world.set{dt = args.dt, substeps = args.substeps, solver_iterations = args.iterations,
           joint_iterations = args.joint_iterations, duration = 1e9}
world.ground{}
local prev
for i = 1, args.n do
  local m = world.spawn(args.type, {at = {-(i - 1) * 0.19, 0, 0.053}, behavior = "behaviors/snake.lua",
                                     params = {index = i - 1}})
  if prev then world.connect(prev, "back", m, "front") end
  prev = m
end)"},
    {"superbots_1000", "N separate SuperBots, every motor alternating between two targets",
     R"(world.set{dt = args.dt, substeps = args.substeps, solver_iterations = args.iterations,
           joint_iterations = args.joint_iterations, duration = 1e9}
world.ground{}
local side = math.ceil(math.sqrt(args.n))
for i = 0, args.n - 1 do
  world.spawn(args.type, {at = {(i % side) * 0.35, (i // side) * 0.30, 0.053}, behavior = "behaviors/alternate.lua"})
end)"},
    {"docking_1000",
     "N SuperBots in zero gravity packed 1 cm apart, every dock enabled, latching at run time",
     R"(world.set{dt = args.dt, substeps = args.substeps, solver_iterations = args.iterations,
           joint_iterations = args.joint_iterations, duration = 1e9, gravity = {0, 0, 0}}
local side = math.ceil(math.sqrt(args.n))
for i = 0, args.n - 1 do
  world.spawn(args.type, {at = {-(i % side) * 0.20, (i // side) * 0.114, 0}})
end)"},
    {"relay_1000", "N SuperBots in one chain on the ground relaying a message per step from head to tail",
     R"(world.set{dt = args.dt, substeps = args.substeps, solver_iterations = args.iterations,
           joint_iterations = args.joint_iterations, duration = 1e9}
world.ground{}
local prev
for i = 1, args.n do
  local m = world.spawn(args.type, {at = {-(i - 1) * 0.19, 0, 0.053}, behavior = "behaviors/relay.lua"})
  if prev then world.connect(prev, "back", m, "front") end
  prev = m
end)"},
};

struct Result {
  std::string name;
  int modules = 0;
  double dt = 0;
  long long steps = 0;
  double stepsPerSecond = 0, realtime = 0;
  double msBehaviours = 0, msPhysics = 0, msOther = 0;
  Quality quality;
  int connections = 0;
  size_t messages = 0;
};

bool runScene(const Scene& s, double dt, const BenchArgs& a, const std::string& root, Result& out) {
  RunOptions o;
  o.projectRoot = root;
  o.threads = a.threads;
  o.echoLog = false;
  const int n = a.modules.value_or(1000);
  o.params = {{"n", std::to_string(n)},
              {"dt", std::to_string(dt)},
              {"substeps", std::to_string(a.substeps.value_or(1))},
              {"iterations", std::to_string(a.iterations.value_or(10))},
              {"joint_iterations", std::to_string(a.jointIterations.value_or(0))},
              {"type", a.type}};
  World w(o);
  try {
    w.loadString(s.script, std::string("bench/") + s.name + ".lua");
  } catch (const InputError& e) {
    std::fprintf(stderr, "rm3d bench: %s: %s\n", s.name, e.what());
    return false;
  }
  const int warm = 30;
  for (int i = 0; i < warm; ++i) w.step();
  double beh = 0, phys = 0, other = 0;
  Quality worst;
  const auto t0 = std::chrono::steady_clock::now();
  for (long long i = 0; i < a.steps; ++i) {
    w.step();
    const World::StepTimes& t = w.lastStepTimes();
    beh += t.behaviours;
    phys += t.physics;
    other += t.other;
    w.sampleTracking();
    if (i % 10 == 9 || i + 1 == a.steps) {
      const Quality q = w.quality();
      worst.hingeGapMm = std::max(worst.hingeGapMm, q.hingeGapMm);
      worst.hingeAngleDeg = std::max(worst.hingeAngleDeg, q.hingeAngleDeg);
      worst.dockGapMm = std::max(worst.dockGapMm, q.dockGapMm);
      worst.dockAngleDeg = std::max(worst.dockAngleDeg, q.dockAngleDeg);
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  worst.trackingRmsDeg = w.quality().trackingRmsDeg;
  out.name = s.name;
  out.modules = int(w.modules().size());
  out.dt = dt;
  out.steps = a.steps;
  out.stepsPerSecond = double(a.steps) / wall;
  out.realtime = out.stepsPerSecond * dt;
  out.msBehaviours = beh / double(a.steps);
  out.msPhysics = phys / double(a.steps);
  out.msOther = other / double(a.steps);
  out.quality = worst;
  out.connections = int(w.connections().size());
  const World::MessageStats ms = w.messageStats();
  out.messages = ms.sent;
  return true;
}

}  // namespace

int benchCommand(const BenchArgs& a, const std::string& root) {
  std::string perr;
  if (!a.json.empty() && !prepareOutputFile("--json", a.json, perr)) {
    std::fprintf(stderr, "rm3d bench: %s\n", perr.c_str());
    return 2;
  }
  std::vector<const Scene*> scenes;
  if (a.scenes.empty()) {
    for (const Scene& s : kScenes) scenes.push_back(&s);
  } else {
    for (const std::string& n : a.scenes) {
      const Scene* found = nullptr;
      for (const Scene& s : kScenes)
        if (n == s.name) found = &s;
      if (!found) {
        std::string names;
        for (const Scene& s : kScenes) names += std::string(names.empty() ? "" : ", ") + s.name;
        std::fprintf(stderr, "rm3d bench: unknown scene '%s' (expected one of: %s)\n", n.c_str(),
                     names.c_str());
        return 2;
      }
      scenes.push_back(found);
    }
  }
  std::vector<double> dts = a.dt ? std::vector<double>{*a.dt} : std::vector<double>{1.0 / 30.0, 1.0 / 60.0};
  std::printf("%-16s %7s %8s %9s %7s %8s %8s %8s | %8s %8s %8s %8s %9s | %6s %9s\n", "scene", "modules", "dt",
              "steps/s", "RTF", "ms beh", "ms phys", "ms other", "hinge mm", "hinge deg", "dock mm",
              "dock deg", "track deg", "conns", "messages");
  std::printf("%s\n", "  (last two columns: connections at the end, messages sent)");
  nlohmann::json out = {{"threads", a.threads},
                        {"iterations", a.iterations.value_or(10)},
                        {"substeps", a.substeps.value_or(1)},
                        {"joint_iterations", a.jointIterations.value_or(0)},
                        {"module_type", a.type},
                        {"scenes", nlohmann::json::array()}};
  for (const Scene* s : scenes)
    for (double dt : dts) {
      Result r;
      if (!runScene(*s, dt, a, root, r)) return 2;
      std::printf(
          "%-16s %7d %8.5f %9.1f %7.2f %8.3f %8.3f %8.3f | %8.3f %9.3f %8.3f %8.3f %9.3f | %6d %9zu\n",
          r.name.c_str(), r.modules, r.dt, r.stepsPerSecond, r.realtime, r.msBehaviours, r.msPhysics,
          r.msOther, r.quality.hingeGapMm, r.quality.hingeAngleDeg, r.quality.dockGapMm,
          r.quality.dockAngleDeg, r.quality.trackingRmsDeg, r.connections, r.messages);
      std::fflush(stdout);
      out["scenes"].push_back(
          {{"name", r.name},
           {"modules", r.modules},
           {"dt", r.dt},
           {"steps", r.steps},
           {"steps_per_second", r.stepsPerSecond},
           {"realtime_factor", r.realtime},
           {"ms", {{"behaviours", r.msBehaviours}, {"physics", r.msPhysics}, {"other", r.msOther}}},
           {"quality",
            {{"hinge_gap_mm", r.quality.hingeGapMm},
             {"hinge_angle_deg", r.quality.hingeAngleDeg},
             {"dock_gap_mm", r.quality.dockGapMm},
             {"dock_angle_deg", r.quality.dockAngleDeg},
             {"tracking_rms_deg", r.quality.trackingRmsDeg}}},
           {"connections", r.connections},
           {"messages_sent", r.messages}});
    }
  if (!a.json.empty()) {
    std::ofstream f(a.json);
    f << out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    f.close();
    if (!f) {
      std::fprintf(stderr, "rm3d bench: --json %s: cannot write the file\n", a.json.c_str());
      return 2;
    }
  }
  return 0;
}

}  // namespace rm3d
