// The Lua script layer as the World sees it (world/programs.h): module types read from Lua
// data, one behaviour VM per module, and the watchdog the VMs share.
#pragma once

#include <memory>
#include <string>

#include "world/programs.h"

namespace rm3d {

class World;
class Watchdog;

class LuaScriptHost : public ScriptHost {
 public:
  explicit LuaScriptHost(World& world);
  ~LuaScriptHost() override;
  ModuleTypeDef loadModuleType(const std::string& path) override;
  std::unique_ptr<ModuleProgram> loadBehaviour(const ModuleHandle& module, const std::string& path,
                                               std::string& err) override;
  /// Limits calls into this world's VMs to RunOptions::watchdogSeconds (null when off).
  Watchdog* watchdog() const { return m_watchdog.get(); }

 private:
  World& m_world;
  std::unique_ptr<Watchdog> m_watchdog;
};

/// The host of a world's scripts, made on first use (World::loadFile and loadString).
LuaScriptHost& scriptHostOf(World& world);

}  // namespace rm3d
