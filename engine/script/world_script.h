// The world VM: runs a world script once (building the world through the `world` table) and
// keeps its hooks (on_step, at, every), called after each step.
#pragma once

#include <string>
#include <vector>

#include "script/lua_vm.h"

namespace rm3d {

class World;

class WorldScript {
 public:
  explicit WorldScript(World& world);
  /// Runs the script; throws InputError with file:line on any error.
  void runFile(const std::string& path);
  void runString(const std::string& source, const std::string& chunkName);
  /// Calls the hooks due at time t. False and err when a hook raised an error.
  bool afterStep(double t, std::string& err);

  struct Timed {
    double time;    ///< at: when; every: next time due
    double period;  ///< 0 for `at`
    int ref;
  };
  World& world() { return m_world; }
  std::vector<int> onStep;
  std::vector<Timed> timed;

 private:
  void setUp(const std::string& folder);
  World& m_world;
  LuaVm m_vm;
};

/// Installs `world`, `expect`, `args`, `log` and the Module and Body handle types.
void openWorldApi(lua_State* L, WorldScript& script);

}  // namespace rm3d
