// `rm3d view`: the interactive window (GLFW + Dear ImGui over the shared SceneRenderer).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace rm3d {

struct ViewArgs {
  std::string world;
  std::optional<unsigned long long> seed;
  std::vector<std::string> params;  ///< key=value
  int threads = 1;
  int chunk = 16;           ///< --chunk N (RunOptions::chunkSize)
  bool quiet = false;       ///< --quiet: no module log lines on the terminal
  int frames = 0;           ///< --exit-after N: > 0: render this many frames, then exit (with --screenshot)
  std::string screenshot;   ///< PNG of the last frame's window contents
  int select = -1;          ///< module id selected (inspector open) at start; -1: none
  double watchdog = 5;      ///< --watchdog S (RunOptions::watchdogSeconds)
  bool graph = true;        ///< the connection-graph panel (G toggles; --no-graph hides it at start)
  bool components = false;  ///< --components: modules coloured by connected component (C toggles)
};

/// Exit codes: 0 closed (or screenshot written), 2 bad input, no display, or a failed screenshot.
int viewCommand(const ViewArgs& a, const std::string& root);

}  // namespace rm3d
