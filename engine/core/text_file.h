// Reading a whole text file.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace rm3d {

/// Reads a file into a string; false if it cannot be read.
inline bool readTextFile(const std::string& path, std::string& out) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return false;
  std::ostringstream ss;
  ss << f.rdbuf();
  out = ss.str();
  return !f.bad();
}

}  // namespace rm3d
