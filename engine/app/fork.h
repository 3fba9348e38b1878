// `rm3d run WORLD --fork FILE --at T`: re-simulates a recorded run to time T with the Lua texts
// stored in the recording (its seed and params too), checks the state there against the
// recorded one, then goes on with the files as they are on disk now: changed behaviours and
// lua/ files are hot-reloaded into the running modules (their `state` kept, as in `view`), the
// physics state is kept. The world script stays the recorded one (its hooks run on).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "io/recording.h"
#include "world/world.h"

namespace rm3d {

struct ForkPlan {
  Recording recording;
  int64_t step = 0;  ///< the fork happens after this many steps
  double at = 0;
  std::string worldFile;                        ///< absolute: WORLD as given now
  std::map<std::string, std::string> recorded;  ///< current path -> recorded text
  bool done = false;
};

/// Reads the recording, lays its texts over the current paths (the recorded world folder and
/// project root are mapped to WORLD's folder and the root now) and sets seed and params as
/// recorded. False and err (naming the file or flag) on a bad recording or a T past its end.
bool prepareFork(const std::string& file, double at, const std::string& world, RunOptions& options,
                 ForkPlan& plan, std::string& err);

/// At the fork step: compares the state with the recorded frame, then switches reads to the
/// disk and reloads what changed. Lines for the terminal go to `report`; false when the
/// re-simulation did not match the recording bit for bit (`report` says where).
bool forkNow(World& world, ForkPlan& plan, std::vector<std::string>& report);

}  // namespace rm3d
