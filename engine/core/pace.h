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
// kSwitch of its own.
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
    if (m_count[0] < kFirst || m_count[1] < kFirst) return m_count[1] <= m_count[0];
    if (!m_chosen) {
      m_way = m_time[1] < m_time[0];
      m_chosen = true;
    }
    if (m_time[!m_way] < kSwitch * m_time[m_way]) m_way = !m_way;
    return m_calls % kProbe == 0 ? !m_way : m_way;
  }
  /// What the call took, s.
  void took(bool threaded, double seconds) {
    const int w = threaded;
    m_recent[w][m_count[w] % kWindow] = seconds;
    ++m_count[w];
    // The median of the last calls, at most kWindow (the lower of the middle two of an even
    // count): a few compares, at most 8 values.
    const int n = int(std::min<long>(m_count[w], kWindow));
    double v[kWindow];
    std::copy(m_recent[w], m_recent[w] + n, v);
    std::sort(v, v + n);
    m_time[w] = v[(n - 1) / 2];
  }

 private:
  double m_recent[2][kWindow] = {};  ///< s: alone's and the threads' last calls (a ring each)
  double m_time[2] = {0, 0};         ///< s: their medians
  long m_count[2] = {0, 0};
  bool m_way = false;  ///< the way taken (true: the threads)
  bool m_chosen = false;
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
