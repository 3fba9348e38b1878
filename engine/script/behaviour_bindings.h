// Behaviour side: registration of the Lua types and tables a behaviour VM sees, one binding
// file each (LÖVE's wrap_*): behaviour_module.cpp (`module`, and openModuleApi, which sets up
// the whole VM), behaviour_sim.cpp (`sim`, `log`/`print`, math.random), behaviour_joint.cpp
// (Joint), behaviour_dock.cpp (Dock). The world script's side is world_bindings.h.
#pragma once

struct lua_State;

namespace rm3d {

struct BehaviourContext;

/// Sets up a behaviour VM's globals: `module`, `sim`, `log`, `print`, seeded `math.random`,
/// `params`, `state`; the Joint and Dock types.
void openModuleApi(lua_State* L, BehaviourContext& ctx);
/// `sim`, `log`, `print`, and math.random/math.randomseed on the module's stream.
void openSimApi(lua_State* L);
void openJointType(lua_State* L);
void openDockType(lua_State* L);
void pushJoint(lua_State* L, int index);
void pushDock(lua_State* L, int index);

/// Shared helpers for the behaviour bindings (behaviour_module.cpp).
BehaviourContext& behaviourContext(lua_State* L);
/// The index held by a Joint or Dock userdata at arg 1: the metatable is compared by address
/// (`meta`), cheaper than luaL_checkudata's registry look-up by name, which is kept for the error.
int checkIndexUserdata(lua_State* L, const void* meta, const char* typeName);
/// Errors with "file:line: fn: expected a finite number" when the argument is NaN or infinite.
double checkFinite(lua_State* L, int arg);

}  // namespace rm3d
