// LuaValue: deep copies between VMs, refusing what cannot be copied.
#include "script/lua_value.h"

#include <doctest/doctest.h>

#include <lua.hpp>
#include <nlohmann/json.hpp>

#include "script/lua_vm.h"

using namespace rm3d;

TEST_CASE("plain values survive a copy from one VM to another") {
  LuaVm a, b;
  luaL_dostring(a.L(), "return {1, 2.5, 'three', true, nested = {x = {y = 'z'}}}");
  LuaValue v;
  std::string err;
  REQUIRE(readLuaValue(a.L(), -1, v, 0, err));
  pushLuaValue(b.L(), v);
  lua_setglobal(b.L(), "v");
  CHECK(luaL_dostring(b.L(),
                      "assert(v[1] == 1 and math.type(v[1]) == 'integer' and v[2] == 2.5 and v[3] == 'three' "
                      "and v[4] == true and v.nested.x.y == 'z')") == LUA_OK);
  CHECK(valueToJson(v)["nested"]["x"]["y"] == "z");
}

TEST_CASE("functions, cycles and oversized values are refused with a reason") {
  LuaVm a;
  LuaValue v;
  std::string err;
  luaL_dostring(a.L(), "return {f = print}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err.find("function at key 'f' cannot be copied") != std::string::npos);
  luaL_dostring(a.L(), "local t = {} t.self = t return t");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err.find("contains itself") != std::string::npos);
  luaL_dostring(a.L(), "return string.rep('x', 100000)");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 65536, err));
  CHECK(err.find("too large") != std::string::npos);
}
