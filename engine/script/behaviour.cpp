// Behaviour VM set-up and the protected calls into its callbacks.
#include "script/behaviour.h"

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <lua.hpp>

#include "script/behaviour_bindings.h"
#include "script/lua_layout.h"
#include "script/watchdog.h"

namespace fs = std::filesystem;

namespace rm3d {

Behaviour::Behaviour(const RunOptions& options, ModuleHandle module, Watchdog* watchdog)
    : m_vm(options.vmMemoryLimit), m_ctx{module} {
  m_vm.setUser(&m_ctx);
  m_vm.setDisplayRoot(options.projectRoot);
  m_vm.setInstructionBudget(options.behaviourBudget);
  m_vm.setName("module " + module.self().name);
  m_vm.setWatchdog(watchdog);
  m_vm.setSources(options.sources.get());
  openModuleApi(m_vm.L(), m_ctx);
}

bool Behaviour::load(const std::string& path, std::string& err) {
  const std::string root = m_ctx.module.world().options().projectRoot;
  m_vm.setRequirePath({fs::path(path).parent_path().string(), (fs::path(root) / "lua").string(),
                       (fs::path(root) / "behaviors").string()});
  // Percepts, actions and noise models load on first use (installLazyPrelude), then the behaviour.
  installLazyPrelude();
  m_file = m_vm.displayName(path);
  if (!m_vm.runFile(path, 0, err)) return false;
  // Check the percept and action declarations now, so a misspelt sensor is a load error.
  if (!checkDeclarations(path, err)) return false;
  return refreshCallbacks(err);
}

namespace {

int requirePrelude(lua_State* L) {
  lua_getglobal(L, "require");
  lua_pushliteral(L, "rm3d_behaviour");
  lua_call(L, 1, 0);
  return 0;
}

/// _G's __index: the global `noise` is lua/noise.lua, loaded on first use.
int lazyGlobal(lua_State* L) {
  if (lua_type(L, 2) != LUA_TSTRING || std::strcmp(lua_tostring(L, 2), "noise") != 0) return 0;
  requirePrelude(L);  // defines the global noise
  lua_rawget(L, 1);
  return 1;
}

/// module.sense / module.act before lua/rm3d_behaviour.lua is loaded: load it (it replaces both)
/// and call the real one.
int lazyPerceptCall(lua_State* L) {
  const int nargs = lua_gettop(L);
  requirePrelude(L);
  lua_getglobal(L, "module");
  lua_getfield(L, -1, lua_tostring(L, lua_upvalueindex(1)));
  lua_remove(L, -2);
  lua_insert(L, 1);
  lua_call(L, nargs, LUA_MULTRET);
  return lua_gettop(L);
}

/// Protected: loads the percept machinery and runs module.__check().
int checkPercepts(lua_State* L) {
  requirePrelude(L);
  lua_getglobal(L, "module");
  lua_getfield(L, -1, "__check");
  lua_call(L, 0, 0);
  return 0;
}

/// Protected: module.__describe() if the percept machinery is loaded, else nil.
int describeModule(lua_State* L) {
  lua_getglobal(L, "module");
  if (!lua_istable(L, -1)) return 0;
  lua_getfield(L, -1, "__describe");
  if (!lua_isfunction(L, -1)) return 0;
  lua_call(L, 0, 1);
  return 1;
}

/// Protected: the callbacks are looked up raw in _G (a behaviour's own _G metatable, e.g. a
/// strict mode that errors on unknown names, is not consulted) and held as references.
int refreshCallbackRefs(lua_State* L) {
  auto* ctx = static_cast<BehaviourContext*>(lua_touserdata(L, 1));
  struct Slot {
    const char* name;
    int* ref;
  };
  lua_pushglobaltable(L);
  const int g = lua_gettop(L);
  for (Slot s :
       {Slot{"step", &ctx->stepRef}, Slot{"init", &ctx->initRef}, Slot{"on_dock", &ctx->onDockRef},
        Slot{"on_reload", &ctx->onReloadRef}, Slot{"observe", &ctx->observeRef}, Slot{"act", &ctx->actRef}}) {
    luaL_unref(L, LUA_REGISTRYINDEX, *s.ref);
    *s.ref = LUA_NOREF;
    lua_pushstring(L, s.name);
    const int type = lua_rawget(L, g);
    if (type == LUA_TFUNCTION) {
      *s.ref = luaL_ref(L, LUA_REGISTRYINDEX);
    } else if (type != LUA_TNIL) {
      // A callback that is not a function would never run: a fault, not silence.
      return luaL_error(L, "the global '%s' is a %s; expected a function %s(...) or nil", s.name,
                        luaL_typename(L, -1), s.name);
    } else {
      lua_pop(L, 1);
    }
  }
  // act_size: how many numbers act(a) takes (the Python API's action row).
  ctx->actSize = -1;
  lua_pushliteral(L, "act_size");
  const int type = lua_rawget(L, g);
  if (type != LUA_TNIL) {
    if (type != LUA_TNUMBER)
      return luaL_error(L, "the global 'act_size' is a %s; expected a whole number from 0 to %d",
                        luaL_typename(L, -1), kMaxActSize);
    // lua_tointegerx takes a float only when it is whole (3.0), never rounding 1.5 down.
    int whole = 0;
    const lua_Integer n = lua_tointegerx(L, -1, &whole);
    if (!whole || n < 0 || n > kMaxActSize)
      return luaL_error(L, "act_size = %s; expected a whole number from 0 to %d", lua_tostring(L, -1),
                        kMaxActSize);
    ctx->actSize = int(n);
  }
  return 0;
}

}  // namespace

void Behaviour::installLazyPrelude() {
  // Percepts, actions and noise models (lua/rm3d_behaviour.lua, lua/noise.lua) load only in the
  // VMs that use them: most behaviours never do, and loading them everywhere cost 0.6 s and
  // memory per 1000 modules.
  lua_State* L = m_vm.L();
  lua_pushglobaltable(L);
  lua_createtable(L, 0, 1);
  lua_pushcfunction(L, lazyGlobal);
  lua_setfield(L, -2, "__index");
  lua_setmetatable(L, -2);
  lua_pop(L, 1);
  lua_getglobal(L, "module");
  for (const char* name : {"sense", "act"}) {
    lua_pushstring(L, name);
    lua_pushcclosure(L, lazyPerceptCall, 1);
    lua_setfield(L, -2, name);
  }
  lua_pop(L, 1);
}

bool Behaviour::checkDeclarations(const std::string& path, std::string& err) {
  lua_State* L = m_vm.L();
  const int top = lua_gettop(L);
  lua_pushglobaltable(L);
  lua_pushliteral(L, "percepts");
  bool declared = lua_rawget(L, top + 1) != LUA_TNIL;
  lua_pushliteral(L, "actions");
  declared = lua_rawget(L, top + 1) != LUA_TNIL || declared;
  lua_settop(L, top);
  if (!declared) return true;
  if (!m_vm.protect(checkPercepts, nullptr, 0, err, "the percept check")) {
    err = locateDeclaration(path, err);
    return false;
  }
  return true;
}

std::string Behaviour::describePercepts() {
  std::string err;
  if (!m_vm.protect(describeModule, nullptr, 1, err, "module.__describe()")) return "(" + err + ")";
  lua_State* L = m_vm.L();
  std::string out = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
  lua_pop(L, 1);
  return out;
}

std::string Behaviour::locateDeclaration(const std::string& path, const std::string& err) const {
  // "percepts.tilt: ..." -> "behaviors/x.lua:12: percepts.tilt: ..." at the line declaring tilt.
  const size_t dot = err.find('.'), colon = err.find(':');
  std::string line = "";
  if (dot != std::string::npos && colon != std::string::npos && dot < colon &&
      (err.rfind("percepts.", 0) == 0 || err.rfind("actions.", 0) == 0)) {
    const std::string key = err.substr(dot + 1, colon - dot - 1);
    std::string text;
    if (readTextFile(path, text)) {
      int n = 1;
      for (size_t pos = 0; pos < text.size(); ++n) {
        const size_t end = text.find('\n', pos);
        std::string l = text.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
        const size_t comment = l.find("--");
        if (comment != std::string::npos) l.resize(comment);  // a name in a comment is not the declaration
        const size_t k = l.find(key);
        if (k != std::string::npos &&
            (k == 0 || (!std::isalnum(static_cast<unsigned char>(l[k - 1])) && l[k - 1] != '_'))) {
          const size_t eq = l.find_first_not_of(" \t\"]", k + key.size());
          if (eq != std::string::npos && l[eq] == '=') {
            line = std::to_string(n);
            break;
          }
        }
        if (end == std::string::npos) break;
        pos = end + 1;
      }
    }
  }
  const std::string where = m_vm.displayName(path) + (line.empty() ? "" : ":" + line);
  return where + ": " + err;
}

bool Behaviour::refreshCallbacks(std::string& err) {
  if (m_vm.protect(refreshCallbackRefs, &m_ctx, 0, err, "the callback look-up")) return true;
  if (err.rfind(m_file + ":", 0) != 0) err = m_file + ": " + err;
  return false;
}

bool Behaviour::reload(const std::string& path, const std::string& source, std::string& err) {
  m_hot.clear();  // (noted again with the world's next note)
  lua_State* L = m_vm.L();
  const int top = lua_gettop(L);
  std::string chunk = "@";
  chunk += m_vm.displayName(path);
  m_file = m_vm.displayName(path);
  if (luaL_loadbufferx(L, source.data(), source.size(), chunk.c_str(), "t") != LUA_OK) {
    err = lua_tostring(L, -1);
    lua_settop(L, top);
    return false;
  }
  // Scratch environment: reads fall through to the current globals, definitions land here.
  lua_newtable(L);
  lua_createtable(L, 0, 1);
  lua_pushglobaltable(L);
  lua_setfield(L, -2, "__index");
  lua_setmetatable(L, -2);
  lua_pushvalue(L, -1);
  lua_setupvalue(L, -3, 1);  // a main chunk's first upvalue is _ENV
  const int env = lua_gettop(L);
  lua_pushvalue(L, env - 1);
  lua_remove(L, env - 1);  // stack: env, chunk
  // Lua modules are required afresh, so edits in lua/ arrive too.
  lua_newtable(L);
  lua_setfield(L, LUA_REGISTRYINDEX, "rm3d.loaded");
  if (!m_vm.call(0, 0, err, "the reloaded script's top level")) {
    lua_settop(L, top);
    return false;
  }
  // Success: the new definitions become the module's globals.
  const int envIndex = lua_gettop(L);
  lua_pushglobaltable(L);
  lua_pushnil(L);
  while (lua_next(L, envIndex) != 0) {
    lua_pushvalue(L, -2);
    lua_insert(L, -2);
    lua_rawset(L, envIndex + 1);
  }
  lua_settop(L, top);
  if (!checkDeclarations(path, err) || !refreshCallbacks(err)) return false;
  if (m_ctx.onReloadRef != LUA_NOREF) {
    lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.onReloadRef);
    if (!m_vm.call(0, 0, err, "on_reload()")) return false;
  }
  return true;
}

