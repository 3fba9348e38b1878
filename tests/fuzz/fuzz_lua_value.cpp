// Fuzzes the message/params copier (script/lua_value.h): a small generator turns the input
// bytes into a Lua value in one state (nil, booleans, integers, any double, binary strings,
// nested and shared tables, and now and then a function, a userdata, a coroutine or a cycle),
// readLuaValue copies it out under a size limit, pushLuaValue pushes it into a second state,
// and reading it back there must give the same value. A refusal must come with a reason.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <lua.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "script/lua_value.h"

using rm3d::LuaValue;

namespace {

struct Bytes {
  const uint8_t* p;
  size_t n;
  uint8_t u8() {
    if (n == 0) return 0;
    --n;
    return *p++;
  }
  uint64_t u64() {
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v = (v << 8) | u8();
    return v;
  }
};

constexpr int kMaxDepth = 80;  // beyond the copier's own limit (64), to reach that refusal

int noop(lua_State*) {
  return 0;
}

// Pushes one generated value. `depth` tables are open below it: with a table at the top of the
// stack slots [base, top), a cycle refers back to one of them.
void gen(lua_State* L, Bytes& b, int depth, int base) {
  luaL_checkstack(L, 8, "fuzz generator");
  const uint8_t kind = b.n == 0 ? 0 : b.u8() % 16;
  switch (kind) {
    case 0:
      lua_pushnil(L);
      break;
    case 1:
      lua_pushboolean(L, b.u8() & 1);
      break;
    case 2:
      lua_pushinteger(L, lua_Integer(b.u64()));
      break;
    case 3:
      lua_pushinteger(L, int8_t(b.u8()));
      break;
    case 4: {
      const uint64_t bits = b.u64();
      double d;
      std::memcpy(&d, &bits, sizeof d);
      lua_pushnumber(L, d);
      break;
    }
    case 5: {
      static const double special[] = {0.0,
                                       -0.0,
                                       0.5,
                                       1.0,
                                       -1.0,
                                       9007199254740993.0,
                                       9223372036854775808.0,
                                       -9223372036854775808.0,
                                       1e308,
                                       std::numeric_limits<double>::infinity(),
                                       -std::numeric_limits<double>::infinity(),
                                       std::nan(""),
                                       std::numeric_limits<double>::denorm_min()};
      lua_pushnumber(L, special[b.u8() % (sizeof special / sizeof special[0])]);
      break;
    }
    case 6:
    case 7: {
      size_t len = b.u8() % 48;
      if (len == 47) len = size_t(b.u8()) * 64;  // now and then a longer one
      std::string s;
      for (size_t i = 0; i < len; ++i) s.push_back(char(b.u8()));
      lua_pushlstring(L, s.data(), s.size());
      break;
    }
    case 8:
    case 9:
    case 10:
    case 11: {
      if (depth >= kMaxDepth) {
        lua_pushinteger(L, depth);
        break;
      }
      const int n = b.u8() % 10;
      lua_createtable(L, 0, 0);
      const int self = lua_gettop(L);
      for (int i = 0; i < n && b.n > 0; ++i) {
        if (b.u8() & 1) {
          gen(L, b, depth + 1, base);  // value at t[i + 1] (array part)
          lua_rawseti(L, self, i + 1);
          continue;
        }
        gen(L, b, depth + 1, base);  // key
        const int kt = lua_type(L, -1);
        if (kt == LUA_TNIL || (kt == LUA_TNUMBER && std::isnan(lua_tonumber(L, -1)))) {
          lua_pop(L, 1);
          lua_pushinteger(L, i + 100);  // not valid keys
        }
        gen(L, b, depth + 1, base);
        lua_rawset(L, self);
      }
      break;
    }
    case 12: {  // a table open below (a cycle), or a shared one (the same table twice)
      const int top = lua_gettop(L);
      int tables = 0;
      for (int i = base; i <= top; ++i) tables += lua_istable(L, i);
      if (tables == 0) {
        lua_pushboolean(L, 0);
        break;
      }
      int pick = b.u8() % tables;
      for (int i = base; i <= top; ++i)
        if (lua_istable(L, i) && pick-- == 0) {
          lua_pushvalue(L, i);
          break;
        }
      break;
    }
    case 13:
      if (b.u8() % 4 == 0) {
        switch (b.u8() % 4) {
          case 0:
            lua_pushcfunction(L, noop);
            break;
          case 1:
            lua_newuserdatauv(L, 8, 0);
            break;
          case 2:
            lua_pushlightuserdata(L, &b);
            break;
          default:
            lua_newthread(L);
            break;
        }
      } else {
        lua_pushstring(L, "k");
      }
      break;
    default:
      lua_pushinteger(L, b.u8());
      break;
  }
}

struct GenArgs {
  Bytes* bytes;
};

int genProtected(lua_State* L) {
  auto* a = static_cast<GenArgs*>(lua_touserdata(L, 1));
  lua_settop(L, 0);
  gen(L, *a->bytes, 0, 1);
  // Only the value: tables opened for cycles were popped by their parents' rawsets.
  return 1;
}

int pushProtected(lua_State* L) {
  const auto* v = static_cast<const LuaValue*>(lua_touserdata(L, 1));
  lua_settop(L, 0);
  rm3d::pushLuaValue(L, *v);
  return 1;
}

// Same value, compared bit for bit (NaN equals itself); table entries in any order among keys
// the copier's order does not tell apart.
bool same(const LuaValue& a, const LuaValue& b);
bool keyOrder(const std::pair<LuaValue, LuaValue>& x, const std::pair<LuaValue, LuaValue>& y) {
  const LuaValue &a = x.first, &c = y.first;
  if (a.type != c.type) return a.type < c.type;
  switch (a.type) {
    case LuaValue::Type::Boolean:
      return a.boolean < c.boolean;
    case LuaValue::Type::Integer:
      return a.integer < c.integer;
    case LuaValue::Type::Number:
      return a.number < c.number;
    case LuaValue::Type::String:
      return a.string < c.string;
    default:
      return false;
  }
}
bool same(const LuaValue& a, const LuaValue& b) {
  if (a.type != b.type) return false;
  switch (a.type) {
    case LuaValue::Type::Nil:
      return true;
    case LuaValue::Type::Boolean:
      return a.boolean == b.boolean;
    case LuaValue::Type::Integer:
      return a.integer == b.integer;
    case LuaValue::Type::Number:
      return std::memcmp(&a.number, &b.number, sizeof a.number) == 0;
    case LuaValue::Type::String:
    case LuaValue::Type::Opaque:
      return a.string == b.string;
    case LuaValue::Type::Table: {
      if (a.table.size() != b.table.size()) return false;
      auto x = a.table, y = b.table;
      std::sort(x.begin(), x.end(), keyOrder);
      std::sort(y.begin(), y.end(), keyOrder);
      for (size_t i = 0; i < x.size(); ++i)
        if (!same(x[i].first, y[i].first) || !same(x[i].second, y[i].second)) return false;
      return true;
    }
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static lua_State* A = luaL_newstate();
  static lua_State* B = luaL_newstate();
  Bytes bytes{data + 1, size - 1};
  static const size_t limits[] = {0, 64, 1024, 65536};
  const size_t limit = limits[data[0] % 4];

  lua_settop(A, 0);
  GenArgs args{&bytes};
  lua_pushcfunction(A, genProtected);
  lua_pushlightuserdata(A, &args);
  if (lua_pcall(A, 1, 1, 0) != LUA_OK) std::abort();  // the generator itself failed
  const int top = lua_gettop(A);

  LuaValue v;
  std::string err;
  const bool ok = rm3d::readLuaValue(A, -1, v, limit, err);
  if (lua_gettop(A) != top) std::abort();  // the reader must leave the stack as it was
  if (!ok) {
    if (err.empty()) std::abort();  // a refusal says why
    lua_settop(A, 0);
    return 0;
  }
  if (limit && rm3d::luaValueSize(v) > limit) std::abort();

  lua_settop(B, 0);
  lua_pushcfunction(B, pushProtected);
  lua_pushlightuserdata(B, &v);
  if (lua_pcall(B, 1, 1, 0) != LUA_OK) std::abort();
  LuaValue back;
  std::string err2;
  if (!rm3d::readLuaValue(B, -1, back, 0, err2)) std::abort();  // a copy copies again
  if (!same(v, back)) std::abort();
  (void)rm3d::valueToJson(v).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  lua_settop(A, 0);
  lua_settop(B, 0);
  lua_gc(A, LUA_GCCOLLECT);
  lua_gc(B, LUA_GCCOLLECT);
  return 0;
}
