// Running world scripts and their hooks.
#include "script/world_script.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <lua.hpp>

#include "core/error.h"
#include "script/script_host.h"
#include "script/watchdog.h"
#include "world/world.h"

namespace fs = std::filesystem;

namespace rm3d {

WorldScript::WorldScript(World& world) : m_world(world), m_vm(world.options().worldMemoryLimit) {
  m_vm.setUser(this);
  m_vm.setOwnerLabel("world script");
  m_vm.setName("the world script");
  m_vm.setWatchdog(scriptHostOf(world).watchdog());
  m_vm.setDisplayRoot(world.options().projectRoot);
  m_vm.setInstructionBudget(world.options().worldBudget);
  m_vm.setSources(world.options().sources.get());
  openWorldApi(m_vm.L(), *this);
  seedWorldRandom(m_vm.L(), world.settings().seed);
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
    ++timed[i].runs;
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

bool WorldScript::atEnd(double t, std::string& err) {
  if (ended) return true;
  ended = true;
  lua_State* L = m_vm.L();
  for (size_t i = 0; i < onEnd.size(); ++i) {
    lua_rawgeti(L, LUA_REGISTRYINDEX, onEnd[i]);
    lua_pushnumber(L, t);
    if (!m_vm.call(1, 0, err)) return false;
  }
  return true;
}

namespace {
/// world.reward / world.done: calls fn(t) and reads what it returned into out[0..modules):
/// a number (boolean) for every module, or a list with one per module. Returns false and err.
template <typename T, typename Read>
bool callPerModule(LuaVm& vm, int ref, double t, int modules, T* out, const char* name, const char* kind,
                   Read read, std::string& err) {
  lua_State* L = vm.L();
  const int top = lua_gettop(L);
  lua_rawgeti(L, LUA_REGISTRYINDEX, ref);
  // Where the function was written, so that a wrong return names its file and line.
  std::string where;
  lua_Debug ar;
  lua_pushvalue(L, -1);
  if (lua_getinfo(L, ">S", &ar) && ar.linedefined > 0)
    where = std::string(ar.short_src) + ":" + std::to_string(ar.linedefined) + ": ";
  lua_pushnumber(L, t);
  if (!vm.call(1, 1, err, name)) return false;
  auto fail = [&](const std::string& what) {
    err = where + name + "'s function returned " + what + "; expected a " + kind +
          " or a list with one per module (" + std::to_string(modules) + ")";
    lua_settop(L, top);
    return false;
  };
  if (lua_istable(L, -1)) {
    const size_t n = lua_rawlen(L, -1);
    if (n != size_t(modules)) return fail("a list of " + std::to_string(n));
    for (int i = 0; i < modules; ++i) {
      lua_rawgeti(L, -1, i + 1);
      if (!read(L, out[i]))
        return fail(std::string("a ") + luaL_typename(L, -1) + " at [" + std::to_string(i + 1) + "]");
      lua_pop(L, 1);
    }
  } else {
    T v{};
    if (!read(L, v)) return fail(std::string("a ") + luaL_typename(L, -1));
    std::fill(out, out + modules, v);
  }
  lua_settop(L, top);
  return true;
}
}  // namespace

bool WorldScript::reward(int modules, double* out, std::string& err) {
  if (rewardRef < 0) return true;
  return callPerModule(
      m_vm, rewardRef, m_world.time(), modules, out, "world.reward", "finite number",
      [](lua_State* L, double& v) {
        if (lua_type(L, -1) != LUA_TNUMBER) return false;
        v = lua_tonumber(L, -1);
        return std::isfinite(v);
      },
      err);
}

bool WorldScript::done(int modules, uint8_t* out, std::string& err) {
  if (doneRef < 0) return true;
  return callPerModule(
      m_vm, doneRef, m_world.time(), modules, out, "world.done", "boolean",
      [](lua_State* L, uint8_t& v) {
        if (lua_type(L, -1) != LUA_TBOOLEAN) return false;
        v = lua_toboolean(L, -1) ? 1 : 0;
        return true;
      },
      err);
}

std::vector<std::string> WorldScript::hooksNeverRun(double endTime) const {
  // One line per call site (a loop may schedule many hooks from one line).
  std::vector<std::string> out;
  std::vector<std::pair<std::string, std::vector<double>>> sites;  // "file:line: world.at", times
  for (const Timed& h : timed) {
    if (h.runs > 0) continue;
    const std::string key = h.where + (h.period > 0 ? "world.every" : "world.at");
    auto it = std::find_if(sites.begin(), sites.end(), [&](const auto& s) { return s.first == key; });
    if (it == sites.end()) it = sites.insert(sites.end(), {key, {}});
    it->second.push_back(h.first);
  }
  for (const auto& [key, times] : sites) {
    std::string text = key + (times.size() == 1 ? "(" : " hooks (t = ");
    for (size_t i = 0; i < times.size() && i < 4; ++i) {
      char num[32];
      std::snprintf(num, sizeof num, "%s%g", i ? ", " : "", times[i]);
      text += num;
    }
    if (times.size() > 4) text += ", and " + std::to_string(times.size() - 4) + " more";
    char tail[160];
    std::snprintf(tail, sizeof tail,
                  ") never ran: the run ended at t=%.3f s (world.on_end(fn) runs whatever the run's length)",
                  endTime);
    out.push_back(text + tail);
  }
  return out;
}

}  // namespace rm3d