bool Behaviour::init(std::string& err) {
  if (m_ctx.initRef == LUA_NOREF) return true;
  lua_rawgeti(m_vm.L(), LUA_REGISTRYINDEX, m_ctx.initRef);
  if (!m_vm.call(0, 0, err, "init()")) return false;
  return refreshCallbacks(err);  // init may define step
}

bool Behaviour::onDock(int dock, DockEventKind event, std::string& err) {
  if (m_ctx.onDockRef == LUA_NOREF) return true;
  lua_State* L = m_vm.L();
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.onDockRef);
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.dockTableRef);
  lua_getfield(L, -1, m_ctx.module.self().type->docks[size_t(dock)].name.c_str());
  lua_remove(L, -2);
  lua_pushstring(L, dockEventName(event));
  return m_vm.call(2, 0, err, "on_dock()");
}

bool Behaviour::observe(std::vector<double>& out, std::string& err) {
  if (m_ctx.observeRef == LUA_NOREF) return true;
  lua_State* L = m_vm.L();
  const int top = lua_gettop(L);
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.observeRef);
  if (!m_vm.call(0, 1, err, "observe()")) return false;
  if (!lua_istable(L, -1)) {
    err = m_file + ": observe() returned a " + luaL_typename(L, -1) + "; expected a list of numbers";
    lua_settop(L, top);
    return false;
  }
  const lua_Integer n = lua_Integer(lua_rawlen(L, -1));
  if (n > kMaxObsSize) {
    err = m_file + ": observe() returned " + std::to_string(n) + " numbers; at most " +
          std::to_string(kMaxObsSize) + " are allowed";
    lua_settop(L, top);
    return false;
  }
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L, -1, i);
    int isnum = 0;
    const double v = lua_tonumberx(L, -1, &isnum);
    if (!isnum || !std::isfinite(v)) {
      err = m_file + ": observe() returned " +
            (isnum ? "a number that is not finite" : std::string("a ") + luaL_typename(L, -1)) + " at [" +
            std::to_string(i) + "]; expected a list of finite numbers";
      lua_settop(L, top);
      return false;
    }
    out.push_back(v);
    lua_pop(L, 1);
  }
  lua_settop(L, top);
  return true;
}

