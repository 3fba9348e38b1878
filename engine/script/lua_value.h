// Copying values (messaging/value.h) out of and into Lua states: nil, booleans, numbers,
// strings and tables of these. One copier serves messages (functions, userdata, threads and
// cycles refused, size-limited) and module-type files (other values kept as placeholders so
// their messages can say "got a function", keys limited to names and list positions).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "messaging/value.h"

struct lua_State;

namespace rm3d {

using LuaValue = Value;  ///< the message value type (messaging/value.h), as the Lua side names it

/// How readLuaValue copies; the defaults are what messages need.
struct LuaValueOptions {
  size_t limit = 0;         ///< bound on the copied size in bytes, as luaValueSize counts (0: none)
  int maxDepth = 64;        ///< tables nested deeper than this fail (TooDeep)
  bool keepOpaque = false;  ///< functions, userdata and threads become Value::Type::Opaque placeholders
  bool plainKeys = false;   ///< only string and integer keys; others fail (BadKey)
};

/// One key on the way from the copied value down to where a copy failed.
struct LuaPathStep {
  bool isIndex = false;  ///< an integer key (index holds it)
  int64_t index = 0;
  std::string name;  ///< the key as Lua's tostring gives it (strings, numbers), else empty
};

/// Why a copy failed, and where.
struct LuaValueError {
  enum class Kind : uint8_t {
    Unsupported,  ///< a function, userdata or thread (typeName) without keepOpaque
    Cycle,        ///< a table that contains itself
    TooDeep,      ///< tables nested deeper than maxDepth
    NoStack,      ///< no Lua stack space left to traverse a table
    TableKey,     ///< a table used as a key
    BadKey,       ///< plainKeys: a key that is not a string or an integer (typeName, number)
    TooLarge,     ///< over the size limit
  };
  Kind kind = Kind::Unsupported;
  std::string typeName;           ///< Unsupported, BadKey: the Lua type name of the value or key
  double number = 0;              ///< BadKey with a number key: that number
  std::vector<LuaPathStep> path;  ///< outermost key first; for Cycle, TooDeep, NoStack, TableKey
                                  ///< and BadKey it ends at the table concerned
};

/// Copies the value at idx, table keys sorted (copies are deterministic). On failure returns
/// false and fills err; the path is built only then, so a copy that succeeds allocates nothing
/// beyond the value itself. Never raises.
bool readLuaValue(lua_State* L, int idx, LuaValue& out, const LuaValueOptions& options, LuaValueError& err);
/// The message form: on failure sets err (e.g. "a function at key 'f' cannot be copied").
/// `limit` bounds the copied size in bytes (0: none). Never raises.
bool readLuaValue(lua_State* L, int idx, LuaValue& out, size_t limit, std::string& err);
/// Pushes a fresh copy (placeholders as nil). Needs stack space only; may raise a memory error.
void pushLuaValue(lua_State* L, const LuaValue& v);
/// Approximate size in bytes (what the limit counts).
inline size_t luaValueSize(const LuaValue& v) {
  return valueSize(v);
}

}  // namespace rm3d
