// One world being watched and edited: what `run --watch` and `view` share. Owns the World, the
// RunOptions it is built with and the FileWatcher; loads the world file, and on poll() reloads
// changed behaviours and lua/ files into the running modules (state kept) or rebuilds the world
// when the world file changed. A world file that fails to load keeps the last good world
// running; the error (file:line) is kept until a later save loads.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "app/file_watcher.h"
#include "world/world.h"

namespace rm3d {

/// What one poll() (or rebuild()) did.
struct SessionChanges {
  struct Reload {
    std::string file;
    int modules = 0;    ///< modules that took the new code
    double millis = 0;  ///< time the reload took
  };
  struct Rejected {
    std::string file;
    std::string error;  ///< file:line: what is wrong; the old code keeps running
  };
  std::vector<Reload> reloaded;
  std::vector<Rejected> rejected;
  bool rebuilt = false;    ///< a new world replaced the previous one
  std::string worldError;  ///< the world file was rejected (file:line); the previous world, if any, runs on

  bool empty() const { return reloaded.empty() && rejected.empty() && !rebuilt && worldError.empty(); }
};

class WorldSession {
 public:
  using Clock = std::chrono::steady_clock;

  /// `worldFile` as given on the command line. poll() looks at the files at most once per
  /// `pollInterval` (zero: every call).
  WorldSession(std::string worldFile, RunOptions options,
               std::chrono::milliseconds pollInterval = std::chrono::milliseconds(100));

  /// Builds the world from the file. False (and worldError()) when it is rejected: then there
  /// is no world unless an earlier load succeeded, and the world file is still watched.
  bool load();
  /// A new world from the file now (the viewer's R). Same as a world-file edit seen by poll().
  SessionChanges rebuild();
  /// Reloads what changed since the last look, or rebuilds on a changed world file (or any
  /// change while the world file is rejected, since the mistake may sit in a required file).
  SessionChanges poll();

  bool hasWorld() const { return m_world != nullptr; }
  World& world() { return *m_world; }
  const World& world() const { return *m_world; }
  const std::string& worldFile() const { return m_worldFile; }
  const RunOptions& options() const { return m_options; }
  /// Why the world file as last saved is rejected, or empty.
  const std::string& worldError() const { return m_worldError; }
  /// file -> why its last edit was rejected (the old code keeps running); cleared on rebuild.
  const std::map<std::string, std::string>& reloadErrors() const { return m_reloadErrors; }
  /// How many files are watched.
  size_t watchedCount() const { return m_watcher.size(); }

 private:
  std::unique_ptr<World> build(std::string& err) const;
  void takeStamps();

  std::string m_worldFile;
  std::string m_worldPath;  ///< absolute, normalised
  RunOptions m_options;
  std::chrono::milliseconds m_interval;
  Clock::time_point m_lastPoll{};
  std::unique_ptr<World> m_world;
  std::string m_worldError;
  std::map<std::string, std::string> m_reloadErrors;
  FileWatcher m_watcher;
};

}  // namespace rm3d
