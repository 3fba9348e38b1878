// `rm3d bench`: named scale scenes (the paper's scale table, section IV.G, and three of our own),
// each stepped for a fixed number of steps at the world's default settings unless given; reports
// speed and real-time factor beside the paper's, the split between behaviours, physics and the
// rest, and joint/dock fidelity.
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "app/app.h"
#include "app/bench_scenes.h"
#include "app/run_world.h"
#include "core/error.h"
#include "io/summary.h"
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

/// One scene's world at one thread count, measured in one or more blocks of steps (rounds).
class SceneRun {
 public:
  SceneRun(const Scene& s, const BenchArgs& a, int threads) : m_scene(s) {
    RunOptions o;
    o.threads = threads;
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
    m_options = std::move(o);
    m_threads = threads;
  }

  /// Loads the scene and takes its warm-up steps; false (and a message) where it cannot load.
  bool load(const std::string& root) {
    m_options.projectRoot = root;
    m_world = std::make_unique<World>(m_options);
    try {
      m_world->loadString(m_scene.script, std::string("bench/") + m_scene.name + ".lua");
    } catch (const InputError& e) {
      std::fprintf(stderr, "rm3d bench: %s: %s\n", m_scene.name, e.what());
      return false;
    }
    constexpr int kWarm = 30;
    for (int i = 0; i < kWarm && !m_world->stopped(); ++i) m_world->step();
    return true;
  }

