// The value messages and spawn parameters carry between VMs: nil, booleans, numbers, strings
// and tables of these, copied deeply. Plain C++ (the script layer converts to and from Lua), so
// the world, docking and messaging compile without Lua.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

namespace rm3d {

/// Largest spawn `params` value (bytes as luaValueSize counts them).
inline constexpr size_t kParamsLimit = 4u << 20;

struct Value {
  /// Opaque: a placeholder for a Lua value that cannot be copied (function, userdata, thread),
  /// its Lua type name in `string`; only module-type loading makes one (LuaValueOptions).
  enum class Type : uint8_t { Nil, Boolean, Integer, Number, String, Table, Opaque };
  Type type = Type::Nil;
  bool boolean = false;
  int64_t integer = 0;
  double number = 0;
  std::string string;
  std::vector<std::pair<Value, Value>> table;  ///< keys sorted: copies are deterministic

  // Declared here and defaulted below, with the exception specification spelled out: clang
  // (with libstdc++) cannot deduce it for this recursive type and rejects the implicit ones.
  Value() = default;
  Value(const Value&);
  Value(Value&&) noexcept;
  Value& operator=(const Value&);
  Value& operator=(Value&&) noexcept;
  ~Value();
};
inline Value::Value(const Value&) = default;
inline Value::Value(Value&&) noexcept = default;
inline Value& Value::operator=(const Value&) = default;
inline Value& Value::operator=(Value&&) noexcept = default;
inline Value::~Value() = default;

/// Approximate size in bytes (what message and params limits count).
size_t valueSize(const Value& v);
/// How many values (keys included) and string bytes a value holds: what its copies cost.
struct ValueCounts {
  double values = 0, stringBytes = 0;
};
ValueCounts valueCounts(const Value& v);
/// The value as JSON (tables with keys 1..n become arrays).
nlohmann::json valueToJson(const Value& v);

}  // namespace rm3d
