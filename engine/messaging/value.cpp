// Size and JSON form of message values.
#include "messaging/value.h"

#include <nlohmann/json.hpp>

namespace rm3d {

size_t valueSize(const Value& v) {
  size_t s = 16 + v.string.size();
  for (const auto& [k, val] : v.table) s += valueSize(k) + valueSize(val);
  return s;
}

ValueCounts valueCounts(const Value& v) {
  ValueCounts c{1, double(v.string.size())};
  for (const auto& [k, val] : v.table) {
    const ValueCounts a = valueCounts(k), b = valueCounts(val);
    c.values += a.values + b.values;
    c.stringBytes += a.stringBytes + b.stringBytes;
  }
  return c;
}

nlohmann::json valueToJson(const Value& v) {
  switch (v.type) {
    case Value::Type::Nil:
    case Value::Type::Opaque:
      return nullptr;
    case Value::Type::Boolean:
      return v.boolean;
    case Value::Type::Integer:
      return v.integer;
    case Value::Type::Number:
      return v.number;
    case Value::Type::String:
      return v.string;
    case Value::Type::Table: {
      bool isArray = true;
      for (size_t i = 0; i < v.table.size(); ++i)
        if (v.table[i].first.type != Value::Type::Integer || v.table[i].first.integer != int64_t(i + 1))
          isArray = false;
      nlohmann::json j = isArray && !v.table.empty() ? nlohmann::json::array() : nlohmann::json::object();
      for (const auto& [k, val] : v.table) {
        if (isArray)
          j.push_back(valueToJson(val));
        else
          j[k.type == Value::Type::String ? k.string : nlohmann::json(valueToJson(k)).dump()] =
              valueToJson(val);
      }
      return j;
    }
  }
  return nullptr;
}

}  // namespace rm3d
