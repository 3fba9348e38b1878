// Running a world file to its end; interrupts; output paths.
#include "app/run_world.h"

#include <signal.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "script/script_host.h"
#include "script/watchdog.h"
#include "script/world_script.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

volatile std::sig_atomic_t g_signal = 0;
volatile std::time_t g_firstSec = 0;  // when the first signal came (CLOCK_MONOTONIC)
volatile long g_firstNsec = 0;

/// The first SIGINT or SIGTERM asks the run to end after its step (the summary is written); a
/// second one kills as usual, unless it comes within half a second of the first: timeout(1),
/// for one, sends its signal to the process and then again to its process group, and that
/// duplicate used to kill a run before it could write its summary.
extern "C" void onInterrupt(int sig) {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  if (g_signal == 0) {
    g_firstSec = now.tv_sec;
    g_firstNsec = now.tv_nsec;
    g_signal = sig;
    return;
  }
  const double since = double(now.tv_sec - g_firstSec) + 1e-9 * double(now.tv_nsec - g_firstNsec);
  if (since < 0.5) return;
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

void installInterruptHandlers() {
  for (int sig : {SIGINT, SIGTERM}) {
    struct sigaction old {};
    if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    struct sigaction sa {};
    sa.sa_handler = onInterrupt;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);  // one handler at a time
    sigaddset(&sa.sa_mask, SIGTERM);
    sa.sa_flags = SA_RESTART;
    sigaction(sig, &sa, nullptr);
  }
}

int interruptSignal() {
  return int(g_signal);
}

const char* signalName(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "signal";
}

bool prepareOutputFolder(const char* flag, const std::string& path, std::string& err) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return true;
  fs::create_directories(path, ec);
  if (ec || !fs::is_directory(path)) {
    err = std::string(flag) + " " + path + ": cannot create the folder (" +
          (ec ? ec.message() : "not a folder") + ")";
    return false;
  }
  return true;
}

bool prepareOutputFile(const char* flag, const std::string& path, std::string& err) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    err = std::string(flag) + " " + path + ": is a folder (expected a file name)";
    return false;
  }
  const fs::path dir = fs::absolute(path, ec).parent_path();
  if (fs::is_directory(dir, ec)) {
    if (::access(dir.c_str(), W_OK) != 0) {
      err = std::string(flag) + " " + path + ": cannot write into the folder " + dir.string();
      return false;
    }
    return true;
  }
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    err = std::string(flag) + " " + path + ": cannot create the folder " + dir.string() + " (" +
          (ec ? ec.message() : "not a folder") + ")";
    return false;
  }
  return true;
}

bool sourceCallsExpect(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  bool inBlockComment = false;
  while (std::getline(in, line)) {
    if (inBlockComment) {
      const size_t close = line.find("]]");
      if (close == std::string::npos) continue;
      line = line.substr(close + 2);
      inBlockComment = false;
    }
    const size_t comment = line.find("--");
    if (comment != std::string::npos) {
      if (line.compare(comment, 4, "--[[") == 0 && line.find("]]", comment) == std::string::npos)
        inBlockComment = true;
      line.resize(comment);
    }
    for (size_t at = line.find("expect"); at != std::string::npos; at = line.find("expect", at + 6)) {
      const auto ident = [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == ':';
      };
      if (at > 0 && ident(line[at - 1])) continue;
      size_t k = at + 6;
      while (k < line.size() && (line[k] == ' ' || line[k] == '\t')) ++k;
      if (k < line.size() && (line[k] == '(' || line[k] == '"' || line[k] == '\'' || line[k] == '{'))
        return true;
    }
  }
  return false;
}

WorldRun runWorldFile(const std::string& file, const RunOptions& options, std::optional<long long> steps,
                      std::optional<double> seconds, const StepHook& onStep, const StepHook& onStart) {
  WorldRun r;
  const auto t0 = std::chrono::steady_clock::now();
  r.world = std::make_unique<World>(options);
  World& w = *r.world;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    r.loadError = file + ": cannot read world file (" +
                  (fs::exists(file, ec) ? "not a regular file" : "no such file") + ")";
    r.exitCode = kExitBadInput;
    return r;
  }
  try {
    w.loadFile(file);
  } catch (const InputError& e) {
    r.loadError = e.what();
    r.exitCode = w.script() && w.script()->stoppedByWatchdog() ? kExitWatchdog : kExitBadInput;
    return r;
  }
  long long limit = -1;
  if (steps) limit = *steps;
  if (seconds) limit = std::llround(*seconds / w.settings().dt);
  try {
    if (onStart) onStart(w);
    while (limit >= 0 ? (w.steps() < limit && !w.stopped()) : !w.finished()) {
      if ((r.signal = interruptSignal()) != 0) break;
      w.step();
      if (onStep) onStep(w);
    }
    if (!r.signal) r.signal = interruptSignal();
  } catch (const std::exception& e) {
    r.runError = w.worldFile() + ": the run stopped at t=" + std::to_string(w.time()) + " s: " + e.what();
  }
  // The run has ended, however: on_end hooks, then what never ran.
  WorldScript* script = w.script();
  if (script && w.scriptError().empty() && r.runError.empty()) {
    std::string err;
    if (!script->atEnd(w.time(), err)) w.setScriptError(err);
  }
  if (script) {
    r.unrunChecks = script->hooksNeverRun(w.time());
    if (script->expectCount == 0 && w.scriptError().empty() && sourceCallsExpect(file)) {
      char line[160];
      std::snprintf(line, sizeof line,
                    ": the world calls expect() but none was evaluated: the run ended at t=%.3f s", w.time());
      r.unrunChecks.push_back(file + line +
                              " before any check ran (world.on_end(fn) runs whatever the run's length)");
    }
  }
  r.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!w.scriptError().empty() || !r.runError.empty())
    r.exitCode = kExitBadInput;
  else if (!w.failures().empty() || w.fatalFault())
    r.exitCode = kExitFailed;
  // The watchdog stopped the world script (its error ended the run), or under --strict a module
  // (whose fault ended it): a hung run, exit 3 (the message names file:line and "watchdog").
  const int scriptStops = script && script->stoppedByWatchdog() ? 1 : 0;
  const Watchdog* dog = w.scriptHost() ? static_cast<LuaScriptHost*>(w.scriptHost())->watchdog() : nullptr;
  const bool moduleStopped = dog && dog->stops() > scriptStops;
  if ((scriptStops && !w.scriptError().empty()) || (options.strict && w.fatalFault() && moduleStopped))
    r.exitCode = kExitWatchdog;
  if (r.signal) r.exitCode = 128 + r.signal;
  return r;
}

}  // namespace rm3d
