// A `--param key=value` value as scripts and summaries see it: whole numbers and numbers arrive
// as numbers (a whole number beyond 64 bits as a float), `true`/`false` as booleans, anything else as the
// string given.
#pragma once

#include <cerrno>
#include <cstdlib>
#include <string>

namespace rm3d {

struct ParamValue {
  enum class Kind { Integer, Number, Boolean, String } kind = Kind::String;
  long long integer = 0;
  double number = 0;
  bool boolean = false;
};

inline ParamValue parseParamValue(const std::string& v) {
  ParamValue p;
  if (v.empty()) return p;
  char* end = nullptr;
  errno = 0;
  p.integer = std::strtoll(v.c_str(), &end, 10);
  // A whole number beyond 64 bits is a float, as Lua reads the same literal (strtoll would clamp
  // 2^64 to 2^63 - 1).
  if (*end == '\0' && errno != ERANGE) {
    p.kind = ParamValue::Kind::Integer;
    return p;
  }
  p.number = std::strtod(v.c_str(), &end);
  if (*end == '\0') {
    p.kind = ParamValue::Kind::Number;
  } else if (v == "true" || v == "false") {
    p.kind = ParamValue::Kind::Boolean;
    p.boolean = v == "true";
  }
  return p;
}

}  // namespace rm3d
