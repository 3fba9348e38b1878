// The JUnit XML report of `rm3d test --junit`: one testcase per world, failures with their message.
#pragma once

#include <string>
#include <vector>

namespace rm3d {

/// One world's result under `rm3d test`.
struct TestOutcome {
  std::string file;
  bool passed;
  double seconds;
  std::string message;  ///< why it failed (its first line is the failure's message attribute)
};

/// Writes the report to `path` (a <testsuite name="rm3d"> with the counts and total time; names
/// and messages escaped, invalid UTF-8 as U+FFFD). False when the file cannot be written.
bool writeJunit(const std::string& path, const std::vector<TestOutcome>& outcomes);

}  // namespace rm3d
