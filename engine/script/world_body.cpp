// World side: the Body handle (rm3d.Body) of an obstacle made by world.box/sphere/cylinder/
// capsule/mesh, and the shape world.mesh reads from a mesh file (its convex hull, or the triangles
// themselves for a static concave mesh).
#include <string>

#include "assets/mesh_loader.h"
#include "core/error.h"
#include "script/lua_options.h"
#include "script/lua_vm.h"
#include "script/world_bindings.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr const char* kBodyMeta = "rm3d.Body";

const World& world(lua_State* L) {
  return scriptWorld(L);
}

int checkBody(lua_State* L) {
  return *static_cast<int*>(luaL_checkudata(L, 1, kBodyMeta));
}

/// b:position() -> {x,y,z}
int bodyPosition(lua_State* L) {
  pushVec3(L, world(L).obstaclePose(checkBody(L)).pos);
  return 1;
}

/// b:orientation() -> {w,x,y,z}
int bodyOrientation(lua_State* L) {
  pushQuat(L, world(L).obstaclePose(checkBody(L)).rot);
  return 1;
}

/// b:velocity() -> {x,y,z}
int bodyVelocity(lua_State* L) {
  pushVec3(L, world(L).obstacleVelocity(checkBody(L)));
  return 1;
}

/// b:sleeping() -> true when the body is static or asleep (still for 2 s; it wakes when touched)
int bodySleeping(lua_State* L) {
  lua_pushboolean(L, world(L).obstacleSleeping(checkBody(L)));
  return 1;
}

}  // namespace

void openBodyHandle(lua_State* L) {
  static const luaL_Reg bodyMethods[] = {{"position", bodyPosition},
                                         {"orientation", bodyOrientation},
                                         {"velocity", bodyVelocity},
                                         {"sleeping", bodySleeping},
                                         {nullptr, nullptr}};
  luaL_newmetatable(L, kBodyMeta);
  sealMetatable(L);
  luaL_newlib(L, bodyMethods);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
}

void pushBody(lua_State* L, int part) {
  *static_cast<int*>(lua_newuserdatauv(L, sizeof(int), 0)) = part;
  luaL_setmetatable(L, kBodyMeta);
}

void loadMeshShape(const World& w, const char* file, double scale, ShapeKind kind, ShapeDef& out) {
  const std::string path = w.resolvePath(file);
  if (path.empty())
    throw InputError(std::string("mesh file '") + file + "' not found " + w.resolveLookedIn());
  MeshData mesh;
  std::string err;
  MeshCache* cache = w.options().meshes.get();
  if (!(cache ? cache->load(path, scale, mesh, err) : loadMesh(path, scale, mesh, err)))
    throw InputError(err);
  out.kind = kind;
  out.points = std::move(mesh.points);
  out.triangles = std::move(mesh.triangles);
  out.source = file;
}

}  // namespace rm3d
