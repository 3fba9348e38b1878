// `require("linalg")`: dense vectors and matrices, quaternions and rigid transforms for
// behaviours and world scripts, bound to Eigen (README, Lua API reference, "Linear algebra").
#pragma once

struct lua_State;

namespace rm3d {

/// Builds the `linalg` table (luaopen_ style: registers the metatables, returns 1).
int openLinalg(lua_State* L);

}  // namespace rm3d
