// Behaviour side: the `sim` table (clock, the module's seeded random stream), `log`/`print`,
// and math.random/math.randomseed on the module's stream, in a behaviour VM.
#include <cstdint>
#include <lua.hpp>

#include "script/behaviour.h"
#include "script/behaviour_bindings.h"
#include "world/world.h"

namespace rm3d {

namespace {

Module& self(lua_State* L) {
  return behaviourContext(L).module.self();
}

/// sim.time() -> seconds since the start
int simTime(lua_State* L) {
  lua_pushnumber(L, behaviourContext(L).module.world().time());
  return 1;
}

/// sim.dt() -> the control step, seconds
int simDt(lua_State* L) {
  lua_pushnumber(L, behaviourContext(L).module.world().settings().dt);
  return 1;
}

/// sim.random([m [, n]]) -> like math.random, from the module's own seeded stream
int simRandom(lua_State* L) {
  Rng& rng = self(L).rng;
  const int n = lua_gettop(L);
  if (n == 0) {
    lua_pushnumber(L, rng.uniform());
    return 1;
  }
  lua_Integer lo = 1, hi;
  if (n == 1) {
    hi = luaL_checkinteger(L, 1);
  } else {
    lo = luaL_checkinteger(L, 1);
    hi = luaL_checkinteger(L, 2);
  }
  luaL_argcheck(L, lo <= hi, n, "interval is empty");
  const uint64_t span = uint64_t(hi) - uint64_t(lo) + 1;
  const uint64_t r = span == 0 ? rng.next() : rng.next() % span;
  lua_pushinteger(L, lua_Integer(uint64_t(lo) + r));
  return 1;
}

/// sim.gaussian([mu [, sigma]]) -> a normal deviate from the module's stream
int simGaussian(lua_State* L) {
  const double mu = luaL_optnumber(L, 1, 0.0);
  const double sigma = luaL_optnumber(L, 2, 1.0);
  luaL_argcheck(L, sigma >= 0, 2, "sigma must not be negative");
  lua_pushnumber(L, self(L).rng.gaussian(mu, sigma));
  return 1;
}

/// math.randomseed(x): restarts the module's stream from x (and the module id)
int simRandomSeed(lua_State* L) {
  const lua_Integer s = luaL_checkinteger(L, 1);
  self(L).rng.seed(uint64_t(s), uint64_t(self(L).id) ^ 0x5eed5eed00000000ull);
  return 0;
}

/// log(...) / print(...): a line in the run's log, tagged with time and module
int logLine(lua_State* L) {
  const int n = lua_gettop(L);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (int i = 1; i <= n; ++i) {
    luaL_tolstring(L, i, nullptr);
    luaL_addvalue(&b);
    if (i < n) luaL_addchar(&b, '\t');
  }
  luaL_pushresult(&b);
  self(L).log.emplace_back(lua_tostring(L, -1));
  return 0;
}

}  // namespace

void openSimApi(lua_State* L) {
  static const luaL_Reg simFns[] = {
      {"time", simTime}, {"dt", simDt}, {"random", simRandom}, {"gaussian", simGaussian}, {nullptr, nullptr}};
  luaL_newlib(L, simFns);
  lua_setglobal(L, "sim");

  lua_getglobal(L, "math");
  lua_pushcfunction(L, simRandom);
  lua_setfield(L, -2, "random");
  lua_pushcfunction(L, simRandomSeed);
  lua_setfield(L, -2, "randomseed");
  lua_pop(L, 1);

  lua_pushcfunction(L, logLine);
  lua_setglobal(L, "log");
  lua_pushcfunction(L, logLine);
  lua_setglobal(L, "print");
}

}  // namespace rm3d
