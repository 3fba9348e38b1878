// Running one world file to its end: shared by `rm3d run` and `rm3d test`. Also what the
// commands share about ending a run (Ctrl-C, SIGTERM) and about output files.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/path_rule.h"  // checkOutputsApart, the output-overwrite rule
#include "world/world.h"

namespace rm3d {

/// Exit codes (README, "Command line"). When several apply, the highest wins.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailed = 1,     ///< failed expectations; a fault under --strict (or under `rm3d test`)
  kExitBadInput = 2,   ///< bad input, or an output file that could not be written
  kExitWatchdog = 3,   ///< the watchdog stopped a run that hung
  kExitSigint = 130,   ///< 128 + SIGINT: interrupted, summary written
  kExitSigterm = 143,  ///< 128 + SIGTERM
};

struct WorldRun {
  std::unique_ptr<World> world;
  std::string loadError;  ///< bad input found while loading (exit 2)
  std::string runError;   ///< an unexpected error while stepping (exit 2); the summary is still written
  double wallSeconds = 0;
  int exitCode = 0;  ///< see ExitCode
  int signal = 0;    ///< SIGINT or SIGTERM when that ended the run early, else 0
  /// Checks that never ran: world.at/every hooks the run ended before, or a world whose source
  /// calls expect() with none evaluated. Warnings under `rm3d run`, failures under `rm3d test`.
  std::vector<std::string> unrunChecks;
};

using StepHook = std::function<void(World&)>;

/// Loads and steps a world until it finishes (or `steps` steps / `seconds` simulated seconds,
/// or SIGINT/SIGTERM once installInterruptHandlers() was called), calling onStart (if any) once
/// the world is loaded, onStep (if any) after every step, then the world's on_end hooks.
WorldRun runWorldFile(const std::string& file, const RunOptions& options, std::optional<long long> steps,
                      std::optional<double> seconds, const StepHook& onStep = {},
                      const StepHook& onStart = {});

/// SIGINT and SIGTERM set a flag (nothing else) that ends the run after the current step. A
/// second signal of the same kind kills the process as usual. A signal ignored at start (a
/// background job of a script) stays ignored.
void installInterruptHandlers();
/// SIGINT or SIGTERM if one arrived since installInterruptHandlers(), else 0.
int interruptSignal();
const char* signalName(int sig);

/// Creates the folder an output file goes into (and its parents). False, and `err` naming the
/// flag, the path and why, when that fails or the path is a folder.
bool prepareOutputFile(const char* flag, const std::string& path, std::string& err);
/// Creates an output folder (and its parents); false and `err` when that fails.
bool prepareOutputFolder(const char* flag, const std::string& path, std::string& err);

/// True when the text of a Lua file calls expect( ... ) outside comments.
bool sourceCallsExpect(const std::string& file);

}  // namespace rm3d
