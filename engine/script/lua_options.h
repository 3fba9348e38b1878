// Reading option tables in bindings: misspelled keys are rejected (LÖVE's
// luax_checktablefields), values are type-checked, errors carry the caller's file:line.
// These raise Lua errors: call them only while no C++ object with a destructor is alive.
#pragma once

#include <initializer_list>

#include "core/types.h"

struct lua_State;

namespace rm3d {

/// Errors if the table at idx has a key not in `allowed`; `fn` names the call for the message.
void checkOptionKeys(lua_State* L, int idx, const char* fn, std::initializer_list<const char*> allowed);
/// Whether t[key] is present (not nil).
bool hasField(lua_State* L, int idx, const char* key);
/// t[key] as a number, or def when absent; errors on a wrong type.
double optNumberField(lua_State* L, int idx, const char* fn, const char* key, double def);
/// t[key] as an integer, or def when absent.
long long optIntegerField(lua_State* L, int idx, const char* fn, const char* key, long long def);
/// t[key] as {x, y, z}, or def when absent.
Vec3 optVec3Field(lua_State* L, int idx, const char* fn, const char* key, const Vec3& def);
/// t[key] as a string (pointer valid while the table lives), or nullptr when absent.
const char* optStringField(lua_State* L, int idx, const char* fn, const char* key);
/// t[key] as a boolean, or def when absent.
bool optBoolField(lua_State* L, int idx, const char* fn, const char* key, bool def);
/// Pose from `at` = {x,y,z} and `rot` = {roll, pitch, yaw} (radians) or `quat` = {w,x,y,z}.
Pose optPoseFields(lua_State* L, int idx, const char* fn);
/// A number as printf's %g writes it (1e-300, -1e+30, nan), for messages; the text lives in the
/// returned value, which needs no destructor (safe in a luaL_error argument list).
struct NumText {
  char s[32];
};
NumText numText(double v);
/// Pushes {x, y, z}.
void pushVec3(lua_State* L, const Vec3& v);
/// Pushes {w, x, y, z}.
void pushQuat(lua_State* L, const Quat& q);

}  // namespace rm3d