  /// Takes `steps` more measured steps (fewer where the world stops); returns this block's steps
  /// per second (0 where it took none).
  double measure(long long steps) {
    World& w = *m_world;
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = processCpuSeconds();
    long long taken = 0;
    for (long long i = 0; i < steps && !w.stopped(); ++i, ++taken) {
      w.step();
      const World::StepTimes& t = w.lastStepTimes();
      m_beh += t.behaviours;
      m_phys += t.physics;
      m_other += t.other;
      m_part += t.particles;
      for (const auto& ps : w.particleSystems()) {
        m_pt.sort += ps->times().sort;
        m_pt.neighbours += ps->times().neighbours;
        m_pt.solve += ps->times().solve;
        m_pt.finish += ps->times().finish;
      }
      w.sampleTracking();
      if (++m_counted % 10 == 0 || i + 1 == steps) {
        const Quality q = w.quality();
        m_worst.hingeGapMm = std::max(m_worst.hingeGapMm, q.hingeGapMm);
        m_worst.hingeAngleDeg = std::max(m_worst.hingeAngleDeg, q.hingeAngleDeg);
        m_worst.dockGapMm = std::max(m_worst.dockGapMm, q.dockGapMm);
        m_worst.dockAngleDeg = std::max(m_worst.dockAngleDeg, q.dockAngleDeg);
      }
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_wall += wall;
    const double cpu = processCpuSeconds() - cpu0;
    m_cpu += cpu;
    m_taken += taken;
    const double sps = taken > 0 && wall > 0 ? double(taken) / wall : 0;
    m_rounds.push_back(sps);
    m_roundCpu.push_back(taken > 0 ? 1000 * cpu / double(taken) : 0);
    return sps;
  }

  const World& world() const { return *m_world; }
  int threads() const { return m_threads; }
  const std::vector<double>& rounds() const { return m_rounds; }
  /// CPU time a step, ms, a block each.
  const std::vector<double>& roundCpu() const { return m_roundCpu; }
  const Scene& scene() const { return m_scene; }

  Result result() const {
    const World& w = *m_world;
    Result out;
    Quality worst = m_worst;
    worst.trackingRmsDeg = w.quality().trackingRmsDeg;
    out.name = m_scene.name;
    out.modules = int(w.modules().size());
    out.settings = w.settings();
    out.dt = w.settings().dt;
    out.paperFps = m_scene.paperFps;
    out.paperRealtime = m_scene.paperFps * (m_scene.particles ? kPaperParticleDt : kPaperDt);
    // A world that stopped (a divergence) is not timed on: its steps would cost nothing.
    if (w.stopped())
      out.stopped = !w.divergence().empty()    ? w.divergence()
                    : !w.scriptError().empty() ? w.scriptError()
                                               : std::string("the world stopped");
    out.steps = m_taken;
    const double k = 1.0 / double(std::max(1LL, m_taken));
    out.stepsPerSecond = m_taken > 0 && m_wall > 0 ? double(m_taken) / m_wall : 0;
    out.realtime = out.stepsPerSecond * out.dt;
    out.msWall = 1000 * m_wall * k;
    out.msCpu = 1000 * m_cpu * k;
    out.msBehaviours = m_beh * k;
    out.msPhysics = m_phys * k;
    out.msOther = m_other * k;
    out.msParticles = m_part * k;
    out.particleTimes = {m_pt.sort * k, m_pt.neighbours * k, m_pt.solve * k, m_pt.finish * k};
    for (const auto& ps : w.particleSystems()) out.particles += ps->count();
    out.quality = worst;
    out.connections = int(w.connections().size());
    out.messages = w.messageStats().sent;
    return out;
  }

 private:
  const Scene& m_scene;
  RunOptions m_options;
  int m_threads = 1;
  std::unique_ptr<World> m_world;
  double m_beh = 0, m_phys = 0, m_other = 0, m_part = 0, m_wall = 0, m_cpu = 0;
  ParticleSystem::Times m_pt;
  Quality m_worst;
  long long m_taken = 0, m_counted = 0;
  std::vector<double> m_rounds;    ///< steps per second, a block each
  std::vector<double> m_roundCpu;  ///< CPU ms a step, a block each
};

/// How much a second busy thread slows this one: the time of a chain of dependent multiply-adds
/// (about 0.1 s) with another thread running the same chain, over its time alone. About 1 where
/// the two threads have a core each; up to 2 where they share one (a virtual machine's two cores
/// on one physical core, or a busy machine), and then a second thread cannot pay.
double sharedCoreFactor() {
  auto chain = [] {
    double x = 1;
    for (long i = 0; i < 40'000'000; ++i) x = x * 1.0000001 + 1e-9;
    return x;
  };
  volatile double sink = 0;
  auto timed = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    sink = chain();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const double alone = timed();
  std::atomic<bool> go{false};
  std::thread other([&] {
    while (!go.load()) std::this_thread::yield();
    sink = chain();
  });
  go.store(true);
  const double both = timed();
  other.join();
  return alone > 0 ? both / alone : 1;
}

/// Each CPU this process may run on (its affinity mask, at most 64) and the time of one load in
/// a chain of dependent loads over 1 MiB, ns, on a thread pinned there: how fast that core's
/// caches answer now. On a shared machine two cores can differ by half (one shares its caches
/// with a busy neighbour) while sharedCoreFactor sees nothing, and a scene's figure then depends on
/// where its threads land. Empty where the mask cannot be read or a thread cannot be pinned.
std::vector<std::pair<int, double>> coreLoadTimes() {
  std::vector<std::pair<int, double>> out;
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) != 0) return out;
  // One random cycle through 1 MiB of indices (a fixed seed: the same chain every run).
  constexpr uint32_t kSlots = (1u << 20) / sizeof(uint32_t);
  std::vector<uint32_t> order(kSlots), next(kSlots);
  for (uint32_t i = 0; i < kSlots; ++i) order[i] = i;
  uint64_t state = 0x9E3779B97F4A7C15ull;
  for (uint32_t i = kSlots - 1; i > 0; --i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    std::swap(order[i], order[uint32_t((state >> 33) % (i + 1))]);
  }
  for (uint32_t i = 0; i < kSlots; ++i) next[order[i]] = order[(i + 1) % kSlots];
  constexpr long kLoads = 2'000'000;
  for (int cpu = 0; cpu < CPU_SETSIZE && out.size() < 64; ++cpu) {
    if (!CPU_ISSET(cpu, &mask)) continue;
    double ns = -1;
    std::thread t([&] {
      cpu_set_t one;
      CPU_ZERO(&one);
      CPU_SET(cpu, &one);
      if (pthread_setaffinity_np(pthread_self(), sizeof(one), &one) != 0) return;
      uint32_t k = 0;
      for (uint32_t i = 0; i < kSlots; ++i) k = next[k];  // (the chain into this core's caches)
      const auto t0 = std::chrono::steady_clock::now();
      for (long i = 0; i < kLoads; ++i) k = next[k];
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ns = k == kSlots ? 0 : s * 1e9 / double(kLoads);  // (k read: the loop is not dropped)
    });
    t.join();
    if (ns < 0) return {};
    out.emplace_back(cpu, ns);
  }
  return out;
}

