// Where scripts read their Lua sources: the disk, noting every text read (what `run --record`
// stores), or the texts of a recording laid over the disk (what `run --fork` re-simulates with).
// One per run, shared by the world VM, the module-type loader and every behaviour VM; reads may
// come from worker threads (a require inside step()), so it locks.
#pragma once

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace rm3d {

class SourceFiles {
 public:
  /// Reads `path`: the overlay's text when the overlay is on, else the file. Notes what it read
  /// (the first text per path). False when neither has it.
  bool read(const std::string& path, std::string& out, std::string* why = nullptr);
  /// True when `path` is a source: with the overlay on, a .lua path must be in it (so a run
  /// resolves names exactly as the recorded one did); anything else is a regular file on disk.
  bool isFile(const std::string& path) const;
  /// True when the overlay is on and holds `path` (its text needs no check of where it lies).
  bool overlaid(const std::string& path) const;

  /// Serves these texts (absolute, normalised paths) instead of the disk's.
  void setOverlay(std::map<std::string, std::string> texts);
  /// Back to the disk (the fork point: later reads see the files as they are now).
  void clearOverlay();
  bool overlayOn() const;

  /// From now on, files the overlay does not hold are read from disk only inside these folders
  /// (absolute; a restored snapshot's project root); `note` is added to the message of a refusal.
  void limitDisk(std::vector<std::string> folders, std::string note);
  /// True when the file at `path` may be read from disk: no limit, or it really lies (links
  /// resolved) inside a folder of limitDisk.
  bool diskAllowed(const std::string& path) const;
  /// The limit's note ("" without a limit).
  std::string diskNote() const;

  /// The texts read so far, by absolute path, in the order they were first read.
  std::vector<std::pair<std::string, std::string>> taken() const;

  /// The key a path is noted and looked up under: absolute and lexically normal.
  static std::string key(const std::string& path);

 private:
  mutable std::mutex m_mutex;
  bool m_overlayOn = false;
  bool m_diskLimited = false;
  std::vector<std::string> m_diskFolders;
  std::string m_diskNote;
  std::map<std::string, std::string> m_overlay;
  std::vector<std::pair<std::string, std::string>> m_taken;
  std::set<std::string> m_seen;
};

}  // namespace rm3d
