// Reading a whole text file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace rm3d {

/// The largest text file read whole (a script, a behaviour, a module): 64 MiB.
inline constexpr std::uintmax_t kTextFileLimit = std::uintmax_t(64) << 20;

/// Reads a file into a string; false if it cannot be read, with `why` (when given) saying so.
/// Only a regular file of at most `limit` bytes is read: a FIFO or a device would block or never
/// end, and a huge file would take all memory before any message.
inline bool readTextFile(const std::string& path, std::string& out, std::string* why = nullptr,
                         std::uintmax_t limit = kTextFileLimit) {
  namespace fs = std::filesystem;
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) return fail("no such file");
  if (!fs::is_regular_file(st)) return fail("not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) return fail("cannot read its size");
  const std::string tooBig = "over " + std::to_string(limit >> 20) + " MiB, the most a text file may hold";
  if (size > limit) return fail(tooBig);
  std::ifstream f(path, std::ios::binary);
  if (!f) return fail("cannot open it");
  out.assign(size_t(size), '\0');
  f.read(out.data(), std::streamsize(size));
  out.resize(size_t(f.gcount()));
  if (f.bad()) return fail("a read error");
  if (f.peek() != std::char_traits<char>::eof()) return fail(tooBig);  // it grew while read
  return true;
}

}  // namespace rm3d
