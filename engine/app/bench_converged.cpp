// `rm3d bench --converged`: a converged reference for the default solver settings. The 10-module
// SuperBot snake (behaviors/snake.lua) crawls for 2 s twice from the same start: once at the
// world's defaults and once at settings known to converge (20 substeps, 100 solver iterations,
// the same dt). Every step records each joint angle, each module's position and each dock's load;
// the largest differences are printed (and written with --json) against thresholds, and the exit
// code is 1 when one is exceeded. A third run, finer still (40 x 200), says how far the reference
// itself is from converged.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "app/app.h"
#include "app/run_world.h"
#include "core/error.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr int kReferenceSubsteps = 20;
constexpr int kReferenceIterations = 100;
constexpr int kCheckSubsteps = 40;  ///< the reference's own check
constexpr int kCheckIterations = 200;
constexpr double kSeconds = 2.0;
constexpr double kJointDeg = 1.0;  ///< thresholds
constexpr double kPositionMm = 2.0;
constexpr double kLoadPercent = 10.0;
/// Dock loads are compared as means over this window: step by step they follow contact impulses,
/// which differ by about 20% even between 20 x 100 and 40 x 200 (the contact points a substep
/// finds change with the substep), so single steps cannot tell a converged run from another.
constexpr double kLoadWindow = 0.1;  ///< s

/// The snake, as in `bench snake_1000` (started in its gait's pose, lua/snake_chain.lua); solver settings
/// only where given (0 or "": the world's default).
const char* kSnake = R"(world.set{dt = args.dt, duration = 1e9}
if args.solver ~= "" then world.set{solver = args.solver} end
if args.substeps > 0 then world.set{substeps = args.substeps} end
if args.iterations > 0 then world.set{solver_iterations = args.iterations} end
if args.joint_iterations > 0 then world.set{joint_iterations = args.joint_iterations} end
world.ground{}
require("snake_chain").build{n = args.n, type = args.type, behavior = "behaviors/snake.lua"})";

using ConnectionKey = std::tuple<int, int, int, int>;

struct Load {
  double force = 0, torque = 0;
};

/// What one run recorded, per step.
struct Trace {
  int substeps = 0, iterations = 0, jointIterations = 0;
  std::string solver;
  double wallSeconds = 0;
  std::vector<std::vector<double>> joints;   ///< [step][module's joints in order]
  std::vector<std::vector<Vec3>> positions;  ///< [step][module]
  std::vector<std::map<ConnectionKey, Load>> loads;
  std::vector<std::string> jointNames, moduleNames;
  std::map<ConnectionKey, std::string> connectionNames;
};

