// The script layer's side of World: loading world scripts, module types and behaviours.
#include "script/script_host.h"

#include <filesystem>

#include "script/behaviour.h"
#include "script/module_type_loader.h"
#include "script/watchdog.h"
#include "script/world_script.h"
#include "world/module_handle.h"
#include "world/world.h"

namespace fs = std::filesystem;

namespace rm3d {

LuaScriptHost::LuaScriptHost(World& world) : m_world(world) {
  if (world.options().watchdogSeconds > 0)
    m_watchdog = std::make_unique<Watchdog>(world.options().watchdogSeconds);
}

LuaScriptHost::~LuaScriptHost() = default;

ModuleTypeDef LuaScriptHost::loadModuleType(const std::string& path) {
  return rm3d::loadModuleType(path, m_world.options().projectRoot, m_world.options().sources.get(),
                              m_world.options().meshes.get());
}

std::unique_ptr<ModuleProgram> LuaScriptHost::loadBehaviour(const ModuleHandle& module,
                                                            const std::string& path, std::string& err) {
  auto b = std::make_unique<Behaviour>(m_world.options(), module, m_watchdog.get());
  b->load(path, err);
  return b;
}

LuaScriptHost& scriptHostOf(World& world) {
  if (!world.scriptHost()) world.setScriptHost(std::make_unique<LuaScriptHost>(world));
  return static_cast<LuaScriptHost&>(*world.scriptHost());
}

// World's loading entry points are the script layer's (world/world.h says so).
void World::loadFile(const std::string& path) {
  std::error_code ec;
  setWorldFile(fs::absolute(path, ec).lexically_normal().string());
  scriptHostOf(*this);
  auto script = std::make_unique<WorldScript>(*this);
  WorldScript& s = *script;
  setProgram(std::move(script));
  s.runFile(worldFile());
}

void World::loadString(const std::string& source, const std::string& chunkName) {
  if (worldFile().empty()) setWorldFile((fs::path(options().projectRoot) / "worlds" / "inline.lua").string());
  scriptHostOf(*this);
  auto script = std::make_unique<WorldScript>(*this);
  WorldScript& s = *script;
  setProgram(std::move(script));
  s.runString(source, chunkName);
}

WorldScript* World::script() const {
  return static_cast<WorldScript*>(m_program.get());
}

}  // namespace rm3d
