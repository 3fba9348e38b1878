// Sandboxed Lua state: allocator with a soft cap, a VM-wide count hook for the instruction
// budget and the watchdog, the allowed libraries, a path-limited `require`, and the protected
// call with traceback.
#include "script/lua_vm.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lua.hpp>
#include <sstream>

#include "core/path_rule.h"
#include "core/source_files.h"
#include "script/linalg_binding.h"
#include "script/watchdog.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

/// The VM whose outermost call this thread is running (to pause an outer VM's watchdog clock
/// while a nested call on another VM runs, e.g. a behaviour loading during world.spawn).
thread_local LuaVm* tlCurrent = nullptr;

int messageHandler(lua_State* L) {
  const char* msg = lua_tostring(L, 1);
  if (msg == nullptr) {
    // __tostring of an error object is user code: it runs under the hook like any other (and
    // an error in it ends as "error in error handling").
    if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING) return 1;
    msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
  }
  luaL_traceback(L, L, msg, 1);
  return 1;
}

/// setmetatable without finalizers: Lua runs __gc with debug hooks off, so an endless __gc
/// could not be stopped by the budget or the watchdog (it would hang a step or lua_close).
int safeSetmetatable(lua_State* L) {
  if (lua_type(L, 2) == LUA_TTABLE) {
    lua_pushliteral(L, "__gc");
    if (lua_rawget(L, 2) != LUA_TNIL)
      return luaL_error(L,
                        "setmetatable: a metatable with __gc is not allowed in scripts (finalizers run "
                        "outside the instruction budget)");
    lua_pop(L, 1);
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, 1);
  return 1;
}

/// xpcall's message handler, guarded: an error raised by our hook (budget, watchdog, memory)
/// leaves Lua's hooks switched off while the handler runs, so the script's handler could loop
/// unbounded. While the VM is aborting the handler is skipped and the message passes through.
int guardedHandler(lua_State* L) {
  if (LuaVm::from(L)->aborting()) return 1;
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, 1);
  return 1;
}

int xpcallContinue(lua_State* L, int, lua_KContext) {
  return lua_gettop(L);
}

int safeXpcall(lua_State* L) {
  luaL_checktype(L, 2, LUA_TFUNCTION);
  lua_pushvalue(L, 2);
  lua_pushcclosure(L, guardedHandler, 1);
  lua_replace(L, 2);
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_callk(L, lua_gettop(L) - 1, LUA_MULTRET, 0, xpcallContinue);
  return lua_gettop(L);
}

/// string.rep with the result's size checked against the memory cap before it is built.
int safeRep(lua_State* L) {
  size_t len = 0, seplen = 0;
  luaL_checklstring(L, 1, &len);
  const lua_Integer n = luaL_checkinteger(L, 2);
  luaL_optlstring(L, 3, "", &seplen);
  if (n > 1) {
    const double total = double(len) * double(n) + double(seplen) * double(n - 1);
    LuaVm::checkRoom(L, total, "string.rep");
    LuaVm::charge(L, int64_t(total / 16), "string.rep");  // about one instruction's time per 16 bytes copied
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, 1);
  return 1;
}

bool validModuleName(const char* name) {
  // Dot-separated identifiers: "gaits", "lib.noise".
  bool start = true;
  for (const char* p = name; *p; ++p) {
    const unsigned char c = static_cast<unsigned char>(*p);
    if (c == '.') {
      if (start) return false;
      start = true;
    } else if (std::isalpha(c) || c == '_' || (!start && std::isdigit(c))) {
      start = false;
    } else {
      return false;
    }
  }
  return !start;
}

}  // namespace

void LuaVm::checkRoom(lua_State* L, double bytes, const char* what) {
  LuaVm* vm = LuaVm::from(L);
  const size_t limit = vm->memoryLimit();
  if (!limit) return;
  const double room = limit > vm->memoryUsed() ? double(limit - vm->memoryUsed()) : 0.0;
  if (bytes > room)
    luaL_error(L, "out of memory: %s would take %I bytes, more than the memory cap (%d MiB) leaves room for",
               what, lua_Integer(std::min(bytes, 9e18)), int((limit + (1 << 19)) >> 20));
}

void sealMetatable(lua_State* L) {
  lua_pushboolean(L, 0);
  lua_setfield(L, -2, "__metatable");
}

