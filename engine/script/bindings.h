// Registration of the Lua-visible types and tables, one binding file each (LÖVE's wrap_*).
#pragma once

struct lua_State;

namespace rm3d {

struct BehaviourContext;
struct SensorReading;

/// Behaviour VM: `module`, `sim`, `log`, `print`, seeded `math.random`; Joint and Dock types.
void openJointType(lua_State* L);
void openDockType(lua_State* L);
void openModuleApi(lua_State* L, BehaviourContext& ctx);
void pushJoint(lua_State* L, int index);
void pushDock(lua_State* L, int index);
/// Pushes a sensor reading as the Lua value behaviours see.
void pushSensorReading(lua_State* L, const SensorReading& r);

/// Shared helpers for bindings.
BehaviourContext& behaviourContext(lua_State* L);
/// The index held by a Joint or Dock userdata at arg 1: the metatable is compared by address
/// (`meta`), cheaper than luaL_checkudata's registry look-up by name, which is kept for the error.
int checkIndexUserdata(lua_State* L, const void* meta, const char* typeName);
/// Errors with "file:line: fn: expected a finite number" when the argument is NaN or infinite.
double checkFinite(lua_State* L, int arg);

}  // namespace rm3d
