// Option-table helpers shared by the world and module-handle bindings.
#include "script/lua_options.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <lua.hpp>

namespace rm3d {

NumText numText(double v) {
  NumText t;
  std::snprintf(t.s, sizeof t.s, "%g", v);
  return t;
}

void checkOptionKeys(lua_State* L, int idx, const char* fn, std::initializer_list<const char*> allowed) {
  idx = lua_absindex(L, idx);
  luaL_checktype(L, idx, LUA_TTABLE);
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    lua_pop(L, 1);
    bool ok = false;
    if (lua_type(L, -1) == LUA_TSTRING) {
      const char* k = lua_tostring(L, -1);
      for (const char* a : allowed)
        if (std::strcmp(a, k) == 0) ok = true;
    }
    if (!ok) {
      luaL_Buffer b;
      const char* key = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : luaL_typename(L, -1);
      luaL_where(L, 1);
      lua_pushfstring(L, "%s: unknown option '%s' (expected one of:", fn, key);
      luaL_buffinit(L, &b);
      int n = 0;
      for (const char* a : allowed) {
        luaL_addstring(&b, n++ ? ", " : " ");
        luaL_addstring(&b, a);
      }
      luaL_addstring(&b, ")");
      luaL_pushresult(&b);
      lua_concat(L, 3);
      lua_error(L);
    }
  }
}

double optNumberField(lua_State* L, int idx, const char* fn, const char* key, double def) {
  const int t = lua_getfield(L, idx, key);
  double v = def;
  if (t != LUA_TNIL) {
    int isnum = 0;
    v = lua_tonumberx(L, -1, &isnum);
    if (!isnum)
      luaL_error(L, "%s: option '%s' must be a finite number, got %s", fn, key, luaL_typename(L, -1));
    if (!std::isfinite(v))
      luaL_error(L, "%s: option '%s' must be a finite number, got %s", fn, key, numText(v).s);
  }
  lua_pop(L, 1);
  return v;
}

long long optIntegerField(lua_State* L, int idx, const char* fn, const char* key, long long def) {
  const int t = lua_getfield(L, idx, key);
  long long v = def;
  if (t != LUA_TNIL) {
    int isnum = 0;
    v = lua_tointegerx(L, -1, &isnum);
    if (!isnum) luaL_error(L, "%s: option '%s' must be an integer", fn, key);
  }
  lua_pop(L, 1);
  return v;
}

const char* optStringField(lua_State* L, int idx, const char* fn, const char* key) {
  const int t = lua_getfield(L, idx, key);
  const char* s = nullptr;
  if (t != LUA_TNIL) {
    if (t != LUA_TSTRING)
      luaL_error(L, "%s: option '%s' must be a string, got %s", fn, key, luaL_typename(L, -1));
    s = lua_tostring(L, -1);
  }
  lua_pop(L, 1);  // the string stays alive as a value in the table
  return s;
}

bool hasField(lua_State* L, int idx, const char* key) {
  const bool present = lua_getfield(L, idx, key) != LUA_TNIL;
  lua_pop(L, 1);
  return present;
}

bool optBoolField(lua_State* L, int idx, const char* fn, const char* key, bool def) {
  const int t = lua_getfield(L, idx, key);
  bool v = def;
  if (t != LUA_TNIL) {
    if (t != LUA_TBOOLEAN) luaL_error(L, "%s: option '%s' must be true or false", fn, key);
    v = lua_toboolean(L, -1);
  }
  lua_pop(L, 1);
  return v;
}

namespace {
void readNumbers(lua_State* L, const char* fn, const char* key, double* out, int n) {
  if (!lua_istable(L, -1) || lua_rawlen(L, -1) != size_t(n))
    luaL_error(L, "%s: option '%s' must be a table of %d numbers", fn, key, n);
  for (int i = 0; i < n; ++i) {
    lua_rawgeti(L, -1, i + 1);
    int isnum = 0;
    out[i] = lua_tonumberx(L, -1, &isnum);
    if (!isnum) luaL_error(L, "%s: option '%s' must be a table of %d numbers", fn, key, n);
    if (!std::isfinite(out[i]))
      luaL_error(L, "%s: option '%s' must be a table of %d finite numbers, got %s at [%d]", fn, key, n,
                 numText(out[i]).s, i + 1);
    lua_pop(L, 1);
  }
}
}  // namespace

Vec3 optVec3Field(lua_State* L, int idx, const char* fn, const char* key, const Vec3& def) {
  Vec3 v = def;
  if (lua_getfield(L, idx, key) != LUA_TNIL) {
    double d[3];
    readNumbers(L, fn, key, d, 3);
    v = Vec3(d[0], d[1], d[2]);
  }
  lua_pop(L, 1);
  return v;
}

Pose optPoseFields(lua_State* L, int idx, const char* fn) {
  Pose p;
  p.pos = optVec3Field(L, idx, fn, "at", Vec3::Zero());
  const Vec3 rpy = optVec3Field(L, idx, fn, "rot", Vec3::Zero());
  p.rot = quatFromRpy(rpy.x(), rpy.y(), rpy.z());
  if (lua_getfield(L, idx, "quat") != LUA_TNIL) {
    double d[4];
    readNumbers(L, fn, "quat", d, 4);
    Quat q(d[0], d[1], d[2], d[3]);
    if (q.norm() < 1e-9) luaL_error(L, "%s: option 'quat' must not be zero", fn);
    p.rot = q.normalized();
  }
  lua_pop(L, 1);
  return p;
}

void pushVec3(lua_State* L, const Vec3& v) {
  lua_createtable(L, 3, 3);
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    lua_pushnumber(L, v[i]);
    lua_rawseti(L, -2, i + 1);
    lua_pushnumber(L, v[i]);
    lua_setfield(L, -2, names[i]);
  }
}

void pushQuat(lua_State* L, const Quat& q) {
  lua_createtable(L, 4, 4);
  const double v[4] = {q.w(), q.x(), q.y(), q.z()};
  const char* names[4] = {"w", "x", "y", "z"};
  for (int i = 0; i < 4; ++i) {
    lua_pushnumber(L, v[i]);
    lua_rawseti(L, -2, i + 1);
    lua_pushnumber(L, v[i]);
    lua_setfield(L, -2, names[i]);
  }
}

}  // namespace rm3d
