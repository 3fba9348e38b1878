// Running world scripts and their hooks.
#include "script/world_script.h"

#include <lua.hpp>

#include <filesystem>

#include "core/error.h"
#include "script/watchdog.h"
#include "world/world.h"

namespace fs = std::filesystem;

namespace rm3d {

WorldScript::WorldScript(World& world) : m_world(world), m_vm(world.options().worldMemoryLimit) {
  m_vm.setUser(this);
  m_vm.setOwnerLabel("world script");
  m_vm.setName("the world script");
  m_vm.setWatchdog(world.watchdog());
  m_vm.setDisplayRoot(world.options().projectRoot);
  m_vm.setInstructionBudget(world.options().worldBudget);
  openWorldApi(m_vm.L(), *this);
}

void WorldScript::setUp(const std::string& folder) {
  const std::string root = m_world.options().projectRoot;
  m_vm.setRequirePath({folder, (fs::path(root) / "lua").string(), (fs::path(root) / "behaviors").string()});
}

void WorldScript::runFile(const std::string& path) {
  setUp(fs::path(path).parent_path().string());
  std::string err;
  if (!m_vm.runFile(path, 0, err)) throw InputError(err);
}

void WorldScript::runString(const std::string& source, const std::string& chunkName) {
  setUp(fs::path(m_world.worldFile()).parent_path().string());
  lua_State* L = m_vm.L();
  std::string err;
  const std::string chunk = "@" + chunkName;
  if (luaL_loadbufferx(L, source.data(), source.size(), chunk.c_str(), "t") != LUA_OK) {
    err = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "cannot load " + chunkName;
    makeValidUtf8(err);
    lua_pop(L, 1);
    throw InputError(err);
  }
  if (!m_vm.call(0, 0, err, "the world script's top level")) throw InputError(err);
}

bool WorldScript::afterStep(double t, std::string& err) {
  if (onStep.empty() && timed.empty()) return true;
  lua_State* L = m_vm.L();
  const double eps = 0.5 * m_world.settings().dt;
  for (size_t i = 0; i < onStep.size(); ++i) {
    lua_rawgeti(L, LUA_REGISTRYINDEX, onStep[i]);
    lua_pushnumber(L, t);
    if (!m_vm.call(1, 0, err, "a world.on_step hook")) return false;
  }
  for (size_t i = 0; i < timed.size(); ++i) {
    // Index, not reference: a hook may add hooks and grow the vector.
    if (timed[i].ref == LUA_NOREF || t + eps < timed[i].time) continue;
    const int ref = timed[i].ref;
    if (timed[i].period > 0) {
      while (timed[i].time <= t + eps) timed[i].time += timed[i].period;
    } else {
      timed[i].ref = LUA_NOREF;
    }
    lua_rawgeti(L, LUA_REGISTRYINDEX, ref);
    lua_pushnumber(L, t);
    if (!m_vm.call(1, 0, err, timed[i].period > 0 ? "a world.every hook" : "a world.at hook")) return false;
  }
  return true;
}

}  // namespace rm3d
