#include "app/world_session.h"

#include <filesystem>
#include <system_error>

#include "core/error.h"

namespace fs = std::filesystem;

namespace rm3d {

WorldSession::WorldSession(std::string worldFile, RunOptions options, std::chrono::milliseconds pollInterval)
    : m_worldFile(std::move(worldFile)),
      m_worldPath(fs::absolute(m_worldFile).lexically_normal().string()),
      m_options(std::move(options)),
      m_interval(pollInterval) {}

std::unique_ptr<World> WorldSession::build(std::string& err) const {
  std::error_code ec;
  if (!fs::is_regular_file(m_worldFile, ec)) {
    err = m_worldFile + ": cannot read world file (" +
          (fs::exists(m_worldFile, ec) ? "not a regular file" : "no such file") + ")";
    return nullptr;
  }
  auto w = std::make_unique<World>(m_options);
  try {
    w->loadFile(m_worldFile);
  } catch (const InputError& e) {
    err = e.what();
    return nullptr;
  }
  return w;
}

bool WorldSession::load() {
  return rebuild().worldError.empty();
}

SessionChanges WorldSession::rebuild() {
  SessionChanges out;
  std::string err;
  std::unique_ptr<World> w = build(err);
  if (w) {
    m_world = std::move(w);
    m_worldError.clear();
    m_reloadErrors.clear();
    out.rebuilt = true;
  } else {
    m_worldError = err;
    out.worldError = err;
  }
  takeStamps();
  m_lastPoll = Clock::now();
  return out;
}

void WorldSession::takeStamps() {
  // While the world file is rejected, keep watching what the last good world used too: the
  // mistake may sit in a required lua/ file.
  std::vector<std::string> files;
  if (m_world) files = m_world->watchedFiles();
  files.push_back(m_worldPath);
  if (!m_worldError.empty())
    for (const std::string& f : m_watcher.files()) files.push_back(f);
  m_watcher.reset(files);
}

SessionChanges WorldSession::poll() {
  const auto now = Clock::now();
  if (now - m_lastPoll < m_interval) return {};
  m_lastPoll = now;
  SessionChanges out;
  for (const std::string& file : m_watcher.changed()) {
    if (!m_world || !m_worldError.empty() || file == m_worldPath || file == m_world->worldFile())
      return rebuild();
    const auto t0 = Clock::now();
    std::vector<std::string> errors;
    const int n = m_world->reloadFile(file, errors);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (errors.empty()) {
      m_reloadErrors.erase(file);
    } else {
      std::string text;
      for (const std::string& e : errors) {
        out.rejected.push_back({file, e});
        text += (text.empty() ? "" : "\n") + e;
      }
      m_reloadErrors[file] = text;
    }
    if (n > 0) out.reloaded.push_back({file, n, ms});
  }
  return out;
}

}  // namespace rm3d
