// `rm3d test`: every world under the given paths (default tests/worlds), headless, one line
// each, then "N passed, N failed"; optionally a JUnit XML report.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/app.h"
#include "app/run_world.h"
#include "io/junit.h"
#include "script/world_script.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

std::string firstLine(const std::string& s) {
  return s.substr(0, s.find('\n'));
}

/// What makes a world fail under `rm3d test` beyond its exit code: checks that never ran, and
/// faulted modules the world did not declare with world.set{expect_faults=}.
std::vector<std::string> testProblems(const WorldRun& r) {
  std::vector<std::string> problems = r.unrunChecks;
  const World& w = *r.world;
  if (!r.loadError.empty() || !w.scriptError().empty() || w.fatalFault() || !w.script()) return problems;
  const std::optional<int> expected = w.script()->expectFaults;
  const int faulted = w.faultCount();
  std::vector<std::string> faults;
  for (const Module& m : w.modules())
    if (!m.fault.empty())
      faults.push_back("module " + m.name + " (id " + std::to_string(m.id) +
                       ") faulted: " + firstLine(m.fault));
  if (!expected && faulted > 0) {
    problems.push_back(
        std::to_string(faulted) + (faulted == 1 ? " module" : " modules") +
        " faulted; a world that faults modules on purpose says so with world.set{expect_faults = true} "
        "(or the number of faulted modules)");
    problems.insert(problems.end(), faults.begin(), faults.end());
  } else if (expected && *expected < 0 && faulted == 0) {
    problems.push_back("world.set{expect_faults = true}, but no module faulted");
  } else if (expected && *expected >= 0 && faulted != *expected) {
    problems.push_back("world.set{expect_faults = " + std::to_string(*expected) + "}, but " +
                       std::to_string(faulted) + (faulted == 1 ? " module" : " modules") + " faulted");
    problems.insert(problems.end(), faults.begin(), faults.end());
  }
  return problems;
}

}  // namespace

int testCommand(const TestArgs& a, const std::string& root) {
  std::vector<std::string> paths = a.paths;
  if (paths.empty()) paths.push_back((fs::path(root) / "tests" / "worlds").string());
  std::vector<std::string> files;
  for (const std::string& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<std::string> found;
      for (const auto& e : fs::recursive_directory_iterator(p, ec))
        if (e.is_regular_file() && e.path().extension() == ".lua") found.push_back(e.path().string());
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(p, ec)) {
      files.push_back(p);
    } else {
      std::fprintf(stderr, "rm3d test: %s: no such file or folder\n", p.c_str());
      return 2;
    }
  }
  std::string err;
  if (!a.junit.empty() && !prepareOutputFile("--junit", a.junit, err)) {
    std::fprintf(stderr, "rm3d test: %s\n", err.c_str());
    return 2;
  }
  installInterruptHandlers();
  std::vector<TestOutcome> outcomes;
  int passed = 0, failed = 0, signal = 0;
  for (const std::string& file : files) {
    RunOptions o;
    o.projectRoot = root;
    o.threads = a.threads;
    o.chunkSize = a.chunk;
    o.strict = a.strict;
    o.echoLog = false;
    o.echoWorldLog = false;
    o.watchdogSeconds = a.watchdog;
    WorldRun r = runWorldFile(file, o, std::nullopt, std::nullopt);
    const World& w = *r.world;
    if (r.signal) {
      signal = r.signal;
      std::printf("INTERRUPTED %s (%s at %.2f s simulated; no verdict)\n", file.c_str(), signalName(r.signal),
                  w.time());
      break;
    }
    const std::vector<std::string> problems = testProblems(r);
    TestOutcome out{file, r.exitCode == 0 && problems.empty(), r.wallSeconds, {}};
    auto add = [&out](const std::string& line) { out.message += (out.message.empty() ? "" : "\n") + line; };
    if (!r.loadError.empty())
      out.message = r.loadError;
    else if (!r.runError.empty())
      out.message = r.runError;
    else if (!w.scriptError().empty())
      out.message = "world script error: " + w.scriptError();
    else if (!w.divergence().empty())
      out.message = w.divergence();
    for (const Failure& f : w.failures()) add(f.message);
    if (w.fatalFault())
      for (const Module& m : w.modules())
        if (!m.fault.empty()) add("fault in " + m.name + ": " + m.fault);
    for (const std::string& p : problems) add(p);
    std::printf("%s %s (%.2f s simulated, %.2f s)\n", out.passed ? "PASS" : "FAIL", file.c_str(), w.time(),
                r.wallSeconds);
    if (!out.passed) {
      std::string indented = "    " + out.message;
      for (size_t i = 0; (i = indented.find('\n', i)) != std::string::npos; i += 5)
        indented.replace(i, 1, "\n    ");
      std::printf("%s\n", indented.c_str());
    }
    std::fflush(stdout);
    (out.passed ? passed : failed)++;
    outcomes.push_back(std::move(out));
  }
  int code = failed == 0 ? 0 : 1;
  if (!a.junit.empty() && !writeJunit(a.junit, outcomes)) {
    std::fprintf(stderr, "rm3d test: --junit %s: cannot write the file\n", a.junit.c_str());
    code = 2;
  }
  if (signal) {
    std::printf("interrupted (%s): %zu of %zu worlds not run after it\n%d passed, %d failed\n",
                signalName(signal), files.size() - outcomes.size() - 1, files.size(), passed, failed);
    return 128 + signal;
  }
  std::printf("%d passed, %d failed\n", passed, failed);
  return code;
}

}  // namespace rm3d
