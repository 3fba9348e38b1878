// Named series a script records for `rm3d run --trace` (world.trace, module.trace) and the
// viewer's plots: slots in order of first use, the latest value of each, and whether it was
// recorded since the trace writer last took it. A World owns one for its world script and each
// Module one for its behaviour (written only by that behaviour during the behaviour phase).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace rm3d {

struct TraceSeries {
  /// Distinct names one script may record (a world script, or one module's behaviour).
  static constexpr size_t kMaxSeries = 256;
  /// Longest name, in bytes.
  static constexpr size_t kMaxNameLength = 64;

  std::vector<std::string> names;  ///< by slot, in order of first use
  std::vector<double> values;      ///< the latest value per slot
  std::vector<char> fresh;         ///< recorded since the trace writer last took it

  /// A new slot for `name` (the caller has checked it is new and valid, and that there is room).
  int add(std::string_view name) {
    names.emplace_back(name);
    values.push_back(0);
    fresh.push_back(0);
    return int(names.size() - 1);
  }
  void set(int slot, double v) {
    values[size_t(slot)] = v;
    fresh[size_t(slot)] = 1;
  }
  bool full() const { return names.size() >= kMaxSeries; }
};

/// Null when `name` may name a series or metric, else what is wrong with it. Names are 1 to 64
/// characters of letters, digits, `_`, `.` and `-`, so a column `trace.<name>` needs no quoting in
/// CSV, gnuplot or a shell.
inline const char* seriesNameProblem(std::string_view name) {
  if (name.empty()) return "the name is empty";
  if (name.size() > TraceSeries::kMaxNameLength) return "the name is longer than 64 characters";
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '.' || c == '-';
    if (!ok) return "names are letters, digits, '_', '.' and '-'";
  }
  return nullptr;
}

}  // namespace rm3d
