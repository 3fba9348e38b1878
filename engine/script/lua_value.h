// Plain Lua values copied between VMs (spawn params, messages): nil, booleans, numbers,
// strings and tables of these. Functions, userdata, threads and cycles are refused.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

struct lua_State;

namespace rm3d {

/// Largest spawn `params` value (bytes as luaValueSize counts them).
inline constexpr size_t kParamsLimit = 4u << 20;

struct LuaValue {
  enum class Type : uint8_t { Nil, Boolean, Integer, Number, String, Table };
  Type type = Type::Nil;
  bool boolean = false;
  int64_t integer = 0;
  double number = 0;
  std::string string;
  std::vector<std::pair<LuaValue, LuaValue>> table;  ///< keys sorted: copies are deterministic

  // Declared here and defaulted below, with the exception specification spelled out: clang
  // (with libstdc++) cannot deduce it for this recursive type and rejects the implicit ones.
  LuaValue() = default;
  LuaValue(const LuaValue&);
  LuaValue(LuaValue&&) noexcept;
  LuaValue& operator=(const LuaValue&);
  LuaValue& operator=(LuaValue&&) noexcept;
  ~LuaValue();
};
inline LuaValue::LuaValue(const LuaValue&) = default;
inline LuaValue::LuaValue(LuaValue&&) noexcept = default;
inline LuaValue& LuaValue::operator=(const LuaValue&) = default;
inline LuaValue& LuaValue::operator=(LuaValue&&) noexcept = default;
inline LuaValue::~LuaValue() = default;

/// Copies the value at idx. On failure returns false and sets err (e.g. "a function at
/// key 'f' cannot be copied"). `limit` bounds the copied size in bytes (0: none). Never raises.
bool readLuaValue(lua_State* L, int idx, LuaValue& out, size_t limit, std::string& err);
/// Pushes a fresh copy. Needs stack space only; may raise a memory error.
void pushLuaValue(lua_State* L, const LuaValue& v);
/// Approximate size in bytes (what the limit counts).
size_t luaValueSize(const LuaValue& v);
nlohmann::json luaValueToJson(const LuaValue& v);

}  // namespace rm3d
