// world.trace / module.trace / world.metric argument checks and the name -> slot cache.
#include "script/trace_binding.h"

#include <cmath>
#include <lua.hpp>

#include "core/trace_series.h"
#include "script/lua_options.h"

namespace rm3d {

const char* checkSeriesName(lua_State* L, int arg, const char* fn) {
  if (lua_type(L, arg) != LUA_TSTRING)
    luaL_error(L, "%s: the name (argument %d) must be a string, got %s", fn, arg, luaL_typename(L, arg));
  size_t len = 0;
  const char* name = lua_tolstring(L, arg, &len);
  if (const char* why = seriesNameProblem({name, len}))
    luaL_error(L, "%s: bad name '%s': %s", fn, len > 80 ? "(too long to show)" : name, why);
  return name;
}

double checkSeriesValue(lua_State* L, int arg, const char* fn) {
  if (lua_type(L, arg) != LUA_TNUMBER)
    luaL_error(L, "%s: the value (argument %d) must be a number, got %s", fn, arg, luaL_typename(L, arg));
  const double v = lua_tonumber(L, arg);
  if (std::isnan(v)) luaL_error(L, "%s: the value must be a finite number, got nan", fn);
  if (!std::isfinite(v)) luaL_error(L, "%s: the value must be a finite number, got %s", fn, numText(v).s);
  return v;
}

int recordSeries(lua_State* L, TraceSeries& series, const char* fn, const char* owner) {
  const double v = checkSeriesValue(L, 2, fn);
  if (lua_type(L, 1) == LUA_TSTRING) {
    lua_pushvalue(L, 1);
    if (lua_rawget(L, lua_upvalueindex(1)) == LUA_TNUMBER) {  // seen before: no C++ look-up
      series.set(int(lua_tointeger(L, -1)), v);
      return 0;
    }
    lua_pop(L, 1);
  }
  const char* name = checkSeriesName(L, 1, fn);
  if (series.full())
    return luaL_error(L, "%s: too many series names in %s (at most %d); '%s' is one more", fn, owner,
                      int(TraceSeries::kMaxSeries), name);
  const int slot = series.add(name);
  lua_pushvalue(L, 1);
  lua_pushinteger(L, slot);
  lua_rawset(L, lua_upvalueindex(1));
  series.set(slot, v);
  return 0;
}

void pushSeriesClosure(lua_State* L, int (*f)(lua_State*)) {
  lua_newtable(L);
  lua_pushcclosure(L, f, 1);
}

}  // namespace rm3d
