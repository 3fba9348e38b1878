#include "core/source_files.h"

#include <filesystem>

#include "core/path_rule.h"
#include "core/text_file.h"

namespace fs = std::filesystem;

namespace rm3d {

std::string SourceFiles::key(const std::string& path) {
  std::error_code ec;
  const fs::path abs = fs::absolute(path, ec);
  return (ec ? fs::path(path) : abs).lexically_normal().string();
}

bool SourceFiles::read(const std::string& path, std::string& out, std::string* why) {
  const std::string k = key(path);
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_overlayOn) {
      auto it = m_overlay.find(k);
      if (it != m_overlay.end()) {
        out = it->second;
        if (m_seen.insert(k).second) m_taken.emplace_back(k, out);
        return true;
      }
      if (fs::path(k).extension() == ".lua") {
        if (why) *why = "not among the recorded texts";
        return false;
      }
    }
  }
  if (!diskAllowed(path)) {
    if (why) *why = "outside the folders this world reads" + diskNote();
    return false;
  }
  if (!readTextFile(path, out, why)) return false;
  std::lock_guard<std::mutex> lock(m_mutex);
  if (m_seen.insert(k).second) m_taken.emplace_back(k, out);
  return true;
}

bool SourceFiles::isFile(const std::string& path) const {
  const std::string k = key(path);
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_overlayOn && fs::path(k).extension() == ".lua") return m_overlay.count(k) > 0;
  }
  std::error_code ec;
  return diskAllowed(path) && fs::is_regular_file(path, ec);
}

void SourceFiles::limitDisk(std::vector<std::string> folders, std::string note) {
  std::lock_guard<std::mutex> lock(m_mutex);
  m_diskLimited = true;
  m_diskFolders = std::move(folders);
  m_diskNote = std::move(note);
}

bool SourceFiles::diskAllowed(const std::string& path) const {
  std::vector<std::string> folders;
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (!m_diskLimited) return true;
    folders = m_diskFolders;
  }
  std::error_code ec;
  const fs::path real = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) return false;
  for (const std::string& f : folders) {
    const fs::path dir = fs::weakly_canonical(f, ec);
    if (!ec && pathInside(real.lexically_normal().string(), dir.lexically_normal().string())) return true;
  }
  return false;
}

std::string SourceFiles::diskNote() const {
  std::lock_guard<std::mutex> lock(m_mutex);
  return m_diskNote;
}

bool SourceFiles::overlaid(const std::string& path) const {
  std::lock_guard<std::mutex> lock(m_mutex);
  return m_overlayOn && m_overlay.count(key(path)) > 0;
}

void SourceFiles::setOverlay(std::map<std::string, std::string> texts) {
  std::lock_guard<std::mutex> lock(m_mutex);
  m_overlay = std::move(texts);
  m_overlayOn = true;
}

void SourceFiles::clearOverlay() {
  std::lock_guard<std::mutex> lock(m_mutex);
  m_overlayOn = false;
}

bool SourceFiles::overlayOn() const {
  std::lock_guard<std::mutex> lock(m_mutex);
  return m_overlayOn;
}

std::vector<std::pair<std::string, std::string>> SourceFiles::taken() const {
  std::lock_guard<std::mutex> lock(m_mutex);
  return m_taken;
}

}  // namespace rm3d
