// Polls files' modification times for hot reload (`run --watch` and `view`).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace rm3d {

class FileWatcher {
 public:
  /// Starts watching exactly these files, remembering their current times.
  void reset(const std::vector<std::string>& files) {
    m_stamps.clear();
    std::error_code ec;
    for (const std::string& f : files) m_stamps[f] = std::filesystem::last_write_time(f, ec);
  }
  /// Files written since the last reset() or changed(), in name order.
  std::vector<std::string> changed() {
    std::vector<std::string> out;
    std::error_code ec;
    for (auto& [file, stamp] : m_stamps) {
      const auto t = std::filesystem::last_write_time(file, ec);
      if (ec || t == stamp) continue;
      stamp = t;
      out.push_back(file);
    }
    return out;
  }
  std::vector<std::string> files() const {
    std::vector<std::string> out;
    for (const auto& [f, stamp] : m_stamps) out.push_back(f);
    return out;
  }
  size_t size() const { return m_stamps.size(); }

 private:
  std::map<std::string, std::filesystem::file_time_type> m_stamps;
};

}  // namespace rm3d
