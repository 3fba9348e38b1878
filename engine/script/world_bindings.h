// World side: registration of the Lua types and tables the world script sees, one file each:
// world_api.cpp (`world`, `expect`, `args`, `log`), world_module.cpp (the Module handle, a
// spawned module), world_body.cpp (the Body handle, an obstacle), world_cloth.cpp (world.cloth, the Cloth
// handle), world_heightfield.cpp (terrain). Handles are userdata holding an index. Also the bridge that
// turns C++ exceptions from World into Lua errors. The behaviour side is behaviour_bindings.h.
#pragma once

#include <cstring>
#include <exception>
#include <lua.hpp>
#include <new>

#include "physics/shape_def.h"
#include "world/world_editor.h"

namespace rm3d {

class World;
class WorldEditor;

/// The World of the world script running in L, read-only, and the editor that changes it
/// (world_api.cpp; world/world_editor.h).
const World& scriptWorld(lua_State* L);
WorldEditor& scriptEditor(lua_State* L);

void openModuleHandle(lua_State* L);
void openBodyHandle(lua_State* L);
/// Adds world.fluid and world.debris to the table on the stack top (world_particles.cpp).
void openParticleApi(lua_State* L);
void pushModule(lua_State* L, int index);
/// The module index held by the Module handle at arg (errors otherwise).
int checkModule(lua_State* L, int arg);
/// A dock of module `module` named by the string at arg (errors listing the docks otherwise).
int checkDockName(lua_State* L, int arg, int module);
void pushBody(lua_State* L, int part);
void openClothHandle(lua_State* L);
/// world.cloth{...} (world_cloth.cpp)
int worldCloth(lua_State* L);
/// Fills a Hull (or TriMesh) shape from a mesh file (resolved like other world paths). Throws
/// InputError.
void loadMeshShape(const World& world, const char* file, double scale, ShapeKind kind, ShapeDef& out);
/// world.heightfield{...} and its handle (world_heightfield.cpp).
int worldHeightfield(lua_State* L);
void openHeightfieldHandle(lua_State* L);
/// Errors unless `at` lies within the world bounds (world.set{bounds=}).
void checkInBounds(lua_State* L, const char* fn, const Vec3& at);

/// Runs f() (which may throw but must not raise Lua errors) and turns an exception into a Lua
/// error "file:line: fn: message" raised after every C++ object is gone.
template <class F>
int callWorld(lua_State* L, const char* fn, F&& f) {
  int results = -1;
  try {
    results = f();
  } catch (const std::exception& e) {
    // Memory that ran out anywhere reads the same as the physics engine's (its own message).
    const char* what =
        dynamic_cast<const std::bad_alloc*>(&e) && std::strcmp(e.what(), "std::bad_alloc") == 0
            ? "out of memory (the machine's memory or the process's address-space limit is spent)"
            : e.what();
    luaL_where(L, 1);
    lua_pushfstring(L, "%s: %s", fn, what);
    lua_concat(L, 2);
  }
  if (results >= 0) return results;
  return lua_error(L);
}

}  // namespace rm3d