int Behaviour::actSize(int joints) const {
  if (m_ctx.actRef == LUA_NOREF) return -1;
  return m_ctx.actSize >= 0 ? m_ctx.actSize : joints;
}

namespace {
struct ActCall {
  int ref;
  const double* a;
  int n;
};
/// Protected: act(a) with a fresh list (building it may fail under the VM's memory cap).
int callAct(lua_State* L) {
  const auto* c = static_cast<const ActCall*>(lua_touserdata(L, 1));
  lua_rawgeti(L, LUA_REGISTRYINDEX, c->ref);
  lua_createtable(L, c->n, 0);
  for (int i = 0; i < c->n; ++i) {
    lua_pushnumber(L, c->a[i]);
    lua_rawseti(L, -2, i + 1);
  }
  lua_call(L, 1, 0);
  return 0;
}
}  // namespace

bool Behaviour::act(const double* a, int n, std::string& err) {
  if (m_ctx.actRef == LUA_NOREF) return true;
  ActCall c{m_ctx.actRef, a, n};
  return m_vm.protect(callAct, &c, 0, err, "act()");
}

void Behaviour::fetchState(int stage) const {
  if (stage == 2) {  // the list of what step() reads, the step function's reference, the state's address
    const char* hot = reinterpret_cast<const char*>(m_hot.data());
    for (size_t at = 0; at < m_hot.size() * sizeof(const void*); at += 64) __builtin_prefetch(hot + at);
    __builtin_prefetch(&m_ctx.stepRef);
    __builtin_prefetch(m_vm.stateSlot());
    return;
  }
  if (stage == 1) {  // what step() reads (into the second-level cache: tens of lines at once)
    for (const void* p : m_hot) __builtin_prefetch(p, 0, 2);
    return;
  }
  // The Lua state's first lines (its stack top, global state and call info).
  const char* L = reinterpret_cast<const char*>(m_vm.L());
  if (!L) return;
  for (int at = 0; at < 192; at += 64) __builtin_prefetch(L + at);
}

void Behaviour::noteHotLines() {
  // At most kHotLines lines: the travelling-wave snake's step() reaches 85 (its code and
  // constants, its globals' tables, the gait helper, the joint's methods), the SuperBots'
  // alternating servos 39, an ATRON's wheel 29.
  constexpr size_t kHotLines = 128;
  m_hot.clear();
  m_hot.reserve(kHotLines);  // (once: no later note allocates)
  if (m_ctx.stepRef == LUA_NOREF) return;
  lua_State* L = m_vm.L();
  if (const void* slot = lua_layout::arraySlot(L, LUA_REGISTRYINDEX, m_ctx.stepRef)) m_hot.push_back(slot);
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.stepRef);
  lua_layout::hotLines(L, kHotLines, m_hot);
  lua_pop(L, 1);
}

bool Behaviour::step(double dt, std::string& err) {
  if (m_ctx.stepRef == LUA_NOREF) return true;
  lua_State* L = m_vm.L();
  lua_rawgeti(L, LUA_REGISTRYINDEX, m_ctx.stepRef);
  lua_pushnumber(L, dt);
  return m_vm.call(1, 0, err, "step()");
}

}  // namespace rm3d
