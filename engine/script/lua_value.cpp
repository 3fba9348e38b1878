// Deep copy of plain Lua values, with cycle, type, key and size checks.
#include "script/lua_value.h"

#include <algorithm>
#include <cstdio>
#include <lua.hpp>

namespace rm3d {

namespace {

bool keyLess(const LuaValue& a, const LuaValue& b) {
  auto rank = [](const LuaValue& v) { return v.type == LuaValue::Type::String ? 1 : 0; };
  if (rank(a) != rank(b)) return rank(a) < rank(b);
  if (a.type == LuaValue::Type::String) return a.string < b.string;
  if (a.type == LuaValue::Type::Integer && b.type == LuaValue::Type::Integer) return a.integer < b.integer;
  auto num = [](const LuaValue& v) {
    return v.type == LuaValue::Type::Integer  ? double(v.integer)
           : v.type == LuaValue::Type::Number ? v.number
           : v.boolean                        ? 1.0
                                              : 0.0;
  };
  return num(a) < num(b);
}

/// The copier. Errors fill `err`; the path is added on the way back out, one step per level.
struct Reader {
  lua_State* L;
  const LuaValueOptions& opt;
  LuaValueError& err;
  size_t size = 0;
  std::vector<const void*> seen;  // tables being copied, to catch cycles

  bool fail(LuaValueError::Kind kind) {
    err.kind = kind;
    return false;
  }

  bool tooLarge() const { return opt.limit != 0 && size > opt.limit; }

  /// Adds the key at stack index k to the error's path (built innermost first). Numbers are
  /// named as Lua's tostring names them, formatted here: converting on the stack could raise.
  void addStep(int k) {
    LuaPathStep step;
    const int type = lua_type(L, k);
    if (type == LUA_TSTRING) {
      size_t len = 0;
      const char* s = lua_tolstring(L, k, &len);
      step.name.assign(s, len);
    } else if (type == LUA_TNUMBER && lua_isinteger(L, k)) {
      step.isIndex = true;
      step.index = lua_tointeger(L, k);
      step.name = std::to_string(step.index);
    } else if (type == LUA_TNUMBER) {
      char buf[64];
      std::snprintf(buf, sizeof buf, LUA_NUMBER_FMT, LUAI_UACNUMBER(lua_tonumber(L, k)));
      step.name = buf;
      if (step.name.find_first_not_of("-0123456789") == std::string::npos) step.name += ".0";
    }
    err.path.push_back(std::move(step));
  }

  bool read(int idx, LuaValue& out, int depth) {
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
        const char* s = lua_tolstring(L, idx, &len);  // a string already: no conversion
        out.type = LuaValue::Type::String;
        out.string.assign(s, len);
        size += len;
        break;
      }
      case LUA_TTABLE:
        if (!readTable(idx, out, depth)) return false;
        break;
      default:
        if (!opt.keepOpaque) {
          err.typeName = lua_typename(L, lua_type(L, idx));
          return fail(LuaValueError::Kind::Unsupported);
        }
        out.type = LuaValue::Type::Opaque;
        out.string = lua_typename(L, lua_type(L, idx));
        break;
    }
    return !tooLarge() || fail(LuaValueError::Kind::TooLarge);
  }

  /// False (err filled) when the key at top - 1 cannot be copied: a table, or with plainKeys
  /// anything but a string or an integer.
  bool keyAllowed() {
    const int type = lua_type(L, -2);
    if (!opt.plainKeys) return type != LUA_TTABLE || fail(LuaValueError::Kind::TableKey);
    if (type == LUA_TSTRING || (type == LUA_TNUMBER && lua_isinteger(L, -2))) return true;
    err.typeName = lua_typename(L, type);
    if (type == LUA_TNUMBER) err.number = lua_tonumber(L, -2);
    return fail(LuaValueError::Kind::BadKey);
  }

  bool readTable(int idx, LuaValue& out, int depth) {
    if (depth > opt.maxDepth) return fail(LuaValueError::Kind::TooDeep);
    const void* p = lua_topointer(L, idx);
    if (std::find(seen.begin(), seen.end(), p) != seen.end()) return fail(LuaValueError::Kind::Cycle);
    if (!lua_checkstack(L, 4)) return fail(LuaValueError::Kind::NoStack);
    seen.push_back(p);
    out.type = LuaValue::Type::Table;
    lua_pushnil(L);
    while (lua_next(L, idx) != 0) {  // raw traversal: metatables are ignored
      if (!keyAllowed()) {
        lua_pop(L, 2);
        return false;
      }
      out.table.emplace_back();
      auto& [k, v] = out.table.back();
      if (!read(-2, k, depth + 1) || !read(-1, v, depth + 1)) {
        if (err.kind != LuaValueError::Kind::TooLarge) addStep(lua_gettop(L) - 1);
        lua_pop(L, 2);
        return false;
      }
      lua_pop(L, 1);  // keep the key for lua_next
      if (tooLarge()) {
        lua_pop(L, 1);
        return fail(LuaValueError::Kind::TooLarge);
      }
    }
    seen.pop_back();
    std::sort(out.table.begin(), out.table.end(),
              [](const auto& a, const auto& b) { return keyLess(a.first, b.first); });
    return true;
  }
};

}  // namespace

bool readLuaValue(lua_State* L, int idx, LuaValue& out, const LuaValueOptions& options, LuaValueError& err) {
  Reader r{L, options, err, 0, {}};
  out = LuaValue{};
  err = LuaValueError{};
  if (r.read(idx, out, 0)) return true;
  std::reverse(err.path.begin(), err.path.end());
  return false;
}

bool readLuaValue(lua_State* L, int idx, LuaValue& out, size_t limit, std::string& err) {
  LuaValueOptions options;
  options.limit = limit;
  LuaValueError e;
  if (readLuaValue(L, idx, out, options, e)) return true;
  // Messages name the innermost key only.
  const std::string where = e.path.empty() ? "" : " at key '" + e.path.back().name + "'";
  switch (e.kind) {
    case LuaValueError::Kind::Unsupported:
    case LuaValueError::Kind::BadKey:
      err = "a " + e.typeName + where + " cannot be copied (only nil, booleans, numbers, strings and tables)";
      break;
    case LuaValueError::Kind::Cycle:
      err = "a table that contains itself" + where + " cannot be copied";
      break;
    case LuaValueError::Kind::TooDeep:
    case LuaValueError::Kind::NoStack:
      err = "tables nested too deeply" + where;
      break;
    case LuaValueError::Kind::TableKey:
      err = "a table used as a key" + where + " cannot be copied";
      break;
    case LuaValueError::Kind::TooLarge:
      err = "value too large (over " + std::to_string(limit) + " bytes)";
      break;
  }
  return false;
}

void pushLuaValue(lua_State* L, const LuaValue& v) {
  switch (v.type) {
    case LuaValue::Type::Nil:
    case LuaValue::Type::Opaque:
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
