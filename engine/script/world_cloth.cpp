// World side: world.cloth{...} and the Cloth handle (rm3d.Cloth) it returns: node count,
// bounds, mean velocity, node positions, pinning. Nodes count from 1 in Lua (physics/cloth.h
// numbers them from 0: node (ix, iy) is Lua index iy * nx + ix + 1).
#include <cmath>
#include <lua.hpp>

#include "physics/cloth.h"
#include "script/lua_options.h"
#include "script/lua_vm.h"
#include "script/world_bindings.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr const char* kClothMeta = "rm3d.Cloth";

const World& world(lua_State* L) {
  return scriptWorld(L);
}
WorldEditor& editor(lua_State* L) {
  return scriptEditor(L);
}

int checkCloth(lua_State* L) {
  return *static_cast<int*>(luaL_checkudata(L, 1, kClothMeta));
}

/// The node index (0-based) at arg, given 1-based in Lua.
int checkNode(lua_State* L, int arg, int cloth) {
  const lua_Integer i = luaL_checkinteger(L, arg);
  const int n = world(L).physicsConst().clothNodeCount(cloth);
  if (i < 1 || i > n) luaL_error(L, "cloth: node index must be 1..%d (the cloth's nodes), got %I", n, i);
  return int(i - 1);
}

/// corners = {{x,y,z}, {x,y,z}, {x,y,z}, {x,y,z}}: the sheet's corners in order around its edge.
void readCorners(lua_State* L, const char* fn, ClothDesc& d) {
  const char* expected =
      "option 'corners' must be 4 points {{x,y,z}, {x,y,z}, {x,y,z}, {x,y,z}} in order around the edge";
  if (lua_getfield(L, 1, "corners") != LUA_TTABLE)
    luaL_error(L, "%s: %s, got %s", fn, expected, luaL_typename(L, -1));
  if (lua_rawlen(L, -1) != 4) luaL_error(L, "%s: %s, got %d points", fn, expected, int(lua_rawlen(L, -1)));
  for (int k = 0; k < 4; ++k) {
    lua_rawgeti(L, -1, k + 1);
    if (!lua_istable(L, -1) || lua_rawlen(L, -1) != 3)
      luaL_error(L, "%s: %s; corner %d is not {x, y, z}", fn, expected, k + 1);
    for (int i = 0; i < 3; ++i) {
      lua_rawgeti(L, -1, i + 1);
      int isnum = 0;
      const double v = lua_tonumberx(L, -1, &isnum);
      if (!isnum || !std::isfinite(v))
        luaL_error(L, "%s: %s; corner %d has a coordinate that is not a finite number", fn, expected, k + 1);
      d.corners[size_t(k)][i] = v;
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  const double bounds = world(L).settings().limits.bounds;
  for (int k = 0; k < 4; ++k) {
    const Vec3& a = d.corners[size_t(k)];
    const Vec3& b = d.corners[size_t((k + 1) % 4)];
    if (!(a.norm() <= bounds))
      luaL_error(L, "%s: corner %d must lie within the world bounds (%s m from the origin)", fn, k + 1,
                 numText(bounds).s);
    if (!((b - a).norm() >= 1e-4))
      luaL_error(L, "%s: corners %d and %d must be apart (at least 0.1 mm), got %s m", fn, k + 1,
                 (k + 1) % 4 + 1, numText((b - a).norm()).s);
  }
  const Vec3 area = (d.corners[2] - d.corners[0]).cross(d.corners[3] - d.corners[1]);
  if (!(area.norm() >= 1e-8))
    luaL_error(L, "%s: corners must span an area (they are in a line; list them in order around the edge)",
               fn);
}

/// Checks that option `key` is absent or an array of whole numbers in [1, max]. Raises (longjmp)
/// before anything is allocated, so no C++ object is left behind.
void checkIndices(lua_State* L, const char* fn, const char* key, int max, const char* what) {
  const int t = lua_getfield(L, 1, key);
  if (t != LUA_TNIL && t != LUA_TTABLE)
    luaL_error(L, "%s: option '%s' must be a list of %s (1..%d)", fn, key, what, max);
  const lua_Integer n = t == LUA_TTABLE ? lua_Integer(lua_rawlen(L, -1)) : 0;
  for (lua_Integer k = 1; k <= n; ++k) {
    lua_rawgeti(L, -1, k);
    int isint = 0;
    const lua_Integer i = lua_tointegerx(L, -1, &isint);
    if (!isint || i < 1 || i > max)
      luaL_error(L, "%s: option '%s' must be a list of %s (1..%d); item %I is %s", fn, key, what, max, k,
                 luaL_tolstring(L, -1, nullptr));
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

/// Appends option `key`'s numbers (checked by checkIndices) to out, 0-based.
void readIndices(lua_State* L, const char* key, std::vector<int>& out) {
  if (lua_getfield(L, 1, key) == LUA_TTABLE) {
    const lua_Integer n = lua_Integer(lua_rawlen(L, -1));
    for (lua_Integer k = 1; k <= n; ++k) {
      lua_rawgeti(L, -1, k);
      out.push_back(int(lua_tointeger(L, -1) - 1));
      lua_pop(L, 1);
    }
  }
  lua_pop(L, 1);
}

/// c:count() -> number of nodes
int clothCount(lua_State* L) {
  lua_pushinteger(L, world(L).physicsConst().clothNodeCount(checkCloth(L)));
  return 1;
}

/// c:resolution() -> nx, ny
int clothResolution(lua_State* L) {
  const World::Cloth& c = world(L).cloths()[size_t(checkCloth(L))];
  lua_pushinteger(L, c.nx);
  lua_pushinteger(L, c.ny);
  return 2;
}

/// c:bounds() -> {min={x,y,z}, max={x,y,z}} of the nodes (nil when a node is NaN)
int clothBounds(lua_State* L) {
  const World::ClothStats st = world(L).clothStats(checkCloth(L));
  if (st.nan) return 0;
  lua_createtable(L, 0, 2);
  pushVec3(L, st.lo);
  lua_setfield(L, -2, "min");
  pushVec3(L, st.hi);
  lua_setfield(L, -2, "max");
  return 1;
}

/// c:velocity() -> mean node velocity {x,y,z}
int clothVelocity(lua_State* L) {
  pushVec3(L, world(L).clothStats(checkCloth(L)).meanVelocity);
  return 1;
}

/// c:node(i) -> {x,y,z} of node i (1..count)
int clothNode(lua_State* L) {
  const int c = checkCloth(L);
  pushVec3(L, world(L).physicsConst().clothNode(c, checkNode(L, 2, c)));
  return 1;
}

/// c:positions() -> array of {x,y,z}, node 1 first
int clothPositions(lua_State* L) {
  const int c = checkCloth(L);
  const PhysicsWorld& ph = world(L).physicsConst();
  const int n = ph.clothNodeCount(c);
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; ++i) {
    pushVec3(L, ph.clothNode(c, i));
    lua_rawseti(L, -2, i + 1);
  }
  return 1;
}

/// c:pin(i): node i stays where it is now; c:unpin(i) frees it; c:pinned(i) -> bool
int clothPin(lua_State* L) {
  const int c = checkCloth(L);
  editor(L).setClothNodePinned(c, checkNode(L, 2, c), true);
  return 0;
}
int clothUnpin(lua_State* L) {
  const int c = checkCloth(L);
  editor(L).setClothNodePinned(c, checkNode(L, 2, c), false);
  return 0;
}
int clothPinned(lua_State* L) {
  const int c = checkCloth(L);
  lua_pushboolean(L, world(L).physicsConst().clothNodePinned(c, checkNode(L, 2, c)));
  return 1;
}

}  // namespace

void openClothHandle(lua_State* L) {
  static const luaL_Reg methods[] = {{"count", clothCount},   {"resolution", clothResolution},
                                     {"bounds", clothBounds}, {"velocity", clothVelocity},
                                     {"node", clothNode},     {"positions", clothPositions},
                                     {"pin", clothPin},       {"unpin", clothUnpin},
                                     {"pinned", clothPinned}, {nullptr, nullptr}};
  luaL_newmetatable(L, kClothMeta);
  sealMetatable(L);
  luaL_newlib(L, methods);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
}

/// world.cloth{corners={{x,y,z} x4}, resolution={nx, ny}, mass=, stiffness=, pinned={corner...},
/// pinned_nodes={node...}, friction=, thickness=, color={r,g,b}} -> Cloth
int worldCloth(lua_State* L) {
  const char* fn = "world.cloth";
  checkOptionKeys(L, 1, fn,
                  {"corners", "resolution", "mass", "stiffness", "pinned", "pinned_nodes", "friction",
                   "thickness", "color"});
  ClothDesc d;
  readCorners(L, fn, d);
  if (lua_getfield(L, 1, "resolution") != LUA_TNIL) {
    bool ok = lua_istable(L, -1) && lua_rawlen(L, -1) == 2;
    lua_Integer v[2] = {0, 0};
    for (int i = 0; ok && i < 2; ++i) {
      lua_rawgeti(L, -1, i + 1);
      int isint = 0;
      v[i] = lua_tointegerx(L, -1, &isint);
      ok = isint != 0;
      lua_pop(L, 1);
    }
    if (!ok) luaL_error(L, "%s: option 'resolution' must be {nx, ny}, two whole numbers of nodes", fn);
    if (v[0] < 2 || v[1] < 2 || v[0] > kClothMaxSide || v[1] > kClothMaxSide || v[0] * v[1] > kClothMaxNodes)
      luaL_error(L, "%s: resolution must be 2..%d nodes a side and at most %d nodes in all, got {%I, %I}", fn,
                 kClothMaxSide, kClothMaxNodes, v[0], v[1]);
    d.nx = int(v[0]);
    d.ny = int(v[1]);
  } else {
    d.nx = d.ny = 16;
  }
  lua_pop(L, 1);
  d.mass = optNumberField(L, 1, fn, "mass", 0.1);
  if (!(d.mass > 0))
    luaL_error(L, "%s: mass must be positive (kg, the whole sheet), got %s", fn, numText(d.mass).s);
  d.stiffness = optNumberField(L, 1, fn, "stiffness", 0.9);
  if (!(d.stiffness > 0 && d.stiffness <= 1))
    luaL_error(L, "%s: stiffness must be in (0, 1], got %s", fn, numText(d.stiffness).s);
  d.friction = optNumberField(L, 1, fn, "friction", 0.5);
  if (!(d.friction >= 0 && d.friction <= 1))
    luaL_error(L, "%s: friction must be in [0, 1], got %s", fn, numText(d.friction).s);
  d.thickness = optNumberField(L, 1, fn, "thickness", 0.005);
  if (!(d.thickness >= 1e-4 && d.thickness <= 0.1))
    luaL_error(L, "%s: thickness must be 0.0001..0.1 m, got %s", fn, numText(d.thickness).s);
  const Vec3 rgb = optVec3Field(L, 1, fn, "color", Vec3(0.8, 0.3, 0.25));
  if (!(rgb.minCoeff() >= 0 && rgb.maxCoeff() <= 1))
    luaL_error(L, "%s: color must be {r, g, b} each in [0, 1]", fn);
  checkIndices(L, fn, "pinned", 4, "corner numbers");
  checkIndices(L, fn, "pinned_nodes", d.nx * d.ny, "node indices");
  const std::array<float, 4> color{float(rgb.x()), float(rgb.y()), float(rgb.z()), 1.0f};
  // Lua errors are longjmps: everything that allocates lives inside the call below, whose
  // exceptions unwind it before the error is raised.
  int c = -1;
  callWorld(L, fn, [&] {
    ClothDesc desc = d;
    std::vector<int> corners;
    readIndices(L, "pinned", corners);
    for (int k : corners) desc.pinned.push_back(clothCornerNode(desc.nx, desc.ny, k));
    readIndices(L, "pinned_nodes", desc.pinned);
    c = editor(L).addCloth(desc, color);
    return 0;
  });
  // The handle is made outside the try: making it may raise a Lua error (a longjmp).
  *static_cast<int*>(lua_newuserdatauv(L, sizeof(int), 0)) = c;
  luaL_setmetatable(L, kClothMeta);
  return 1;
}

}  // namespace rm3d
