// Behaviour VM set-up and the protected calls into its callbacks.
#include "script/behaviour.h"

#include <lua.hpp>

#include <filesystem>

#include "script/bindings.h"
#include "world/world.h"

namespace fs = std::filesystem;

namespace rm3d {

Behaviour::Behaviour(World& world, int module) : m_vm(world.options().vmMemoryLimit) {
  m_ctx.world = &world;
  m_ctx.module = module;
  m_vm.setUser(&m_ctx);
  m_vm.setDisplayRoot(world.options().projectRoot);
  m_vm.setInstructionBudget(world.options().behaviourBudget);
  openModuleApi(m_vm.L(), m_ctx);
}

bool Behaviour::load(const std::string& path, std::string& err) {
  const std::string root = m_ctx.world->options().projectRoot;
  m_vm.setRequirePath({fs::path(path).parent_path().string(), (fs::path(root) / "lua").string(),
                       (fs::path(root) / "behaviors").string()});
  if (!m_vm.runFile(path, 0, err)) return false;
  refreshCallbacks();
  return true;
}

void Behaviour::refreshCallbacks() {
  lua_State* L = m_vm.L();
  struct Slot {
    const char* name;
    int* ref;
  };
  for (Slot s : {Slot{"step", &m_ctx.stepRef}, Slot{"init", &m_ctx.initRef}, Slot{"on_dock", &m_ctx.onDockRef},
                 Slot{"on_reload", &m_ctx.onReloadRef}}) {
    luaL_unref(L, LUA_REGISTRYINDEX, *s.ref);
    lua_getglobal(L, s.name);
    *s.ref = lua_isfunction(L, -1) ? luaL_ref(L, LUA_REGISTRYINDEX) : (lua_pop(L, 1), LUA_NOREF);
  }
}

bool Behaviour::callInit(std::string& err) {
  if (m_ctx.initRef == LUA_NOREF) return true;
  lua_rawgeti(m_vm.L(), LUA_REGISTRYINDEX, m_ctx.initRef);
  if (!m_vm.call(0, 0, err)) return false;
  refreshCallbacks();  // init may define step
  return true;
}

bool Behaviour::callOnDock(int dock, const char* event, std::string& err) {
  if (m_ctx.onDockRef == LUA_NOREF) return true;
  lua_State* L = m_vm.L();
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.onDockRef);
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.dockTableRef);
  lua_getfield(L, -1, m_ctx.world->module(m_ctx.module).type->docks[size_t(dock)].name.c_str());
  lua_remove(L, -2);
  lua_pushstring(L, event);
  return m_vm.call(2, 0, err);
}

bool Behaviour::callStep(double dt, std::string& err) {
  if (m_ctx.stepRef == LUA_NOREF) return true;
  lua_State* L = m_vm.L();
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.stepRef);
  lua_pushnumber(L, dt);
  return m_vm.call(1, 0, err);
}

}  // namespace rm3d
