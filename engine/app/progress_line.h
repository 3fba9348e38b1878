// `rm3d run`'s progress line: on a terminal (stderr), once a run has taken more than 3 s of wall
// time, a line rewritten 4 times a second with the simulated time, the share done, the speed and
// the time left. Nothing when stderr is not a terminal (pipes, files, tests).
#pragma once

#include <chrono>

namespace rm3d {

class World;

class ProgressLine {
 public:
  /// `endTime`: the simulated time the run stops at (<= 0: unknown, no share or time left).
  explicit ProgressLine(double endTime);
  ~ProgressLine() { clear(); }
  /// After a step: redraws the line when it is due. A clock read, nothing more, when it is not.
  void update(const World& w);
  /// Erases the line (before the run's own output).
  void clear();

 private:
  using Clock = std::chrono::steady_clock;
  bool m_enabled;
  bool m_shown = false;
  double m_endTime;
  Clock::time_point m_start, m_next;
};

}  // namespace rm3d
