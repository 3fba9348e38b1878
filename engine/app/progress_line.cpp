// The progress line of `rm3d run` on a terminal.
#include "app/progress_line.h"

#include <unistd.h>

#include <cstdio>

#include "world/world.h"

namespace rm3d {

namespace {
constexpr double kQuietSeconds = 3;      ///< wall time before the line appears
constexpr double kRedrawSeconds = 0.25;  ///< between redraws
}  // namespace

ProgressLine::ProgressLine(double endTime)
    : m_enabled(::isatty(STDERR_FILENO) == 1),
      m_endTime(endTime),
      m_start(Clock::now()),
      m_next(m_start +
             std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kQuietSeconds))) {}

void ProgressLine::update(const World& w) {
  if (!m_enabled) return;
  const Clock::time_point now = Clock::now();
  if (now < m_next) return;
  m_next = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kRedrawSeconds));
  const double wall = std::chrono::duration<double>(now - m_start).count();
  const double rtf = wall > 0 ? w.time() / wall : 0;
  char line[160];
  if (m_endTime > 0 && rtf > 0) {
    const double left = (m_endTime - w.time()) / rtf;
    std::snprintf(line, sizeof line, "t=%.2f of %.2f s (%.0f%%), step %lld, %.2fx real time, %.0f s left",
                  w.time(), m_endTime, 100 * w.time() / m_endTime, (long long)w.steps(), rtf,
                  left > 0 ? left : 0);
  } else {
    std::snprintf(line, sizeof line, "t=%.2f s, step %lld, %.2fx real time", w.time(), (long long)w.steps(),
                  rtf);
  }
  // Erase the line, write it, and leave the cursor at its start: a log line printed next
  // overwrites it instead of being glued to its end.
  std::fprintf(stderr, "\r\033[K%s\r", line);
  std::fflush(stderr);
  m_shown = true;
}

void ProgressLine::clear() {
  if (!m_shown) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  m_shown = false;
}

}  // namespace rm3d