void makeValidUtf8(std::string& s) {
  // Invalid bytes become U+FFFD (as the JSON writer does), so a message reads the same everywhere.
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const size_t n = s.size();
  std::string out;
  bool changed = false;
  for (size_t i = 0; i < n;) {
    const unsigned char c = p[i];
    size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool ok = len > 0 && i + len <= n;
    for (size_t k = 1; ok && k < len; ++k) ok = (p[i + k] & 0xC0) == 0x80;
    if (ok && len > 1) {
      // No overlong forms, surrogates or code points past U+10FFFF.
      uint32_t cp = c & (0x7F >> len);
      for (size_t k = 1; k < len; ++k) cp = (cp << 6) | (p[i + k] & 0x3F);
      ok = !(len == 2 && cp < 0x80) && !(len == 3 && cp < 0x800) && !(len == 4 && cp < 0x10000) &&
           !(cp >= 0xD800 && cp <= 0xDFFF) && cp <= 0x10FFFF;
    }
    if (ok) {
      out.append(s, i, len);
      i += len;
    } else {
      out += "\xEF\xBF\xBD";
      changed = true;
      ++i;
    }
  }
  if (changed) s = std::move(out);
}

void* LuaVm::alloc(void* ud, void* ptr, size_t osize, size_t nsize) {
  auto* vm = static_cast<LuaVm*>(ud);
  if (ptr == nullptr) osize = 0;  // osize encodes the object type when allocating
  if (nsize == 0) {
    vm->m_heap.realloc(ptr, osize, 0);
    vm->m_used -= osize;
    if (vm->m_memArmed && vm->m_used <= vm->m_limit) vm->m_memArmed = false;
    return nullptr;
  }
  if (vm->m_limit && nsize > osize && vm->m_used + (nsize - osize) > vm->m_limit && vm->m_depth > 0) {
    // Soft cap: the first allocation over it succeeds and the next instruction raises a normal
    // error (with file:line and traceback); past 1.25x the cap allocations fail outright.
    if (vm->m_used + (nsize - osize) > vm->m_limit + vm->m_limit / 4) return nullptr;
    if (!vm->m_memArmed) {
      vm->m_memArmed = true;
      if (vm->m_abort == Abort::None) {
        vm->m_abort = Abort::Memory;
        lua_sethook(vm->m_L, &LuaVm::hook, LUA_MASKCOUNT, 1);
      }
    }
  }
  void* p = vm->m_heap.realloc(ptr, osize, nsize);
  if (p) vm->m_used = vm->m_used - osize + nsize;
  return p;
}

int LuaVm::panic(lua_State* L) {
  // Every call into a VM is protected; reaching this is a bug in the host. Say so, loudly.
  LuaVm* vm = from(L);
  const char* msg = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "(not a string)";
  std::fprintf(stderr, "rm3d: internal error: unprotected Lua error in %s: %s\n",
               vm && !vm->m_name.empty() ? vm->m_name.c_str() : "a Lua VM", msg);
  std::fflush(stderr);
  std::abort();
}

std::string LuaVm::abortMessage() const {
  char buf[256];
  switch (m_abort) {
    case Abort::Watchdog: {
      const char* what = m_what.load(std::memory_order_relaxed);
      std::snprintf(buf, sizeof buf, "watchdog: %s did not return within %g s", what ? what : "the call",
                    m_interruptSeconds.load(std::memory_order_relaxed));
      break;
    }
    case Abort::Memory:
      std::snprintf(buf, sizeof buf, "out of memory: the %s's memory cap is %d MiB", m_owner.c_str(),
                    int((m_limit + (1 << 19)) >> 20));
      break;
    default:
      if (m_abortWhat)
        std::snprintf(buf, sizeof buf,
                      "instruction budget exceeded in %s (over %lld instructions' worth in one call; a "
                      "pattern that backtracks too much?)",
                      m_abortWhat, static_cast<long long>(m_budget));
      else
        std::snprintf(buf, sizeof buf,
                      "instruction budget exceeded (over %lld instructions in one call; an endless loop?)",
                      static_cast<long long>(m_budget));
  }
  return buf;
}

void LuaVm::raiseAbort(lua_State* L, int level) {
  // Keep raising on every instruction of whatever runs next, in this thread and in the one the
  // call started on, until the host has control again.
  LuaVm* vm = from(L);
  lua_sethook(L, &LuaVm::hook, LUA_MASKCOUNT, 1);
  if (L != vm->m_L) lua_sethook(vm->m_L, &LuaVm::hook, LUA_MASKCOUNT, 1);
  char buf[256];
  {
    const std::string msg = vm->abortMessage();
    std::snprintf(buf, sizeof buf, "%s", msg.c_str());
  }
  luaL_where(L, level);
  lua_pushstring(L, buf);
  lua_concat(L, 2);
  lua_error(L);
  std::abort();  // lua_error does not return
}

