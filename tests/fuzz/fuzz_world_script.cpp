// Fuzzes the world-script API: the input is world-script source, run by World::loadString and
// then stepped a few times, with small instruction budgets and memory caps so that a runaway
// script ends quickly. Bad input must end in InputError (or a recorded script error); anything
// else is a finding. The summary is built as `rm3d run --json` builds it.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "io/summary.h"
#include "world/world.h"

namespace {
constexpr int kSteps = 8;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rm3d::RunOptions o;
  o.projectRoot = RM3D_SOURCE_DIR;
  o.echoLog = false;
  o.threads = 1;
  o.vmMemoryLimit = size_t(8) << 20;
  o.behaviourBudget = 200'000;
  o.worldBudget = 2'000'000;
  try {
    rm3d::World w(o);
    w.loadString(std::string(reinterpret_cast<const char*>(data), size), "fuzz.lua");
    for (int i = 0; i < kSteps && !w.stopped(); ++i) w.step();
    (void)runSummary(w, 0).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  } catch (const rm3d::InputError&) {
  }
  return 0;
}
