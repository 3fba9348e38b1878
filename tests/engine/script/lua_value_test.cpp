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

TEST_CASE("message errors name the innermost key as Lua writes it") {
  LuaVm a;
  LuaValue v;
  std::string err;
  const std::string only = " cannot be copied (only nil, booleans, numbers, strings and tables)";
  luaL_dostring(a.L(), "return {a = {[1.5] = print}}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "a function at key '1.5'" + only);
  luaL_dostring(a.L(), "return {{{x = 1, [1e100] = {print}}}}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "a function at key '1'" + only);
  luaL_dostring(a.L(), "return {list = {1, 2, {x = coroutine.create(print)}}}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "a thread at key 'x'" + only);
  luaL_dostring(a.L(), "return {[print] = 1}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "a function at key ''" + only);
  luaL_dostring(a.L(), "return {a = {[{}] = 1}}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "a table used as a key at key 'a' cannot be copied");
  luaL_dostring(a.L(), "local t = {} t.b = {c = t} return t");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "a table that contains itself at key 'c' cannot be copied");
  luaL_dostring(a.L(), "local t = {} for i = 1, 70 do t = {t} end return t");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "tables nested too deeply at key '1'");
  luaL_dostring(a.L(), "return print");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, 0, err));
  CHECK(err == "a function" + only);
  CHECK(lua_gettop(a.L()) == 8);  // every failed copy left the stack as it found it
}

TEST_CASE("integer keys sort exactly, beyond the doubles' precision") {
  LuaVm a;
  LuaValue v;
  std::string err;
  luaL_dostring(a.L(), "return {[(1 << 53) + 1] = 'b', [1 << 53] = 'a', [1.5] = 'h', [-1] = 'm', s = 'z'}");
  REQUIRE(readLuaValue(a.L(), -1, v, 0, err));
  REQUIRE(v.table.size() == 5);
  CHECK(v.table[0].second.string == "m");
  CHECK(v.table[1].second.string == "h");
  CHECK(v.table[2].first.integer == int64_t(1) << 53);
  CHECK(v.table[3].first.integer == (int64_t(1) << 53) + 1);
  CHECK(v.table[4].first.string == "s");
}

TEST_CASE("module-type options keep placeholders, refuse odd keys and give the whole path") {
  LuaVm a;
  LuaValue v;
  LuaValueOptions opt;
  opt.keepOpaque = true;
  opt.plainKeys = true;
  LuaValueError err;
  luaL_dostring(a.L(), "return {step = print, co = coroutine.create(print), n = 3}");
  REQUIRE(readLuaValue(a.L(), -1, v, opt, err));
  REQUIRE(v.table.size() == 3);
  CHECK(v.table[0].first.string == "co");
  CHECK(v.table[0].second.type == Value::Type::Opaque);
  CHECK(v.table[0].second.string == "thread");
  CHECK(v.table[2].second.type == Value::Type::Opaque);
  CHECK(v.table[2].second.string == "function");
  CHECK(valueToJson(v).dump() == R"({"co":null,"n":3,"step":null})");

  auto path = [&] {
    std::string s;
    for (const LuaPathStep& p : err.path) s += p.isIndex ? "[" + std::to_string(p.index) + "]" : "." + p.name;
    return s;
  };
  luaL_dostring(a.L(), "return {links = {{shapes = {{[1.5] = 1}}}}}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, opt, err));
  CHECK(err.kind == LuaValueError::Kind::BadKey);
  CHECK(err.typeName == "number");
  CHECK(err.number == 1.5);
  CHECK(path() == ".links[1].shapes[1]");
  luaL_dostring(a.L(), "return {a = {[true] = 1}}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, opt, err));
  CHECK(err.kind == LuaValueError::Kind::BadKey);
  CHECK(err.typeName == "boolean");
  CHECK(path() == ".a");
  opt.maxDepth = 3;
  luaL_dostring(a.L(), "return {{{{{}}}}}");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, opt, err));
  CHECK(err.kind == LuaValueError::Kind::TooDeep);
  CHECK(path() == "[1][1][1][1]");
  luaL_dostring(a.L(), "local t = {x = {}} t.x.back = t return t");
  CHECK_FALSE(readLuaValue(a.L(), -1, v, opt, err));
  CHECK(err.kind == LuaValueError::Kind::Cycle);
  CHECK(path() == ".x.back");
}