void LuaVm::abort(lua_State* L, Abort why) {
  if (m_abort == Abort::None) {
    m_abort = why;
    if (why == Abort::Watchdog) noteWatchdogStop();
  }
  raiseAbort(L, 0);
}

void LuaVm::noteWatchdogStop() {
  ++m_watchdogStops;
  if (m_watchdog) m_watchdog->noteStop();
}

void LuaVm::hook(lua_State* L, lua_Debug*) {
  LuaVm* vm = from(L);
  if (vm->m_depth == 0) return;  // lua_close, host pushes
  if (vm->m_abort != Abort::None) raiseAbort(L, 0);
  const int n = lua_gethookcount(L);
  vm->m_count += n;
  if (n != kHookInterval) lua_sethook(L, &LuaVm::hook, LUA_MASKCOUNT, kHookInterval);
  if (vm->m_budget > 0 && vm->m_count > vm->m_budget) vm->abort(L, Abort::Budget);
  if (vm->m_interruptStamp.load(std::memory_order_relaxed) == vm->stamp()) vm->abort(L, Abort::Watchdog);
}

void LuaVm::charge(lua_State* L, int64_t n, const char* what) {
  LuaVm* vm = from(L);
  if (vm->m_depth == 0) return;
  vm->m_count += n;
  if (vm->m_abort == Abort::None) {
    if (vm->m_budget > 0 && vm->m_count > vm->m_budget) {
      vm->m_abort = Abort::Budget;
      vm->m_abortWhat = what;
    } else if (vm->m_interruptStamp.load(std::memory_order_relaxed) == vm->stamp()) {
      vm->m_abort = Abort::Watchdog;
      vm->noteWatchdogStop();
    }
  }
  if (vm->m_abort != Abort::None) raiseAbort(L, 1);
}

void LuaVm::interrupt(uint64_t stamp, double seconds) {
  m_interruptSeconds.store(seconds, std::memory_order_relaxed);
  m_interruptStamp.store(stamp, std::memory_order_relaxed);
  // The count hook sees this within kHookInterval instructions, in every coroutine; C code
  // that charges work (the pattern matcher) sees it at its next charge.
}

LuaVm::LuaVm(size_t memoryLimit) : m_limit(memoryLimit) {
  m_L = lua_newstate(&LuaVm::alloc, this);
  if (!m_L) {
    std::fprintf(stderr, "rm3d: cannot create a Lua state (out of memory)\n");
    std::abort();
  }
  *static_cast<LuaVm**>(lua_getextraspace(m_L)) = this;
  lua_atpanic(m_L, &LuaVm::panic);
  // One count hook for the VM's life: coroutines inherit it, and each firing adds to the
  // VM's counter, so the budget is shared by all threads of the VM.
  lua_sethook(m_L, &LuaVm::hook, LUA_MASKCOUNT, kHookInterval);
  openSandbox();
}

LuaVm::~LuaVm() {
  setWatchdog(nullptr);
  // Scripts cannot install finalizers (safeSetmetatable), so closing runs no script code.
  if (m_L) lua_close(m_L);
}

void LuaVm::setWatchdog(Watchdog* w) {
  if (m_watchdog == w) return;
  const uint64_t stamp = this->stamp();
  if (m_watchdog) m_watchdog->remove(m_slotIndex);
  m_watchdog = w;
  m_ownSlot.stamp.store(stamp, std::memory_order_relaxed);
  m_slot = m_watchdog ? m_watchdog->add(this, stamp, m_slotIndex) : &m_ownSlot;
}

LuaVm* LuaVm::from(lua_State* L) {
  return *static_cast<LuaVm**>(lua_getextraspace(L));
}

namespace {

int openSandboxProtected(lua_State* L) {
  static const luaL_Reg libs[] = {{LUA_GNAME, luaopen_base},        {LUA_TABLIBNAME, luaopen_table},
                                  {LUA_STRLIBNAME, luaopen_string}, {LUA_MATHLIBNAME, luaopen_math},
                                  {LUA_UTF8LIBNAME, luaopen_utf8},  {LUA_COLIBNAME, luaopen_coroutine}};
  for (const luaL_Reg& lib : libs) {
    luaL_requiref(L, lib.name, lib.func, 1);
    lua_pop(L, 1);
  }
  // No file access or bytecode from scripts: drop the loaders that reach the file system.
  for (const char* name : {"dofile", "loadfile"}) {
    lua_pushnil(L);
    lua_setglobal(L, name);
  }
  // `load` stays, text chunks only.
  if (luaL_dostring(L,
                    "local load = load\n"
                    "_G.load = function(chunk, name, mode, env) return load(chunk, name, 't', env) end") !=
      LUA_OK)
    return lua_error(L);
  lua_getglobal(L, "setmetatable");
  lua_pushcclosure(L, safeSetmetatable, 1);
  lua_setglobal(L, "setmetatable");
  lua_getglobal(L, "xpcall");
  lua_pushcclosure(L, safeXpcall, 1);
  lua_setglobal(L, "xpcall");
  lua_getglobal(L, "string");
  lua_getfield(L, -1, "rep");
  lua_pushcclosure(L, safeRep, 1);
  lua_setfield(L, -2, "rep");
  lua_pop(L, 1);
  openBoundedPatterns(L);
  return 0;
}

}  // namespace

