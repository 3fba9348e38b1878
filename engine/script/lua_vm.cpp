// Sandboxed Lua state: allocator with a cap, count hook for the instruction budget, the
// allowed libraries, a path-limited `require`, and the protected call with traceback.
#include "script/lua_vm.h"

#include <lua.hpp>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace rm3d {

namespace {

int messageHandler(lua_State* L) {
  const char* msg = lua_tostring(L, 1);
  if (msg == nullptr) {
    if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING) return 1;
    msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
  }
  luaL_traceback(L, L, msg, 1);
  return 1;
}

void budgetHook(lua_State* L, lua_Debug*) { luaL_error(L, "instruction budget exceeded (an endless loop?)"); }

}  // namespace

bool readTextFile(const std::string& path, std::string& out) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return false;
  std::ostringstream ss;
  ss << f.rdbuf();
  out = ss.str();
  return !f.bad();
}

void* LuaVm::alloc(void* ud, void* ptr, size_t osize, size_t nsize) {
  auto* vm = static_cast<LuaVm*>(ud);
  if (ptr == nullptr) osize = 0;  // osize encodes the object type when allocating
  if (nsize == 0) {
    std::free(ptr);
    vm->m_used -= osize;
    return nullptr;
  }
  if (vm->m_limit && nsize > osize && vm->m_used + (nsize - osize) > vm->m_limit) return nullptr;
  void* p = std::realloc(ptr, nsize);
  if (p) vm->m_used = vm->m_used - osize + nsize;
  return p;
}

LuaVm::LuaVm(size_t memoryLimit) : m_limit(memoryLimit) {
  m_L = lua_newstate(&LuaVm::alloc, this);
  *static_cast<LuaVm**>(lua_getextraspace(m_L)) = this;
  openSandbox();
}

LuaVm::~LuaVm() {
  if (m_L) lua_close(m_L);
}

LuaVm* LuaVm::from(lua_State* L) { return *static_cast<LuaVm**>(lua_getextraspace(L)); }

void LuaVm::openSandbox() {
  static const luaL_Reg libs[] = {{LUA_GNAME, luaopen_base},          {LUA_TABLIBNAME, luaopen_table},
                                  {LUA_STRLIBNAME, luaopen_string},   {LUA_MATHLIBNAME, luaopen_math},
                                  {LUA_UTF8LIBNAME, luaopen_utf8},    {LUA_COLIBNAME, luaopen_coroutine}};
  for (const luaL_Reg& lib : libs) {
    luaL_requiref(m_L, lib.name, lib.func, 1);
    lua_pop(m_L, 1);
  }
  // No file access or bytecode from scripts: drop the loaders that reach the file system.
  for (const char* name : {"dofile", "loadfile"}) {
    lua_pushnil(m_L);
    lua_setglobal(m_L, name);
  }
  // `load` stays, text chunks only.
  luaL_dostring(m_L,
                "local load = load\n"
                "_G.load = function(chunk, name, mode, env) return load(chunk, name, 't', env) end");
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
  if (!readTextFile(path, text)) {
    err = displayName(path) + ": cannot read file (" + std::strerror(errno) + ")";
    return false;
  }
  std::string chunk = "@";
  chunk += displayName(path);
  if (luaL_loadbufferx(m_L, text.data(), text.size(), chunk.c_str(), "t") != LUA_OK) {
    err = lua_tostring(m_L, -1);
    lua_pop(m_L, 1);
    return false;
  }
  return true;
}

bool LuaVm::call(int nargs, int nresults, std::string& err) {
  const int base = lua_gettop(m_L) - nargs;
  lua_pushcfunction(m_L, messageHandler);
  lua_insert(m_L, base);
  if (m_budget > 0) lua_sethook(m_L, budgetHook, LUA_MASKCOUNT, int(std::min<int64_t>(m_budget, 0x7fffffff)));
  const int status = lua_pcall(m_L, nargs, nresults, base);
  if (m_budget > 0) lua_sethook(m_L, nullptr, 0, 0);
  lua_remove(m_L, base);
  if (status != LUA_OK) {
    if (status == LUA_ERRMEM)
      err = "out of memory (the script's memory cap is " + std::to_string(m_limit / 1024) + " KiB)";
    else
      err = lua_tostring(m_L, -1) ? lua_tostring(m_L, -1) : "error";
    lua_pop(m_L, 1);
    return false;
  }
  return true;
}

bool LuaVm::runFile(const std::string& path, int nresults, std::string& err) {
  if (!loadFile(path, err)) return false;
  return call(0, nresults, err);
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
  if (lua_getfield(L, loaded, name) != LUA_TNIL) return 1;
  lua_pop(L, 1);
  bool found = false;
  {
    std::string rel = name;
    if (rel.empty() || rel.find("..") != std::string::npos || rel.find('/') != std::string::npos) {
      luaL_where(L, 1);
      lua_pushfstring(L, "require: bad module name '%s' (expected a name like 'gaits' or 'lib.noise')", name);
      lua_concat(L, 2);
    } else {
      for (char& c : rel)
        if (c == '.') c = '/';
      rel += ".lua";
      std::string tried;
      for (const std::string& dir : vm->m_requirePath) {
        const std::string path = (fs::path(dir) / rel).string();
        if (!fs::is_regular_file(path)) {
          tried += "\n\tno file '" + vm->displayName(path) + "'";
          continue;
        }
        std::string text;
        std::string chunk = "@";
        chunk += vm->displayName(path);
        if (!readTextFile(path, text)) {
          lua_pushfstring(L, "require: cannot read '%s'", chunk.c_str() + 1);
        } else if (luaL_loadbufferx(L, text.data(), text.size(), chunk.c_str(), "t") == LUA_OK) {
          found = true;
        }
        tried.clear();
        break;
      }
      if (!tried.empty() || vm->m_requirePath.empty()) {
        luaL_where(L, 1);
        lua_pushfstring(L, "module '%s' not found:%s", name, tried.c_str());
        lua_concat(L, 2);
      }
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
