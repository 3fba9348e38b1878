// `rm3d bench`: named scale scenes (the paper's scale table, section IV.G, and three of our own),
// each stepped for a fixed number of steps at the world's default settings unless given; reports
// speed and real-time factor beside the paper's, the split between behaviours, physics and the
// rest, and joint/dock fidelity.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "app/app.h"
#include "app/bench_scenes.h"
#include "app/run_world.h"
#include "core/error.h"
#include "world/world.h"

namespace rm3d {

namespace {

struct Scene {
  const char* name;
  const char* what;
  int modules;         ///< default module count (--modules overrides)
  double paperFps;     ///< the paper's frames per second at dt 1/30 (section IV.G); 0: none
  const char* script;  ///< world script; see kSettings for the `args` it gets
  /// Particle scenes: `modules` is the particle count, and the paper's figure is at dt 1/60
  /// (Macklin et al.'s PhysX GPU figures the ReMod3D paper quotes).
  bool particles = false;
};

/// The paper ran every scene at dt 1/30, one frame per step, on a 2013 quad-core laptop.
constexpr double kPaperDt = 1.0 / 30.0;

// Settings come in as `args`: n, type, and dt, substeps, iterations, joint_iterations only when
// given on the command line (absent, world.set leaves the world's default).
#define RM3D_BENCH_SETTINGS                                                                      \
  "world.set{solver = args.solver, dt = args.dt, substeps = args.substeps, solver_iterations = " \
  "args.iterations,\n"                                                                           \
  "          joint_iterations = args.joint_iterations, duration = 1e9"

// The chain starts in its gait's pose (lua/snake_chain.lua): a straight chain must first get
// shorter, and dragging its halves over the ground breaks a long one's middle docks.
const char* const kSnake = RM3D_BENCH_SETTINGS R"(}
world.ground{}
require("snake_chain").build{n = args.n, type = args.type, behavior = "behaviors/snake.lua"})";

const char* const kSuperbots = RM3D_BENCH_SETTINGS R"(}
world.ground{}
local side = math.ceil(math.sqrt(args.n))
for i = 0, args.n - 1 do
  world.spawn(args.type, {at = {(i % side) * 0.35, (i // side) * 0.30, 0.043}, behavior = "behaviors/alternate.lua"})
end)";

const char* const kAtrons = RM3D_BENCH_SETTINGS R"(}
world.ground{}
local side = math.ceil(math.sqrt(args.n))
for i = 0, args.n - 1 do
  world.spawn("atron", {at = {(i % side) * 0.16, (i // side) * 0.16, 0.056}, behavior = "behaviors/atron_wheel.lua",
                        params = {speed = 1}})
end)";

// The paper's scalability scenes (section IV.G), with one VM per module running a behaviour,
// and three of our own (ten times the largest scale, run-time docking, message relay).
const Scene kScenes[] = {
    {"snake_150", "N SuperBots docked in one chain, each VM running the travelling-wave gait", 150, 30,
     kSnake},
    {"superbots_200", "N separate SuperBots, every motor alternating between two targets", 200, 30,
     kSuperbots},
    {"atrons_275", "N separate ATRONs, each spinning its equator with a velocity drive", 275, 30, kAtrons},
    {"snake_1000", "N SuperBots docked in one chain, each VM running the travelling-wave gait", 1000, 3,
     kSnake},
    {"superbots_1000", "N separate SuperBots, every motor alternating between two targets", 1000, 4,
     kSuperbots},
    {"atrons_1500", "N separate ATRONs, each spinning its equator with a velocity drive", 1500, 3, kAtrons},
    {"superbots_10000", "N separate SuperBots, every motor alternating between two targets", 10000, 0,
     kSuperbots},
    {"docking_1000",
     "N SuperBots in zero gravity in rows, end faces 1 cm apart, every dock enabled, latching into chains "
     "at run time",
     1000, 0, RM3D_BENCH_SETTINGS R"(, gravity = {0, 0, 0}}
local side = math.ceil(math.sqrt(args.n))
for i = 0, args.n - 1 do
  world.spawn(args.type, {at = {-(i % side) * 0.20, (i // side) * 0.15, 0}})
end)"},
    {"relay_1000", "N SuperBots in one chain on the ground relaying a message per step from head to tail",
     1000, 0, RM3D_BENCH_SETTINGS R"(}
world.ground{}
local prev
for i = 1, args.n do
  local m = world.spawn(args.type, {at = {-(i - 1) * 0.19, 0, 0.043}, behavior = "behaviors/relay.lua"})
  if prev then world.connect(prev, "back", m, "front") end
  prev = m
end)"},
};

#undef RM3D_BENCH_SETTINGS

/// The paper's particle figures are at dt 1/60.
constexpr double kPaperParticleDt = 1.0 / 60.0;

// Particle scenes: args.n particles 2.5 cm apart, 12 layers deep, filling 60 % of a walled tank
// (a dam break), with a floating box of half the fluid's density in the empty part; debris: a
// layer of grains with a heavy box dropped on it. dt, substeps and iterations as above.
#define RM3D_PARTICLE_TANK                                                                             \
  "world.set{dt = args.dt, substeps = args.substeps, solver_iterations = args.iterations, duration = " \
  "1e9}\n"                                                                                             \
  "world.ground{}\n"                                                                                   \
  "local s, layers = 0.025, 12\n"                                                                      \
  "local side = math.floor(math.sqrt(tonumber(args.n) / layers) + 0.5)\n"                              \
  "local L, W, H, T = side * s / 0.6, side * s, 0.6, 0.1\n"                                            \
  "world.box{size = {L + 2 * T, T, H}, at = {0, W / 2 + T / 2, H / 2}}\n"                              \
  "world.box{size = {L + 2 * T, T, H}, at = {0, -W / 2 - T / 2, H / 2}}\n"                             \
  "world.box{size = {T, W, H}, at = {L / 2 + T / 2, 0, H / 2}}\n"                                      \
  "world.box{size = {T, W, H}, at = {-L / 2 - T / 2, 0, H / 2}}\n"

const char* const kFluidTank = RM3D_PARTICLE_TANK R"(
world.fluid{min = {-L / 2, -W / 2, 0}, max = {-L / 2 + side * s, W / 2, layers * s}, spacing = s}
world.box{size = {0.15, 0.15, 0.15}, at = {L / 2 - 0.2, 0, 0.1}, mass = 500 * 0.15 ^ 3})";

const char* const kDebrisField = RM3D_PARTICLE_TANK R"(
world.debris{min = {-L / 2, -W / 2, 0}, max = {-L / 2 + side * s, W / 2, layers * s}, spacing = s}
world.box{size = {0.2, 0.2, 0.2}, at = {-L / 4, 0, layers * s + 0.3}, mass = 8})";

#undef RM3D_PARTICLE_TANK

const Scene kParticleScenes[] = {
    {"fluid_20k", "N fluid particles in a tank (a dam break) with a floating box", 20000, 51, kFluidTank,
     true},
    {"fluid_50k", "N fluid particles in a tank (a dam break) with a floating box", 50000, 15, kFluidTank,
     true},
    {"fluid_100k", "N fluid particles in a tank (a dam break) with a floating box", 100000, 7, kFluidTank,
     true},
    {"debris_100k", "N debris grains in a tank with a heavy box dropped on them", 100000, 16, kDebrisField,
     true},
};

/// Every scene: the paper's and ours, then the particle scenes.
std::vector<const Scene*> allScenes() {
  std::vector<const Scene*> out;
  for (const Scene& s : kScenes) out.push_back(&s);
  for (const Scene& s : kParticleScenes) out.push_back(&s);
  return out;
}

struct Result {
  std::string name;
  int modules = 0;
  double dt = 0;
  WorldSettings settings;  ///< what the world ran at
  double paperFps = 0, paperRealtime = 0;
  long long steps = 0;  ///< measured (fewer than asked when the world stopped)
  std::string stopped;  ///< why the world stopped (a divergence, a script error), or empty
  double stepsPerSecond = 0, realtime = 0;
  double msWall = 0, msCpu = 0;  ///< per step: wall clock, and CPU time of every thread together
  double msBehaviours = 0, msPhysics = 0, msOther = 0;
  double msParticles = 0;  ///< part of msOther
  int particles = 0;
  ParticleSystem::Times particleTimes;  ///< summed over the systems, mean per step
  Quality quality;
  int connections = 0;
  size_t messages = 0;
};

/// CPU time of the whole process (every thread), s: beside the wall clock it shows how much of
/// the machine a step used, and it is what a busy machine's neighbours do not inflate.
double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

bool runScene(const Scene& s, const BenchArgs& a, const std::string& root, Result& out) {
  RunOptions o;
  o.projectRoot = root;
  o.threads = a.threads;
  o.echoLog = false;
  o.echoWorldLog = false;
  o.params = {{"n", std::to_string(a.modules.value_or(s.modules))}, {"type", a.type}};
  // Only what was given: the rest stays at the world's defaults (WorldSettings).
  auto number = [](double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return std::string(buf);
  };
  if (a.dt) o.params["dt"] = number(*a.dt);
  if (a.substeps) o.params["substeps"] = std::to_string(*a.substeps);
  if (a.solver) o.params["solver"] = *a.solver;
  if (a.iterations) o.params["iterations"] = std::to_string(*a.iterations);
  if (a.jointIterations) o.params["joint_iterations"] = std::to_string(*a.jointIterations);
  World w(o);
  try {
    w.loadString(s.script, std::string("bench/") + s.name + ".lua");
  } catch (const InputError& e) {
    std::fprintf(stderr, "rm3d bench: %s: %s\n", s.name, e.what());
    return false;
  }
  const int warm = 30;
  for (int i = 0; i < warm && !w.stopped(); ++i) w.step();
  double beh = 0, phys = 0, other = 0, part = 0;
  ParticleSystem::Times pt;
  Quality worst;
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();
  long long taken = 0;
  for (long long i = 0; i < a.steps && !w.stopped(); ++i, ++taken) {
    w.step();
    const World::StepTimes& t = w.lastStepTimes();
    beh += t.behaviours;
    phys += t.physics;
    other += t.other;
    part += t.particles;
    for (const auto& ps : w.particleSystems()) {
      pt.sort += ps->times().sort;
      pt.neighbours += ps->times().neighbours;
      pt.solve += ps->times().solve;
      pt.finish += ps->times().finish;
    }
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
  const double cpu = processCpuSeconds() - cpu0;
  worst.trackingRmsDeg = w.quality().trackingRmsDeg;
  out.name = s.name;
  out.modules = int(w.modules().size());
  out.settings = w.settings();
  out.dt = w.settings().dt;
  out.paperFps = s.paperFps;
  out.paperRealtime = s.paperFps * (s.particles ? kPaperParticleDt : kPaperDt);
  // A world that stopped (a divergence) is not timed on: its steps would cost nothing.
  if (w.stopped())
    out.stopped = !w.divergence().empty()    ? w.divergence()
                  : !w.scriptError().empty() ? w.scriptError()
                                             : std::string("the world stopped");
  out.steps = taken;
  const double k = 1.0 / double(std::max(1LL, taken));
  out.stepsPerSecond = taken > 0 ? double(taken) / wall : 0;
  out.realtime = out.stepsPerSecond * out.dt;
  out.msWall = 1000 * wall * k;
  out.msCpu = 1000 * cpu * k;
  out.msBehaviours = beh * k;
  out.msPhysics = phys * k;
  out.msOther = other * k;
  out.msParticles = part * k;
  out.particleTimes = {pt.sort * k, pt.neighbours * k, pt.solve * k, pt.finish * k};
  for (const auto& ps : w.particleSystems()) out.particles += ps->count();
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
    scenes = allScenes();
  } else {
    for (const std::string& n : a.scenes) {
      const Scene* found = nullptr;
      for (const Scene* s : allScenes())
        if (n == s->name) found = s;
      if (!found) {
        std::string names;
        for (const Scene* s : allScenes()) names += std::string(names.empty() ? "" : ", ") + s->name;
        std::fprintf(stderr, "rm3d bench: unknown scene '%s' (expected one of: %s)\n", n.c_str(),
                     names.c_str());
        return 2;
      }
      scenes.push_back(found);
    }
  }
  // The settings every scene runs at: the world's defaults, except what was given.
  const WorldSettings defaults;
  const SolverKind solver = !a.solver            ? defaults.solver
                            : *a.solver == "pgs" ? SolverKind::Pgs
                                                 : SolverKind::Exact;
  const double dt = a.dt.value_or(defaults.dt);
  const int substeps = a.substeps.value_or(defaultSubsteps(solver));
  const int iterations = a.iterations.value_or(defaultIterations(solver));
  const int jointIterations = a.jointIterations.value_or(defaults.jointIterations);
  auto given = [](bool g) { return g ? "given" : "world default"; };
  std::printf(
      "settings: solver %s (%s), dt %.5f s (%s), substeps %d (%s), "
      "solver iterations %d (%s), joint iterations %d%s (%s)\n",
      solverName(solver), given(a.solver.has_value()), dt, given(a.dt.has_value()), substeps,
      given(a.substeps.has_value()), iterations, given(a.iterations.has_value()), jointIterations,
      jointIterations == 0 ? " (as solver)" : "", given(a.jointIterations.has_value()));
  std::printf(
      "paper: ReMod3D (section IV.G), dt 1/30, one step per frame, a 2013 quad-core laptop (particle scenes: "
      "dt "
      "1/60, PhysX on a GeForce GT 650M); RTF = simulated s per wall s\n");
  std::printf("%-15s %7s %9s %7s %9s %7s %8s %8s %8s %8s %8s | %8s %9s %8s %8s %9s | %6s %9s\n", "scene",
              "modules", "steps/s", "RTF", "paper fps", "paper RTF", "ms wall", "ms cpu", "ms beh", "ms phys",
              "ms other", "hinge mm", "hinge deg", "dock mm", "dock deg", "track deg", "conns", "messages");
  std::printf(
      "%s\n",
      "  (ms a step: wall clock, CPU time of all threads, and the wall clock's behaviours, physics and "
      "the rest; last two columns: connections at the end, messages sent)");
  nlohmann::json out = {
      {"threads", a.threads},
      {"solver", solverName(solver)},
      {"dt", dt},
      {"iterations", iterations},
      {"substeps", substeps},
      {"joint_iterations", jointIterations},
      {"settings_given",
       {{"dt", a.dt.has_value()},
        {"substeps", a.substeps.has_value()},
        {"iterations", a.iterations.has_value()},
        {"joint_iterations", a.jointIterations.has_value()}}},
      {"module_type", a.type},
      {"paper", {{"dt", kPaperDt}, {"machine", "2013 quad-core laptop (ReMod3D, section IV.G)"}}},
      {"scenes", nlohmann::json::array()}};
  bool anyStopped = false;
  for (const Scene* s : scenes) {
    Result r;
    if (!runScene(*s, a, root, r)) return 2;
    char paperFps[16] = "-", paperRtf[16] = "-";
    if (r.paperFps > 0) {
      std::snprintf(paperFps, sizeof paperFps, "%.0f", r.paperFps);
      std::snprintf(paperRtf, sizeof paperRtf, "%.2f", r.paperRealtime);
    }
    std::printf(
        "%-15s %7d %9.1f %7.2f %9s %9s %8.3f %8.3f %8.3f %8.3f %8.3f | %8.3f %9.3f %8.3f %8.3f %9.3f | %6d "
        "%9zu\n",
        r.name.c_str(), r.modules, r.stepsPerSecond, r.realtime, paperFps, paperRtf, r.msWall, r.msCpu,
        r.msBehaviours, r.msPhysics, r.msOther, r.quality.hingeGapMm, r.quality.hingeAngleDeg,
        r.quality.dockGapMm, r.quality.dockAngleDeg, r.quality.trackingRmsDeg, r.connections, r.messages);
    if (r.particles > 0)
      std::printf(
          "  %d particles: %.3f ms a step (sort %.3f, neighbours %.3f, solve %.3f, velocities and push "
          "%.3f)\n",
          r.particles, r.msParticles, r.particleTimes.sort, r.particleTimes.neighbours, r.particleTimes.solve,
          r.particleTimes.finish);
    if (!r.stopped.empty()) {
      anyStopped = true;
      std::printf("  stopped after %lld measured steps: %s\n", r.steps, r.stopped.c_str());
    }
    std::fflush(stdout);
    nlohmann::json paper = nullptr;
    if (r.paperFps > 0)
      paper = {{"frames_per_second", r.paperFps}, {"dt", kPaperDt}, {"realtime_factor", r.paperRealtime}};
    out["scenes"].push_back(
        {{"name", r.name},
         {"modules", r.modules},
         {"dt", r.dt},
         {"settings",
          {{"dt", r.settings.dt},
           {"substeps", r.settings.substeps},
           {"solver_iterations", r.settings.solverIterations},
           {"joint_iterations", r.settings.jointIterations},
           {"erp", r.settings.erp}}},
         {"steps", r.steps},
         {"steps_per_second", r.stepsPerSecond},
         {"realtime_factor", r.realtime},
         {"paper", paper},
         {"ms",
          {{"wall", r.msWall},
           {"cpu", r.msCpu},
           {"behaviours", r.msBehaviours},
           {"physics", r.msPhysics},
           {"other", r.msOther},
           {"particles", r.msParticles},
           {"particle_phases",
            {{"sort", r.particleTimes.sort},
             {"neighbours", r.particleTimes.neighbours},
             {"solve", r.particleTimes.solve},
             {"finish", r.particleTimes.finish}}}}},
         {"particles", r.particles},
         {"quality",
          {{"hinge_gap_mm", r.quality.hingeGapMm},
           {"hinge_angle_deg", r.quality.hingeAngleDeg},
           {"dock_gap_mm", r.quality.dockGapMm},
           {"dock_angle_deg", r.quality.dockAngleDeg},
           {"tracking_rms_deg", r.quality.trackingRmsDeg}}},
         {"connections", r.connections},
         {"messages_sent", r.messages},
         {"stopped", r.stopped.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.stopped)}});
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
  return anyStopped ? 1 : 0;
}

std::string benchSceneHelp() {
  std::string out = "Scenes:\n";
  for (const Scene* s : allScenes()) {
    char line[512];
    std::snprintf(line, sizeof line, "  %-16s %s (%d %s)\n", s->name, s->what, s->modules,
                  s->particles ? "particles" : "modules");
    out += line;
  }
  return out;
}

}  // namespace rm3d