void LuaVm::openSandbox() {
  lua_pushcfunction(m_L, openSandboxProtected);
  if (lua_pcall(m_L, 0, 0, 0) != LUA_OK) {
    std::fprintf(stderr, "rm3d: cannot set up a Lua state: %s\n", lua_tostring(m_L, -1));
    std::abort();
  }
  lua_pushcfunction(m_L, &LuaVm::require);
  lua_setglobal(m_L, "require");
}

std::string LuaVm::displayName(const std::string& path) const {
  if (m_displayRoot.empty()) return path;
  std::error_code ec;
  const fs::path rel = fs::relative(fs::path(path), fs::path(m_displayRoot), ec);
  if (ec || rel.empty() || rel.native().rfind("..", 0) == 0) return path;
  return rel.string();
}

bool LuaVm::loadFile(const std::string& path, std::string& err) {
  std::string text;
  std::string why;
  if (m_sources ? !m_sources->read(path, text, &why) : !readTextFile(path, text, &why)) {
    err = displayName(path) + ": cannot read file (" + why + ")";
    return false;
  }
  std::string chunk = "@";
  chunk += displayName(path);
  if (luaL_loadbufferx(m_L, text.data(), text.size(), chunk.c_str(), "t") != LUA_OK) {
    err = lua_type(m_L, -1) == LUA_TSTRING ? lua_tostring(m_L, -1) : "cannot load " + chunk.substr(1);
    // Syntax errors name file:line already; a refused binary chunk does not.
    if (err.rfind(chunk.substr(1), 0) != 0)
      err = chunk.substr(1) + ": " + err + " (expected a Lua text file)";
    makeValidUtf8(err);
    lua_pop(m_L, 1);
    return false;
  }
  return true;
}

void LuaVm::beginCall(const char* what) {
  m_count = 0;
  m_abort = Abort::None;
  m_abortWhat = nullptr;
  if (m_memArmed) {
    // Still over the memory cap since an earlier call: this one fails at once.
    m_abort = Abort::Memory;
    lua_sethook(m_L, &LuaVm::hook, LUA_MASKCOUNT, 1);
  }
  m_what.store(what, std::memory_order_relaxed);
  m_outer = tlCurrent;
  tlCurrent = this;
  if (m_outer) m_outer->publish(false);
  publish(true);
}

void LuaVm::publish(bool busy) {
  // Busy after the new stamp, idle before it: the watchdog never sees the old stamp busy again.
  if (busy) {
    m_slot->stamp.store(stamp() + 1, std::memory_order_relaxed);
    m_slot->busy.store(true, std::memory_order_relaxed);
  } else {
    m_slot->busy.store(false, std::memory_order_relaxed);
    m_slot->stamp.store(stamp() + 1, std::memory_order_relaxed);
  }
}

void LuaVm::endCall() {
  publish(false);
  tlCurrent = m_outer;
  if (m_outer) {
    m_outer->publish(true);
    m_outer = nullptr;
  }
  if (m_abort != Abort::None) {
    m_abort = Abort::None;
    lua_sethook(m_L, &LuaVm::hook, LUA_MASKCOUNT, kHookInterval);
  }
}

bool LuaVm::call(int nargs, int nresults, std::string& err, const char* what) {
  const int base = lua_gettop(m_L) - nargs;
  lua_pushcfunction(m_L, messageHandler);
  lua_insert(m_L, base);
  // Over the memory cap since an earlier call: collect first (the hog may be garbage now).
  if (m_depth == 0 && m_memArmed) lua_gc(m_L, LUA_GCCOLLECT);
  if (m_depth++ == 0) beginCall(what);
  const int status = lua_pcall(m_L, nargs, nresults, base);
  // A limit tripped, but the error was swallowed on the way out (a coroutine that failed
  // just before the call returned): the call still fails.
  const bool aborted = m_depth == 1 && m_abort != Abort::None;
  if (aborted && status == LUA_OK) {
    err = abortMessage();
    lua_settop(m_L, base - 1);
    --m_depth;
    endCall();
    return false;
  }
  if (--m_depth == 0) endCall();
  lua_remove(m_L, base);
  if (status != LUA_OK) {
    if (status == LUA_ERRMEM)
      err = "out of memory: the " + m_owner + "'s memory cap is " +
            std::to_string((m_limit + (1 << 19)) >> 20) +
            " MiB (an allocation failed outright, so there is no traceback)";
    else if (lua_type(m_L, -1) == LUA_TSTRING)
      err = lua_tostring(m_L, -1);
    else
      err = "error (the error handler failed)";
    makeValidUtf8(err);
    lua_pop(m_L, 1);
    return false;
  }
  return true;
}