bool runSnake(const BenchArgs& a, const std::string& root, double dt, long long steps, int substeps,
              int iterations, int jointIterations, Trace& out) {
  RunOptions o;
  o.projectRoot = root;
  o.threads = a.threads.front();
  o.echoLog = false;
  o.echoWorldLog = false;
  o.params = {{"n", std::to_string(a.modules.value_or(10))},
              {"dt", std::to_string(dt)},
              {"substeps", std::to_string(substeps)},
              {"iterations", std::to_string(iterations)},
              {"joint_iterations", std::to_string(jointIterations)},
              {"solver", a.solver.value_or("")},
              {"type", a.type}};
  World w(o);
  try {
    w.loadString(kSnake, "bench/converged_snake.lua");
  } catch (const InputError& e) {
    std::fprintf(stderr, "rm3d bench --converged: %s\n", e.what());
    return false;
  }
  const WorldSettings& s = w.settings();
  out.substeps = s.substeps;
  out.iterations = s.solverIterations;
  out.jointIterations = s.jointIterations;
  out.solver = solverName(s.solver);
  for (const Module& m : w.modules()) {
    out.moduleNames.push_back(m.name);
    for (const JointDef& j : m.type->joints) out.jointNames.push_back(m.name + " " + j.name);
  }
  const auto t0 = std::chrono::steady_clock::now();
  for (long long i = 0; i < steps; ++i) {
    w.step();
    if (!w.divergence().empty() || !w.scriptError().empty()) {
      std::fprintf(stderr, "rm3d bench --converged: at %d x %d: %s\n", out.substeps, out.iterations,
                   (w.divergence().empty() ? w.scriptError() : w.divergence()).c_str());
      return false;
    }
    std::vector<double> joints;
    std::vector<Vec3> positions;
    for (int m = 0; m < int(w.modules().size()); ++m) {
      positions.push_back(w.modulePose(m).pos);
      for (int j = 0; j < int(w.module(m).type->joints.size()); ++j) joints.push_back(w.jointAngle(m, j));
    }
    std::map<ConnectionKey, Load> loads;
    for (const Connection& c : w.connections()) {
      const ConnectionKey k{c.moduleA, c.dockA, c.moduleB, c.dockB};
      const Wrench l = w.connectionLoad(c);
      loads[k] = {l.force.norm(), l.torque.norm()};
      if (!out.connectionNames.count(k)) {
        const Module& ma = w.module(c.moduleA);
        const Module& mb = w.module(c.moduleB);
        out.connectionNames[k] = ma.name + "." + ma.type->docks[size_t(c.dockA)].name + "-" + mb.name + "." +
                                 mb.type->docks[size_t(c.dockB)].name;
      }
    }
    out.joints.push_back(std::move(joints));
    out.positions.push_back(std::move(positions));
    out.loads.push_back(std::move(loads));
  }
  out.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

/// One compared quantity: the largest difference, where and when.
struct Worst {
  double value = 0;
  std::string where;
  double time = 0;
};

struct Comparison {
  Worst jointDeg, positionMm;
  Worst forcePercent, torquePercent;          ///< loads averaged over kLoadWindow (thresholds)
  Worst forceStepPercent, torqueStepPercent;  ///< step by step (reported only)
  int missingConnections = 0;                 ///< connection-steps present in one run only (a dock broke)
  /// Root mean square over every step and joint (module): what the whole run is off by, where the
  /// largest difference is one moment's (a landing a substep early or late).
  double jointRmsDeg = 0, positionRmsMm = 0;
};

/// Trailing means of each connection's load over `window` steps (over the steps where it exists).
std::vector<std::map<ConnectionKey, Load>> windowed(const std::vector<std::map<ConnectionKey, Load>>& loads,
                                                    size_t window) {
  std::vector<std::map<ConnectionKey, Load>> out(loads.size());
  for (size_t i = 0; i < loads.size(); ++i)
    for (const auto& [k, l] : loads[i]) {
      Load sum;
      int n = 0;
      for (size_t j = i + 1 > window ? i + 1 - window : 0; j <= i; ++j) {
        const auto it = loads[j].find(k);
        if (it == loads[j].end()) continue;
        sum.force += it->second.force;
        sum.torque += it->second.torque;
        ++n;
      }
      out[i][k] = {sum.force / n, sum.torque / n};
    }
  return out;
}

/// Per connection, the largest difference over the run relative to that connection's peak load
/// in the reference (a load that passes through zero makes a step-by-step ratio meaningless).
void compareLoads(const std::vector<std::map<ConnectionKey, Load>>& run,
                  const std::vector<std::map<ConnectionKey, Load>>& ref,
                  const std::map<ConnectionKey, std::string>& names, double dt, Worst& force, Worst& torque) {
  std::map<ConnectionKey, Load> peak, diff;
  std::map<ConnectionKey, double> forceAt, torqueAt;
  for (size_t i = 0; i < std::min(run.size(), ref.size()); ++i)
    for (const auto& [k, r] : ref[i]) {
      Load& p = peak[k];
      p.force = std::max(p.force, r.force);
      p.torque = std::max(p.torque, r.torque);
      const auto it = run[i].find(k);
      if (it == run[i].end()) continue;
      Load& d = diff[k];
      if (std::abs(it->second.force - r.force) > d.force) {
        d.force = std::abs(it->second.force - r.force);
        forceAt[k] = double(i + 1) * dt;
      }
      if (std::abs(it->second.torque - r.torque) > d.torque) {
        d.torque = std::abs(it->second.torque - r.torque);
        torqueAt[k] = double(i + 1) * dt;
      }
    }
  for (const auto& [k, d] : diff) {
    const Load& p = peak[k];
    if (p.force > 0 && 100.0 * d.force / p.force > force.value)
      force = {100.0 * d.force / p.force, names.at(k), forceAt[k]};
    if (p.torque > 0 && 100.0 * d.torque / p.torque > torque.value)
      torque = {100.0 * d.torque / p.torque, names.at(k), torqueAt[k]};
  }
}

/// Differences of `run` from `ref`, step by step.
Comparison compare(const Trace& run, const Trace& ref, double dt) {
  Comparison c;
  const size_t steps = std::min(run.joints.size(), ref.joints.size());
  double jointSq = 0, positionSq = 0;
  size_t jointN = 0, positionN = 0;
  for (size_t i = 0; i < steps; ++i) {
    const double t = double(i + 1) * dt;
    for (size_t j = 0; j < run.joints[i].size() && j < ref.joints[i].size(); ++j) {
      const double d = std::abs(run.joints[i][j] - ref.joints[i][j]) * 180.0 / kPi;
      if (d > c.jointDeg.value) c.jointDeg = {d, run.jointNames[j], t};
      jointSq += d * d;
      ++jointN;
    }
    for (size_t m = 0; m < run.positions[i].size() && m < ref.positions[i].size(); ++m) {
      const double d = (run.positions[i][m] - ref.positions[i][m]).norm() * 1000.0;
      if (d > c.positionMm.value) c.positionMm = {d, run.moduleNames[m], t};
      positionSq += d * d;
      ++positionN;
    }
    for (const auto& [k, l] : ref.loads[i])
      if (!run.loads[i].count(k)) ++c.missingConnections;
    for (const auto& [k, l] : run.loads[i])
      if (!ref.loads[i].count(k)) ++c.missingConnections;
  }
  c.jointRmsDeg = jointN ? std::sqrt(jointSq / double(jointN)) : 0.0;
  c.positionRmsMm = positionN ? std::sqrt(positionSq / double(positionN)) : 0.0;
  compareLoads(run.loads, ref.loads, ref.connectionNames, dt, c.forceStepPercent, c.torqueStepPercent);
  const size_t window = size_t(std::max(1.0, std::round(kLoadWindow / dt)));
  compareLoads(windowed(run.loads, window), windowed(ref.loads, window), ref.connectionNames, dt,
               c.forcePercent, c.torquePercent);
  return c;
}

std::string settingsText(const Trace& t) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%s solver, %d substeps x %d iterations", t.solver.c_str(), t.substeps,
                t.iterations);
  return buf;
}

