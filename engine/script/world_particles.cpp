// World side: world.fluid{...} and world.debris{...} (particles/particle_system.h), and the
// Particles handle (rm3d.Particles) they return.
#include <cmath>

#include "script/lua_options.h"
#include "script/lua_vm.h"
#include "script/world_bindings.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr const char* kParticlesMeta = "rm3d.Particles";

const ParticleSystem& checkParticles(lua_State* L) {
  const int i = *static_cast<int*>(luaL_checkudata(L, 1, kParticlesMeta));
  return *scriptWorld(L).particleSystems()[size_t(i)];
}

/// p:count() -> number of particles
int particlesCount(lua_State* L) {
  lua_pushinteger(L, checkParticles(L).count());
  return 1;
}

/// p:kind() -> "fluid" or "debris"
int particlesKind(lua_State* L) {
  lua_pushstring(L, checkParticles(L).kindName());
  return 1;
}

/// p:radius() -> particle radius (m, half the spacing)
int particlesRadius(lua_State* L) {
  lua_pushnumber(L, checkParticles(L).radius());
  return 1;
}

/// p:bounds() -> min {x,y,z}, max {x,y,z} of the particles now
int particlesBounds(lua_State* L) {
  Vec3 lo, hi;
  checkParticles(L).bounds(lo, hi);
  pushVec3(L, lo);
  pushVec3(L, hi);
  return 2;
}

/// p:mean_velocity() -> {x,y,z} (m/s)
int particlesMeanVelocity(lua_State* L) {
  pushVec3(L, checkParticles(L).meanVelocity());
  return 1;
}

