// Copying message values (messaging/value.h) out of and into Lua states: nil, booleans,
// numbers, strings and tables of these. Functions, userdata, threads and cycles are refused.
#pragma once

#include <string>

#include "messaging/value.h"

struct lua_State;

namespace rm3d {

using LuaValue = Value;  ///< the message value type (messaging/value.h), as the Lua side names it

/// Copies the value at idx. On failure returns false and sets err (e.g. "a function at
/// key 'f' cannot be copied"). `limit` bounds the copied size in bytes (0: none). Never raises.
bool readLuaValue(lua_State* L, int idx, LuaValue& out, size_t limit, std::string& err);
/// Pushes a fresh copy. Needs stack space only; may raise a memory error.
void pushLuaValue(lua_State* L, const LuaValue& v);
/// Approximate size in bytes (what the limit counts).
inline size_t luaValueSize(const LuaValue& v) {
  return valueSize(v);
}

}  // namespace rm3d