nlohmann::json worstJson(const Worst& w, double threshold) {
  nlohmann::json j = {{"max", w.value}, {"where", w.where}, {"time", w.time}};
  if (threshold > 0) {
    j["threshold"] = threshold;
    j["ok"] = w.value <= threshold;
  }
  return j;
}

nlohmann::json comparisonJson(const Comparison& c, bool withThresholds) {
  return {{"joint_deg", worstJson(c.jointDeg, withThresholds ? kJointDeg : 0)},
          {"position_mm", worstJson(c.positionMm, withThresholds ? kPositionMm : 0)},
          {"dock_force_percent", worstJson(c.forcePercent, withThresholds ? kLoadPercent : 0)},
          {"dock_torque_percent", worstJson(c.torquePercent, withThresholds ? kLoadPercent : 0)},
          {"load_window_seconds", kLoadWindow},
          {"dock_force_step_percent", worstJson(c.forceStepPercent, 0)},
          {"dock_torque_step_percent", worstJson(c.torqueStepPercent, 0)},
          {"connection_steps_in_one_run_only", c.missingConnections},
          {"joint_rms_deg", c.jointRmsDeg},
          {"position_rms_mm", c.positionRmsMm}};
}

/// threshold 0: reported only.
void printRow(const char* what, const Worst& w, double threshold, double checkValue) {
  if (threshold > 0)
    std::printf("  %-24s %10.3f %10.3f %10s %12.3f   %s at t=%.3f s\n", what, w.value, threshold,
                w.value <= threshold ? "ok" : "EXCEEDED", checkValue, w.where.c_str(), w.time);
  else
    std::printf("  %-24s %10.3f %10s %10s %12.3f   %s at t=%.3f s\n", what, w.value, "-", "", checkValue,
                w.where.c_str(), w.time);
}

}  // namespace

