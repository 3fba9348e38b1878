// Deep copy of plain Lua values, with cycle, type and size checks.
#include "script/lua_value.h"

#include <algorithm>
#include <lua.hpp>
#include <nlohmann/json.hpp>

namespace rm3d {

namespace {

bool keyLess(const LuaValue& a, const LuaValue& b) {
  auto rank = [](const LuaValue& v) { return v.type == LuaValue::Type::String ? 1 : 0; };
  if (rank(a) != rank(b)) return rank(a) < rank(b);
  if (a.type == LuaValue::Type::String) return a.string < b.string;
  auto num = [](const LuaValue& v) {
    return v.type == LuaValue::Type::Integer  ? double(v.integer)
           : v.type == LuaValue::Type::Number ? v.number
           : v.boolean                        ? 1.0
                                              : 0.0;
  };
  return num(a) < num(b);
}

struct Reader {
  lua_State* L;
  size_t limit;
  size_t size = 0;
  std::string& err;
  std::vector<const void*> seen;

  bool read(int idx, LuaValue& out, const std::string& where, int depth) {
    idx = lua_absindex(L, idx);
    size += 16;
    switch (lua_type(L, idx)) {
      case LUA_TNIL:
        out.type = LuaValue::Type::Nil;
        break;
      case LUA_TBOOLEAN:
        out.type = LuaValue::Type::Boolean;
        out.boolean = lua_toboolean(L, idx);
        break;
      case LUA_TNUMBER:
        if (lua_isinteger(L, idx)) {
          out.type = LuaValue::Type::Integer;
          out.integer = lua_tointeger(L, idx);
        } else {
          out.type = LuaValue::Type::Number;
          out.number = lua_tonumber(L, idx);
        }
        break;
      case LUA_TSTRING: {
        size_t len = 0;
        const char* s = lua_tolstring(L, idx, &len);
        out.type = LuaValue::Type::String;
        out.string.assign(s, len);
        size += len;
        break;
      }
      case LUA_TTABLE: {
        const void* p = lua_topointer(L, idx);
        if (std::find(seen.begin(), seen.end(), p) != seen.end()) {
          err = "a table that contains itself" + where + " cannot be copied";
          return false;
        }
        if (depth > 64 || !lua_checkstack(L, 4)) {
          err = "tables nested too deeply" + where;
          return false;
        }
        seen.push_back(p);
        out.type = LuaValue::Type::Table;
        lua_pushnil(L);
        while (lua_next(L, idx) != 0) {
          LuaValue k, v;
          if (lua_type(L, -2) == LUA_TTABLE) {
            lua_pop(L, 2);
            err = "a table used as a key" + where + " cannot be copied";
            return false;
          }
          std::string keyName = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : "";
          if (keyName.empty() && lua_type(L, -2) == LUA_TNUMBER) {
            lua_pushvalue(L, -2);
            keyName = lua_tostring(L, -1);
            lua_pop(L, 1);
          }
          const std::string sub = " at key '" + keyName + "'";
          if (!read(-2, k, sub, depth + 1) || !read(-1, v, sub, depth + 1)) {
            lua_pop(L, 2);
            return false;
          }
          out.table.emplace_back(std::move(k), std::move(v));
          lua_pop(L, 1);
          if (limit && size > limit) {
            lua_pop(L, 1);
            err = "value too large (over " + std::to_string(limit) + " bytes)";
            return false;
          }
        }
        seen.pop_back();
        std::sort(out.table.begin(), out.table.end(),
                  [](const auto& a, const auto& b) { return keyLess(a.first, b.first); });
        break;
      }
      default:
        err = std::string("a ") + lua_typename(L, lua_type(L, idx)) + where +
              " cannot be copied (only nil, booleans, numbers, strings and tables)";
        return false;
    }
    if (limit && size > limit) {
      err = "value too large (over " + std::to_string(limit) + " bytes)";
      return false;
    }
    return true;
  }
};

}  // namespace

bool readLuaValue(lua_State* L, int idx, LuaValue& out, size_t limit, std::string& err) {
  Reader r{L, limit, 0, err, {}};
  out = LuaValue{};
  return r.read(idx, out, "", 0);
}

void pushLuaValue(lua_State* L, const LuaValue& v) {
  switch (v.type) {
    case LuaValue::Type::Nil:
      lua_pushnil(L);
      break;
    case LuaValue::Type::Boolean:
      lua_pushboolean(L, v.boolean);
      break;
    case LuaValue::Type::Integer:
      lua_pushinteger(L, v.integer);
      break;
    case LuaValue::Type::Number:
      lua_pushnumber(L, v.number);
      break;
    case LuaValue::Type::String:
      lua_pushlstring(L, v.string.data(), v.string.size());
      break;
    case LuaValue::Type::Table:
      luaL_checkstack(L, 3, "copying a table");
      lua_createtable(L, 0, int(v.table.size()));
      for (const auto& [k, val] : v.table) {
        pushLuaValue(L, k);
        pushLuaValue(L, val);
        lua_rawset(L, -3);
      }
      break;
  }
}

}  // namespace rm3d
