// LuaVm: sandbox, memory cap, instruction budget, protected calls with file:line and traceback.
#include "script/lua_vm.h"

#include <doctest/doctest.h>

#include <cstring>
#include <lua.hpp>

using rm3d::LuaVm;

namespace {
bool runString(LuaVm& vm, const char* code, std::string& err) {
  if (luaL_loadbufferx(vm.L(), code, std::strlen(code), "@probe.lua", "t") != LUA_OK) {
    err = lua_tostring(vm.L(), -1);
    lua_pop(vm.L(), 1);
    return false;
  }
  return vm.call(0, 0, err);
}
}  // namespace

TEST_CASE("the sandbox hides io, os and file loaders and refuses binary chunks") {
  LuaVm vm;
  std::string err;
  CHECK(runString(
      vm, "assert(io == nil and os == nil and dofile == nil and loadfile == nil and package == nil)", err));
  CHECK(runString(vm, "assert(load(string.dump(function() end)) == nil)", err));
  CHECK(runString(vm, "assert(math and string and table and utf8 and coroutine)", err));
}

TEST_CASE("errors carry file:line and a traceback; the stack is left clean") {
  LuaVm vm;
  std::string err;
  const int top = lua_gettop(vm.L());
  CHECK_FALSE(runString(vm, "local x\n\nlocal y = x.field", err));
  CHECK(err.find("probe.lua:3: attempt to index a nil value") == 0);
  CHECK(err.find("stack traceback") != std::string::npos);
  CHECK(lua_gettop(vm.L()) == top);
}

TEST_CASE("the memory cap stops a hog with a clear message, and the VM stays usable") {
  LuaVm vm(2u << 20);
  std::string err;
  CHECK_FALSE(runString(vm, "local t = {} for i = 1, 1e7 do t[i] = {i} end", err));
  CHECK(err.find("out of memory") != std::string::npos);
  CHECK(runString(vm, "local s = 0 for i = 1, 10 do s = s + i end", err));
}

TEST_CASE("the instruction budget stops an endless loop, per call") {
  LuaVm vm;
  vm.setInstructionBudget(100000);
  std::string err;
  CHECK_FALSE(runString(vm, "while true do end", err));
  CHECK(err.find("instruction budget exceeded") != std::string::npos);
  CHECK(runString(vm, "for i = 1, 10000 do end", err));  // a fresh call has a fresh budget
}

TEST_CASE("require searches only the given folders and rejects paths") {
  LuaVm vm;
  vm.setRequirePath({RM3D_SOURCE_DIR "/lua"});
  std::string err;
  CHECK_FALSE(runString(vm, "require('../CMakeLists')", err));
  CHECK(err.find("bad module name") != std::string::npos);
  CHECK_FALSE(runString(vm, "require('no_such_module')", err));
  CHECK(err.find("module 'no_such_module' not found") != std::string::npos);
  CHECK(runString(
      vm, "local g = require('gaits') assert(type(g.wave) == 'function') assert(require('gaits') == g)",
      err));
}