int convergedCommand(const BenchArgs& a, const std::string& root) {
  if (!a.scenes.empty()) {
    std::fprintf(stderr,
                 "rm3d bench: --converged runs its own scene (the 10-module snake); no scene names\n");
    return 2;
  }
  std::string perr;
  if (!a.json.empty() && !prepareOutputFile("--json", a.json, perr)) {
    std::fprintf(stderr, "rm3d bench: %s\n", perr.c_str());
    return 2;
  }
  const double dt = a.dt.value_or(1.0 / 60.0);
  const long long steps = a.stepsGiven ? a.steps : std::max(1LL, (long long)std::llround(kSeconds / dt));
  Trace run, ref, check;
  if (!runSnake(a, root, dt, steps, a.substeps.value_or(0), a.iterations.value_or(0),
                a.jointIterations.value_or(0), run) ||
      !runSnake(a, root, dt, steps, kReferenceSubsteps, kReferenceIterations, 0, ref) ||
      !runSnake(a, root, dt, steps, kCheckSubsteps, kCheckIterations, 0, check))
    return 2;
  const Comparison c = compare(run, ref, dt);
  const Comparison self = compare(ref, check, dt);  // how converged the reference is

  std::printf("converged reference: %d-module %s snake, %lld steps of %.5f s (%.2f s)\n",
              int(run.moduleNames.size()), a.type.c_str(), steps, dt, double(steps) * dt);
  std::printf("  run:       %s (%.2f s wall)\n", settingsText(run).c_str(), run.wallSeconds);
  std::printf("  reference: %s (%.2f s wall); its own check against %s (%.2f s wall)\n",
              settingsText(ref).c_str(), ref.wallSeconds, settingsText(check).c_str(), check.wallSeconds);
  std::printf("  %-24s %10s %10s %10s %12s   %s\n", "largest difference", "run-ref", "threshold", "",
              "ref-finer", "where (run-ref)");
  printRow("joint angle (deg)", c.jointDeg, kJointDeg, self.jointDeg.value);
  printRow("module position (mm)", c.positionMm, kPositionMm, self.positionMm.value);
  std::printf("  %-24s %10.3f %10s %10s %12.3f   over every joint and step\n", "joint angle, RMS (deg)",
              c.jointRmsDeg, "-", "", self.jointRmsDeg);
  std::printf("  %-24s %10.3f %10s %10s %12.3f   over every module and step\n", "module position, RMS (mm)",
              c.positionRmsMm, "-", "", self.positionRmsMm);
  printRow("dock force (%)", c.forcePercent, kLoadPercent, self.forcePercent.value);
  printRow("dock torque (%)", c.torquePercent, kLoadPercent, self.torquePercent.value);
  printRow("dock force, 1 step (%)", c.forceStepPercent, 0, self.forceStepPercent.value);
  printRow("dock torque, 1 step (%)", c.torqueStepPercent, 0, self.torqueStepPercent.value);
  std::printf(
      "  (dock loads: means over %.2f s, or single steps; the largest difference over the run relative to\n"
      "   that dock's peak in the reference)\n",
      kLoadWindow);
  if (c.missingConnections)
    std::printf("  %d connection-steps exist in one run only (a dock broke in one of them)\n",
                c.missingConnections);
  const bool ok = c.jointDeg.value <= kJointDeg && c.positionMm.value <= kPositionMm &&
                  c.forcePercent.value <= kLoadPercent && c.torquePercent.value <= kLoadPercent &&
                  c.missingConnections == 0;
  std::printf("%s\n", ok ? "converged reference: within every threshold"
                         : "converged reference: a threshold was exceeded (exit code 1)");
  std::fflush(stdout);

  if (!a.json.empty()) {
    auto settingsJson = [](const Trace& t) {
      return nlohmann::json{{"solver", t.solver},
                            {"substeps", t.substeps},
                            {"solver_iterations", t.iterations},
                            {"joint_iterations", t.jointIterations},
                            {"wall_seconds", t.wallSeconds}};
    };
    const nlohmann::json out = {{"scene", "snake"},
                                {"modules", int(run.moduleNames.size())},
                                {"module_type", a.type},
                                {"dt", dt},
                                {"steps", steps},
                                {"run", settingsJson(run)},
                                {"reference", settingsJson(ref)},
                                {"reference_check", settingsJson(check)},
                                {"differences", comparisonJson(c, true)},
                                {"reference_vs_check", comparisonJson(self, false)},
                                {"ok", ok}};
    std::ofstream f(a.json);
    f << out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    f.close();
    if (!f) {
      std::fprintf(stderr, "rm3d bench: --json %s: cannot write the file\n", a.json.c_str());
      return 2;
    }
  }
  return ok ? 0 : 1;
}

}  // namespace rm3d
