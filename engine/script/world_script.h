// The world VM: runs a world script once (building the world through the `world` table) and
// keeps its hooks (on_step, at, every), called after each step.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "script/lua_vm.h"
#include "world/programs.h"
#include "world/world_editor.h"

namespace rm3d {

class World;

class WorldScript : public WorldProgram {
 public:
  explicit WorldScript(World& world);
  /// Runs the script; throws InputError with file:line on any error.
  void runFile(const std::string& path);
  void runString(const std::string& source, const std::string& chunkName);
  /// Calls the hooks due at time t. False and err when a hook raised an error.
  bool afterStep(double t, std::string& err) override;
  /// Calls the world.on_end hooks (once; later calls do nothing). False and err on an error.
  bool atEnd(double t, std::string& err);
  bool hasReward() const override { return rewardRef >= 0; }
  bool hasDone() const override { return doneRef >= 0; }
  bool reward(int modules, double* out, std::string& err) override;
  bool done(int modules, uint8_t* out, std::string& err) override;
  /// One line per world.at / world.every hook that never ran ("file:line: world.at(2) never
  /// ran: the run ended at t=1.000 s ...").
  std::vector<std::string> hooksNeverRun(double endTime) const;

  struct Timed {
    double time;    ///< at: when; every: next time due
    double period;  ///< 0 for `at`
    int ref;
    std::string where;  ///< "file:line:" of the world.at / world.every call
    double first = 0;   ///< the time asked for (at) or the period (every)
    int runs = 0;       ///< times called
  };
  /// The world, read-only, and the narrow editor the bindings change it through.
  const World& world() const { return m_world; }
  WorldEditor& editor() { return m_editor; }
  /// True once the watchdog stopped a call into the world script (its load or a hook).
  bool stoppedByWatchdog() const { return m_vm.watchdogStops() > 0; }
  std::vector<int> onStep;
  std::vector<Timed> timed;
  std::vector<int> onEnd;
  int rewardRef = -1, doneRef = -1;  ///< world.reward(fn), world.done(fn) (registry refs; -1: none)
  bool ended = false;
  long long expectCount = 0;  ///< expect() calls evaluated, passed or failed
  /// world.set{expect_faults=}: unset: no module may fault (under `rm3d test`); -1 (true): one
  /// or more; n >= 0: exactly n faulted modules.
  std::optional<int> expectFaults;

 private:
  void setUp(const std::string& folder);
  World& m_world;
  WorldEditor m_editor{m_world};
  LuaVm m_vm;
};

/// Installs `world`, `expect`, `args`, `log` and the Module and Body handle types.
void openWorldApi(lua_State* L, WorldScript& script);
/// math.random in the world VM draws from the run's seed (Lua seeds it from the clock otherwise):
/// the same world and seed give the same draws.
void seedWorldRandom(lua_State* L, uint64_t seed);

}  // namespace rm3d
