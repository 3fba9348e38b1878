// Whether handing a piece of a step's work to other threads pays, by the clock.
//
// Every piece that goes to the worker threads (the behaviours, the narrowphase's pairs, the
// passes over bodies, the solver's batches, a long tree's halves) gives the same bits on one
// thread, so the choice may follow measured time. It does not always pay: on a machine whose two
// cores passed a cache line back and forth in 0.5 us, a 150-module snake ran at 269 steps/s with a
// second thread on its tree's halves against 398 without, and its behaviours took 0.25 ms a step
// on two threads against 0.17 on one. Both ways are timed, in turn at first; then the faster is
// taken, and the other again once every kProbe calls, so that a change (a scene growing, a machine
// getting busy) is seen. A way's time is the median of its last kWindow calls (the way taken: its
// last calls; the other: its last probes), and the way taken is left when the other's is under
// kSwitch of its own. The way left is then timed afresh, every other call for its first kFirst
// calls: its last calls, the ones that made it look slower, may have been slowed by the machine,
// and with a probe once in 64 calls it took hundreds of calls to see that they were not.
//
// The median, because on a shared machine a call now and then takes several times as long (the
// thread was descheduled), and such a call is noise, not a change of pace. An exponential average
// of about the last 8 calls with a margin of 10% took such a call whole: one call of three times
// the average, in a way 5% faster, moved its average past the other's over the margin; the other
// was taken, and the faster way, from then on only probed and never 10% faster, was not taken
// again (tests/engine/core/pace_test.cpp: threads 5% faster, one call in 20 three times as long:
// 1321 of 2560 calls went to the threads). With the median a way is left after kWindow / 2 + 1
// slow calls in its window. (Before that, every way averaging about its last 4 calls with no
// margin had flipped back and forth on a busy machine: atrons_275's solver batches ran alone in
// half the calls though alone took 1.21 ms against 0.81 on the threads.)
#pragma once

#include <algorithm>
#include <chrono>

namespace rm3d {

class Pace {
 public:
  static constexpr int kFirst = 3;   ///< calls each way, in turn, before choosing
  static constexpr int kProbe = 64;  ///< the way not taken, once in this many calls
  static constexpr int kWindow = 8;  ///< a way's time: the median of this many of its calls
  static constexpr double kSwitch = 0.98;

  /// Whether this call goes to the threads.
  bool threaded() {
    ++m_calls;
    if (m_fresh[0] < kFirst || m_fresh[1] < kFirst) {
      if (!m_chosen) return m_fresh[1] <= m_fresh[0];  // at first: in turn, the threads first
      return m_calls % 2 == 0 ? !m_way : m_way;        // the way just left: every other call
    }
    if (!m_chosen) {
      m_way = m_time[1] < m_time[0];
      m_chosen = true;
    } else if (m_time[!m_way] < kSwitch * m_time[m_way]) {
      m_way = !m_way;
      m_fresh[!m_way] = 0;  // the way left is timed afresh (its last calls may have been slowed)
    }
    return m_calls % kProbe == 0 ? !m_way : m_way;
  }
  /// What the call took, s.
  void took(bool threaded, double seconds) {
    const int w = threaded;
    m_recent[w][m_next[w]] = seconds;
    m_next[w] = (m_next[w] + 1) % kWindow;
    m_fresh[w] = std::min(m_fresh[w] + 1, kWindow);
    // The median of its calls since it was last timed afresh, at most kWindow (the lower of the
    // middle two of an even count): a few compares, at most 8 values.
    const int n = m_fresh[w];
    double v[kWindow];
    for (int i = 0; i < n; ++i) v[i] = m_recent[w][(m_next[w] + kWindow - 1 - i) % kWindow];
    std::sort(v, v + n);
    m_time[w] = v[(n - 1) / 2];
  }

 private:
  double m_recent[2][kWindow] = {};  ///< s: alone's and the threads' last calls (a ring each)
  int m_next[2] = {0, 0};            ///< where each ring's next call goes
  int m_fresh[2] = {0, 0};           ///< calls in each way's time (at most kWindow)
  double m_time[2] = {0, 0};         ///< s: their medians
  bool m_way = false;                ///< the way taken (true: the threads)
  bool m_chosen = false;             ///< the first calls are over
  long m_calls = 0;
};

/// Runs threads() or alone(), as `pace` says (always threads() with `always`), and times it;
/// returns whether it took the threads.
template <class Threads, class Alone>
bool runPaced(Pace& pace, bool always, const Threads& threads, const Alone& alone) {
  const bool t = always || pace.threaded();
  const auto start = std::chrono::steady_clock::now();
  if (t)
    threads();
  else
    alone();
  pace.took(t, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return t;
}

}  // namespace rm3d
