// Running one world file to its end: shared by `rm3d run` and `rm3d test`.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "world/world.h"

namespace rm3d {

struct WorldRun {
  std::unique_ptr<World> world;
  std::string loadError;  ///< bad input found while loading (exit 2)
  double wallSeconds = 0;
  int exitCode = 0;       ///< 0 ok, 1 failed expectations or fatal fault, 2 bad input
};

using StepHook = std::function<void(World&)>;

/// Loads and steps a world until it finishes (or `steps` steps / `seconds` simulated seconds),
/// calling onStep (if any) after every step.
WorldRun runWorldFile(const std::string& file, const RunOptions& options, std::optional<long long> steps,
                      std::optional<double> seconds, const StepHook& onStep = {});

}  // namespace rm3d