/// p:positions() -> array of {x,y,z}, one per particle (in no fixed order)
int particlesPositions(lua_State* L) {
  const ParticleSystem& ps = checkParticles(L);
  const int n = ps.count();
  // About 136 bytes a particle (a slot in the list, a 3-entry table): checked against the memory
  // cap before anything is built, so a huge system is an error with file:line.
  LuaVm::checkRoom(L, double(n) * 136.0, "p:positions() (a table per particle)");
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; ++i) {
    lua_createtable(L, 3, 0);
    lua_pushnumber(L, ps.x()[size_t(i)]);
    lua_rawseti(L, -2, 1);
    lua_pushnumber(L, ps.y()[size_t(i)]);
    lua_rawseti(L, -2, 2);
    lua_pushnumber(L, ps.z()[size_t(i)]);
    lua_rawseti(L, -2, 3);
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

/// p:count_in(min {x,y,z}, max {x,y,z}) -> particles inside the box
int particlesCountIn(lua_State* L) {
  const ParticleSystem& ps = checkParticles(L);
  double b[6];
  for (int k = 0; k < 2; ++k) {
    luaL_checktype(L, 2 + k, LUA_TTABLE);
    for (int a = 0; a < 3; ++a) {
      lua_rawgeti(L, 2 + k, a + 1);
      if (!lua_isnumber(L, -1)) return luaL_argerror(L, 2 + k, "expected {x, y, z} (three numbers)");
      b[3 * k + a] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
  }
  lua_Integer n = 0;
  for (int i = 0; i < ps.count(); ++i) {
    const double x = ps.x()[size_t(i)], y = ps.y()[size_t(i)], z = ps.z()[size_t(i)];
    n += x >= b[0] && x <= b[3] && y >= b[1] && y <= b[4] && z >= b[2] && z <= b[5];
  }
  lua_pushinteger(L, n);
  return 1;
}

int particlesToString(lua_State* L) {
  const ParticleSystem& ps = checkParticles(L);
  lua_pushfstring(L, "Particles(%s, %d)", ps.kindName(), ps.count());
  return 1;
}

/// Reads the options shared by both calls and those of `kind`; errors name file:line.
int addParticles(lua_State* L, const char* fn, ParticleDef::Kind kind) {
  luaL_checktype(L, 1, LUA_TTABLE);
  const bool fluid = kind == ParticleDef::Kind::Fluid;
  if (fluid)
    checkOptionKeys(L, 1, fn,
                    {"min", "max", "spacing", "density", "viscosity", "tension", "friction",
                     "kinetic_friction", "damping", "iterations", "substeps", "kernel", "max_speed"});
  else
    checkOptionKeys(L, 1, fn,
                    {"min", "max", "spacing", "density", "friction", "kinetic_friction", "damping",
                     "iterations", "substeps", "max_speed"});
  lua_getfield(L, 1, "min");
  const bool hasMin = !lua_isnil(L, -1);
  lua_getfield(L, 1, "max");
  const bool hasMax = !lua_isnil(L, -1);
  lua_pop(L, 2);
  if (!hasMin || !hasMax)
    return luaL_error(L, "%s: options 'min' and 'max' ({x, y, z}: the box to fill) are required", fn);
  ParticleDef d;
  d.kind = kind;
  d.min = optVec3Field(L, 1, fn, "min", Vec3::Zero());
  d.max = optVec3Field(L, 1, fn, "max", Vec3::Zero());
  d.spacing = optNumberField(L, 1, fn, "spacing", fluid ? 0.02 : 0.02);
  d.density = optNumberField(L, 1, fn, "density", fluid ? 1000.0 : 1600.0);
  d.viscosity = optNumberField(L, 1, fn, "viscosity", fluid ? 0.01 : 0.0);
  d.tension = optNumberField(L, 1, fn, "tension", fluid ? 0.01 : 0.0);
  d.friction = optNumberField(L, 1, fn, "friction", fluid ? 0.0 : 0.6);
  d.kineticFriction = optNumberField(L, 1, fn, "kinetic_friction", -1);
  d.damping = optNumberField(L, 1, fn, "damping", fluid ? 0.0 : 0.5);
  d.kernel = optNumberField(L, 1, fn, "kernel", 1.8);
  d.maxSpeed = optNumberField(L, 1, fn, "max_speed", 4.0);
  const long long iterations = optIntegerField(L, 1, fn, "iterations", fluid ? 3 : 3);
  // Fluids: one substep per iteration (a deep pool is compressed far less); debris: one.
  const long long substeps = optIntegerField(L, 1, fn, "substeps", fluid ? iterations : 1);
  const double bounds = scriptWorld(L).settings().limits.bounds;
  for (int a = 0; a < 3; ++a)
    if (!(d.min[a] < d.max[a]))
      return luaL_error(L,
                        "%s: 'min' must be below 'max' on every axis, got min {%s, %s, %s}, max {%s, %s, %s}",
                        fn, numText(d.min.x()).s, numText(d.min.y()).s, numText(d.min.z()).s,
                        numText(d.max.x()).s, numText(d.max.y()).s, numText(d.max.z()).s);
  if (!(d.min.norm() <= bounds && d.max.norm() <= bounds))
    return luaL_error(
        L, "%s: the box must lie within the world bounds (%s m from the origin; world.set{bounds=})", fn,
        numText(bounds).s);
  auto positive = [&](const char* key, double v) {
    return luaL_error(L, "%s: %s must be positive, got %s", fn, key, numText(v).s);
  };
  if (!(d.spacing > 0) || !std::isfinite(d.spacing)) return positive("spacing", d.spacing);
  if (!(d.density > 0) || !std::isfinite(d.density)) return positive("density", d.density);
  if (!(d.maxSpeed > 0) || !std::isfinite(d.maxSpeed)) return positive("max_speed", d.maxSpeed);
  auto range = [&](const char* key, double v, double lo, double hi) {
    return luaL_error(L, "%s: %s must be in [%s, %s], got %s", fn, key, numText(lo).s, numText(hi).s,
                      numText(v).s);
  };
  if (!(d.viscosity >= 0 && d.viscosity <= 1)) return range("viscosity", d.viscosity, 0, 1);
  if (!(d.tension >= 0 && d.tension <= 1)) return range("tension", d.tension, 0, 1);
  if (!(d.friction >= 0 && d.friction <= 10)) return range("friction", d.friction, 0, 10);
  if (d.kineticFriction != -1 && !(d.kineticFriction >= 0 && d.kineticFriction <= 10))
    return range("kinetic_friction", d.kineticFriction, 0, 10);
  if (!(d.damping >= 0 && d.damping <= 100)) return range("damping", d.damping, 0, 100);
  if (!(d.kernel >= 1.2 && d.kernel <= 2.5)) return range("kernel", d.kernel, 1.2, 2.5);
  if (iterations < 1 || iterations > 50) return range("iterations", double(iterations), 1, 50);
  d.iterations = int(iterations);
  if (substeps < 1 || substeps > 50) return range("substeps", double(substeps), 1, 50);
  if (substeps > iterations)
    return luaL_error(L,
                      "%s: substeps (%d) must not exceed iterations (%d): the iterations are spread over the "
                      "substeps, so at most %d substeps can run; raise iterations or lower substeps",
                      fn, int(substeps), int(iterations), int(iterations));
  d.substeps = int(substeps);
  int index = -1;
  callWorld(L, fn, [&] {
    index = scriptEditor(L).addParticles(d);
    return 0;
  });
  // The handle is made outside the try: making it may raise a Lua error (a longjmp).
  *static_cast<int*>(lua_newuserdatauv(L, sizeof(int), 0)) = index;
  luaL_setmetatable(L, kParticlesMeta);
  return 1;
}

/// world.fluid{min=, max=, spacing=, density=, viscosity=, tension=, friction=, iterations=,
/// substeps=, kernel=, damping=, max_speed=} -> Particles (position-based fluid)
int worldFluid(lua_State* L) {
  return addParticles(L, "world.fluid", ParticleDef::Kind::Fluid);
}

/// world.debris{min=, max=, spacing=, density=, friction=, kinetic_friction=, iterations=,
/// substeps=, damping=, max_speed=} -> Particles (granular)
int worldDebris(lua_State* L) {
  return addParticles(L, "world.debris", ParticleDef::Kind::Debris);
}

}  // namespace

void openParticleApi(lua_State* L) {
  static const luaL_Reg methods[] = {{"count", particlesCount},
                                     {"kind", particlesKind},
                                     {"radius", particlesRadius},
                                     {"bounds", particlesBounds},
                                     {"mean_velocity", particlesMeanVelocity},
                                     {"positions", particlesPositions},
                                     {"count_in", particlesCountIn},
                                     {nullptr, nullptr}};
  luaL_newmetatable(L, kParticlesMeta);
  sealMetatable(L);
  luaL_newlib(L, methods);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, particlesToString);
  lua_setfield(L, -2, "__tostring");
  lua_pop(L, 1);
  lua_pushcfunction(L, worldFluid);
  lua_setfield(L, -2, "fluid");
  lua_pushcfunction(L, worldDebris);
  lua_setfield(L, -2, "debris");
}

}  // namespace rm3d
