// Behaviour side: the `sim` table (clock, the module's seeded random stream), `log`/`print`,
// and math.random/math.randomseed on the module's stream, in a behaviour VM.
#include <cstdint>
#include <lua.hpp>
#include <new>

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

/// Like math.random on `rng`: () -> [0, 1), (n) -> 1..n, (m, n) -> m..n.
int pushRandom(lua_State* L, Rng& rng) {
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

int pushGaussian(lua_State* L, Rng& rng) {
  const double mu = luaL_optnumber(L, 1, 0.0);
  const double sigma = luaL_optnumber(L, 2, 1.0);
  luaL_argcheck(L, sigma >= 0, 2, "sigma must not be negative");
  lua_pushnumber(L, rng.gaussian(mu, sigma));
  return 1;
}

/// sim.random([m [, n]]) -> like math.random, from the module's own seeded stream
int simRandom(lua_State* L) {
  return pushRandom(L, self(L).rng);
}

/// sim.gaussian([mu [, sigma]]) -> a normal deviate from the module's stream
int simGaussian(lua_State* L) {
  return pushGaussian(L, self(L).rng);
}

Rng& streamOf(lua_State* L) {
  return *static_cast<Rng*>(lua_touserdata(L, lua_upvalueindex(1)));
}
int streamRandom(lua_State* L) {
  return pushRandom(L, streamOf(L));
}
int streamGaussian(lua_State* L) {
  return pushGaussian(L, streamOf(L));
}

/// sim.stream(key) -> {random = fn, gaussian = fn}: a random stream of its own, seeded from the
/// world seed, the module's stream and the key, so what draws from it (a percept's or an action's
/// noise, keyed by its name) gets the same numbers whatever else draws, and in whatever order.
int simStream(lua_State* L) {
  size_t len = 0;
  const char* key = luaL_checklstring(L, 1, &len);
  const Module& m = self(L);
  uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a of the key
  for (size_t i = 0; i < len; ++i) h = (h ^ static_cast<unsigned char>(key[i])) * 0x100000001b3ull;
  const uint64_t seed = behaviourContext(L).module.world().settings().seed;
  lua_createtable(L, 0, 2);
  new (lua_newuserdatauv(L, sizeof(Rng), 0))
      Rng(seed, m.rngStream ^ (h * 0x9E3779B97F4A7C15ull) ^ 0x5354524541ull);
  lua_pushvalue(L, -1);
  lua_pushcclosure(L, streamRandom, 1);
  lua_setfield(L, -3, "random");
  lua_pushcclosure(L, streamGaussian, 1);
  lua_setfield(L, -2, "gaussian");
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
  static const luaL_Reg simFns[] = {{"time", simTime},         {"dt", simDt},         {"random", simRandom},
                                    {"gaussian", simGaussian}, {"stream", simStream}, {nullptr, nullptr}};
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