/// "1,2,4".
std::string joined(const std::vector<int>& v) {
  std::string out;
  for (int x : v) out += (out.empty() ? "" : ",") + std::to_string(x);
  return out;
}

/// The median of `v` (the mean of the middle two of an even count).
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// One world's row of the table, its stop if any, and its JSON entry (under out["scenes"]); false
/// where the world stopped.
bool reportScene(const Result& r, int threads, const std::vector<double>& rounds, uint64_t digest,
                 nlohmann::json& out) {
  char digestText[24];
  std::snprintf(digestText, sizeof digestText, "%016llx", static_cast<unsigned long long>(digest));
  char paperFps[16] = "-", paperRtf[16] = "-";
  if (r.paperFps > 0) {
    std::snprintf(paperFps, sizeof paperFps, "%.0f", r.paperFps);
    std::snprintf(paperRtf, sizeof paperRtf, "%.2f", r.paperRealtime);
  }
  std::printf(
      "%-15s %7d %7d %9.1f %7.2f %9s %9s %8.3f %8.3f %8.3f %8.3f %8.3f | %8.3f %9.3f %8.3f %8.3f %9.3f | "
      "%6d %9zu\n",
      r.name.c_str(), r.modules, threads, r.stepsPerSecond, r.realtime, paperFps, paperRtf, r.msWall, r.msCpu,
      r.msBehaviours, r.msPhysics, r.msOther, r.quality.hingeGapMm, r.quality.hingeAngleDeg,
      r.quality.dockGapMm, r.quality.dockAngleDeg, r.quality.trackingRmsDeg, r.connections, r.messages);
  if (r.particles > 0)
    std::printf(
        "  %d particles: %.3f ms a step (sort %.3f, neighbours %.3f, solve %.3f, velocities and push "
        "%.3f)\n",
        r.particles, r.msParticles, r.particleTimes.sort, r.particleTimes.neighbours, r.particleTimes.solve,
        r.particleTimes.finish);
  if (!r.stopped.empty()) {
    std::printf("  stopped after %lld measured steps: %s\n", r.steps, r.stopped.c_str());
  }
  std::fflush(stdout);
  nlohmann::json paper = nullptr;
  if (r.paperFps > 0)
    paper = {{"frames_per_second", r.paperFps}, {"dt", kPaperDt}, {"realtime_factor", r.paperRealtime}};
  out["scenes"].push_back(
      {{"name", r.name},
       {"threads", threads},
       {"rounds_steps_per_second", rounds},
       {"state_digest", digestText},
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
  return r.stopped.empty();
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
  for (size_t i = 0; i < a.threads.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (a.threads[i] == a.threads[k]) {
        std::fprintf(stderr, "rm3d bench: --threads: %d is given twice (expected each count once)\n",
                     a.threads[i]);
        return 2;
      }
  if (a.rounds > a.steps) {
    std::fprintf(stderr, "rm3d bench: --rounds %d: more rounds than measured steps (--steps %lld)\n",
                 a.rounds, a.steps);
    return 2;
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
  const std::vector<int>& counts = a.threads;
  const int rounds = a.rounds > 0 ? a.rounds : counts.size() > 1 || a.together ? 4 : 1;
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
  std::printf("%-15s %7s %7s %9s %7s %9s %7s %8s %8s %8s %8s %8s | %8s %9s %8s %8s %9s | %6s %9s\n", "scene",
              "modules", "threads", "steps/s", "RTF", "paper fps", "paper RTF", "ms wall", "ms cpu", "ms beh",
              "ms phys", "ms other", "hinge mm", "hinge deg", "dock mm", "dock deg", "track deg", "conns",
              "messages");
  std::printf(
      "%s\n",
      "  (ms a step: wall clock, CPU time of all threads, and the wall clock's behaviours, physics and "
      "the rest; last two columns: connections at the end, messages sent)");
  nlohmann::json out = {
      {"threads", a.threads.front()},
      {"thread_counts", a.threads},
      {"rounds", rounds},
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
      {"scenes", nlohmann::json::array()},
      {"comparisons", nlohmann::json::array()}};
  bool anyStopped = false, differs = false;
  // Whether the machine's cores are its own now: thread counts compared on cores that share one
  // physical core (or are busy) measure the machine, not the engine.
  double coresBefore = 0;
  if (counts.size() > 1) {
    coresBefore = sharedCoreFactor();
    std::printf(
        "cores: one thread's work took %.2f times as long with a second thread busy (1: a core each; 2: one "
        "core "
        "shared)\n",
        coresBefore);
    out["cores_before"] = coresBefore;
  }
  // Whether the cores are alike now (a 1-thread figure is the core it ran on too).
  const auto loads = coreLoadTimes();
  if (loads.size() > 1) {
    std::string line;
    double fastest = loads[0].second, slowest = loads[0].second;
    for (const auto& [cpu, ns] : loads) {
      char buf[48];
      std::snprintf(buf, sizeof(buf), "%s%d: %.1f", line.empty() ? "" : ", ", cpu, ns);
      line += buf;
      fastest = std::min(fastest, ns);
      slowest = std::max(slowest, ns);
    }
    std::printf(
        "cores' caches: ns a dependent load over 1 MiB, by CPU: %s (the slowest %.2f times the fastest; "
        "pin a run with taskset -c to compare builds on one)\n",
        line.c_str(), fastest > 0 ? slowest / fastest : 1.0);
    nlohmann::json j = nlohmann::json::array();
    for (const auto& [cpu, ns] : loads) j.push_back({{"cpu", cpu}, {"load_ns", ns}});
    out["core_load_ns"] = j;
  }
  if (counts.size() > 1 || rounds > 1)
    std::printf(
        "threads %s: each scene's worlds built side by side and measured in %d rounds of %lld steps each, "
        "in turn (every other round in the reverse order)\n",
        joined(counts).c_str(), rounds, (a.steps + rounds - 1) / rounds);
  if (a.together && scenes.size() > 1)
    std::printf("together: every scene's worlds built first, then measured in the same turns\n");
  // Each scene's worlds, one per thread count; with --together all of them are built before any is
  // measured, and the rounds take every world in turn (else each scene's are built, measured and
  // let go before the next scene's).
  std::vector<std::vector<std::unique_ptr<SceneRun>>> built(scenes.size());
  auto build = [&](size_t si) {
    for (int t : counts) {
      built[si].push_back(std::make_unique<SceneRun>(*scenes[si], a, t));
      if (!built[si].back()->load(root)) return false;
    }
    return true;
  };
  auto measureRounds = [&](const std::vector<SceneRun*>& runs) {
    // The steps in `rounds` blocks, the worlds in turn: A B, B A, A B ... so that a machine's
    // slow minute falls on every count alike.
    for (int r = 0; r < rounds; ++r) {
      const long long steps = a.steps / rounds + (r < a.steps % rounds ? 1 : 0);
      if (steps == 0) continue;
      for (size_t k = 0; k < runs.size(); ++k) runs[r % 2 ? runs.size() - 1 - k : k]->measure(steps);
    }
  };
  auto measureScenes = [&](size_t from, size_t to) {
    std::vector<SceneRun*> runs;
    for (size_t si = from; si < to; ++si)
      for (const auto& run : built[si]) runs.push_back(run.get());
    measureRounds(runs);
  };
  if (a.together) {
    for (size_t si = 0; si < scenes.size(); ++si)
      if (!build(si)) return 2;
    measureScenes(0, scenes.size());
  }
  for (size_t si = 0; si < scenes.size(); ++si) {
    const Scene* s = scenes[si];
    if (!a.together) {
      if (!build(si)) return 2;
      measureScenes(si, si + 1);
    }
    const std::vector<std::unique_ptr<SceneRun>>& runs = built[si];
    for (const auto& run : runs) {
      const Result r = run->result();
      const uint64_t digest = stateDigest(run->world());
      if (!reportScene(r, run->threads(), run->rounds(), digest, out)) anyStopped = true;
    }
    // Each further count against the first: the ratio of their steps per second round by round,
    // and whether their states are the same bits after the same steps.
    const Result first = runs[0]->result();
    const uint64_t firstDigest = stateDigest(runs[0]->world());
    for (size_t k = 1; k < runs.size(); ++k) {
      std::vector<double> ratios;
      for (size_t i = 0; i < runs[k]->rounds().size() && i < runs[0]->rounds().size(); ++i)
        if (runs[k]->rounds()[i] > 0 && runs[0]->rounds()[i] > 0)
          ratios.push_back(runs[k]->rounds()[i] / runs[0]->rounds()[i]);
      const Result r = runs[k]->result();
      const bool comparable = r.steps == first.steps && r.stopped.empty() && first.stopped.empty();
      const bool same = comparable && stateDigest(runs[k]->world()) == firstDigest;
      if (comparable && !same) differs = true;
      const auto low = ratios.empty() ? 0.0 : *std::min_element(ratios.begin(), ratios.end());
      const auto high = ratios.empty() ? 0.0 : *std::max_element(ratios.begin(), ratios.end());
      std::printf(
          "  %s: %d thread%s / %d: %.3f times the steps per second (median of %zu rounds, %.3f to %.3f); "
          "%s\n",
          s->name, runs[k]->threads(), runs[k]->threads() == 1 ? "" : "s", runs[0]->threads(), median(ratios),
          ratios.size(), low, high,
          !comparable ? "states not compared (a world stopped)"
          : same      ? "the same state, bit for bit"
                      : "NOT the same state (a determinism fault)");
      out["comparisons"].push_back(
          {{"scene", s->name},
           {"threads", runs[k]->threads()},
           {"against", runs[0]->threads()},
           {"ratios", ratios},
           {"ratio_median", median(ratios)},
           {"ratio_min", low},
           {"ratio_max", high},
           {"same_state", comparable ? nlohmann::json(same) : nlohmann::json(nullptr)}});
    }
    // Measured together: this scene's CPU a step against the first scene's, round by round, at
    // each thread count (how the step's cost grows with the world: the same steps of the same
    // simulated time, on a machine whose load drifts alike for both).
    if (a.together && si > 0)
      for (size_t k = 0; k < runs.size(); ++k) {
        const SceneRun& base = *built[0][k];
        std::vector<double> ratios;
        for (size_t i = 0; i < runs[k]->roundCpu().size() && i < base.roundCpu().size(); ++i)
          if (runs[k]->roundCpu()[i] > 0 && base.roundCpu()[i] > 0)
            ratios.push_back(runs[k]->roundCpu()[i] / base.roundCpu()[i]);
        const double low = ratios.empty() ? 0.0 : *std::min_element(ratios.begin(), ratios.end());
        const double high = ratios.empty() ? 0.0 : *std::max_element(ratios.begin(), ratios.end());
        const int m0 = int(base.world().modules().size()), m1 = int(runs[k]->world().modules().size());
        const double perModule = m0 > 0 && m1 > 0 ? median(ratios) * m0 / m1 : 0;
        std::printf(
            "  %s / %s at %d thread%s: %.3f times the CPU a step (median of %zu rounds, %.3f to %.3f); "
            "%.3f times a module's\n",
            s->name, base.scene().name, runs[k]->threads(), runs[k]->threads() == 1 ? "" : "s",
            median(ratios), ratios.size(), low, high, perModule);
        out["comparisons"].push_back({{"scene", s->name},
                                      {"against_scene", base.scene().name},
                                      {"threads", runs[k]->threads()},
                                      {"cpu_ratios", ratios},
                                      {"cpu_ratio_median", median(ratios)},
                                      {"cpu_ratio_min", low},
                                      {"cpu_ratio_max", high},
                                      {"cpu_ratio_per_module", perModule}});
      }
    std::fflush(stdout);
    if (!a.together) built[si].clear();  // (the next scene's worlds need the memory)
  }
  if (counts.size() > 1) {
    const double coresAfter = sharedCoreFactor();
    std::printf("cores: %.2f before the scenes, %.2f after\n", coresBefore, coresAfter);
    out["cores_after"] = coresAfter;
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
  return anyStopped || differs ? 1 : 0;
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