bool LuaVm::protect(int (*f)(lua_State*), void* ud, int nresults, std::string& err, const char* what) {
  lua_pushcfunction(m_L, f);
  lua_pushlightuserdata(m_L, ud);
  return call(1, nresults, err, what);
}

bool LuaVm::runFile(const std::string& path, int nresults, std::string& err) {
  if (!loadFile(path, err)) return false;
  return call(0, nresults, err, "the script's top level");
}

int LuaVm::require(lua_State* L) {
  // Lua errors longjmp: no C++ object with a destructor may be alive when one is raised, so the
  // search runs in its own scope and leaves either a loaded chunk or a message on the stack.
  const char* name = luaL_checkstring(L, 1);
  LuaVm* vm = from(L);
  lua_getfield(L, LUA_REGISTRYINDEX, "rm3d.loaded");
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    lua_newtable(L);
    lua_pushvalue(L, -1);
    lua_setfield(L, LUA_REGISTRYINDEX, "rm3d.loaded");
  }
  const int loaded = lua_gettop(L);
  lua_pushvalue(L, 1);
  if (lua_rawget(L, loaded) != LUA_TNIL) return 1;
  lua_pop(L, 1);
  // Modules built into the engine come before any file of the same name (loaders for
  // `require`, documented as modules in the README, hence &fn).
  static const luaL_Reg builtins[] = {{"linalg", &openLinalg}};
  for (const luaL_Reg& b : builtins)
    if (std::strcmp(name, b.name) == 0) {
      lua_pushcfunction(L, b.func);
      lua_call(L, 0, 1);
      lua_pushvalue(L, -1);
      lua_setfield(L, loaded, name);
      return 1;
    }
  if (!validModuleName(name))
    return luaL_error(L,
                      "require: bad module name '%s' (expected names of letters, digits and '_' joined by "
                      "dots, like 'gaits' or 'lib.noise')",
                      name);
  bool found = false;
  {
    std::string rel = name;
    for (char& c : rel)
      if (c == '.') c = '/';
    rel += ".lua";
    std::string tried, problem;
    const ScriptFile f = findScriptFile(rel, vm->m_requirePath, vm->m_requirePath, vm->m_sources);
    const std::string shown = vm->displayName(f.path);
    std::string text;
    if (f.status == ScriptFile::Status::Missing) {
      for (const std::string& dir : vm->m_requirePath)
        tried += "\n\tno file '" + vm->displayName((fs::path(dir) / rel).string()) + "'";
    } else if (f.status == ScriptFile::Status::Outside) {
      problem = "require: '" + shown +
                "' leads outside the folders scripts may load from (lua/, behaviors/, the script's folder)" +
                (vm->m_sources ? vm->m_sources->diskNote() : "");
    } else if (std::string why;
               vm->m_sources ? !vm->m_sources->read(f.path, text, &why) : !readTextFile(f.path, text, &why)) {
      problem = "require: cannot read '" + shown + "' (" + why + ")";
    } else {
      const std::string chunk = "@" + shown;
      if (luaL_loadbufferx(L, text.data(), text.size(), chunk.c_str(), "t") == LUA_OK)
        found = true;
      else
        problem =
            lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "require: cannot load '" + shown + "'";
      if (!found) lua_pop(L, 1);
    }
    if (!found) {
      luaL_where(L, 1);
      if (!problem.empty())
        lua_pushlstring(L, problem.data(), problem.size());
      else
        lua_pushfstring(L, "module '%s' not found:%s", name,
                        tried.empty() ? " (no folders to search)" : tried.c_str());
      lua_concat(L, 2);
    }
  }
  if (!found) return lua_error(L);
  lua_pushstring(L, name);
  lua_call(L, 1, 1);
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    lua_pushboolean(L, 1);
  }
  lua_pushvalue(L, -1);
  lua_setfield(L, loaded, name);
  return 1;
}

}  // namespace rm3d
