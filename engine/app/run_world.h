// Running one world file to its end: shared by `rm3d run` and `rm3d test`.
#pragma once

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

/// Loads and steps a world until it finishes (or `steps` steps / `seconds` simulated seconds).
WorldRun runWorldFile(const std::string& file, const RunOptions& options, std::optional<long long> steps,
                      std::optional<double> seconds);

}  // namespace rm3d
